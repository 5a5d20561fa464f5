"""Wrong actions by effect: what reaches the robots when the NLU or the station misreads.

`vahr nlu --eval` and `bench/station_hearing.py` count a reading other than the label as
wrong. Issue 31's targets count wrong *actions*: a robot command other than what was said.
Here every reading is handed to the real skill (`tests/support/skill_effects.py`: the Alexa
simulator, ask-sdk-core under moto, idle robots at the loading zone) and its commands are
compared with those of the label:

- typed text: the NLU development set and the roles development set, each sentence
  understood as the simulator understands typed text;
- push-to-talk: the development set spoken by the development voices and decided as the
  station decides (its second ear, else the N best weighed with the station's constants),
  from the clips and transcripts `bench/station_hearing.py` keeps (it runs them first when
  they are missing).

An outcome is `as labelled` (the label's commands, or none where it has none), `wrong
action` (any command other than the label's: another robot, zone or order, or any command
for an out-of-domain sentence) or `nothing sent` where the label sends something (the
skill asked, refused, or the station did not catch it). Nothing here is tuned.
Run: `.venv/bin/python bench/wrong_actions.py`.
"""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

from _results import write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from station_hearing import (  # noqa: E402
    DEVELOPMENT_VOICES,
    Reader,
    decide_with_second_ear,
    hear,
    hear_again,
)

from tests.support.skill_effects import VERDICTS, SkillEffects  # noqa: E402
from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet, LabelledUtterance  # noqa: E402
from vahr.assistant.nbest import Weighing  # noqa: E402
from vahr.assistant.nlu import InteractionModel, Understanding  # noqa: E402
from vahr.domain.fleet import load_fleet  # noqa: E402
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.speech.tts import engine_of  # noqa: E402
from vahr.speech.whisper_stt import WhisperTranscriber  # noqa: E402
from vahr.station.vocabulary import command_recognizer, whisper_prompt  # noqa: E402

ROLES_SET = DEVELOPMENT_SET.with_name("roles-devset-en-US.yaml")
HEADER = (
    "| | requests | as labelled | moved wrongly | stopped wrongly | less or nothing sent | "
    "out of domain | out of domain: moving a robot | any command |\n"
    "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
)


class EffectTally:
    """Verdicts for requests and for out-of-domain sentences, and the wrong ones' texts."""

    def __init__(self) -> None:
        self.requests: Counter[str] = Counter()
        self.out_of_domain: Counter[str] = Counter()
        self.wrong: list[str] = []

    def add(
        self, effects: SkillEffects, item: LabelledUtterance, got: Understanding, voice: str = ""
    ) -> None:
        verdict = effects.verdict(item, got)
        (self.requests if item.intent != FALLBACK_INTENT else self.out_of_domain)[verdict] += 1
        if verdict in ("moved wrongly", "stopped wrongly"):
            sent = "; ".join(f"{topic.split('/')[-2]} {action} {params}"
                             for topic, action, params in effects.of(got))  # fmt: skip
            said_by = f" ({voice})" if voice else ""
            self.wrong.append(f'"{item.text}"{said_by}: {sent}')

    def absorb(self, other: EffectTally) -> None:
        self.requests.update(other.requests)
        self.out_of_domain.update(other.out_of_domain)
        self.wrong.extend(other.wrong)

    def row(self, name: str) -> str:
        asked = sum(self.requests.values())
        ood = sum(self.out_of_domain.values())
        share = lambda n, total: f"{n} ({n / total:.1%})" if total else "-"  # noqa: E731
        cells = [share(self.requests[v], asked) for v in VERDICTS]
        moved = self.out_of_domain["moved wrongly"]
        commanded = moved + self.out_of_domain["stopped wrongly"]
        return (
            f"| {name} | {asked} | {' | '.join(cells)} | {ood} | {share(moved, ood)} | "
            f"{share(commanded, ood)} |"
        )


def typed(model: InteractionModel, effects: SkillEffects, file: Path) -> EffectTally:
    tally, read = EffectTally(), Reader(model)
    for item in LabelledSet.load(file).items():
        tally.add(effects, item, read(item.text))
    return tally


def spoken(model: InteractionModel, effects: SkillEffects) -> dict[str, EffectTally]:
    """Per development voice, and the human-like voices together."""
    read, weighing = Reader(model), Weighing()
    recognizer = command_recognizer()
    whisper = WhisperTranscriber(whisper_prompt(load_fleet()))
    items = LabelledSet.load(DEVELOPMENT_SET).items()
    tallies: dict[str, EffectTally] = {}
    together = EffectTally()
    for voice in DEVELOPMENT_VOICES:
        clips = hear(recognizer, [(item, voice) for item in items])
        second = hear_again(whisper, clips)
        tally = tallies[voice] = EffectTally()
        for n, clip in enumerate(clips):
            got = decide_with_second_ear(clip, second[n][0], read, weighing)
            tally.add(effects, clip.item, got, voice)
        if engine_of(voice) != "espeak-ng":
            together.absorb(tally)
    tallies["human-like voices together"] = together
    return tallies


def main() -> int:
    model = InteractionModel.load()
    with SkillEffects(model) as effects:
        text = {
            f"typed: {DEVELOPMENT_SET.name}": typed(model, effects, DEVELOPMENT_SET),
            f"typed: {ROLES_SET.name}": typed(model, effects, ROLES_SET),
        }
        heard = spoken(model, effects)
    both = EffectTally()
    for tally in text.values():
        both.absorb(tally)
    text_rows = "\n".join(tally.row(name) for name, tally in text.items())
    heard_rows = "\n".join(tally.row(name) for name, tally in heard.items())
    text_wrong = "\n".join(f"- {line}" for line in both.wrong) or "- none"
    heard_wrong = "\n".join(
        f"- {line}" for line in heard["human-like voices together"].wrong
    ) or "- none"  # fmt: skip
    body = f"""
Each reading handed to the real skill (the Alexa simulator, ask-sdk-core under moto, a
fresh session, idle robots at the loading zone, a sunny experiment) and its commands
compared with the label's (`bench/wrong_actions.py`). *Moved wrongly*: a request that sent
a motion command the label does not (a robot sent where nobody asked); *stopped wrongly*:
one that sent another command the label does not (a stop); *less or nothing sent*: the
skill asked which robot or zone, asked to confirm, refused, or the station did not catch
the words.

Typed text, as the simulator understands it:

{HEADER}
{text_rows}
{both.row("typed: both sets")}

The wrong actions:

{text_wrong}

Push-to-talk, the development set spoken and decided as the station decides (what its two
ears agree on, else the N best weighed with the station's constants, a robot or zone the
ears dispute asked about):

{HEADER}
{heard_rows}

The wrong actions in the human-like voices:

{heard_wrong}
"""
    write_section("wrong_actions", "Wrong actions by what reaches the robots", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
