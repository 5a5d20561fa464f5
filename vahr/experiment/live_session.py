"""Run a session against a live system: the entry points for `vahr experiment`, `vahr demo`
and each trial of `vahr rehearse`.

`run_live` connects the recorder to the broker and lets a performer (the simulated
participant or the observer's console) run the tasks. `run_simulated_session` is the one
call a demo and each trial of a study need: open (or resume) a simulated session, publish
its plan to the experiment shadow, run it, and return the judge's verdict with the log's path.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.experiment.bus import Bus
from vahr.experiment.participant import Console, SimulatedParticipant
from vahr.experiment.recorder import Recorder
from vahr.experiment.session import (
    SessionSpec,
    end_session,
    open_session,
    rebuild_world,
    run_tasks,
)
from vahr.experiment.station_link import WILL, StatusBroadcast
from vahr.experiment.tasks import default_seed
from vahr.experiment.timing import Person
from vahr.protocol.identities import RECORDER_CLIENT_PREFIX

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.experiment.judge import SessionVerdict
    from vahr.experiment.session import OpenSession, Performer
    from vahr.plumbing.client import Assistant
    from vahr.protocol.broker import ClientCredentials


def run_live(
    session: OpenSession,
    fleet: Fleet,
    *,
    broker_url: str,
    performer_for: Callable[[Console], Performer],
    announce: Callable[[str], None] = lambda line: None,
    tls: ClientCredentials | None = None,
) -> SessionVerdict:
    """Record the wire into the session's log while `performer_for(console)` runs the tasks,
    then end the session; return the judge's verdict."""
    recorder = Recorder(session.log, rebuild_world(fleet, session), session=session.spec.name)
    bus = Bus(
        broker_url,
        recorder.on_message,
        client_id=f"{RECORDER_CLIENT_PREFIX}{session.spec.name}",
        tls=tls,
        will=WILL,
    )
    bus.start()
    # The operator station shows the session from its status (vahr.experiment.station_link).
    status = StatusBroadcast(
        session, recorder, lambda topic, payload, retain: bus.publish(topic, payload, retain=retain)
    ).start()
    ended = False
    try:
        console = Console(bus.publish, session.spec.method)
        run_tasks(session, recorder, performer_for(console), announce=announce)
        # Nothing is logged after the end: a late robot event must not follow it.
        recorder.close()
        verdict = end_session(session)
        ended = True
    finally:
        status.stop(ended=ended)
        bus.stop()
    return verdict


def simulated_performer(
    session: OpenSession,
    fleet: Fleet,
    assistant: Assistant | None,
    person: Person | None = None,
) -> Callable[[Console], Performer]:
    """A factory of the simulated participant for `run_live`. Both methods talk to the
    assistant (the keyboard-and-mouse method asks it for the weather in task II)."""

    def build(console: Console) -> Performer:
        method = session.spec.method
        return SimulatedParticipant(
            method=method,
            fleet=fleet,
            plan=session.plan,
            log=session.log,
            person=person or Person(),
            seed=session.plan.seed,
            speed_factor=session.spec.speed_factor,
            assistant=assistant,
            console=console if method == "keyboard" else None,
        )

    return build


def run_simulated_session(
    *,
    fleet: Fleet,
    method: str,
    log_dir: Path,
    broker_url: str,
    assistant: Assistant | None = None,
    participant: str = "SIM",
    trial: int = 1,
    seed: int | None = None,
    speed_factor: float = 1.0,
    task_timeout_s: float = 600.0,
    pause_s: float = 0.0,
    data_plane_url: str | None = None,
    write_shadow: bool = True,
    announce: Callable[[str], None] = lambda line: None,
    tls: ClientCredentials | None = None,
    person: Person | None = None,
) -> tuple[SessionVerdict, Path]:
    """Run (or resume) one simulated session end to end; return the verdict and the log."""
    spec = SessionSpec(
        participant=participant,
        method=method,
        trial=trial,
        seed=seed if seed is not None else default_seed(participant, method, trial),
        log_dir=log_dir,
        simulated=True,
        speed_factor=speed_factor,
        task_timeout_s=task_timeout_s,
        pause_s=pause_s,
    )
    session = open_session(spec, fleet)
    try:
        if write_shadow:
            from vahr.experiment.experiment_shadow import ExperimentShadow

            shadow = ExperimentShadow(fleet, endpoint_url=data_plane_url)
            shadow.write(session.plan.experiment_state(spec.name))
        verdict = run_live(
            session,
            fleet,
            broker_url=broker_url,
            performer_for=simulated_performer(session, fleet, assistant, person),
            announce=announce,
            tls=tls,
        )
    finally:
        session.log.close()
    return verdict, spec.path
