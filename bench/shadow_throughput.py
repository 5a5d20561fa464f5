"""Shadow service throughput: accepted shadow updates per second over MQTT.

The local stack (mosquitto, the shadow service with its SQLite store, the data plane) runs
in this process. A load process, as robots are on their own machines, connects to the
plaintext listener, subscribes to every `update/accepted`, and publishes `--updates`
reported-state updates (the robot-agent's own document: status, zone, cargo, last
command, pose, a client token) round-robin over `--things` shadows as fast as its QoS 1
window allows. The clock runs from the first publish to the last `update/accepted`, so
every update was merged, versioned, stamped, committed to disk and answered.
Run: `.venv/bin/python bench/shadow_throughput.py [--things 1000] [--updates 20000] [--runs 3]`.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from _results import median, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.twin.stack import LocalStack, StackConfig  # noqa: E402

TARGET_PER_S = 5000
BEFORE = "about 700 acknowledgments per second (measured through `bench/fanout.py`)"


def _report(thing: str, sequence: int) -> bytes:
    """A robot's reported state as robot-agent sends it (about 330 bytes)."""
    return (
        '{"state":{"reported":{"status":"navigating","zone":null,"cargo":false,'
        f'"last_command":{{"id":"cmd-{sequence:08d}","action":"navigate","result":"accepted"}},'
        '"task":"navigate","destination":"B",'
        f'"pose":{{"x":{sequence % 97 / 10:.3f},"y":4.250,"theta":0.785}},"connected":true}}}},'
        f'"clientToken":"{thing}-{sequence}"}}'
    ).encode()


def load_process(mqtt_url: str, things: int, updates: int, runs: int, results: Any) -> None:
    """Publish the updates and time them to the last accepted answer, `runs` times."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
    from vahr.protocol import topics

    port = int(mqtt_url.rsplit(":", 1)[1])
    names = [f"load{index:05d}" for index in range(things)]
    accepted = 0
    lock = threading.Lock()
    done = threading.Event()
    expected = 0

    def on_accepted(topic: str, payload: bytes) -> None:
        nonlocal accepted
        with lock:
            accepted += 1
            if accepted >= expected:
                done.set()

    with MqttClient(MqttEndpoint(port=port)) as client:
        client.subscribe(topics.ALL_SHADOW_UPDATES_ACCEPTED, on_accepted)
        for run in range(runs + 1):  # the first run warms up (creates the shadows)
            bodies = [
                (topics.shadow(names[i % things], "update"), _report(names[i % things], i))
                for i in range(updates)
            ]
            with lock:
                accepted, expected = 0, updates
                done.clear()
            started = time.perf_counter()
            for topic, body in bodies:
                client.publish(topic, body, qos=1, wait=False)
            if not done.wait(120):
                results.put(("error", f"only {accepted} of {updates} updates accepted"))
                return
            elapsed = time.perf_counter() - started
            results.put(("run" if run else "warm-up", elapsed))
            time.sleep(1.0)
    results.put(("end", None))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--things", type=int, default=1000)
    parser.add_argument("--updates", type=int, default=20000)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    rates: list[float] = []
    service_cpu_us: list[float] = []
    with tempfile.TemporaryDirectory(prefix="vahr-shadow-load-") as state:
        config = StackConfig(
            state_dir=Path(state), mqtts_port=free_port(), mqtt_port=free_port(),
            api_port=free_port(),
        )  # fmt: skip
        with LocalStack(config) as stack:
            assert stack.mqtt_url is not None and stack.shadows is not None
            context = multiprocessing.get_context("spawn")
            results = context.Queue()
            loader = context.Process(
                target=load_process,
                args=(stack.mqtt_url, args.things, args.updates, args.runs, results),
            )
            loader.start()
            cpu_before = time.process_time()
            try:
                while True:
                    kind, value = results.get(timeout=600)
                    if kind == "error":
                        raise RuntimeError(value)
                    if kind == "end":
                        break
                    if kind == "warm-up":
                        cpu_before = time.process_time()
                        continue
                    rates.append(args.updates / value)
                    cpu = time.process_time() - cpu_before
                    service_cpu_us.append(cpu / args.updates * 1e6)
                    print(
                        f"{args.updates} updates in {value:.2f} s, "
                        f"{service_cpu_us[-1]:.0f} us of the stack's CPU each",
                        file=sys.stderr,
                    )
                    cpu_before = time.process_time()  # each run's CPU is its own
            finally:
                loader.join(30)
                if loader.is_alive():
                    loader.kill()
            bursts = stack.shadows.bursts
    total = args.updates * (args.runs + 1)
    rows = "\n".join(
        f"| {i + 1} | {args.updates / r:.2f} | {r:,.0f} | {c:.0f} |"
        for i, (r, c) in enumerate(zip(rates, service_cpu_us, strict=True))
    )
    body = f"""
{args.updates:,} reported-state updates (robot-agent's document, about 330 bytes) over
MQTT to {args.things:,} shadows, published by one load process as fast as its QoS 1 window
allows, timed from the first publish to the last `update/accepted` (each update merged,
versioned, stamped, committed to SQLite and answered on `accepted` and `documents`). The
stack and the load process share the machine's 2 cores; a warm-up run creates the shadows.

| run | seconds | accepted updates/s | CPU of the stack's process per update (µs) |
| --- | --- | --- | --- |
{rows}

Median **{median(rates):,.0f} accepted updates/s** (target at least {TARGET_PER_S:,}:
{"met" if median(rates) >= TARGET_PER_S else "NOT met"}); {total:,} updates were committed in
{bursts:,} SQLite transactions. The stack's CPU per update (its MQTT client, the
service, SQLite; mosquitto apart) bounds what one quiet core could do:
{1e6 / median(service_cpu_us):,.0f} updates/s. Before (one commit and one publish call per
answer on the MQTT network thread): {BEFORE}.
"""
    write_section("shadow_throughput", "Shadow service throughput", body)
    return 0


if __name__ == "__main__":
    os.environ.setdefault("AWS_ACCESS_KEY_ID", "bench")
    raise SystemExit(main())
