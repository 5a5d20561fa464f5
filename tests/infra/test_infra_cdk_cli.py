"""`cdk synth` as a user runs it: the pinned CLI, no AWS credentials, no network needed,
the Lambda bundle built locally (no Docker); a missing skill id refused in one line."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest
from template_tools import REPO_ROOT

from tests.support.node_tools import node_modules

CDK_CLI = Path("aws-cdk") / "bin" / "cdk"  # in node_modules


def cdk_synth(outdir: Path, *context: str) -> subprocess.CompletedProcess[str]:
    # The environment a first-time user has: no credentials, no profile, no region.
    environment = {
        key: value for key, value in os.environ.items() if not key.startswith(("AWS_", "CDK_"))
    }
    environment.update(
        AWS_CONFIG_FILE=str(outdir / "no-config"),
        AWS_SHARED_CREDENTIALS_FILE=str(outdir / "no-credentials"),
        CDK_DISABLE_CLI_TELEMETRY="true",
        JSII_SILENCE_WARNING_END_OF_LIFE_NODE_VERSION="20",
        JSII_RUNTIME_PACKAGE_CACHE_ROOT=str(REPO_ROOT / ".cache" / "jsii"),
    )
    # A developer's own `ask deploy` state must not change what is synthesized here.
    flags = ["-c", f"askStatesFile={outdir.parent / 'no-ask-states.json'}"]
    flags += [arg for pair in context for arg in ("-c", pair)]
    cli = node_modules() / CDK_CLI
    return subprocess.run(
        ["node", str(cli), "synth", "--quiet", "--no-notices", "-o", str(outdir), *flags],
        capture_output=True, text=True, timeout=300, cwd=REPO_ROOT, env=environment,
    )  # fmt: skip


# Two runs of the CLI (node and the Python app each time), one of them a whole synth: more
# than the suite's default bound beside the rest of the suite on two cores. The optional
# parts are synthesized in-process (test_infra_app.py); here a `-c` flag reaching the app is
# shown by allowAnySkill. A bad flag takes the refusal's path to the same one line
# (`infra.app.main`); each flag's message is checked in-process (test_infra_config.py).
@pytest.mark.slow
@pytest.mark.timeout(300)
def test_cdk_synth_works_offline_without_credentials_and_refuses_in_one_line(
    tmp_path: Path,
) -> None:
    assert (node_modules() / CDK_CLI).is_file(), "run `make setup` (npm ci) to install the CDK CLI"
    outdir = tmp_path / "cdk.out"
    # Given no credentials and no skill id yet, When the default app is synthesized
    refused = cdk_synth(outdir)
    # Then it is refused in one line that names the flag accepting the risk
    assert refused.returncode != 0
    [line] = [line for line in refused.stderr.splitlines() if line.startswith("error: ")]
    assert line == (
        "error: skillId: none is known, so any Alexa skill could invoke the skill function; "
        "give -c skillId=amzn1.ask.skill... (ask deploy prints it), create the skill with the "
        "stack (-c skill=true), or accept that risk with -c allowAnySkill=true"
    )
    # When the user accepts it by name
    lean = cdk_synth(outdir, "allowAnySkill=true")
    assert lean.returncode == 0, lean.stderr[-3000:]
    # Then the skill's code was bundled locally from the one build script
    assets = json.loads((outdir / "Vahr.assets.json").read_text())["files"]
    bundles = [
        outdir / f["source"]["path"]
        for f in assets.values()
        if f["source"]["path"].startswith("asset.")
    ]
    skill_bundle = next(path for path in bundles if (path / "skill" / "app.py").exists())
    assert (skill_bundle / "vahr" / "domain" / "fleet.yaml").is_file()
    assert (skill_bundle / "vahr" / "protocol" / "__init__.py").is_file()
    # And cdk-nag passed with only acknowledged findings
    reports = json.loads((outdir / "validation-report.json").read_text())["pluginReports"]
    [nag] = [r for r in reports if r["pluginName"] == "AwsSolutions"]
    assert (nag["conclusion"], nag["violations"]) == ("success", [])
    # And the user is told, as a warning, that any skill may call the function for now
    assert "allowAnySkill=true: any Alexa skill may invoke this function" in lean.stderr
