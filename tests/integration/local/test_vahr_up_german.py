"""German end to end, as a user meets it: `vahr up --locale de-DE` runs the whole system,
`vahr say --locale de-DE` moves a robot and is answered in German, and a locale the system
does not speak, or none VAHR ships, is one line and exit code 2."""

from __future__ import annotations

import json
import subprocess
import time
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, start_up, stop_up
from vahr.plumbing.client import call

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

GERMAN_REQUEST = "Alexa, sage Roboterflotte, schicke Placebot eins in Zone B"


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    state = tmp_path_factory.mktemp("german")
    running = start_up(state, "--locale", "de-DE", "--sim-speed-factor", "20")
    try:
        yield running
    finally:
        stop_up(running.process)


def vahr_say(api: str, *words: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*VAHR, "say", "--api", api, *words],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=120,
    )  # fmt: skip


def zone_of(up: Up, thing: str) -> Any:
    shadow = call(up.endpoints["api"], "GET", f"/things/{thing}/shadow")
    return shadow["state"]["reported"].get("zone")


def test_a_german_request_moves_the_robot_and_is_answered_in_german(up: Up) -> None:
    # When the person says it in German
    result = vahr_say(up.endpoints["api"], "--locale", "de-DE", "--json", GERMAN_REQUEST)
    assert result.returncode == 0, result.stderr
    turn = json.loads(result.stdout)
    # Then the simulator understood it, the skill sent one command and said so in German
    assert turn["intent"] == "NavigateIntent"
    assert turn["slots"]["robot"]["id"] == "placebot1"
    assert turn["slots"]["zone"]["id"] == "B"
    assert len(turn["commands"]) == 1
    assert turn["speech"] == "Placebot eins ist unterwegs Richtung Zone B."
    # And placebot1 arrives in zone B
    deadline = time.monotonic() + 30
    while zone_of(up, "placebot1") != "B":
        assert time.monotonic() < deadline, "placebot1 did not reach zone B"
        time.sleep(0.2)


def test_english_to_a_german_system_is_one_line_and_exit_code_2(up: Up) -> None:
    result = vahr_say(up.endpoints["api"], "send placebot one to zone a")
    assert result.returncode == 2
    [line] = result.stderr.strip().splitlines()
    assert line.startswith("vahr say: error: ")
    assert line.endswith("locale: this system speaks de-DE; start it with vahr up --locale en-US")


def test_an_unknown_locale_is_one_line_naming_the_supported_ones(up: Up) -> None:
    result = vahr_say(up.endpoints["api"], "--locale", "fr-FR", "bonjour")
    assert (result.returncode, result.stderr) == (
        2,
        "vahr say: error: unknown locale 'fr-FR'; supported: de-DE, en-US\n",
    )


@pytest.mark.parametrize("command", ["up", "console", "nlu"])
def test_every_command_refuses_an_unknown_locale_before_it_starts(
    command: str, tmp_path: Path
) -> None:
    extra = ["--state-dir", str(tmp_path)] if command == "up" else []
    result = subprocess.run(
        [*VAHR, command, "--locale", "fr-FR", *extra, *(["bonjour"] if command == "nlu" else [])],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert (result.returncode, result.stderr) == (
        2,
        f"vahr {command}: error: unknown locale 'fr-FR'; supported: de-DE, en-US\n",
    )
    assert list(tmp_path.iterdir()) == []
