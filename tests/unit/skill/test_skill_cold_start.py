"""What the Lambda pays at cold start: only ask-sdk-core, boto3 and vahr.protocol."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
# Packages the skill must never load: the robot side, the local stack, the experiment,
# PyYAML (the fleet's JSON twin spares it), and the test tools.
FORBIDDEN = (
    "yaml",
    "paho",
    "awsiot",
    "rospy",
    "pocketsphinx",
    "numpy",
    "moto",
    "robot_agent",
    "vahr.local",
    "vahr.skill_model",
    "vahr.experiment",
    "vahr.commands",
)


def fresh_interpreter(code: str) -> str:
    """What `code` prints in a fresh interpreter with only a region configured."""
    env = {key: value for key, value in os.environ.items() if not key.startswith(("AWS_", "VAHR_"))}
    env.update(
        AWS_DEFAULT_REGION="us-east-1",
        PYTHONPATH=os.pathsep.join([str(ROOT / "lambda"), str(ROOT)]),
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        env=env,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    return done.stdout


def test_cold_start_loads_nothing_beyond_the_skills_needs() -> None:
    # When Lambda resolves the handler
    code = "import json, sys\nfrom skill.app import lambda_handler\nprint(json.dumps(sorted(sys.modules)))"
    modules = json.loads(fresh_interpreter(code))
    # Then the skill, ask-sdk-core, boto3 and the wire contract are loaded, and nothing else of ours
    assert {"skill.app", "ask_sdk_core.skill_builder", "boto3", "vahr.protocol"} <= set(modules)
    loaded = [
        m for m in modules if any(m == name or m.startswith(name + ".") for name in FORBIDDEN)
    ]
    assert loaded == []


def test_the_entry_point_freezes_what_it_made_and_leaves_the_collector_as_it_found_it() -> None:
    # The skill's modules are imported with the collector paused and then frozen: then it
    # collects again, and a process that had paused it itself finds it paused still
    code = "import gc\n{}from skill.app import lambda_handler\nprint(gc.isenabled(), gc.get_freeze_count())"
    enabled, frozen = fresh_interpreter(code.format("")).split()
    assert enabled == "True" and int(frozen) > 0
    assert fresh_interpreter(code.format("gc.disable()\n")).split()[0] == "False"
