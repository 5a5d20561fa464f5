"""`vahr demo` (what `make demo` runs): the paper's scenario end to end, exit code 0."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest


@pytest.mark.slow
@pytest.mark.timeout(240)
def test_the_demo_plays_the_conversation_and_the_papers_tasks_to_the_end() -> None:
    # When the demo runs on this machine
    done = subprocess.run(
        [sys.executable, "-m", "vahr.cli", "demo", "--json"],
        capture_output=True,
        text=True,
        timeout=220,
        check=False,
    )
    # Then it ends with exit code 0 and nothing on stderr but log lines
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Traceback" not in done.stderr, done.stderr[-2000:]
    lines = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    exchanges = [line for line in lines if "utterance" in line]
    experiments = [line["experiment"] for line in lines if "experiment" in line]
    summary = next(line["summary"] for line in lines if "summary" in line)
    # and every exchange got its answer and the robots did what each line asked
    assert len(exchanges) == summary["exchanges"] >= 10
    assert all(not exchange["missing"] for exchange in exchanges), exchanges
    spoken = {exchange["utterance"]: exchange["speech"] for exchange in exchanges}
    assert spoken["send robot one to zone b"] == (
        "Placebot one is on its way to zone B. What else would you like the robots to do?"
    )
    assert spoken["where is robot two"].startswith("Placebot two is idle in the loading zone.")
    # and the simulated participant passed tasks I-III with both methods
    assert [result["method"] for result in experiments] == ["vahr", "keyboard"]
    for result in experiments:
        assert result["simulated"] is True
        assert result["tasks"] == {"I": True, "II": True, "III": True}, result
        assert 0 < result["rad"] < 1 and result["fan_out_s"] > result["time_taken_s"]
    # and the data plane counted the billable operations it served
    assert summary["billable_operations"]["http.publish"] >= 8
