"""Answering "Zone B or zone D?" by push-to-talk: the letter, or its spelling-alphabet word.

B, C and D are the letters a recognizer confuses most, so the skill asks about them ("Zone
B or zone D?"), and the answer is the same letter again. This measures, on `vahr up`, how
such a question is answered in each voice: the question is typed into being (placebot one
sent to the loading zone, then "no, zone b or zone d"), and the answer is spoken to the
station's `/api/voice` in one of three forms: the letter ("zone b"), its spelling-alphabet
word alone ("bravo", what the reprompt offers) or with "zone" ("zone bravo"). Each answer
ends right (the robot sent to the zone said), wrong (to another zone), asked again, or not
caught ("Sorry, I didn't catch that"). Nothing here is tuned: the station's constants are
those chosen on the tuning voices (`bench/station_hearing.py`).

A clip is decoded the same way each time, so a person repeating the letter in the same
voice is heard the same way again: within two answers, a letter then the word is the
letter's outcome or, when that was not done, the word's.
Run: `.venv/bin/python bench/station_answers.py`.
"""

from __future__ import annotations

import sys
import tempfile
from collections import Counter
from pathlib import Path

from _results import write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from station_hearing import spoken  # noqa: E402

from tests.support.push_to_talk import talk  # noqa: E402
from tests.support.push_to_talk import type_in as typed  # noqa: E402
from tests.support.vahr_up import Up, start_up, stop_up  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402

ENGINES = {
    "flite (slt, rms, awb, kal)": ("flite:slt", "flite:rms", "flite:awb", "flite:kal"),
    "festival HTS": ("festival:cmu_us_slt_arctic_hts",),
    "espeak-ng (en-us+f2, en-us+m3)": ("espeak-ng:en-us+f2", "espeak-ng:en-us+m3"),
}
# The confusable letters, asked about two at a time.
PAIRS = (("B", "D"), ("C", "D"), ("B", "C"))
WORDS = {"B": "bravo", "C": "charlie", "D": "delta"}
FORMS = ("letter", "word", "zone and word")
OUTCOMES = ("right", "wrong", "asked again", "not caught")


def said(form: str, zone: str) -> str:
    return {
        "letter": f"zone {zone.lower()}",
        "word": WORDS[zone],
        "zone and word": f"zone {WORDS[zone]}",
    }[form]


def type_in(up: Up, text: str) -> str:
    return str(typed(up.endpoints["station"], text)["speech"])


def answer_once(up: Up, voice: str, pair: tuple[str, str], zone: str, form: str) -> str:
    """Ask "Zone X or zone Y?" and answer it by voice; the outcome."""
    type_in(up, "send placebot one to the loading zone")
    question = f"Zone {pair[0]} or zone {pair[1]}?"
    asked = type_in(up, f"no, zone {pair[0].lower()} or zone {pair[1].lower()}")
    if asked != question:
        raise SystemExit(f"the question was {asked!r}, not {question!r}")
    speech = str(talk(up.endpoints["station"], spoken(voice, said(form, zone)))["speech"])
    type_in(up, "stop placebot one")  # ends any question still open
    if "is on its way to zone" in speech:
        return "right" if f"on its way to zone {zone}." in speech else "wrong"
    return "asked again" if speech.startswith(question) else "not caught"


def run() -> dict[str, dict[str, Counter[str]]]:
    tallies: dict[str, dict[str, Counter[str]]] = {}
    with tempfile.TemporaryDirectory() as state:
        up = start_up(Path(state), "--station-port", str(free_port()), "--sim-speed-factor", "10")
        try:
            for engine, voices in ENGINES.items():
                tally = tallies.setdefault(engine, {f: Counter() for f in [*FORMS, "two"]})
                for voice in voices:
                    for pair in PAIRS:
                        for zone in pair:
                            got = {f: answer_once(up, voice, pair, zone, f) for f in FORMS}
                            for form, outcome in got.items():
                                tally[form][outcome] += 1
                            # A letter, then (not done) the word the reprompt offers
                            two = got["letter"] if got["letter"] == "right" else got["word"]
                            tally["two"][two] += 1
                            print(voice, pair, zone, got, flush=True)
        finally:
            stop_up(up.process)
    return tallies


def table(tallies: dict[str, dict[str, Counter[str]]]) -> str:
    rows = [
        "| voices | answer | n | right | wrong | asked again | not caught |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    names = {
        "letter": '"zone b" (the letter)',
        "word": '"bravo" (the word offered)',
        "zone and word": '"zone bravo"',
        "two": "the letter, then the word when not done",
    }
    for engine, tally in tallies.items():
        for form in [*FORMS, "two"]:
            counts = tally[form]
            n = sum(counts.values())
            cells = [f"{counts[o]} ({counts[o] / n:.0%})" for o in OUTCOMES]
            rows.append(f"| {engine} | {names[form]} | {n} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def main() -> int:
    tallies = run()
    body = (
        'Each voice answers "Zone B or zone D?", "Zone C or zone D?" and "Zone B or '
        'zone C?" for each of the two zones, in each form, on `vahr up` (station '
        "constants as shipped, nothing tuned here). Repeating the letter in the same voice "
        "is decoded the same way, so it ends as the letter once did.\n\n" + table(tallies)
    )
    write_section("station_answers", "Push-to-talk: answering a question about B, C or D", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
