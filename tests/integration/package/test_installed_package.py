"""The package as a user installs it: the wheel built from this checkout, a fresh venv, and
an empty directory with no checkout in sight.

`robot-agent run` must find its bundled fleet, and `vahr up` / `vahr say` the bundled
interaction model and the skill, all from inside the installed package. Dependencies are
installed at the pinned versions by uv, which takes them from the cache `make setup` filled.
"""

from __future__ import annotations

import json
import os
import queue
import shutil
import signal
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path
from typing import IO, TYPE_CHECKING

import pytest

from vahr.plumbing.lifetime import spawn
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from vahr.twin.broker import Mosquitto

ROOT = Path(__file__).resolve().parents[3]
INSTALL_TIMEOUT_S = 600
START_TIMEOUT_S = 60.0
# Building the wheel and installing it with its dependencies (scikit-learn among them) has
# its own deadline above; the suite's 120 s per test must not cut it short on a busy machine.
pytestmark = pytest.mark.timeout(INSTALL_TIMEOUT_S + 120)


def copy_of_the_checkout(destination: Path) -> Path:
    """The files git knows here (as they are now, links kept as links), so that building
    leaves nothing behind in the checkout itself."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT, check=True, capture_output=True, timeout=60,
    ).stdout.decode()  # fmt: skip
    for name in filter(None, listed.split("\0")):
        source, target = ROOT / name, destination / name
        if not source.is_symlink() and not source.is_file():
            continue  # deleted in the working tree
        target.parent.mkdir(parents=True, exist_ok=True)
        if source.is_symlink():
            target.symlink_to(source.readlink())
        else:
            shutil.copy2(source, target)
    return destination


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The bin/ directory of a fresh venv holding only the built wheel and its dependencies."""
    work = tmp_path_factory.mktemp("installed")
    source = copy_of_the_checkout(work / "source")
    wheels = work / "dist"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(wheels), str(source)],
        check=True, capture_output=True, timeout=INSTALL_TIMEOUT_S,
    )  # fmt: skip
    [wheel] = wheels.glob("vahr-*.whl")
    venv = work / "venv"
    # With uv, as `make setup` installs (its cache already holds every pinned dependency), and
    # without byte-compiling them (botocore's thousands of modules among them): a module is
    # compiled when it is first imported, as it would be after pip's install.
    uv = str(Path(sys.executable).with_name("uv"))
    subprocess.run([uv, "venv", "-q", str(venv)], check=True, timeout=120)
    subprocess.run(
        [uv, "pip", "install", "-q", "--python", str(venv / "bin" / "python"),
         "-c", str(ROOT / "requirements.txt"), str(wheel)],
        check=True, capture_output=True, timeout=INSTALL_TIMEOUT_S,
    )  # fmt: skip
    return venv / "bin"


def clean_env() -> dict[str, str]:
    """This environment without anything that points back at the checkout."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "VAHR_"))}
    for name in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY", "AWS_PROFILE", "VIRTUAL_ENV"):
        env.pop(name, None)
    return env


def first_line(stream: IO[str], timeout_s: float) -> str:
    box: queue.Queue[str] = queue.Queue()
    threading.Thread(target=lambda: box.put(stream.readline()), daemon=True).start()
    try:
        return box.get(timeout=timeout_s)
    except queue.Empty:
        return ""


def stop(process: subprocess.Popen[str]) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=10)


@pytest.mark.slow
def test_the_installed_package_is_not_the_checkout(installed: Path, tmp_path: Path) -> None:
    # When the installed interpreter says where the packages come from
    where = subprocess.run(
        [str(installed / "python"), "-c",
         "import vahr, robot_agent, skill, vahr.domain.fleet as f; "
         "from robot_agent.voice.adaptation import BUNDLED; "
         "print(vahr.__file__, robot_agent.__file__, skill.__file__, f.DEFAULT_FLEET_FILE, "
         "BUNDLED / 'sendump')"],
        cwd=tmp_path, env=clean_env(), capture_output=True, text=True, timeout=60, check=True,
    ).stdout.split()  # fmt: skip
    # Then every one is inside the venv, the bundled fleet and hearing adaptation included
    assert all(str(installed.parent) in path for path in where), where
    assert Path(where[-2]).is_file() and Path(where[-1]).is_file()


@pytest.mark.slow
def test_robot_agent_runs_from_an_empty_directory(
    installed: Path, tmp_path: Path, mosquitto: Mosquitto
) -> None:
    from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
    from vahr.protocol import topics

    empty = tmp_path / "empty"
    empty.mkdir()
    online = threading.Event()
    port = int(mosquitto.config.plain_port or 0)
    with MqttClient(MqttEndpoint(port=port)) as watcher:
        watcher.subscribe(
            topics.robot_presence("placebot1"),
            lambda _t, p: online.set() if json.loads(p).get("online") else None,
        )
        # When the installed robot-agent runs with the bundled fleet, from an empty directory
        agent = spawn(
            [str(installed / "robot-agent"), "run", "--thing", "placebot1",
             "--broker", f"mqtt://127.0.0.1:{port}", "--backend", "sim"],
            started_for=tmp_path, cwd=empty, env=clean_env(), stdout=subprocess.DEVNULL,
            stderr=(tmp_path / "agent.err").open("w"), text=True,
        )  # fmt: skip
        try:
            # Then the robot comes online
            assert online.wait(START_TIMEOUT_S), (tmp_path / "agent.err").read_text()
        finally:
            stop(agent)
    assert agent.returncode == 0, (tmp_path / "agent.err").read_text()


@pytest.mark.slow
def test_vahr_up_and_say_run_from_an_empty_directory(installed: Path, tmp_path: Path) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    # When the installed `vahr up` starts the whole system from an empty directory
    up = spawn(
        [str(installed / "vahr"), "up", "--json", "--no-voice", "--robots", "1",
         "--api-port", str(free_port()), "--mqtts-port", str(free_port()), "--mqtt-port", "0",
         "--station-port", str(free_port()), "--sim-speed-factor", "20"],
        started_for=tmp_path, cwd=empty, env=clean_env(), stdout=subprocess.PIPE,
        stderr=(tmp_path / "up.err").open("w"), text=True,
    )  # fmt: skip
    try:
        assert up.stdout is not None
        line = first_line(up.stdout, START_TIMEOUT_S)
        assert line, (tmp_path / "up.err").read_text()
        endpoints = json.loads(line)
        api = endpoints["api"]
        # The operator station's page and its files ship in the wheel
        with urllib.request.urlopen(endpoints["station"] + "static/station.js", timeout=10) as js:
            assert js.status == 200 and b"EventSource" in js.read()
        # And a person speaks to it with the installed `vahr say`
        deadline = time.monotonic() + START_TIMEOUT_S
        while True:
            said = subprocess.run(
                [str(installed / "vahr"), "say", "--json", "--api", api,
                 "Alexa, ask robot fleet to send robot one to zone b"],
                cwd=empty, env=clean_env(), capture_output=True, text=True, timeout=60,
            )  # fmt: skip
            assert said.returncode == 0, said.stderr
            turn = json.loads(said.stdout)
            # The robot may still be connecting: wait for its acknowledgment.
            if "on its way" in turn["speech"] or time.monotonic() > deadline:
                break
            time.sleep(1.0)
        # Then the skill understood, published one command, and the robot acknowledged it
        assert turn["intent"] == "NavigateIntent"
        assert len(turn["commands"]) == 1
        assert "on its way" in turn["speech"], turn
    finally:
        stop(up)
    assert "Traceback" not in (tmp_path / "up.err").read_text()
