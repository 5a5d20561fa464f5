"""Understanding people: the Alexa simulator's NLU per utterance, its build, and `vahr up`.

In one run:
- NLU time per utterance (p50, p99) over the development set, every sentence said
  `--rounds` times, with the classifier loaded from its cache (what a turn pays);
- the NLU's build at start-up in a fresh process, imports included: cold (empty cache,
  scikit-learn imported and the classifier trained) and cached (the exported model read);
- `vahr up` from spawn to its endpoints line and to a first answered `vahr say`, for this
  checkout (NLU cache warm and cold) and for the commit before the statistical NLU
  (`--before`, checked out in a temporary worktree and run with the same interpreter).
Run: `.venv/bin/python bench/understanding.py [--rounds N] [--runs N] [--before REF]`.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

from _results import median, percentile, write_section

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet  # noqa: E402
from vahr.assistant.nlu import InteractionModel  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402

# The last commit whose simulator matched samples literally (before issue 13's NLU).
BEFORE = "74f297b"
BUILD_PROBE = """
import sys, time
started = time.perf_counter()
from pathlib import Path
from vahr.assistant.nlu import InteractionModel
model = InteractionModel.load(cache_dir=Path(sys.argv[1]))
model.understand("send robot one to zone b")
print(time.perf_counter() - started, model.cached)
"""


def nlu_times(rounds: int) -> tuple[list[float], int]:
    """Milliseconds per `understand` over the development set, `rounds` times."""
    model = InteractionModel.load()
    sentences = [item.text for item in LabelledSet.load(DEVELOPMENT_SET).items()]
    model.understand(sentences[0])
    times = []
    for _ in range(rounds):
        for sentence in sentences:
            started = time.perf_counter()
            model.understand(sentence)
            times.append((time.perf_counter() - started) * 1000)
    return times, len(sentences)


def build_seconds(cache_dir: Path) -> tuple[float, bool]:
    """A fresh interpreter's import, build and first answer, in seconds; and whether the
    classifier came from the cache."""
    done = subprocess.run(
        [sys.executable, "-c", BUILD_PROBE, str(cache_dir)],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    seconds, cached = done.stdout.split()
    return float(seconds), cached == "True"


def up_seconds(checkout: Path, cache_home: Path) -> tuple[float, float]:
    """`vahr up` in `checkout`: seconds to its endpoints line and to a first answered turn."""
    with tempfile.TemporaryDirectory(prefix="vahr-bench-up-") as state:
        api = free_port()
        command = [
            sys.executable,
            "-c",
            "import sys; from vahr.cli import main; sys.exit(main())",
            "up",
            "--json",
            "--no-voice",
            "--state-dir",
            state,
            "--api-port",
            str(api),
            "--mqtt-port",
            "0",
            "--mqtts-port",
            str(free_port()),
        ]
        env = {**os.environ, "PYTHONPATH": str(checkout), "XDG_CACHE_HOME": str(cache_home)}
        started = time.perf_counter()
        process = subprocess.Popen(
            command, cwd=checkout, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL
        )
        try:
            assert process.stdout is not None
            if not process.stdout.readline():
                raise RuntimeError(f"vahr up in {checkout} printed nothing")
            endpoints = time.perf_counter() - started
            request = urllib.request.Request(
                f"http://127.0.0.1:{api}/vahr/say",
                data=json.dumps({"utterance": "where are the robots"}).encode(),
                headers={"Content-Type": "application/json"},
                method="POST",
            )
            with urllib.request.urlopen(request, timeout=300) as answer:
                answer.read()
            first_turn = time.perf_counter() - started
        finally:
            process.send_signal(signal.SIGTERM)
            process.wait(60)
    return endpoints, first_turn


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=20)
    parser.add_argument("--runs", type=int, default=5, help="vahr up starts per variant")
    parser.add_argument("--before", default=BEFORE, help="commit to compare vahr up with")
    args = parser.parse_args()

    times, sentences = nlu_times(args.rounds)
    with tempfile.TemporaryDirectory(prefix="vahr-bench-nlu-") as scratch:
        cold_dir = Path(scratch) / "cold"
        cold = [build_seconds(cold_dir / str(run))[0] for run in range(2)]
        warm_dir = Path(scratch) / "warm"
        build_seconds(warm_dir)
        warm = [build_seconds(warm_dir)[0] for _ in range(args.runs)]

        before_tree = Path(scratch) / "before"
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(before_tree), args.before],
            check=True,
            capture_output=True,
        )
        try:
            warm_home = Path(scratch) / "home-warm"
            up_seconds(ROOT, warm_home)  # fills the warm cache
            runs: dict[str, list[tuple[float, float]]] = {
                "before": [],
                "after, NLU cached": [],
                "after, NLU cold": [],
            }
            for run in range(args.runs):
                runs["before"].append(up_seconds(before_tree, Path(scratch) / "home-before"))
                runs["after, NLU cached"].append(up_seconds(ROOT, warm_home))
                if run < 2:
                    cold_home = Path(scratch) / f"home-cold-{run}"
                    runs["after, NLU cold"].append(up_seconds(ROOT, cold_home))
        finally:
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(before_tree)],
                check=False,
                capture_output=True,
            )

    p50, p99 = median(times), percentile(times, 99)
    before_up = median([endpoints for endpoints, _ in runs["before"]])
    rows = []
    for name, measured in runs.items():
        up = median([endpoints for endpoints, _ in measured])
        turn = median([first for _, first in measured])
        rows.append(
            f"| {name} | {len(measured)} | {up:.2f} s | {up - before_up:+.2f} s | {turn:.2f} s |"
        )
    body = f"""
NLU per utterance ({sentences} development-set sentences x {args.rounds}; classifier from its
cache): **p50 {p50:.2f} ms**, p99 {p99:.2f} ms (budget: at most 5 ms p50 added to a turn).

NLU build at start-up, a fresh interpreter importing, building and answering once:

| build | runs | median |
| --- | --- | --- |
| cold (scikit-learn imported, classifier trained and cached) | {len(cold)} | {median(cold):.2f} s |
| cached (exported model read, no scikit-learn) | {len(warm)} | {median(warm):.2f} s |

`vahr up --no-voice`, spawn to the endpoints line and to the first answered turn ("where
are the robots"); `before` is the literal-match simulator (`--before`). The
classifier builds on a thread while the stack starts; `vahr up` prints its endpoints only
once it can answer, so a cold cache (the classifier trained, a first start only) delays
the endpoints and the first turn alike. Budget: at most 1 s added to a start with the NLU
cached.

| checkout | runs | to endpoints (median) | vs before | to first turn (median) |
| --- | --- | --- | --- | --- |
{chr(10).join(rows)}

The robot's hearing (per clip, beside the recognizer alone) is `bench/hearing.py`'s section.
"""
    write_section("understanding", "Understanding people: the simulator's NLU", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
