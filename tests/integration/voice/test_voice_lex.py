"""The Lex V2 interpreter with credentials from the IoT credentials provider.

moto 5.2.5 has no `lexv2-runtime` (only `lexv2-models`), so Lex runs here as a local HTTP
stub of the RecognizeText REST shape, and the credentials provider as a local HTTPS server
that requires the robot's client certificate (issued by the local CA). The tests check what
goes over the wire: the path, the text, the SigV4 signature made with the temporary
credentials, and the certificate the robot presented.
"""

from __future__ import annotations

import json
import ssl
import threading
from datetime import UTC, datetime, timedelta
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import TYPE_CHECKING, Any
from urllib.parse import unquote

import pytest

from robot_agent.voice.answers import WeatherAnswers
from robot_agent.voice.interpreter import LocalInterpreter
from robot_agent.voice.iot_credentials import IotCredentialsProvider
from robot_agent.voice.lex import LexInterpreter
from vahr.pki import LocalCA
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.pki import ClientCredentials


class Recorder:
    def __init__(self) -> None:
        self.requests: list[dict[str, Any]] = []


def serve(handler: type[BaseHTTPRequestHandler], context: ssl.SSLContext | None = None) -> Any:
    server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    if context is not None:
        server.socket = context.wrap_socket(server.socket, server_side=True)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    return server, thread


@pytest.fixture
def pki(tmp_path: Path) -> tuple[LocalCA, ClientCredentials]:
    ca = LocalCA.load_or_create(tmp_path / "state")
    return ca, ca.issue_client("placebot1", tmp_path / "robot")


@pytest.fixture
def credentials_server(
    pki: tuple[LocalCA, ClientCredentials],
) -> Iterator[tuple[str, Recorder]]:
    """AWS IoT's credentials provider: mTLS, role alias in the path, thing name header."""
    ca, _ = pki
    seen = Recorder()
    expiration = (datetime.now(UTC) + timedelta(hours=1)).strftime("%Y-%m-%dT%H:%M:%SZ")

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            peer = self.connection.getpeercert()  # type: ignore[attr-defined]
            subject = dict(item[0] for item in peer["subject"])
            seen.requests.append(
                {"path": self.path, "thing": self.headers["x-amzn-iot-thingname"],
                 "cn": subject["commonName"]}
            )  # fmt: skip
            if self.path != "/role-aliases/vahr-robot-lex/credentials":
                self.send_response(403)
                self.end_headers()
                self.wfile.write(b'{"message":"Access Denied"}')
                return
            body = json.dumps({"credentials": {
                "accessKeyId": f"ASIATEMP{len(seen.requests)}",
                "secretAccessKey": "secret", "sessionToken": "token-from-iot",
                "expiration": expiration}}).encode()  # fmt: skip
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args: object) -> None:
            pass

    context = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH, cafile=str(ca.ca_file))
    context.load_cert_chain(str(ca.server_cert_file), str(ca.server_key_file))
    context.verify_mode = ssl.CERT_REQUIRED
    server, thread = serve(Handler, context)
    try:
        yield f"127.0.0.1:{server.server_address[1]}", seen
    finally:
        server.shutdown()
        server.server_close()
        thread.join(5)


@pytest.fixture
def lex_server() -> Iterator[tuple[str, Recorder]]:
    """RecognizeText: POST /bots/{bot}/botAliases/{alias}/botLocales/{locale}/sessions/{id}/text.
    Its NLU is the local interpreter over the same sample phrasings the real bot is built from."""
    seen = Recorder()
    nlu = LocalInterpreter(WeatherAnswers.load())

    class Handler(BaseHTTPRequestHandler):
        def do_POST(self) -> None:
            body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
            parts = [unquote(p) for p in self.path.split("/")]
            seen.requests.append(
                {"parts": parts, "text": body["text"],
                 "authorization": self.headers["Authorization"],
                 "token": self.headers.get("X-Amz-Security-Token")}
            )  # fmt: skip
            meaning = nlu.interpret(body["text"])
            name = meaning.intent if meaning.intent != "unknown" else "FallbackIntent"
            answer = {
                "sessionId": parts[8],
                "sessionState": {"intent": {"name": name, "state": "ReadyForFulfillment"}},
                "interpretations": [
                    {"intent": {"name": name}, "nluConfidence": {"score": 0.87}},
                    {"intent": {"name": "FallbackIntent"}},
                ],
            }
            data = json.dumps(answer).encode()
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(data)))
            self.end_headers()
            self.wfile.write(data)

        def log_message(self, *args: object) -> None:
            pass

    server, thread = serve(Handler)
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}", seen
    finally:
        server.shutdown()
        server.server_close()
        thread.join(5)


def make_lex(
    pki: tuple[LocalCA, ClientCredentials], endpoint: str, lex_url: str, alias: str
) -> LexInterpreter:
    _, robot = pki
    provider = IotCredentialsProvider(
        endpoint=endpoint, role_alias=alias, thing="placebot1",
        cert=robot.cert_file, key=robot.key_file, ca=robot.ca_file,
    )  # fmt: skip
    return LexInterpreter(
        bot_id="WEATHERBOT", bot_alias_id="TSTALIASID", locale_id="en_US",
        session_id="placebot1", region="us-east-1", credentials=provider.get,
        endpoint_url=lex_url,
    )  # fmt: skip


def test_lex_interprets_with_credentials_bought_by_the_robot_certificate(
    pki: tuple[LocalCA, ClientCredentials],
    credentials_server: tuple[str, Recorder],
    lex_server: tuple[str, Recorder],
) -> None:
    endpoint, iot = credentials_server
    lex_url, lex = lex_server
    interpreter = make_lex(pki, endpoint, lex_url, "vahr-robot-lex")
    # When the robot interprets two answers
    sunny = interpreter.interpret("the weather is sunny")
    other = interpreter.interpret("what a lovely robot")
    # Then Lex's intents come back as the robot's, with Lex's confidence
    assert (sunny.intent, sunny.confidence) == ("sunny", 0.87)
    assert (other.intent, other.confidence) == ("unknown", 0.0)
    # And the credentials were fetched once, with the robot's certificate and thing name
    assert iot.requests == [
        {
            "path": "/role-aliases/vahr-robot-lex/credentials",
            "thing": "placebot1",
            "cn": "placebot1",
        }
    ]
    # And each RecognizeText call was signed with those temporary credentials
    first = lex.requests[0]
    assert first["parts"][1:] == ["bots", "WEATHERBOT", "botAliases", "TSTALIASID",
                                  "botLocales", "en_US", "sessions", "placebot1", "text"]  # fmt: skip
    assert first["text"] == "the weather is sunny"
    assert "Credential=ASIATEMP1/" in first["authorization"]
    assert "/us-east-1/lex/aws4_request" in first["authorization"]
    assert first["token"] == "token-from-iot"
    assert len(lex.requests) == 2


def test_a_refused_role_alias_is_a_voice_error(
    pki: tuple[LocalCA, ClientCredentials],
    credentials_server: tuple[str, Recorder],
    lex_server: tuple[str, Recorder],
) -> None:
    endpoint, _ = credentials_server
    lex_url, lex = lex_server
    interpreter = make_lex(pki, endpoint, lex_url, "someone-elses-alias")
    with pytest.raises(SpeechError, match=r"refused \(403\).*Access Denied"):
        interpreter.interpret("the weather is sunny")
    assert lex.requests == []


def test_an_unreachable_lex_is_a_voice_error(
    pki: tuple[LocalCA, ClientCredentials], credentials_server: tuple[str, Recorder]
) -> None:
    endpoint, _ = credentials_server
    from vahr.plumbing.ports import free_port

    interpreter = make_lex(pki, endpoint, f"http://127.0.0.1:{free_port()}", "vahr-robot-lex")
    with pytest.raises(SpeechError, match="Amazon Lex could not interpret"):
        interpreter.interpret("the weather is rainy")


def test_credentials_are_reused_until_near_expiry(
    pki: tuple[LocalCA, ClientCredentials], credentials_server: tuple[str, Recorder]
) -> None:
    endpoint, iot = credentials_server
    _, robot = pki
    clock = [datetime.now(UTC)]
    provider = IotCredentialsProvider(
        endpoint=endpoint, role_alias="vahr-robot-lex", thing="placebot1",
        cert=robot.cert_file, key=robot.key_file, ca=robot.ca_file, now=lambda: clock[0],
    )  # fmt: skip
    first = provider.get()
    assert provider.get() is first
    clock[0] += timedelta(minutes=56)  # within five minutes of the one-hour expiry
    assert provider.get().access_key_id == "ASIATEMP2"
    assert len(iot.requests) == 2
