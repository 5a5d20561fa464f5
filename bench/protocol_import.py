"""Benchmark: the cold-start cost of `import vahr.protocol` and its decode throughput.

The import is timed inside fresh interpreters (the way a Lambda cold start pays it): in the
development venv, alone and after boto3 and ask-sdk-core (what the skill actually adds),
beside msgspec alone; and from the precompiled Lambda bundle in CPython 3.12, the
function's own environment. Throughput decodes and validates a typical
command against the fleet, in one process.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import median, percentile, write_section

TIMER = (
    "import time; t = time.perf_counter(); import {module}; print((time.perf_counter() - t) * 1000)"
)


def import_ms(module: str, preload: str = "", runs: int = 25) -> list[float]:
    code = (f"import {preload}; " if preload else "") + TIMER.format(module=module)
    command = [sys.executable, "-c", code]
    return [
        float(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
        for _ in range(runs)
    ]


def import_ms_in_bundle(runs: int) -> list[float] | None:
    """`import vahr.protocol` from the precompiled Lambda bundle, isolated, in CPython 3.12."""
    from lambda_bundle import python312

    python = python312()
    if python is None:
        return None
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from infra import lambda_asset

    with tempfile.TemporaryDirectory() as scratch:
        bundle = lambda_asset.build(Path(scratch) / "bundle", compile_with=Path(python)).out_dir
        code = f"import sys; sys.path[:0] = [{str(bundle)!r}]; " + TIMER.format(
            module="vahr.protocol"
        )
        command = [python, "-I", "-c", code]
        return [
            float(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
            for _ in range(runs)
        ]


def decode_rate(seconds: float = 2.0) -> tuple[float, float]:
    from vahr.domain import load_fleet
    from vahr.protocol import decode_command, encode, new_command

    fleet = load_fleet()
    payload = encode(new_command("deliver", {"zone": "B"}, source="alexa"))
    bad = payload.replace(b'"B"', b'"E"')
    rates = []
    for sample in (payload, bad):
        count, deadline = 0, time.perf_counter() + seconds / 2
        start = time.perf_counter()
        while time.perf_counter() < deadline:
            for _ in range(1000):
                try:
                    decode_command(sample, fleet)
                except ValueError:
                    pass
            count += 1000
        rates.append(count / (time.perf_counter() - start))
    return rates[0], rates[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=25, help="fresh interpreters per measurement")
    args = parser.parse_args()
    alone = import_ms("vahr.protocol", runs=args.runs)
    msgspec_alone = import_ms("msgspec", runs=args.runs)
    after_skill_deps = import_ms(
        "vahr.protocol", preload="boto3, ask_sdk_core.skill_builder", runs=args.runs
    )
    in_bundle = import_ms_in_bundle(args.runs)
    good, bad = decode_rate()
    rows = [
        ("`vahr.protocol` alone", alone),
        ("`msgspec` alone (the validation library it is built on)", msgspec_alone),
        (
            "`vahr.protocol` after `boto3` and `ask_sdk_core` (what the skill adds)",
            after_skill_deps,
        ),
    ]
    if in_bundle is not None:
        rows.append(("`vahr.protocol` from the Lambda bundle in CPython 3.12", in_bundle))
    table = "\n".join(
        f"| {what} | {median(ms):.1f} | {percentile(ms, 90):.1f} |" for what, ms in rows
    )
    body = (
        f"Import time in a fresh interpreter ({args.runs} runs each; target under 30 ms):\n\n"
        "| what is imported | median ms | p90 ms |\n| --- | ---: | ---: |\n"
        f"{table}\n\n"
        f"Decode and validate against the fleet (one process): {good:,.0f} valid commands/s;\n"
        f"{bad:,.0f} rejected commands/s (bad zone, error message built).\n"
    )
    write_section("protocol_import", "Wire contract: import cost and decode throughput", body)


if __name__ == "__main__":
    main()
