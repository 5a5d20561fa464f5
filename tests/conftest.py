"""Fixtures shared by every test: the fleet, real-shaped events, and a real mosquitto."""

from __future__ import annotations

import gc
import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.scheduling import FileGroupScheduling, longest_files_first
from vahr.domain import Fleet, load_fleet
from vahr.plumbing.ports import free_port
from vahr.twin.broker import BrokerConfig, Mosquitto
from vahr.twin.stack import LocalStack, StackConfig

if TYPE_CHECKING:
    from collections.abc import Iterator

    from xdist.remote import Producer

EVENTS_DIR = Path(__file__).parent / "events"


def pytest_configure() -> None:
    """Every test process: fewer full garbage collections (below), and one BLAS and OpenMP
    thread per process, set before numpy loads: the suite's workers already keep both
    cores busy, and the threads numpy, scipy and scikit-learn would add per core only
    contend (a model fit in each worker at once took 14 s instead of 4). The robots and
    stacks the tests start inherit the threads' setting."""
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(name, "1")
    # A worker's heap holds what a whole suite imports and loads (botocore's service models,
    # the CDK's jsii proxies, trained models) for the worker's life, and CPython's default
    # thresholds walk all of it in a full collection after every ten younger ones: those
    # took 5 to 14% of a worker's CPU over the unit tests (timed with gc.callbacks; 14 s of
    # 149 on two workers). One after every hundred took 4 s, the young generations'
    # collections left as they are.
    young, middle, _ = gc.get_threshold()
    gc.set_threshold(young, middle, 100)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Any:
    """A failed test that used a `vahr up` says whether it still ran and what it logged
    (a stack that went away mid-module shows why, not only that nothing answered): each
    stack of its fixtures, and each it started itself."""
    from tests.support import vahr_up

    report = yield
    if report.failed:
        stacks = {
            id(value): (name, value)
            for name, value in getattr(item, "funcargs", {}).items()
            if isinstance(value, vahr_up.Up)
        }
        for number, up in enumerate(vahr_up.started, 1):
            stacks.setdefault(id(up), (f"started by the test, {number}", up))
        for name, up in stacks.values():
            report.sections.append((f"vahr up ({name})", up.story()))
    if report.when == "teardown":
        vahr_up.started.clear()
    return report


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The longest files run first, so that the workers finish close together."""
    longest_files_first(items)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Producer) -> FileGroupScheduling | None:
    """With `--dist loadgroup`, each test file runs whole on one worker (its module fixtures,
    a stack or a robot, start once), and every infra test on one worker (the CDK apps they
    share are synthesized once per session): tests/support/scheduling.py."""
    if config.getvalue("dist") != "loadgroup":
        return None
    return FileGroupScheduling(config, log)


@pytest.fixture(scope="session")
def fleet() -> Fleet:
    return load_fleet()


def load_event(name: str) -> dict[str, Any]:
    """A real-shaped JSON event from tests/events/ by file name (without `.json`)."""
    loaded: dict[str, Any] = json.loads((EVENTS_DIR / f"{name}.json").read_text())
    return loaded


@pytest.fixture
def mosquitto(tmp_path: Path) -> Iterator[Mosquitto]:
    """A real mosquitto with a plaintext listener on a free loopback port."""
    broker = Mosquitto(BrokerConfig(state_dir=tmp_path / "broker", plain_port=free_port()))
    broker.start()
    try:
        yield broker
    finally:
        broker.stop()


@pytest.fixture
def stack(tmp_path: Path) -> Iterator[LocalStack]:
    """A fresh local stack of its own: broker (mTLS and plaintext), shadow service and
    data plane, on free loopback ports."""
    config = StackConfig(
        state_dir=tmp_path / "stack",
        mqtts_port=free_port(),
        mqtt_port=free_port(),
        api_port=free_port(),
    )
    with LocalStack(config) as running:
        yield running
