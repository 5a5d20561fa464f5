"""The Lambda entry point: `skill.app.lambda_handler` (code root `lambda/`).

At cold start the configuration is read once, the fleet is loaded and the iot-data client
is created; warm invocations reuse them. That happens when `lambda_handler` is first looked
up (Lambda's runtime does so while initialising), not on import, so tools that import this
module without AWS settings (the local stack, the tests) do not fail or pay for it.
`make_lambda_handler` (`skill.builder`) builds the same handler around another
configuration or gateway.

The skill's modules are imported, and the handler built, with Python's cyclic garbage
collector paused, and what they made is then frozen (`gc.freeze`): both make many
long-lived objects and next to no garbage (ask-sdk-model alone defines some 250 modules of
classes; botocore's client reads its service model's JSON), which collections during the
cold start, and every full collection after it, would only walk in vain: 697 -> 619 ms of
CPU measured back to back (docs/benchmarks.md, "Alexa skill: cold start"). A process that
imports the skill in-process (the local stack's Alexa host, a test worker) freezes its own
heap of that moment too: objects that live on anyway, and never walked again.
"""

from __future__ import annotations

import contextlib
import gc
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator


@contextlib.contextmanager
def _collector_paused() -> Iterator[None]:
    """The cyclic garbage collector off for the block, then as it was, with what the block
    made frozen (never collected, never walked again)."""
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if collecting:
            gc.enable()


with _collector_paused():
    from skill.builder import build_skill_builder, make_lambda_handler, request_handlers

__all__ = ["build_skill_builder", "lambda_handler", "make_lambda_handler", "request_handlers"]

lambda_handler: Callable[[dict[str, Any], Any], dict[str, Any]]


def __getattr__(name: str) -> Any:
    # PEP 562: build the environment's handler once, on first access, then keep it.
    if name == "lambda_handler":
        with _collector_paused():
            handler = make_lambda_handler()
        globals()["lambda_handler"] = handler
        return handler
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
