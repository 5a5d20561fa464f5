"""The shadow's `last_command` describes the last command only: after a failed command, the
next one's result carries no reason of the failure (a shadow update merges objects key by
key, so the robot sends `reason: null`). The zone a failure's reason names is sent with it,
so speech and the station can say it by its name."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.unit.agent.conftest import make_executor
from tests.unit.agent.test_agent_executor import cmd
from vahr.twin.shadow_store import ShadowStore

if TYPE_CHECKING:
    from vahr.domain import Fleet


async def test_a_command_done_after_a_failure_leaves_no_reason_in_the_shadow(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet)
    store = ShadowStore()
    # Given a command that failed, its reason stored in the shadow
    backend.inject_failure("an injected fault")
    executor.execute(cmd("navigate", {"zone": "B"}, "f1"))
    await executor.wait_idle()
    for state in rec.states:
        store.update("placebot1", None, state.to_payload())
    failed = store.get("placebot1")["state"]["reported"]["last_command"]
    assert failed == {
        "id": "f1",
        "action": "navigate",
        "result": "failed",
        "reason": "goal to B aborted: an injected fault",
        "zone": "B",
    }
    assert rec.first("failed", "f1").zone == "B"
    # When the fault is cleared and the next command succeeds
    backend.clear_faults()
    seen = len(rec.states)
    executor.execute(cmd("navigate", {"zone": "C"}, "n2"))
    await executor.wait_idle()
    for state in rec.states[seen:]:
        store.update("placebot1", None, state.to_payload())
    # Then the shadow's last command is that one, with nothing of the failure
    last = store.get("placebot1")["state"]["reported"]["last_command"]
    assert last == {"id": "n2", "action": "navigate", "result": "done", "zone": "C"}
