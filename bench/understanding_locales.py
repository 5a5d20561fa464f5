"""Understanding people in each shipped locale: the simulator's NLU per utterance and its build.

In one run, for en-US and de-DE:
- NLU time per utterance (p50, p99) over the locale's development set, every sentence said
  `--rounds` times, with the models loaded from their cache (what a turn pays);
- the NLU's build in a fresh process, imports included: cold (empty cache: the classifier
  and the roles taggers trained) and cached (the exported models read).
Run: `.venv/bin/python bench/understanding_locales.py [--rounds N] [--runs N]`.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import median, percentile, write_section

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet  # noqa: E402
from vahr.assistant.localized import load_model  # noqa: E402

LOCALES = ("en-US", "de-DE")
BUILD_PROBE = """
import sys, time
started = time.perf_counter()
from pathlib import Path
from vahr.assistant.localized import load_model
model = load_model(sys.argv[2], cache_dir=Path(sys.argv[1]))
model.understand("placebot eins fahr in zone b")
print(time.perf_counter() - started)
"""


def devset(locale: str) -> Path:
    return DEVELOPMENT_SET.with_name(f"devset-{locale}.yaml")


def nlu_times(locale: str, rounds: int) -> tuple[list[float], int]:
    """Milliseconds per `understand` over the locale's development set, `rounds` times."""
    model = load_model(locale)
    sentences = [item.text for item in LabelledSet.load(devset(locale)).items()]
    model.understand(sentences[0])
    times = []
    for _ in range(rounds):
        for sentence in sentences:
            started = time.perf_counter()
            model.understand(sentence)
            times.append((time.perf_counter() - started) * 1000)
    return times, len(sentences)


def build_seconds(cache: Path, locale: str) -> float:
    result = subprocess.run(
        [sys.executable, "-c", BUILD_PROBE, str(cache), locale],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=600,
    )  # fmt: skip
    return float(result.stdout.split()[-1])


def load_average() -> str:
    return Path("/proc/loadavg").read_text().split()[0]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--runs", type=int, default=3, help="cached builds per locale")
    args = parser.parse_args()
    rows = []
    loads = [load_average()]
    for locale in LOCALES:
        times, sentences = nlu_times(locale, args.rounds)
        with tempfile.TemporaryDirectory(prefix="vahr-bench-locale-") as scratch:
            cold = build_seconds(Path(scratch) / "cold", locale)
            warm_dir = Path(scratch) / "warm"
            build_seconds(warm_dir, locale)
            warm = median([build_seconds(warm_dir, locale) for _ in range(args.runs)])
        loads.append(load_average())
        rows.append(
            f"| {locale} | {sentences} | {median(times):.2f} | {percentile(times, 99):.2f} "
            f"| {cold:.1f} | {warm:.2f} |"
        )
    body = (
        "Per utterance over each locale's development set (said "
        f"{args.rounds} times, models cached), and the NLU's build in a fresh process "
        "(imports included; cold: empty cache, the classifier and roles taggers trained; "
        f"cached: median of {args.runs}). Load average (1 min) during the run: "
        f"{', '.join(loads)} on a shared machine.\n\n"
        "| locale | sentences | p50 ms | p99 ms | build cold s | build cached s |\n"
        "| --- | ---: | ---: | ---: | ---: | ---: |\n" + "\n".join(rows)
    )
    write_section(
        "understanding_locales", "Understanding people in each locale (en-US, de-DE)", body
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
