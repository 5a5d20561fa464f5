"""Load on the data plane: 50 concurrent boto3 iot-data clients for 2 minutes.

Each client is a real boto3 `iot-data` client (its own connection pool) pointed at the
local data plane, as the skill's is; each loops over a random mix of Publish (to its
robot's command topic), GetThingShadow and UpdateThingShadow of its own thing. Clients run
as threads spread over worker processes (so boto3's own CPU use is not all behind one
GIL), and the stack serves from this process. Reported: throughput, p50/p99 latency per
operation, client errors and server errors (5xx, the target is none).
Run: `.venv/bin/python bench/dataplane_load.py [--clients 50] [--seconds 120]`.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import random
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from _results import percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.twin.stack import LocalStack, StackConfig  # noqa: E402

OPERATIONS = ("publish", "get", "update")
THREADS_PER_PROCESS = 10


def _client_loop(api: str, thing: str, deadline: float, seed: int) -> dict[str, Any]:
    import boto3
    from botocore.config import Config
    from botocore.exceptions import ClientError, EndpointConnectionError

    client = boto3.client(
        "iot-data",
        endpoint_url=api,
        region_name="us-east-1",
        aws_access_key_id="load",
        aws_secret_access_key="load",
        config=Config(retries={"max_attempts": 1}, max_pool_connections=2),
    )
    rng = random.Random(seed)
    latencies: dict[str, list[float]] = {op: [] for op in OPERATIONS}
    errors = {"client": 0, "server": 0}
    client.update_thing_shadow(thingName=thing, payload=b'{"state":{"reported":{"n":0}}}')
    count = 0
    while time.monotonic() < deadline:
        operation = rng.choice(OPERATIONS)
        started = time.perf_counter()
        try:
            if operation == "publish":
                client.publish(topic=f"vahr/robots/{thing}/cmd", qos=1, payload=b'{"load":1}')
            elif operation == "get":
                client.get_thing_shadow(thingName=thing)["payload"].read()
            else:
                count += 1
                payload = b'{"state":{"reported":{"n":%d}}}' % count
                client.update_thing_shadow(thingName=thing, payload=payload)["payload"].read()
        except ClientError as err:
            status = err.response.get("ResponseMetadata", {}).get("HTTPStatusCode", 0)
            errors["server" if status >= 500 else "client"] += 1
            continue
        except EndpointConnectionError:
            errors["server"] += 1
            continue
        latencies[operation].append((time.perf_counter() - started) * 1000)
    return {"latencies": latencies, "errors": errors}


def _worker(api: str, first: int, threads: int, deadline: float, out: Any) -> None:
    results: list[dict[str, Any]] = []
    lock = threading.Lock()

    def run(index: int) -> None:
        result = _client_loop(api, f"loadbot{index}", deadline, seed=index)
        with lock:
            results.append(result)

    workers = [threading.Thread(target=run, args=(first + i,)) for i in range(threads)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join()
    out.put(results)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--clients", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=120.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        config = StackConfig(
            state_dir=Path(tmp), mqtts_port=free_port(), mqtt_port=None, api_port=free_port()
        )
        with LocalStack(config) as stack:
            context = multiprocessing.get_context("spawn")
            queue = context.Queue()
            deadline = time.monotonic() + args.seconds + 5  # clients start within 5 s
            processes = []
            for first in range(0, args.clients, THREADS_PER_PROCESS):
                threads = min(THREADS_PER_PROCESS, args.clients - first)
                process = context.Process(
                    target=_worker, args=(stack.api_url, first, threads, deadline, queue)
                )
                process.start()
                processes.append(process)
            results = [r for _ in processes for r in queue.get(timeout=args.seconds + 120)]
            for process in processes:
                process.join(timeout=30)
    by_operation = {
        op: [value for r in results for value in r["latencies"][op]] for op in OPERATIONS
    }
    total = sum(len(values) for values in by_operation.values())
    client_errors = sum(r["errors"]["client"] for r in results)
    server_errors = sum(r["errors"]["server"] for r in results)
    rows = [
        f"| {op} | {len(values):,} | {percentile(values, 50):.1f} | {percentile(values, 99):.1f} |"
        for op, values in by_operation.items()
    ]
    everything = [value for values in by_operation.values() for value in values]
    body = f"""
{args.clients} boto3 iot-data clients (threads in {len(processes)} processes), a random mix
of Publish, GetThingShadow and UpdateThingShadow on each client's own thing, for
{args.seconds:.0f} s against the local data plane (`LocalStack`, one process).

| operation | requests | p50 ms | p99 ms |
| --- | --- | --- | --- |
{chr(10).join(rows)}
| all | {total:,} | {percentile(everything, 50):.1f} | {percentile(everything, 99):.1f} |

Throughput {total / args.seconds:,.0f} requests/s; client errors (4xx) {client_errors};
server errors (5xx or dropped connections) {server_errors} (target 0).
"""
    write_section("dataplane_load", "Data plane under load", body)
    if server_errors:
        raise SystemExit(f"{server_errors} server errors")


if __name__ == "__main__":
    os.environ.setdefault("AWS_EC2_METADATA_DISABLED", "true")
    main()
