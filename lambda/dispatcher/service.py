"""A robot taken out of service or put back, on AWS: recorded in the task table, then the
core acts on it (`Dispatcher.withdrawn`, `Dispatcher.reinstated`), as the local host does.

The table's record is one conditional write, so of two invocations changing one robot at
once only one changes it (`changed`) and acts; the other answers what the robot waits for.
The fleet search reads the robots out of service from the table on every search, so the
core sees the change at once (`RobotState.in_service`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

from vahr.dispatch import ServiceChange, timestamp

if TYPE_CHECKING:
    from vahr.dispatch import Dispatcher


@runtime_checkable
class ServiceRecord(Protocol):
    """Where the robots out of service are recorded: the task table (`TaskTable`)."""

    def set_in_service(self, thing: str, in_service: bool, *, at: str) -> bool:
        """Record `thing` in service or out of it; False when it already was."""
        ...

    def out_of_service(self) -> list[str]:
        """The robots out of service now, sorted."""
        ...


def out_of_service(dispatcher: Dispatcher) -> list[str]:
    """The robots out of service now (none when the store records no service)."""
    store = dispatcher.store
    return store.out_of_service() if isinstance(store, ServiceRecord) else []


def set_in_service(dispatcher: Dispatcher, thing: str, in_service: bool) -> ServiceChange:
    """Take `thing` out of service, or put it back; what that did."""
    table = dispatcher.store
    assert isinstance(table, ServiceRecord), "the task store records no service"
    changed = table.set_in_service(thing, in_service, at=timestamp(dispatcher.clock()))
    if not changed:
        return dispatcher.service_kept(thing, in_service)
    if in_service:
        return dispatcher.reinstated(thing)
    return dispatcher.withdrawn(thing)
