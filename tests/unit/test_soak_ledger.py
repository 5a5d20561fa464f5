"""The soak's books: what a sender was told decides what a robot owes.

A console publish that got no PUBACK in time is reported as unconfirmed ("the broker may
still have received it"), not as failed: a robot that then runs it once has done nothing
wrong, so it is not "ran after refusal"; running it twice still is a fault. The 30-minute
soak counted 5 such commands as run after refusal."""

from __future__ import annotations

from tests.support.soak_ledger import Ledger, Record, Sent


def _ran(*events: str) -> Record:
    return Record([(event, None) for event in events])


def test_an_unconfirmed_publish_that_ran_once_is_neither_refused_nor_owed() -> None:
    # Given a publish the sender was told may or may not have reached the broker
    ledger = Ledger()
    ledger.send(Sent("c1", "ping", ("swarm0001",), "console", 1.0, "no PUBACK", unconfirmed=True))
    # When the robot ran it once
    verdict = ledger.verdict({("swarm0001", "c1"): _ran("accepted", "done")})
    # Then it is counted as unconfirmed and run, not as run after refusal, lost or owed
    assert (verdict.unconfirmed, verdict.unconfirmed_ran) == (1, 1)
    assert verdict.ran_after_refusal == [] and verdict.lost == [] and verdict.owed == 0
    assert ledger.settled({})


def test_an_unconfirmed_publish_run_twice_is_run_twice() -> None:
    ledger = Ledger()
    ledger.send(Sent("c1", "ping", ("swarm0001",), "console", 1.0, "no PUBACK", unconfirmed=True))
    verdict = ledger.verdict({("swarm0001", "c1"): _ran("accepted", "done", "accepted", "done")})
    assert verdict.run_twice == ["c1"]


def test_a_refused_publish_that_ran_is_run_after_refusal() -> None:
    ledger = Ledger()
    ledger.send(Sent("c1", "ping", ("swarm0001",), "console", 1.0, "not connected"))
    verdict = ledger.verdict({("swarm0001", "c1"): _ran("accepted", "done")})
    assert verdict.ran_after_refusal == ["c1"]
