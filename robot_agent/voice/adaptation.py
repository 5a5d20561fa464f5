"""Adapting the recognizer to the voice a robot hears: pocketsphinx's acoustic model
re-estimated for it with sphinxtrain (MAP), or, from little speech, one MLLR transform.

A robot hears the assistant, and on the local stack the assistant speaks with espeak-ng, a
voice that pocketsphinx's US English model (trained on people) transcribes poorly. The
model is adapted to that voice: sphinxtrain's `bw` counts how the voice's speech falls on
the model's Gaussians (a forced alignment of known sentences), then either

- `map_adapt` moves each Gaussian, mixture weight and transition towards the counts, as
  far as the counts for it allow (maximum a posteriori): the parameters of a new model,
  written as a folder the decoder loads in place of the model's own; it needs speech
  covering most of the language's sounds, and gives by far the larger gain; or
- `mllr_solve` turns the counts into one linear transform of all the means per feature
  stream, a text file of a few kilobytes: the choice for a few minutes of recordings.

The bundled adaptation (`data/espeak-ng/`, `make hearing-adaptation` remakes it byte for
byte) is MAP, estimated from `weather_answers.yaml`'s sentences and, for the sounds the
weather does not use, everyday sentences written for it (`data/everyday-sentences.txt`)
and the licence texts every Debian system carries (`/usr/share/common-licenses`), spoken by
eight espeak-ng voices that are neither the tuning set's nor the evaluation set's, clean
and with white noise at 20 dB and 10 dB SNR: never an evaluation voice, never an
evaluation sentence (docs/voice.md, "How well it hears"). For another assistant (a real
Alexa in the room), call `adapt` with recordings of it and their transcripts.

Needs Debian's sphinxtrain, pocketsphinx and sphinxbase-utils (the tools, not the model:
the model is pocketsphinx's from PyPI, whose mixture weights ship only quantized in
`sendump`, so they are expanded back into the `mixture_weights` file `bw` reads, and
quantized again with `mk_s2sendump` after MAP).
"""

from __future__ import annotations

import argparse
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from vahr.domain.text import normalize
from vahr.lifeline import lifeline_command
from vahr.speech.audio import SAMPLE_RATE, add_white_noise
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator, Sequence

    from vahr.speech.audio import Audio

BUNDLED = Path(__file__).with_name("data") / "espeak-ng"
# Neither the hearing tuning set's voices (data/hearing-tuning.yaml: en-us+f2, m2, f3) nor
# the evaluation set's (data/hearing-eval.yaml: en-us+f4, m3, m1).
VOICES = (
    "en-us+m4", "en-us+m5", "en-us+m6", "en-us+m7",
    "en-us+f1", "en-us+f5", "en-us+Andy", "en-us+Annie",
)  # fmt: skip
NOISE_SNR_DB = (20.0, 10.0)
NOISE_SEED = 5
# Plain English for the sounds weather answers do not use: sentences written for it, and
# the licence texts Debian's base-files ships.
EVERYDAY = Path(__file__).with_name("data") / "everyday-sentences.txt"
LICENCES = Path("/usr/share/common-licenses")
SPHINXTRAIN = Path("/usr/lib/sphinxtrain")
_DEBIAN_PACKAGES = "sphinxtrain pocketsphinx sphinxbase-utils"
# pocketsphinx stores each mixture weight as an 8-bit -log in base 1.0001 ** 1024
# (ptm_mgau.c: the decoder's log base shifted by SENSCR_SHIFT = 10 bits).
_SENDUMP_LOG_STEP = np.log(1.0001) * 1024
# What MAP writes, under the names the decoder loads (vahr.speech.stt.adapted_to).
_MAP_OUTPUTS = {
    "-mapmeanfn": "means",
    "-mapvarfn": "variances",
    "-mapmixwfn": "mixture_weights",
    "-maptmatfn": "transition_matrices",
}


def adapt(clips: Iterable[tuple[Audio, str]], out: Path, *, method: str = "map") -> int:
    """Adapt the model to the voice of `clips` (audio, what it says): `map` writes the
    re-estimated parameters into the folder `out`, `mllr` one transform into the file
    `out`. Returns how many clips were used (those whose every word the dictionary knows)."""
    if method not in ("map", "mllr"):
        raise SpeechError(f"unknown adaptation method {method!r}: map or mllr")
    tools = _tools()
    from pocketsphinx import get_model_path

    model = Path(get_model_path()) / "en-us"
    acoustic = model / "en-us"
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        used = _count(clips, model, work, tools)
        out.parent.mkdir(parents=True, exist_ok=True)
        if method == "mllr":
            _run(tools["mllr_solve"], "-meanfn", acoustic / "means",
                 "-varfn", acoustic / "variances", "-outmllrfn", out,
                 "-accumdir", work / "counts")  # fmt: skip
            return used
        solved = work / "map"
        solved.mkdir()
        outputs = [(option, solved / name) for option, name in _MAP_OUTPUTS.items()]
        _run(tools["map_adapt"], "-moddeffn", work / "mdef.txt", "-ts2cbfn", ".ptm.",
             "-meanfn", acoustic / "means", "-varfn", acoustic / "variances",
             "-mixwfn", work / "mixture_weights", "-tmatfn", acoustic / "transition_matrices",
             "-accumdir", work / "counts",
             *[part for pair in outputs for part in pair])  # fmt: skip
        # The decoder reads mixture weights quantized (a quarter of the size).
        _run(tools["mk_s2sendump"], "-pocketsphinx", "yes", "-moddeffn", work / "mdef.txt",
             "-mixwfn", solved / "mixture_weights", "-sendumpfn", solved / "sendump")  # fmt: skip
        (solved / "mixture_weights").unlink()
        if out.exists():
            shutil.rmtree(out)
        shutil.copytree(solved, out)
    return used


def _count(
    clips: Iterable[tuple[Audio, str]], model: Path, work: Path, tools: dict[str, Path]
) -> int:
    """Align `clips` on the model with `bw`: its counts land in `work/counts`."""
    dictionary = model / "cmudict-en-us.dict"
    acoustic = model / "en-us"
    known = _dictionary_words()
    (work / "wav").mkdir()
    ids, lines = [], []
    for number, (audio, text) in enumerate(clips):
        words = normalize(text).split()
        if not words or any(w not in known for w in words):
            continue
        name = f"clip{number:06d}"
        (work / "wav" / f"{name}.wav").write_bytes(audio.to_wav())
        ids.append(name)
        lines.append(f"<s> {' '.join(words)} </s> ({name})")
    if not ids:
        raise SpeechError("no clip to adapt on: every one has a word the dictionary lacks")
    (work / "clips.fileids").write_text("\n".join(ids) + "\n", encoding="utf-8")
    (work / "clips.transcription").write_text("\n".join(lines) + "\n", encoding="utf-8")
    _run(tools["sphinx_fe"], "-argfile", acoustic / "feat.params",
         "-samprate", str(SAMPLE_RATE), "-c", work / "clips.fileids",
         "-di", work / "wav", "-ei", "wav", "-do", work / "mfc", "-eo", "mfc",
         "-mswav", "yes")  # fmt: skip
    _run(tools["pocketsphinx_mdef_convert"], "-text", acoustic / "mdef", work / "mdef.txt")
    write_mixture_weights(acoustic / "sendump", work / "mixture_weights")
    (work / "counts").mkdir()
    _run(tools["bw"], "-moddeffn", work / "mdef.txt", "-mixwfn", work / "mixture_weights",
         "-meanfn", acoustic / "means", "-varfn", acoustic / "variances",
         "-tmatfn", acoustic / "transition_matrices", "-ts2cbfn", ".ptm.",
         "-feat", "1s_c_d_dd", "-svspec", "0-12/13-25/26-38", "-cmn", "current",
         "-agc", "none", "-dictfn", dictionary, "-fdictfn", acoustic / "noisedict",
         "-ctlfn", work / "clips.fileids", "-lsnfn", work / "clips.transcription",
         "-cepdir", work / "mfc", "-cepext", "mfc", "-accumdir", work / "counts",
         "-timing", "no")  # fmt: skip
    return len(ids)


def write_mixture_weights(sendump: Path, out: Path) -> None:
    """Expand pocketsphinx's quantized `sendump` into sphinxtrain's `mixture_weights`
    (float32 [senone][stream][density], each distribution normalized again)."""
    data = sendump.read_bytes()
    offset = 0
    while True:  # header: length-prefixed strings up to a zero length
        (length,) = struct.unpack_from("<i", data, offset)
        offset += 4 + length
        if length == 0:
            break
    densities, senones = struct.unpack_from("<2i", data, offset)
    offset += 8
    streams, rest = divmod(len(data) - offset, densities * senones)
    if rest or streams == 0:
        raise SpeechError(f"{sendump}: not a pocketsphinx sendump of {densities}x{senones}")
    levels = np.frombuffer(data, np.uint8, offset=offset).reshape(streams, densities, senones)
    weights = np.exp(-levels.astype(np.float64) * _SENDUMP_LOG_STEP).transpose(2, 0, 1)
    weights /= weights.sum(axis=2, keepdims=True)
    header = b"s3\nversion 1.0\n"
    header += b" " * (-(len(header) + len(b"endhdr\n")) % 4) + b"endhdr\n"  # 4-byte aligned
    shape = struct.pack("<4i", senones, streams, densities, weights.size)
    out.write_bytes(
        header + struct.pack("<I", 0x11223344) + shape + weights.astype("<f4").tobytes()
    )


def synthesized_clips(
    sentences: Sequence[str],
    voices: Sequence[str] = VOICES,
    snr_db: Sequence[float] = NOISE_SNR_DB,
) -> Iterator[tuple[Audio, str]]:
    """Every sentence in every voice, clean and at each SNR (seeded: the same every run),
    one at a time (ten thousand clips would hold a gigabyte)."""
    from vahr.speech.tts import EspeakSynthesizer

    noise = np.random.default_rng(NOISE_SEED)
    for voice in voices:
        synthesizer = EspeakSynthesizer(voice=voice)
        for sentence in sentences:
            clean = synthesizer.synthesize(sentence)
            yield clean, sentence
            for snr in snr_db:
                yield add_white_noise(clean, snr, noise), sentence


def _dictionary_words() -> set[str]:
    """Every entry of pocketsphinx's pronunciation dictionary (`word(2)` as it stands)."""
    from vahr.speech.lm_stt import dictionary_entries

    return {entry for entry, _ in dictionary_entries()}


def _tools() -> dict[str, Path]:
    found = {
        "sphinx_fe": shutil.which("sphinx_fe"),
        "pocketsphinx_mdef_convert": shutil.which("pocketsphinx_mdef_convert"),
        **{tool: SPHINXTRAIN / tool for tool in ("bw", "mllr_solve", "map_adapt", "mk_s2sendump")},
    }
    missing = [name for name, path in found.items() if not path or not Path(path).is_file()]
    if missing:
        raise SpeechError(
            f"adaptation needs {', '.join(missing)}: apt-get install {_DEBIAN_PACKAGES}"
        )
    return {name: Path(str(path)) for name, path in found.items()}


def _run(*command: object) -> None:
    # Through the lifeline, so that a killed `make hearing-adaptation` leaves no `bw` behind.
    line = lifeline_command([str(part) for part in command], signal.SIGKILL)
    done = subprocess.run(line, capture_output=True, text=True)
    if done.returncode != 0:
        last = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
        raise SpeechError(f"{Path(str(command[0])).name} failed: {last[0]}")


def adaptation_sentences(held_out: Iterable[str] = ()) -> list[str]:
    """What the bundled adaptation is estimated from: every sentence of
    `weather_answers.yaml` and of `everyday-sentences.txt`, and the licence texts' plain
    sentences of 4 to 16 words (no digits or symbols); only sentences whose every word the
    dictionary knows, none of `held_out` (normalized, sorted, no duplicates)."""
    from robot_agent.voice.answers import WeatherAnswers

    known = _dictionary_words()
    everyday = EVERYDAY.read_text(encoding="utf-8").splitlines()
    found = {normalize(s) for s in WeatherAnswers.load().corpus()}
    found |= {
        sentence
        for line in everyday
        if line.strip() and not line.startswith("#")
        for sentence in [normalize(line)]
        if all(word in known for word in sentence.split())
    }
    for licence in sorted(LICENCES.glob("*")):
        text = licence.read_text(encoding="utf-8", errors="replace")
        for sentence in re.split(r"[.;:!?]\s|\n\s*\n", text):
            if re.search(r"[\d_/\\<>{}()\[\]=@`|$%&*+#]", sentence):
                continue
            words = normalize(sentence).split()
            if 4 <= len(words) <= 16 and all(word in known for word in words):
                found.add(" ".join(words))
    return sorted(found - {normalize(s) for s in held_out})


def main(argv: Sequence[str] | None = None) -> int:
    """Remake the bundled adaptation (the weather answers and plain English, spoken by
    espeak-ng voices that no hearing set uses)."""
    from robot_agent.voice.evaluation import held_out_sentences

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("--out", type=Path, default=BUNDLED, help=f"default: {BUNDLED}")
    parser.add_argument(
        "--method", choices=("map", "mllr"), default="map", help="map (a folder) or mllr (a file)"
    )
    args = parser.parse_args(argv)
    held_out = held_out_sentences()
    try:
        sentences = adaptation_sentences(held_out)
        used = adapt(synthesized_clips(sentences), args.out, method=args.method)
    except SpeechError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    print(f"{args.out}: from {used} clips ({len(sentences)} sentences, {len(VOICES)} voices)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
