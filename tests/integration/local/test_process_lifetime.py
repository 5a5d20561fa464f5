"""Process lifetime: nothing `vahr up` (or a test's stack) starts outlives it, however it
dies, and the next start on the same state directory recovers what a crash left."""

from __future__ import annotations

import json
import os
import queue
import signal
import socket
import subprocess
import sys
import textwrap
import threading
import urllib.request
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.support.fault_injection_steps import (
    alive,
    kill_hard,
    processes_of,
    wait_all_gone,
    wait_until,
)
from vahr.errors import VahrError
from vahr.plumbing.lifetime import STARTED_FOR, spawn
from vahr.plumbing.ports import free_port
from vahr.twin.broker import BrokerConfig
from vahr.twin.stack import LocalStack, StackConfig

if TYPE_CHECKING:
    from collections.abc import Iterator

ROOT = Path(__file__).resolve().parents[3]
START_TIMEOUT_S = 60.0
# The bar: after SIGKILL of `vahr up`, nothing it started is alive within 2 s.
GONE_WITHIN_S = 2.0


def _env() -> dict[str, str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.pop("VAHR_API", None)
    return env


class UpProcess:
    """`vahr up --json` on given ports and state directory; its first line and stderr."""

    def __init__(self, state: Path, ports: dict[str, int]) -> None:
        self.stderr_file = state.parent / f"{state.name}-up-{len(list(state.parent.iterdir()))}.err"
        self.process = subprocess.Popen(
            [sys.executable, "-m", "vahr.cli", "up", "--json", "--no-voice",
             "--state-dir", str(state), "--api-port", str(ports["api"]),
             "--mqtts-port", str(ports["mqtts"]), "--mqtt-port", "0",
             "--sim-speed-factor", "20"],
            cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=self.stderr_file.open("w"),
            text=True,
        )  # fmt: skip
        self.endpoints = self._first_line()

    def _first_line(self) -> dict[str, str]:
        box: queue.Queue[str] = queue.Queue()
        stream = self.process.stdout
        assert stream is not None
        threading.Thread(target=lambda: box.put(stream.readline()), daemon=True).start()
        try:
            line = box.get(timeout=START_TIMEOUT_S)
        except queue.Empty:
            line = ""
        assert line, f"vahr up printed nothing: {self.stderr()}"
        endpoints: dict[str, str] = json.loads(line)
        return endpoints

    def stderr(self) -> str:
        return self.stderr_file.read_text()

    def stop(self) -> int:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        return self.process.wait(timeout=30)


@pytest.fixture
def up_ports() -> dict[str, int]:
    return {"api": free_port(), "mqtts": free_port()}


@pytest.fixture
def ups() -> Iterator[list[UpProcess]]:
    started: list[UpProcess] = []
    yield started
    for up in started:
        if up.process.poll() is None:
            up.process.kill()
            up.process.wait(timeout=10)


@pytest.mark.slow
def test_kill_9_of_vahr_up_leaves_nothing_and_the_next_run_recovers(
    tmp_path: Path, up_ports: dict[str, int], ups: list[UpProcess]
) -> None:
    state = tmp_path / "state"
    # Given vahr up running with its broker and two robot-agents
    first = UpProcess(state, up_ports)
    ups.append(first)
    children = processes_of(state)
    assert sorted(c.name for c in children) == ["mosquitto", "robot-agent", "robot-agent"]
    # When it is killed with SIGKILL (no handler runs)
    kill_hard(first.process.pid)
    first.process.wait(timeout=5)
    # Then nothing it started is alive within 2 s
    wait_all_gone(children, GONE_WITHIN_S)
    assert processes_of(state) == []
    # And a new vahr up on the same state directory and ports starts cleanly, saying in
    # one line what it recovered
    second = UpProcess(state, up_ports)
    ups.append(second)
    recovered = [line for line in second.stderr().splitlines() if "recovered" in line]
    assert len(recovered) == 1
    assert recovered[0].startswith(
        f"vahr up: recovered: the run before (pid {first.process.pid}) did not stop cleanly; "
        "replayed the shadow database's unfinished write-ahead log ("
    )
    with urllib.request.urlopen(second.endpoints["api"] + "/vahr/status", timeout=10) as answer:
        assert json.loads(answer.read())["online"] == {"placebot1": True, "placebot2": True}
    # And a clean stop leaves nothing behind and nothing to recover next time
    assert second.stop() == 0
    assert processes_of(state) == []
    assert (state / "vahr.pid").read_text() == ""


def _stack_config(state: Path) -> StackConfig:
    return StackConfig(
        state_dir=state, mqtts_port=free_port(), mqtt_port=free_port(), api_port=free_port()
    )


def test_a_broker_an_earlier_run_left_holding_the_port_is_stopped(tmp_path: Path) -> None:
    # Given a mosquitto left running by an earlier run (an older release, started without
    # a lifeline) that still holds this state directory's port
    config = _stack_config(tmp_path / "state")
    broker_dir = config.state_dir / "broker"
    broker_dir.mkdir(parents=True)
    conf = broker_dir / "mosquitto.conf"
    conf.write_text(BrokerConfig(state_dir=broker_dir, plain_port=config.mqtts_port).render())
    orphan = subprocess.Popen(
        ["mosquitto", "-c", str(conf)],
        env={**os.environ, STARTED_FOR: str(broker_dir)},
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )  # fmt: skip
    try:
        wait_until(lambda: _listening(config.mqtts_port), 10)
        # When a stack starts on that state directory
        with LocalStack(config) as stack:
            # Then the orphan is stopped, the line says so, and the stack serves
            assert stack.recovered == f"stopped what it left running: mosquitto (pid {orphan.pid})"
            assert orphan.wait(timeout=5) is not None
            assert stack.broker is not None and stack.broker.is_running()
    finally:
        if orphan.poll() is None:
            orphan.kill()
        orphan.wait(timeout=5)


def _listening(port: int) -> bool:
    with socket.socket() as sock:
        return sock.connect_ex(("127.0.0.1", port)) == 0


def test_a_second_run_on_a_state_directory_in_use_is_refused(tmp_path: Path) -> None:
    config = _stack_config(tmp_path / "state")
    with LocalStack(config) as running:
        # When a second stack is started on the same state directory
        with pytest.raises(VahrError) as refused:
            LocalStack(_stack_config(config.state_dir)).start()
        # Then it is refused in one line naming the holder, and the first keeps serving
        assert str(refused.value) == (
            f"the state directory {config.state_dir} is in use by another run "
            f"(pid {os.getpid()}); stop it or pass another --state-dir"
        )
        assert running.broker is not None and running.broker.is_running()
        with urllib.request.urlopen(running.api_url + "/vahr/health", timeout=5) as answer:
            assert answer.status == 200


def test_shadows_written_before_a_crash_survive_and_the_journal_is_replayed(
    tmp_path: Path,
) -> None:
    # Given a process that stored a shadow and was killed before closing its database
    state = tmp_path / "state"
    writer = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(f"""
            import os
            from pathlib import Path
            from vahr.twin.shadow_store import ShadowStore
            store = ShadowStore(Path({str(state / "shadows.sqlite3")!r}))
            store.update("placebot1", None, b'{{"state":{{"reported":{{"zone":"B"}}}}}}')
            os.kill(os.getpid(), 9)
        """)],
        cwd=ROOT, env=_env(), timeout=60, check=False,
    )  # fmt: skip
    assert writer.returncode == -signal.SIGKILL
    assert (state / "shadows.sqlite3-wal").stat().st_size > 0
    # When a stack starts on the directory
    with LocalStack(_stack_config(state)) as stack:
        # Then one line says the journal was replayed, and the shadow is there
        assert stack.recovered is not None
        assert stack.recovered.startswith(
            "replayed the shadow database's unfinished write-ahead log ("
        )
        assert stack.store is not None
        assert stack.store.get("placebot1")["state"]["reported"] == {"zone": "B"}


def test_a_damaged_shadow_database_is_moved_aside_not_served(tmp_path: Path) -> None:
    state = tmp_path / "state"
    state.mkdir()
    (state / "shadows.sqlite3").write_bytes(b"SQLite format 3\x00" + os.urandom(4096))
    with LocalStack(_stack_config(state)) as stack:
        assert stack.recovered is not None
        assert stack.recovered.startswith("the shadow database was damaged; moved it to ")
        aside = stack.recovered.split("moved it to ", 1)[1].split(" ", 1)[0]
        assert (state / aside).exists()
        assert stack.store is not None
        stack.store.update("placebot1", None, b'{"state":{"reported":{"zone":"A"}}}')


def test_a_child_started_from_a_short_lived_thread_outlives_that_thread(tmp_path: Path) -> None:
    # The parent-death signal follows the thread that forked; spawn() must not tie a
    # child to a worker thread that ends.
    box: list[subprocess.Popen[bytes]] = []
    worker = threading.Thread(
        target=lambda: box.append(spawn(["sleep", "30"], started_for=tmp_path))
    )
    worker.start()
    worker.join()
    child = box[0]
    try:
        with pytest.raises(TimeoutError):
            wait_until(lambda: child.poll() is not None, 0.5)
        assert alive(child.pid)
    finally:
        child.kill()
        child.wait(timeout=5)


HOLD_TEST = """
from pathlib import Path

def test_hold(stack, tmp_path):
    (Path({ready!r})).write_text("ready")
    import time
    time.sleep(120)
"""


@pytest.mark.slow
def test_a_killed_pytest_leaves_no_broker_behind(tmp_path: Path) -> None:
    # Given a pytest run holding the suite's `stack` fixture (mosquitto and all)
    ready = tmp_path / "ready"
    test_file = tmp_path / "test_hold.py"
    test_file.write_text(HOLD_TEST.format(ready=str(ready)))
    base = tmp_path / "base"
    run = subprocess.Popen(
        [sys.executable, "-m", "pytest", "-q", "-p", "tests.conftest", "-p", "no:cacheprovider",
         "--rootdir", str(ROOT), "-c", str(ROOT / "pyproject.toml"), "--basetemp", str(base),
         str(test_file)],
        cwd=ROOT, env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        wait_until(ready.exists, START_TIMEOUT_S)
        brokers = processes_of(base)
        assert [b.name for b in brokers] == ["mosquitto"]
        # When pytest is killed with SIGKILL
        kill_hard(run.pid)
        run.wait(timeout=5)
        # Then its broker is gone within 2 s
        wait_all_gone(brokers, GONE_WITHIN_S)
    finally:
        if run.poll() is None:
            run.kill()
            run.wait(timeout=5)
