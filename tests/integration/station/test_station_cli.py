"""`vahr station` against a running local stack: the page's address first, a clean stop,
and one-line errors for bad flags."""

from __future__ import annotations

import json
import signal
import ssl
import subprocess
import urllib.request
from typing import TYPE_CHECKING

import pytest

from tests.support.vahr_up import ROOT, VAHR, clean_env
from vahr.plumbing.lifetime import spawn
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack


def test_vahr_station_serves_the_page_for_a_running_stack(stack: LocalStack) -> None:
    # Given a local stack (broker, shadows, data plane)
    assert stack.mqtt_url is not None
    process = spawn(
        [*VAHR, "station", "--broker", stack.mqtt_url, "--api", stack.api_url,
         "--port", str(free_port()), "--no-voice", "--json"],
        started_for=stack.config.state_dir, cwd=ROOT, env=clean_env(), stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert process.stdout is not None
        # When it starts, its first line is the page's address (no token on loopback)
        first = json.loads(process.stdout.readline())
        assert first["token"] is None and first["station"].startswith("http://127.0.0.1:")
        # Then the page is served with the fleet it was given
        with urllib.request.urlopen(first["station"] + "api/snapshot", timeout=10) as answer:
            snapshot = json.loads(answer.read())
        assert [r["thing"] for r in snapshot["fleet"]["robots"]] == ["placebot1", "placebot2"]
    finally:
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=30) == 0


def test_vahr_station_off_loopback_serves_https_from_the_local_ca_over_mtls(
    stack: LocalStack,
) -> None:
    # Given a local stack without a plaintext listener in use: the station connects with a
    # service identity over mTLS, and serves the lab network (127.0.0.2 stands in) over
    # HTTPS with a certificate of the stack's own CA
    assert stack.ca is not None
    identity = stack.ca.service_credentials()
    process = spawn(
        [*VAHR, "station", "--broker", stack.mqtts_url, "--cert", str(identity.cert_file),
         "--key", str(identity.key_file), "--ca", str(identity.ca_file), "--api", stack.api_url,
         "--host", "127.0.0.2", "--port", str(free_port()), "--tls",
         "--state-dir", str(stack.config.state_dir), "--no-voice", "--json"],
        started_for=stack.config.state_dir, cwd=ROOT, env=clean_env(), stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert process.stdout is not None
        first = json.loads(process.stdout.readline())
        assert first["station"] == f"{first['station'].split('?')[0]}?token={first['token']}"
        assert first["station"].startswith("https://127.0.0.2:")
        # Then a browser that trusts the stack's CA opens it, the certificate checked
        context = ssl.create_default_context(cafile=str(stack.ca.ca_file))
        request = urllib.request.Request(
            first["station"].split("?")[0] + "api/health",
            headers={"Authorization": f"Bearer {first['token']}"},
        )
        with urllib.request.urlopen(request, timeout=10, context=context) as answer:
            assert json.loads(answer.read()) == {"ok": True}
    finally:
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=30) == 0


@pytest.mark.parametrize(
    ("flags", "error"),
    [
        (["--port", "70000"], "vahr station: error: --port 70000: not a usable port"),
        (["--token", "short"], "vahr station: error: --token must be at least 16 characters"),
        (["--cert", "a.pem"], "vahr station: error: --cert, --key and --ca go together"),
        (
            ["--broker", "mqtts://127.0.0.1:1"],
            "vahr station: error: broker mqtts://127.0.0.1:1 needs --cert, --key and --ca for mTLS",
        ),
        (["--tls-cert", "a.pem"], "vahr station: error: --tls-cert and --tls-key go together"),
        (
            ["--tls", "--tls-cert", "a.pem", "--tls-key", "a.key"],
            "vahr station: error: give --tls (the local CA) or --tls-cert and --tls-key, not both",
        ),
        (
            ["--tls-cert", "missing.pem", "--tls-key", "missing.key"],
            "vahr station: error: --tls-cert missing.pem: cannot serve with it ([Errno 2] No such "
            "file or directory)",
        ),
        (
            ["--public-origin", "station.lab.example"],
            "vahr station: error: --public-origin 'station.lab.example': give the scheme, name and "
            "port only (https://station.lab.example)",
        ),
    ],
)
def test_bad_flags_are_one_line(flags: list[str], error: str) -> None:
    argv = [*VAHR, "station", "--broker", f"mqtt://127.0.0.1:{free_port()}", *flags]
    result = subprocess.run(
        argv, cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 2
    assert result.stderr.strip() == error
