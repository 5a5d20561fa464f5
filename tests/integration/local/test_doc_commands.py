"""Every command the README and the guides show (and docs/local.md's boto3 example) is
checked against the product, so a page that says what is not so fails here.

Each shell block's command lines are read as a shell would read them (comments off). What
runs in a moment runs: `vahr nlu`, `python -m vahr.skill_model`, `robot-agent speak` and
`hear`, the boto3 example against a running local stack, `pytest` on the files named (by
their paths). What would start a long-running stack, deploy to AWS or build a wheel is
parsed by the command's own argument parser instead (a flag or subcommand the command
does not have fails); a `make` target must exist (`make -n`); a sentence given to
`vahr say` must be understood, robot and zone, by the stack the same block starts (its
`--fleet` and `--locale`). Lines in a block that are output, not commands, are left out.
Every docs page's block that calls a running `vahr up` with `curl` (its data plane, its
station's push-to-talk) runs against one, each line as written; what a line's comment says
it answers is what it answers, and a clip posted to the station is answered with the fields
docs/push-to-talk.md lists.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import json
import re
import shlex
import shutil
import subprocess
import sys
import urllib.parse
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.support.node_tools import node_modules
from tests.support.vahr_up import clean_env, start_up, stop_up
from vahr.assistant.nlu import InteractionModel
from vahr.assistant.understanding import load_understanding
from vahr.domain import load_fleet
from vahr.skill_model.generator import build_interaction_model, build_locale_model

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack

ROOT = Path(__file__).resolve().parents[3]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs" / "guides").glob("*.md"))]
BOTO3_PAGE = ROOT / "docs" / "local.md"
# Where the docs' `curl` examples reach a running `vahr up` (its default ports), and which
# of its endpoints each is: the data plane and the station.
LOCAL_ADDRESSES = {"localhost:8180": "api", "127.0.0.1:8181": "station"}
# What the station answers a clip with (docs/push-to-talk.md, `POST /api/voice`).
VOICE_ANSWER = {"heard", "recognizer_ms", "understood", "speech", "turn"}
SHELL_LANGUAGES = ("", "sh", "bash", "console", "shell")
# The programs a command line may start with; any other line of a block is output.
PROGRAMS = ("make", "npx", "pip", "robot-agent", "vahr", "export", ".venv/bin/")


@dataclass(frozen=True)
class Command:
    page: str
    block: int
    words: tuple[str, ...]

    def __str__(self) -> str:
        return f"{self.page} block {self.block}: {shlex.join(self.words)}"


def fenced_blocks(text: str) -> list[tuple[str, str]]:
    """Each fenced block of a Markdown text: (its language, its text)."""
    blocks: list[tuple[str, str]] = []
    language: str | None = None
    lines: list[str] = []
    for line in text.splitlines():
        if line.startswith("```"):
            if language is None:
                language, lines = line[3:].strip(), []
            else:
                blocks.append((language, "\n".join(lines)))
                language = None
        elif language is not None:
            lines.append(line)
    return blocks


def shell_blocks(page: Path) -> list[str]:
    text = page.read_text(encoding="utf-8")
    return [block for language, block in fenced_blocks(text) if language in SHELL_LANGUAGES]


def commands(page: Path) -> list[list[Command]]:
    """Each shell block of `page` as its commands, in order."""
    blocks = []
    for number, block in enumerate(shell_blocks(page), start=1):
        found = []
        for line in block.splitlines():
            # Output shown in a block ("vahr up: error: ...", JSON) is no command.
            if not line.strip().startswith(PROGRAMS) or re.match(r"^\S+( \S+)?: ", line):
                continue
            for part in re.split(r"\s&&\s", line):
                words = tuple(shlex.split(part, comments=True))
                if words:
                    found.append(Command(page.name, number, words))
        blocks.append(found)
    return blocks


ALL = [command for page in PAGES for block in commands(page) for command in block]


def test_the_pages_hold_commands() -> None:
    # A change to how blocks are written must not leave this test checking nothing.
    assert len(ALL) >= 35
    assert {command.page for command in ALL} >= {"README.md", "bring-your-own-fleet.md"}


@pytest.fixture(scope="module")
def guide_fleet(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The guide's own example fleet (its first YAML block), as `my-fleet.yaml`."""
    text = (ROOT / "docs" / "guides" / "bring-your-own-fleet.md").read_text(encoding="utf-8")
    path = tmp_path_factory.mktemp("guide") / "my-fleet.yaml"
    [first, *_] = [block for language, block in fenced_blocks(text) if language == "yaml"]
    path.write_text(first, encoding="utf-8")
    return path


def _program(words: tuple[str, ...]) -> tuple[str, list[str]]:
    """(program, arguments), `.venv/bin/` taken off."""
    head = words[0].removeprefix(".venv/bin/")
    return head, list(words[1:])


def _parse(module_names: dict[str, tuple[str, str]], argv: list[str]) -> argparse.Namespace:
    """`argv` parsed by the subcommand's own parser, as the CLI would; SystemExit on a flag
    it does not have."""
    name, rest = argv[0], argv[1:]
    assert name in module_names, f"no subcommand {name!r}"
    parser = argparse.ArgumentParser(prog=name, exit_on_error=False)
    importlib.import_module(module_names[name][0]).configure(parser)
    return parser.parse_args(rest)


def _stack_of(block: list[Command], fleet_file: Path) -> tuple[Path | None, str]:
    """The fleet and locale of the `vahr up` the block starts (the bundled fleet, en-US
    when it starts none)."""
    for command in block:
        program, argv = _program(command.words)
        if program == "vahr" and argv[:1] == ["up"]:
            args = _parse(_vahr(), argv)
            fleet = fleet_file if args.fleet is not None else None
            return fleet, args.locale
    return None, "en-US"


def _vahr() -> dict[str, tuple[str, str]]:
    from vahr.cli import SUBCOMMANDS

    return SUBCOMMANDS


def _robot_agent() -> dict[str, tuple[str, str]]:
    from robot_agent.cli import SUBCOMMANDS

    return SUBCOMMANDS


_models: dict[tuple[Path | None, str], InteractionModel] = {}


def _understood(utterance: str, fleet_file: Path | None, locale: str) -> None:
    key = (fleet_file, locale)
    if key not in _models:
        fleet = load_fleet(fleet_file)
        document = (
            build_interaction_model(fleet)
            if locale == "en-US"
            else build_locale_model(fleet, locale)
        )
        _models[key] = InteractionModel(document, understanding=load_understanding(locale))
    from vahr.assistant.simulator import strip_invocation

    model = _models[key]
    text = strip_invocation(model.invocation_name, utterance)
    understood = model.understand(text)
    assert understood.intent != "AMAZON.FallbackIntent", f"{utterance!r} is not understood"
    unresolved = [name for name, value in understood.slots.items() if not value.resolved]
    assert unresolved == [], f"{utterance!r}: {unresolved} not understood"


def _run(words: list[str], cwd: Path, env: dict[str, str] | None = None) -> str:
    done = subprocess.run(
        words, cwd=cwd, env=env or clean_env(), capture_output=True, text=True, timeout=120,
        check=False,
    )  # fmt: skip
    assert done.returncode == 0, f"{shlex.join(words)}: {done.stderr.strip()[-500:]}"
    return done.stdout


def _fleet_words(argv: list[str], fleet_file: Path) -> list[str]:
    return [str(fleet_file) if word == "my-fleet.yaml" else word for word in argv]


@pytest.mark.parametrize("page", PAGES, ids=lambda page: page.name)
def test_every_command_on_the_page_is_true(page: Path, guide_fleet: Path, tmp_path: Path) -> None:
    for block in commands(page):
        fleet, locale = _stack_of(block, guide_fleet)
        for command in block:
            _check(command, block, guide_fleet, fleet, locale, tmp_path)


# What `npx` runs from an npm workspace that `make setup` installs and `make test` need not
# (the ASK CLI is for deploying): the program, its workspace and the package giving it.
WORKSPACE_TOOLS = {"ask": ("tools/ask-cli", "ask-cli")}


def _npx_runs(program: str) -> bool:
    """Whether `npx PROGRAM` runs after `make setup`: installed, or pinned in a workspace of
    the root package that set-up installs."""
    if (node_modules() / ".bin" / program).exists():
        return True
    if program not in WORKSPACE_TOOLS:
        return False
    workspace, package = WORKSPACE_TOOLS[program]
    root = json.loads((ROOT / "package.json").read_text())
    pinned = json.loads((ROOT / workspace / "package.json").read_text())["devDependencies"]
    installs = subprocess.run(["make", "-n", "setup"], cwd=ROOT, capture_output=True, text=True)
    return (
        workspace in root["workspaces"]
        and package in pinned
        and f"--workspace={workspace}" in installs.stdout
    )


def _check(
    command: Command,
    block: list[Command],
    guide_fleet: Path,
    fleet: Path | None,
    locale: str,
    tmp_path: Path,
) -> None:
    program, argv = _program(command.words)
    argv = _fleet_words(argv, guide_fleet)
    python = [sys.executable, "-m"]
    if program == "make":
        assert subprocess.run(["make", "-n", *argv], cwd=ROOT, capture_output=True,
                              check=False).returncode == 0, str(command)  # fmt: skip
    elif program == "npx":
        assert _npx_runs(argv[0]), str(command)
    elif program == "pip":
        assert argv[0] in ("install", "wheel"), str(command)
    elif program == "pytest":
        paths = [word for word in argv if not word.startswith("-")]
        assert paths and all((ROOT / path).exists() for path in paths), str(command)
    elif program == "python" and argv[:2] == ["-m", "vahr.skill_model"]:
        from vahr.skill_model.__main__ import main as skill_model

        words = [w.replace("/tmp/my-fleet", str(tmp_path / "model")) for w in argv[2:]]
        if "--root" not in words:
            words += ["--root", str(tmp_path / "model")]
        # A check needs something written to check (in the guide, the generate line).
        assert skill_model([w for w in words if w != "--check"]) == 0, str(command)
        assert skill_model(words) == 0, str(command)
    elif program == "python" and argv[:1] == ["-m"]:
        importlib.import_module(argv[1])
    elif program == "pip" or program == "export":
        pass
    elif program == "robot-agent":
        args = _parse(_robot_agent(), argv)
        if argv[0] in ("speak", "hear"):
            _run([*python, "robot_agent.cli", *argv], tmp_path)
        else:
            assert args is not None
    elif program == "vahr":
        parsed = _parse(_vahr(), argv)
        if argv[0] == "nlu" and "--eval" not in argv:
            from vahr.cli import main as vahr

            printed = io.StringIO()
            with contextlib.redirect_stdout(printed):
                assert vahr(argv) == 0, str(command)
            out = printed.getvalue()
            assert '"intent"' in out and "AMAZON.FallbackIntent" not in out, str(command)
        elif argv[0] == "say":
            _understood(parsed.utterance, fleet, locale)
    else:
        raise AssertionError(f"{command}: no check for {program!r}")


def test_the_boto3_example_reads_a_shadow_as_written(local_stack: LocalStack) -> None:
    # Given a robot's shadow on a running stack
    assert local_stack.dataplane is not None
    local_stack.dataplane.handle(
        "POST", "/things/placebot1/shadow", b'{"state": {"reported": {"status": "idle"}}}'
    )
    [block] = [b for b in shell_blocks(BOTO3_PAGE) if "boto3" in b]
    env = {k: v for k, v in clean_env().items() if not k.startswith("AWS_")}
    env["HOME"] = str(Path(local_stack.config.state_dir))  # no ~/.aws of the machine's
    script = ""
    for line in block.splitlines():
        line = line.replace("http://127.0.0.1:8180", local_stack.api_url)
        script += line.replace(".venv/bin/python", shlex.quote(sys.executable)) + "\n"
    # When the page's lines run in a shell, exactly as written (ports aside)
    done = subprocess.run(["bash", "-e", "-c", script], env=env, cwd=ROOT, capture_output=True,
                          text=True, timeout=60, check=False)  # fmt: skip
    # Then boto3 reads the shadow
    assert done.returncode == 0, done.stderr[-800:]
    assert '"status": "idle"' in done.stdout or '"status":"idle"' in done.stdout


def local_blocks() -> list[tuple[str, list[str]]]:
    """Each docs page's shell block with a `curl` line to a running `vahr up`, in page
    order: (the page, the block's lines)."""
    found = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        for block in shell_blocks(page):
            lines = [line.strip() for line in block.splitlines() if line.strip()]
            if any(line.startswith("curl ") and _local_address(line) for line in lines):
                found.append((page.name, lines))
    return found


def _local_address(line: str) -> str | None:
    return next((address for address in LOCAL_ADDRESSES if address in line), None)


def test_every_local_curl_in_the_docs_is_answered(tmp_path: Path) -> None:
    # Given the docs' blocks that call a running stack (the tasks of docs/dispatch.md, the
    # zones of docs/floors.md, the clips of docs/push-to-talk.md)
    blocks = local_blocks()
    assert {page for page, _ in blocks} >= {"dispatch.md", "floors.md", "push-to-talk.md"}
    # (Whisper aside: a clip is answered with the same fields without its second hearing.)
    up = start_up(tmp_path, env={"VAHR_WHISPER": "off"})
    try:
        for page, lines in blocks:
            spoken = None
            for line in lines:
                command, _, shown = line.partition(" #")
                words = shlex.split(command)
                if words[0].startswith(".venv/bin/"):
                    words[0] = str(ROOT / words[0])
                address = _local_address(command)
                if not (words[0] == "curl" and address):
                    _run(words, tmp_path)  # the clip the next line posts
                    spoken = words[words.index("speak") + 1] if "speak" in words else None
                    continue
                # When each call runs as written against the stack (its port aside)
                running = urllib.parse.urlsplit(up.endpoints[LOCAL_ADDRESSES[address]]).netloc
                words = [word.replace(address, running) for word in words]
                answer = _run([*words, "-w", "\n%{http_code}"], tmp_path)
                body, _, status = answer.rpartition("\n")
                # Then it is answered, with what its comment shows, or a clip with its fields
                assert status == "200", f"{page}: {line}: {status} {body}"
                if shown.strip():
                    assert json.loads(body) == json.loads(shown), f"{page}: {line}"
                if "/api/voice" in command:
                    # heard as it was spoken, and acted on
                    voiced = json.loads(body)
                    assert set(voiced) >= VOICE_ANSWER, f"{page}: {line}: {body}"
                    assert voiced["heard"]["transcript"] == spoken, f"{page}: {body}"
                    assert voiced["turn"] is not None, f"{page}: {body}"
    finally:
        stop_up(up.process)


def test_a_command_the_product_lacks_fails_here() -> None:
    with pytest.raises((SystemExit, argparse.ArgumentError)):
        _parse(_vahr(), ["up", "--colour", "blue"])
    with pytest.raises(AssertionError):
        _understood("send tug nine to the moon", None, "en-US")
    assert shutil.which("make") and (ROOT / "Makefile").exists()
