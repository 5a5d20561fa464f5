"""The layer contracts (pyproject's [tool.importlinter], docs/architecture.md) hold, and a
change that breaks one fails the check `make lint` runs. No module imports itself through
others, a package and its own modules included."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import grimp
import pytest

ROOT = Path(__file__).resolve().parents[2]
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")


def lint_imports(tree: Path) -> subprocess.CompletedProcess[str]:
    """`lint-imports` over the packages in `tree`, with the repository's contracts."""
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", "--config", str(ROOT / "pyproject.toml")],
        cwd=tree, env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(tree)},
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip


def copy_packages(into: Path) -> Path:
    """A copy of the five packages the contracts speak of (their Python files, which is all
    the check reads), importable from `into`."""

    def ignore(directory: str, names: list[str]) -> set[str]:
        return {
            name
            for name in names
            if name == "__pycache__" or not (name.endswith(".py") or Path(directory, name).is_dir())
        }

    for package, source in (
        ("vahr", "vahr"),
        ("robot_agent", "robot_agent"),
        ("skill", "lambda/skill"),
        ("announcer", "lambda/announcer"),
        ("dispatcher", "lambda/dispatcher"),
    ):
        shutil.copytree(ROOT / source, into / package, ignore=ignore, symlinks=True)
    return into


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    return copy_packages(tmp_path)


def test_the_packages_keep_every_contract(tree: Path) -> None:
    result = lint_imports(tree)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


# (module, the import added to it, the start of the name of the contract it breaks)
WRONG_IMPORTS = [
    ("vahr/protocol/topics.py", "import vahr.plumbing.mqtt", "The wire contract"),
    ("vahr/protocol/topics.py", "import vahr.domain.fleet", "The wire contract"),
    ("vahr/protocol/topics.py", "import yaml", "The wire contract"),
    ("vahr/domain/fleet.py", "import vahr.assistant.nlu", "The domain and the dispatch"),
    ("vahr/dispatch/tasks.py", "import boto3", "The domain and the dispatch"),
    ("vahr/speech/audio.py", "import vahr.plumbing.mqtt", "Speech imports nothing"),
    ("robot_agent/agent.py", "import vahr.local.room_assistant", "robot_agent never imports"),
    ("robot_agent/agent.py", "import vahr.assistant.nlu", "robot_agent never imports"),
    ("vahr/local/system.py", "import robot_agent.assembly", "vahr never imports robot_agent"),
    ("skill/app.py", "import vahr.speech.tts", "The skill imports only"),
    ("skill/app.py", "import vahr.announce", "The skill imports only"),
    ("skill/app.py", "import vahr.assistant", "The skill imports only"),
    ("skill/app.py", "import announcer.app", "The skill imports only"),
    ("announcer/app.py", "import vahr.plumbing.mqtt", "The announcer imports only"),
    ("announcer/app.py", "import skill.iot_data", "The announcer imports only"),
    ("announcer/app.py", "import boto3", "Only the announcer's data-access module"),
    ("dispatcher/app.py", "import vahr.twin.fleet_index", "The dispatcher imports only"),
    ("dispatcher/app.py", "import boto3", "Only the dispatcher's five adapters"),
    ("vahr/announce/policy.py", "import vahr.errors", "The announcement policy imports"),
    ("vahr/announce/speech.py", "import vahr.skill_model", "The announcement policy"),
    # The local stack starting the station itself: the station is handed to it from above.
    ("vahr/local/system.py", "import vahr.station.deployment", "The top layer is one-way"),
    ("vahr/plumbing/mqtt.py", "import vahr.twin.broker", "No import cycle"),
    ("vahr/experiment/bus.py", "import vahr.station.desk", "The top layer is one-way"),
    ("vahr/twin/stack.py", "import vahr.local.system", "The top layer is one-way"),
    # The plumbing and the assistant are siblings: neither knows the other.
    ("vahr/plumbing/client.py", "import vahr.assistant.nlu", "The top layer is one-way"),
    # The station serves any deployment: nothing of the twin or the local hosts.
    (
        "vahr/station/voice.py",
        "import vahr.twin.dataplane",
        "The station and the experiment know",
    ),
    ("vahr/station/app.py", "import vahr.local.system", "The station and the experiment know"),
    (
        "vahr/experiment/bus.py",
        "import vahr.twin.broker",
        "The station and the experiment know",
    ),
    ("vahr/station/vocabulary.py", "import vahr.assistant.nlu", "The station and the"),
    ("robot_agent/link/shadow.py", "import robot_agent.voice.port", "robot_agent's adapters"),
    # Cycles no layer names: two modules of one package, two packages of robot_agent.
    ("vahr/experiment/tlx.py", "import vahr.experiment.results", "No import cycle"),
    ("vahr/station/errors.py", "import vahr.station.app", "No import cycle"),
    ("robot_agent/backends/sim.py", "import robot_agent.core.executor", "No import cycle"),
]


@pytest.fixture(scope="module")
def checked_with_each_wrong_import(tmp_path_factory: pytest.TempPathFactory) -> list[Any]:
    """The check's exit code and report with each of `WRONG_IMPORTS` added alone to the
    packages (the module put back after each), all in one interpreter
    (tests/support/lint_imports_each.py): a `lint-imports` process for each took 26 s."""
    tree = copy_packages(tmp_path_factory.mktemp("packages"))
    result = subprocess.run(
        [sys.executable, str(ROOT / "tests" / "support" / "lint_imports_each.py"),
         str(ROOT / "pyproject.toml")],
        input=json.dumps([[module, line] for module, line, _ in WRONG_IMPORTS]),
        cwd=tree, env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(tree)},
        capture_output=True, text=True, timeout=300, check=True,
    )  # fmt: skip
    outcomes: list[Any] = json.loads(result.stdout)
    return outcomes


@pytest.mark.parametrize(
    "case", range(len(WRONG_IMPORTS)), ids=lambda n: " ".join(WRONG_IMPORTS[n][:2])
)
def test_an_import_against_a_layer_fails_the_check_naming_the_contract(
    checked_with_each_wrong_import: list[Any], case: int
) -> None:
    # Given one module with one more import: across a layer boundary, or round a loop
    _, _, contract = WRONG_IMPORTS[case]
    # When the contracts are checked
    outcome = checked_with_each_wrong_import[case]
    # Then the check fails and names the broken contract
    assert outcome["exit"] != 0
    # A contract with ignored imports ends its line with "BROKEN (N ignored imports)".
    broken = [line for line in outcome["report"].splitlines() if " BROKEN" in line]
    assert any(name.startswith(contract) for name in broken), outcome["report"]


def import_cycles(graph: grimp.ImportGraph) -> list[list[str]]:
    """Every set of modules that import one another round a loop (Tarjan's strongly
    connected components of more than one module), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []
    for root in sorted(graph.modules):
        if root in index:
            continue
        # An iterative depth-first walk: (module, the modules it imports not yet walked).
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            module, imported = work[-1]
            for target in imported:
                if target not in index:
                    index[target] = low[target] = len(index)
                    stack.append(target)
                    on_stack.add(target)
                    work.append(
                        (target, iter(sorted(graph.find_modules_directly_imported_by(target))))
                    )
                    break
                if target in on_stack:
                    low[module] = min(low[module], index[target])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[module])
                if low[module] == index[module]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == module:
                            break
                    if len(component) > 1:
                        cycles.append(sorted(component))
    return cycles


def test_no_module_imports_itself_through_others() -> None:
    # Given the import graph of the four packages, imports inside functions and under
    # TYPE_CHECKING included (the one lint-imports checks)
    graph = grimp.build_graph("vahr", "robot_agent", "skill", "announcer", cache_dir=None)
    # Then no module reaches itself: not two siblings (lint-imports says so too), nor a
    # package's __init__ and a module inside it, which lint-imports does not look at
    assert import_cycles(graph) == []


def test_a_package_and_its_own_module_importing_each_other_is_a_cycle() -> None:
    # Given a package whose __init__ re-exports a module that imports the package back
    graph = grimp.ImportGraph()
    for module in ("pkg", "pkg.model", "pkg.other", "pkg.leaf"):
        graph.add_module(module)
    graph.add_import(importer="pkg", imported="pkg.model")
    graph.add_import(importer="pkg.model", imported="pkg.leaf")
    graph.add_import(importer="pkg.model", imported="pkg")
    graph.add_import(importer="pkg.other", imported="pkg.leaf")
    # When its cycles are looked for, then the loop is found, and only the loop
    assert import_cycles(graph) == [["pkg", "pkg.model"]]
