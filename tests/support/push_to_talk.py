"""Speaking to a running station's push-to-talk (`POST /api/voice`) as its page does: a
clip synthesized by a named voice, padded with the silence a button press leaves; and
typing to it (`POST /api/say`)."""

from __future__ import annotations

import http.client
import json
import urllib.parse
import urllib.request
from typing import Any

from vahr.speech.audio import Audio, concatenate
from vahr.speech.tts import make_synthesizer


def clip(voice: str, text: str) -> Audio:
    spoken = make_synthesizer(voice).synthesize(text)
    return concatenate(Audio.silence(0.3), spoken, Audio.silence(0.3))


def talk(station_url: str, audio: Audio) -> dict[str, Any]:
    """Release of the talk button: the clip posted as the page posts it; the answer's JSON."""
    station = urllib.parse.urlsplit(station_url)
    connection = http.client.HTTPConnection(station.hostname or "", station.port, timeout=60)
    try:
        connection.request(
            "POST", "/api/voice", body=audio.to_wav(), headers={"Content-Type": "audio/wav"}
        )
        response = connection.getresponse()
        body = response.read()
    finally:
        connection.close()
    assert response.status == 200, body
    answer: dict[str, Any] = json.loads(body)
    return answer


def type_in(station_url: str, text: str) -> dict[str, Any]:
    """`text` typed at the station (`POST /api/say`), in the same conversation as its
    push-to-talk; the answer's JSON."""
    request = urllib.request.Request(
        station_url + "/api/say",
        data=json.dumps({"utterance": text}).encode(),
        headers={"Content-Type": "application/json"},
    )
    with urllib.request.urlopen(request, timeout=30) as answer:
        reply: dict[str, Any] = json.loads(answer.read())
        return reply
