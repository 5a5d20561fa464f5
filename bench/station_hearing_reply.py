"""Release of the talk button to the reply shown: push-to-talk end to end on `vahr up`.

Starts `vahr up` (simulated robots at 10x), then posts clips of about 3 s to the station's
`/api/voice` as the page does when the button is released, and times each answer (the
recognizer, the weighing of its N best, the simulator, the skill's turn with its wait for
the robot's acknowledgment, and the reply). The clips are development sentences spoken by
flite's slt and rms voices and festival's HTS voice, cut to those of 2.5 to 3.5 s; each is
posted once, in turn. The target is p95 at most 1 s.
Run: `.venv/bin/python bench/station_hearing_reply.py [--clips N]`.
"""

from __future__ import annotations

import argparse
import http.client
import json
import sys
import tempfile
import time
import urllib.parse
from pathlib import Path

from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from station_hearing import spoken  # noqa: E402

from tests.support.vahr_up import start_up, stop_up  # noqa: E402
from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402

VOICES = ("flite:slt", "flite:rms", "festival:cmu_us_slt_arctic_hts")


def ms(seconds: float) -> str:
    return f"{seconds * 1000:.0f} ms"


def post(station: str, wav: bytes) -> dict[str, object]:
    address = urllib.parse.urlsplit(station)
    host = address.hostname or "127.0.0.1"
    connection = http.client.HTTPConnection(host, address.port, timeout=60)
    try:
        connection.request("POST", "/api/voice", body=wav, headers={"Content-Type": "audio/wav"})
        answer: dict[str, object] = json.loads(connection.getresponse().read())
        return answer
    finally:
        connection.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--clips", type=int, default=30)
    args = parser.parse_args()
    clips = []
    for n, item in enumerate(LabelledSet.load(DEVELOPMENT_SET).utterances):
        audio = spoken(VOICES[n % len(VOICES)], item.text)
        if 2.5 <= audio.seconds <= 3.5:
            clips.append(audio)
        if len(clips) == args.clips:
            break
    with tempfile.TemporaryDirectory() as state:
        up = start_up(Path(state), "--station-port", str(free_port()), "--sim-speed-factor", "10")
        try:
            station = up.endpoints["station"]
            post(station, clips[0].to_wav())  # the recognizer and the NLU built
            times, acted = [], 0
            for audio in clips:
                started = time.perf_counter()
                answer = post(station, audio.to_wav())
                times.append(time.perf_counter() - started)
                turn = answer.get("turn")
                acted += bool(isinstance(turn, dict) and turn.get("commands"))
        finally:
            stop_up(up.process)
    load = " ".join(Path("/proc/loadavg").read_text().split()[:3])
    body = f"""
{len(clips)} clips of 2.5 to 3.5 s (development sentences in {", ".join(VOICES)} in turn)
posted to a running `vahr up`'s `/api/voice`, each timed from the post (the release of the
button) to the answer holding the reply; {acted} of them sent a command, whose reply waits
for the robot's acknowledgment. Load average {load} (the machine is shared).

| release to reply | median | p95 | max |
| --- | --- | --- | --- |
| push-to-talk, 3 s clip | {ms(median(times))} | {ms(percentile(times, 95))} | {ms(max(times))} |

Target: p95 at most 1 s.
"""
    write_section("station_hearing_reply", "Push-to-talk: release of the button to the reply", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
