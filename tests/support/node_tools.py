"""npm's packages, for the tests that use npm's tools (the CDK CLI, the docs' `npx` commands).

`make test` starts the suite as soon as the Python venv is made, while `npm ci` is still at
work beside it (it waits on the network on a fresh machine, and nothing else in the suite
needs it). It says so with VAHR_AWAIT_NODE_MODULES, and these tests then wait for the marker
make writes when `npm ci` is done; anywhere else a missing install fails at once.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
NODE_MODULES = ROOT / "node_modules"
# Written by the Makefile's `node_modules/.installed` rule once `npm ci` succeeded.
INSTALLED = NODE_MODULES / ".installed"
WAIT_S = 240.0


def node_modules() -> Path:
    """The installed `node_modules`, once `npm ci` is done (waited for under `make test`)."""
    if not INSTALLED.exists() and os.environ.get("VAHR_AWAIT_NODE_MODULES"):
        deadline = time.monotonic() + WAIT_S
        while not INSTALLED.exists() and time.monotonic() < deadline:
            time.sleep(0.5)
    if not INSTALLED.exists():
        pytest.fail("npm's packages are not installed: run `make setup` (it runs npm ci)")
    return NODE_MODULES
