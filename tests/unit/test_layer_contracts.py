"""The layer contracts (pyproject's [tool.importlinter], docs/architecture.md) hold, and a
change that breaks one fails the check `make lint` runs."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

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


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    """A copy of the three packages the contracts speak of, importable from `tmp_path`."""
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for package, source in (
        ("vahr", "vahr"),
        ("robot_agent", "robot_agent"),
        ("skill", "lambda/skill"),
    ):
        shutil.copytree(ROOT / source, tmp_path / package, ignore=ignore, symlinks=True)
    return tmp_path


def test_the_packages_keep_every_contract(tree: Path) -> None:
    result = lint_imports(tree)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


@pytest.mark.parametrize(
    ("module", "line", "contract"),
    [
        ("vahr/protocol/topics.py", "import vahr.local.mqtt", "The bottom layer"),
        ("vahr/speech/audio.py", "import robot_agent.config", "The bottom layer"),
        ("robot_agent/agent.py", "import vahr.local.room", "robot_agent never imports"),
        ("vahr/local/system.py", "import robot_agent.assembly", "vahr never imports robot_agent"),
        ("skill/app.py", "import vahr.speech.tts", "The skill imports only the protocol"),
    ],
)
def test_an_import_against_a_layer_fails_the_check_naming_the_contract(
    tree: Path, module: str, line: str, contract: str
) -> None:
    # Given one module that imports across a layer boundary
    path = tree / module
    path.write_text(path.read_text() + f"\n{line}  # noqa\n")
    # When the contracts are checked
    result = lint_imports(tree)
    # Then the check fails and names the broken contract
    assert result.returncode != 0
    broken = [line for line in result.stdout.splitlines() if line.endswith("BROKEN")]
    assert any(name.startswith(contract) for name in broken), result.stdout
