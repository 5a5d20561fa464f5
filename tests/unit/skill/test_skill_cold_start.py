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


def test_cold_start_loads_nothing_beyond_the_skills_needs() -> None:
    # Given a fresh interpreter with only a region configured
    env = {key: value for key, value in os.environ.items() if not key.startswith(("AWS_", "VAHR_"))}
    env.update(
        AWS_DEFAULT_REGION="us-east-1",
        PYTHONPATH=os.pathsep.join([str(ROOT / "lambda"), str(ROOT)]),
    )
    code = (
        "import json, sys\n"
        "from skill.app import lambda_handler\n"
        "print(json.dumps(sorted(sys.modules)))\n"
    )
    # When Lambda resolves the handler
    done = subprocess.run(
        [sys.executable, "-c", code],
        env=env,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    modules = json.loads(done.stdout)
    # Then the skill, ask-sdk-core, boto3 and the wire contract are loaded, and nothing else of ours
    assert {"skill.app", "ask_sdk_core.skill_builder", "boto3", "vahr.protocol"} <= set(modules)
    loaded = [
        m for m in modules if any(m == name or m.startswith(name + ".") for name in FORBIDDEN)
    ]
    assert loaded == []
