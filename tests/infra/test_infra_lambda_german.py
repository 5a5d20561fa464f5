"""The Lambda bundle speaks German: it carries the locales' files, and the bundled handler
in a clean CPython 3.12 answers a German launch request in German."""

from __future__ import annotations

import json

import pytest
from template_tools import REPO_ROOT

from infra import lambda_asset
from tests.infra.test_infra_lambda_asset import run_in_lambda_python

EVENTS = REPO_ROOT / "tests" / "events"


@pytest.fixture(scope="module")
def bundle(tmp_path_factory: pytest.TempPathFactory) -> lambda_asset.BuildResult:
    return lambda_asset.build(tmp_path_factory.mktemp("asset") / "bundle")


def test_the_bundle_carries_each_locales_words_replies_and_announcements(
    bundle: lambda_asset.BuildResult,
) -> None:
    locales = bundle.out_dir / "vahr" / "domain" / "locales"
    assert sorted(p.relative_to(locales).as_posix() for p in locales.rglob("*.yaml")) == [
        "de-DE/announcements.yaml",
        "de-DE/language.yaml",
        "de-DE/replies.yaml",
        "en-US/language.yaml",
    ]


def test_the_bundled_handler_welcomes_a_german_request_in_german(
    bundle: lambda_asset.BuildResult,
) -> None:
    script = (
        "import json, skill.app\n"
        f"event = json.load(open({str(EVENTS / 'alexa_launch_de.json')!r}))\n"
        "print(json.dumps(skill.app.lambda_handler(event, None)))"
    )
    result = run_in_lambda_python(bundle.out_dir, script)
    assert result.returncode == 0, result.stderr
    speech = json.loads(result.stdout)["response"]["outputSpeech"]["ssml"]
    assert speech.startswith("<speak>Willkommen bei Roboterflotte.")
