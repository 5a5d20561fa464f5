"""`provision --local` then `run --config`: the robot connects over mTLS with its own certificate."""

from __future__ import annotations

import json
import signal
import stat
from pathlib import Path

import pytest
import yaml

from robot_agent.cli import main
from tests.integration.agent.harness import AgentProcess, ShadowResponder, WireTap, command
from vahr.pki import LocalCA
from vahr.plumbing.ports import free_port
from vahr.twin.broker import BrokerConfig, Mosquitto, TlsListener

# Anonymous test clients on the plaintext listener may do anything; a robot known by its
# certificate (username = CN) only its own topics, the fleet topic and its own shadow.
ACL = """\
topic readwrite #
topic readwrite $aws/#
pattern read vahr/fleet/cmd
pattern read vahr/robots/+/events
pattern readwrite vahr/robots/%u/#
pattern readwrite $aws/things/%u/shadow/#
"""


@pytest.mark.slow
def test_a_locally_provisioned_robot_connects_over_mtls_and_serves(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    state = tmp_path / "state"
    # Given credentials issued by the local CA
    assert (
        main(["provision", "--thing", "placebot1", "--local", "--state-dir", str(state), "--json"])
        == 0
    )
    bundle = json.loads(capsys.readouterr().out)
    for name in ("cert", "key", "config"):
        assert stat.S_IMODE(Path(bundle[name]).stat().st_mode) == 0o600, name
    ca = LocalCA.load_or_create(state)
    acl = tmp_path / "acl"
    acl.write_text(ACL)
    tls_port = free_port()
    broker = Mosquitto(
        BrokerConfig(
            state_dir=tmp_path / "broker",
            plain_port=free_port(),
            tls=TlsListener(
                port=tls_port,
                ca_file=ca.ca_file,
                cert_file=ca.server_cert_file,
                key_file=ca.server_key_file,
                acl_file=acl,
            ),
        )
    )
    broker.start()
    tap = shadows = agent = None
    try:
        tap = WireTap(broker.config.plain_port or 0)
        shadows = ShadowResponder(broker.config.plain_port or 0)
        config = yaml.safe_load(Path(bundle["config"]).read_text())
        assert config["thing"] == "placebot1" and config["endpoint"] == "localhost"
        # When the robot runs with the written config file (port given as a flag)
        agent = AgentProcess(
            "--config",
            bundle["config"],
            "--port",
            str(tls_port),
            "--sim-speed-factor",
            "50",
            state_dir=state,
            log_file=tmp_path / "agent.log",
        )
        # Then it is online over mTLS and executes commands
        tap.reported("placebot1", lambda r: r["connected"] is True, timeout_s=20)
        tap.publish("vahr/robots/placebot1/cmd", command("over-tls", "navigate", {"zone": "A"}))
        done = tap.reported(
            "placebot1", lambda r: (r["last_command"] or {}).get("result") == "done", timeout_s=20
        )
        assert done["zone"] == "A"
        assert agent.stop(signal.SIGTERM) == 0, agent.log()
    finally:
        if agent is not None and agent.process.poll() is None:
            agent.kill()
        for part in (tap, shadows):
            if part is not None:
                part.close()
        broker.stop()
