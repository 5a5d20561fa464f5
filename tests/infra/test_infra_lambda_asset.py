"""The skill's Lambda bundle, built by `infra.lambda_asset` as CDK and the ASK path build it,
then loaded the way the Lambda runtime loads it: CPython 3.12, the bundle first on the path,
the runtime's own boto3 after it, nothing from this checkout."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import unquote, urlsplit

import pytest
from template_tools import REPO_ROOT

from infra import lambda_asset
from vahr.errors import VahrError
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from collections.abc import Iterator

# The project's own budget, far below Lambda's 250 MB: precompiled, the bundle is 15.1 MB.
MAX_UNZIPPED_BYTES = 16 * 1000 * 1000
EVENTS = REPO_ROOT / "tests" / "events"


def lambda_python() -> Path:
    """A CPython 3.12 like the Lambda runtime's: $VAHR_PYTHON312, python3.12, or pyenv's."""
    candidates = [os.environ.get("VAHR_PYTHON312"), shutil.which("python3.12")]
    candidates += [str(p) for p in sorted(Path.home().glob(".pyenv/versions/3.12*/bin/python3.12"))]
    for candidate in filter(None, candidates):
        check = subprocess.run([candidate, "-c", "pass"], capture_output=True, timeout=30)
        if check.returncode == 0:
            return Path(candidate)
    pytest.fail("no CPython 3.12 found to load the bundle: set VAHR_PYTHON312 to one")


@pytest.fixture(scope="module")
def bundle(tmp_path_factory: pytest.TempPathFactory) -> lambda_asset.BuildResult:
    return lambda_asset.build(tmp_path_factory.mktemp("asset") / "bundle")


def run_in_lambda_python(bundle: Path, script: str, **env: str) -> subprocess.CompletedProcess[str]:
    """Run `script` in an isolated 3.12 interpreter that sees only the bundle and boto3."""
    path = [str(bundle), str(lambda_asset.runtime_site())]
    # Lambda's code directory is read-only: nothing may be compiled into it on the way.
    prologue = f"import sys; sys.dont_write_bytecode = True; sys.path[:0] = {path!r}\n"
    environment = {
        "PATH": "/usr/bin:/bin", "AWS_REGION": "us-east-1", "AWS_DEFAULT_REGION": "us-east-1",
        "AWS_ACCESS_KEY_ID": "testing", "AWS_SECRET_ACCESS_KEY": "testing",
        "VAHR_IOT_DATA_ENDPOINT": "https://a1b2c3d4e5f6g7-ats.iot.us-east-1.amazonaws.com",
        **env,
    }  # fmt: skip
    return subprocess.run(
        [str(lambda_python()), "-I", "-W", "ignore::SyntaxWarning", "-c", prologue + script],
        capture_output=True, text=True, timeout=120, env=environment, cwd=bundle,
    )  # fmt: skip


def test_the_bundle_holds_the_skill_the_announcer_the_protocol_and_the_fleet(
    bundle: lambda_asset.BuildResult,
) -> None:
    root = bundle.out_dir
    assert (root / "skill" / "app.py").is_file()
    assert (root / "announcer" / "app.py").is_file()
    assert not (root / "skill" / "announcer").exists()
    assert (root / "vahr" / "announce" / "policy.py").is_file()
    assert (root / "vahr" / "protocol" / "topics.py").is_file()
    assert (root / "vahr" / "errors.py").is_file()
    fleet = root / "vahr" / "domain" / "fleet.yaml"
    assert fleet.read_bytes() == (REPO_ROOT / "fleet.yaml").read_bytes()
    assert not (root / "vahr" / "local").exists()  # only what the skill needs


def test_the_bundle_is_small_and_has_no_awscrt_nor_its_own_boto3(
    bundle: lambda_asset.BuildResult,
) -> None:
    assert bundle.size_bytes < MAX_UNZIPPED_BYTES
    names = {path.name for path in bundle.out_dir.iterdir()}
    assert not names & {"awscrt", "awsiot", "boto3", "botocore"}
    assert not any("awscrt" in str(path) for path in bundle.out_dir.rglob("*"))


def test_compiled_modules_are_built_for_the_lambda_runtime_not_this_machine(
    bundle: lambda_asset.BuildResult,
) -> None:
    # This machine runs CPython 3.11; a plain install would bring cpython-311 extensions.
    extensions = [path.name for path in bundle.out_dir.rglob("*.so")]
    assert extensions, "msgspec and PyYAML ship compiled extensions"
    assert all("cpython-312-x86_64-linux-gnu" in name for name in extensions), extensions


def test_a_clean_python_3_12_imports_the_handler_from_the_bundle_alone(
    bundle: lambda_asset.BuildResult,
) -> None:
    script = (
        "import json, sys, skill.app, ask_sdk_core, msgspec, yaml, vahr.domain as p\n"
        "print(json.dumps({'handler': callable(skill.app.lambda_handler),"
        " 'files': [m.__file__ for m in (skill.app, ask_sdk_core, msgspec, yaml, p)],"
        " 'fleet': p.DEFAULT_FLEET_FILE, 'awscrt': 'awscrt' in sys.modules,"
        " 'version': sys.version_info[:2]}))"
    )
    result = run_in_lambda_python(bundle.out_dir, script)
    assert result.returncode == 0, result.stderr
    seen = json.loads(result.stdout)
    assert seen["handler"] is True
    assert seen["version"] == [3, 12]
    assert all(file.startswith(str(bundle.out_dir)) for file in seen["files"]), seen["files"]
    assert seen["fleet"] == str(bundle.out_dir / "vahr" / "domain" / "fleet.yaml")
    assert seen["awscrt"] is False


def test_the_announcer_loads_from_the_same_bundle_without_the_skills_sdk(
    bundle: lambda_asset.BuildResult,
) -> None:
    # When a clean 3.12 imports the announcer's handler from the bundle
    script = (
        "import json, sys, announcer.app\n"
        "print(json.dumps({'handler': callable(announcer.app.lambda_handler),"
        " 'file': announcer.app.__file__,"
        " 'loaded': sorted(m for m in ('skill', 'ask_sdk_core', 'ask_sdk_model', 'awscrt',"
        " 'vahr.announce', 'vahr.protocol') if m in sys.modules)}))"
    )
    result = run_in_lambda_python(bundle.out_dir, script)
    assert result.returncode == 0, result.stderr
    seen = json.loads(result.stdout)
    # Then it comes from the bundle, and its cold start pays for none of the skill's modules
    assert seen["handler"] is True
    assert seen["file"] == str(bundle.out_dir / "announcer" / "app.py")
    assert seen["loaded"] == ["vahr.announce", "vahr.protocol"]


def test_the_dispatcher_loads_from_the_same_bundle_and_answers_in_one_line(
    bundle: lambda_asset.BuildResult,
) -> None:
    # When a clean 3.12 runs the dispatcher's handler from the bundle with a request it
    # cannot carry out (so no AWS service is needed: moto's server needs Flask)
    script = (
        "import json, sys, dispatcher.app\n"
        "answer = dispatcher.app.lambda_handler({'operation': 'launch'}, None)\n"
        "print(json.dumps({'answer': answer, 'file': dispatcher.app.__file__,"
        " 'loaded': sorted(m for m in ('skill', 'ask_sdk_core', 'announcer', 'awscrt',"
        " 'vahr.announce', 'vahr.dispatch') if m in sys.modules)}))"
    )
    result = run_in_lambda_python(bundle.out_dir, script, VAHR_TASK_TABLE="vahr-tasks")
    assert result.returncode == 0, result.stderr
    seen = json.loads(result.stdout)
    # Then it comes from the bundle, reads its configuration and fleet, and answers the
    # skill's way; its cold start loads none of the skill's or the announcer's modules
    assert seen["file"] == str(bundle.out_dir / "dispatcher" / "app.py")
    assert seen["answer"] == {
        "status": 400,
        "body": {
            "code": 400,
            "message": "operation: 'launch' is not one of submit, tasks, pending, cancel, "
            "zones, zone, service, set_service, charge",
        },
    }
    assert seen["loaded"] == ["vahr.dispatch"]


class IotDataRecorder(BaseHTTPRequestHandler):
    """The two iot-data calls the navigate path makes, as AWS answers them for robots that
    never reported: Publish is accepted and recorded; GetThingShadow is 404. (moto's
    server would do, but needs Flask, which this project does not install.)"""

    published: list[tuple[str, bytes]]

    def do_POST(self) -> None:
        url = urlsplit(self.path)
        body = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        if url.path.startswith("/topics/"):
            signature = self.headers.get("Authorization", "")
            # boto3 signs for the iot-data service as `iotdata`; anything else is refused.
            if not signature.startswith("AWS4-HMAC-SHA256") or "/iotdata/" not in signature:
                self._answer(403, b'{"message": "unsigned"}', "UnauthorizedException")
                return
            self.published.append((unquote(url.path.removeprefix("/topics/")), body))
            self._answer(200, b"{}")
        else:
            self._answer(404, b'{"message": "not found"}', "ResourceNotFoundException")

    def do_GET(self) -> None:
        self._answer(404, b'{"message": "No shadow exists"}', "ResourceNotFoundException")

    def _answer(self, status: int, body: bytes, error: str | None = None) -> None:
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        if error:
            self.send_header("x-amzn-ErrorType", error)
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, format: str, *args: object) -> None:  # noqa: A002
        pass


@pytest.fixture
def iot_data() -> Iterator[tuple[str, list[tuple[str, bytes]]]]:
    published: list[tuple[str, bytes]] = []
    handler = type("Recorder", (IotDataRecorder,), {"published": published})
    server = ThreadingHTTPServer(("127.0.0.1", free_port()), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}", published
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)


def test_the_bundled_handler_publishes_a_spoken_command_through_iot_data(
    bundle: lambda_asset.BuildResult, iot_data: tuple[str, list[tuple[str, bytes]]]
) -> None:
    endpoint, published = iot_data
    # Given the bundle in a clean 3.12, its iot-data endpoint pointed at the recorder
    script = (
        "import json, skill.app\n"
        f"event = json.load(open({str(EVENTS / 'alexa_navigate.json')!r}))\n"
        "print(json.dumps(skill.app.lambda_handler(event, None)))"
    )
    # When Alexa sends "send placebot one to zone a"
    result = run_in_lambda_python(
        bundle.out_dir, script, VAHR_IOT_DATA_ENDPOINT=endpoint, VAHR_ACK_TIMEOUT_S="0.3"
    )
    assert result.returncode == 0, result.stderr
    # Then a navigate command went out on placebot1's command topic, signed by boto3
    commands = [
        json.loads(body) for topic, body in published if topic == "vahr/robots/placebot1/cmd"
    ]
    assert [c["action"] for c in commands] == ["navigate"]
    assert commands[0]["params"] == {"zone": "A"}
    assert commands[0]["source"] == "alexa"
    # And the skill answered in words (how long a cold start takes is measured, not
    # asserted: bench/lambda_bundle.py and bench/skill_cold_start.py)
    speech = json.loads(result.stdout)["response"]["outputSpeech"]["ssml"]
    assert speech.startswith("<speak>") and len(speech) > len("<speak></speak>")


def test_a_rebuild_reuses_the_installed_dependencies(tmp_path: Path) -> None:
    lambda_asset.build(tmp_path / "first")  # warm the cache (no-op when the fixture did)
    started = time.monotonic()
    again = lambda_asset.build(tmp_path / "second")
    assert again.from_cache
    assert time.monotonic() - started < 10


def test_the_zip_is_reproducible(bundle: lambda_asset.BuildResult, tmp_path: Path) -> None:
    lambda_asset.write_zip(bundle.out_dir, tmp_path / "a.zip")
    lambda_asset.write_zip(bundle.out_dir, tmp_path / "b.zip")
    assert (tmp_path / "a.zip").read_bytes() == (tmp_path / "b.zip").read_bytes()


def test_a_build_into_a_non_empty_directory_is_refused(tmp_path: Path) -> None:
    (tmp_path / "left-over.txt").write_text("x")
    with pytest.raises(VahrError, match="is not empty: give the build an empty directory"):
        lambda_asset.build(tmp_path)


def test_a_build_into_a_file_is_refused(tmp_path: Path) -> None:
    (tmp_path / "taken").write_text("x")
    with pytest.raises(VahrError, match="cannot make the directory .*taken: File exists"):
        lambda_asset.build(tmp_path / "taken")


def test_the_command_line_prints_one_summary_line(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "infra.lambda_asset", str(tmp_path / "out"), "--zip", str(tmp_path / "skill.zip")],
        capture_output=True, text=True, timeout=300, cwd=REPO_ROOT,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f"{tmp_path / 'out'}: ")
    assert "MB unzipped" in result.stdout
    assert (tmp_path / "skill.zip").stat().st_size > 0


def test_an_arm64_bundle_carries_aarch64_extensions(tmp_path: Path) -> None:
    # Given -c architecture=arm64, When the bundle is built on this x86_64 machine
    arm = lambda_asset.build(tmp_path / "arm64", architecture="arm64")
    # Then its compiled modules are for Graviton, not for this machine
    extensions = [path.name for path in arm.out_dir.rglob("*.so")]
    assert extensions
    assert all("cpython-312-aarch64-linux-gnu" in name for name in extensions), extensions


def test_a_precompiled_bundle_loads_from_byte_code_and_stays_under_the_limit(
    tmp_path: Path,
) -> None:
    # Given a bundle precompiled by CPython 3.12
    compiled = lambda_asset.build(tmp_path / "compiled", compile_with=lambda_python())
    assert compiled.size_bytes < MAX_UNZIPPED_BYTES
    # When a clean 3.12 that may not write byte code imports the handler
    script = (
        "import skill.app, ask_sdk_model, marshal, sys; print(skill.app.__cached__); "
        "print(marshal.loads(open(skill.app.__cached__, 'rb').read()[16:]).co_filename)"
    )
    result = run_in_lambda_python(compiled.out_dir, script)
    # Then it loads, and its byte code is the bundle's own
    assert result.returncode == 0, result.stderr
    cached_line, compiled_as = result.stdout.split()
    cached = Path(cached_line)
    assert cached.name == "app.cpython-312.pyc" and cached.is_file()
    assert cached.is_relative_to(compiled.out_dir)
    # and names its source where Lambda puts it, not where it was built (so the bundle's
    # bytes, and its size, do not depend on the build directory)
    assert compiled_as == "/var/task/skill/app.py"
