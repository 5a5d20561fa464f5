"""Adapting the recognizer to the voice a robot hears: one MLLR transform of pocketsphinx's
acoustic model, estimated with sphinxtrain.

A robot hears the assistant, and on the local stack the assistant speaks with espeak-ng, a
voice that pocketsphinx's US English model (trained on people) transcribes poorly. A
speaker adaptation moves the model's Gaussian means towards that voice: sphinxtrain's `bw`
counts how the voice's speech falls on the model's Gaussians (a forced alignment of known
sentences), and `mllr_solve` turns the counts into one linear transform per feature
stream, a text file of a few kilobytes that the decoder applies at start-up (`mllr`).

The bundled transform (`data/espeak-ng.mllr`, `make hearing-adaptation` remakes it) is
estimated from `weather_answers.yaml`'s sentences spoken by the tuning set's voices, clean
and with white noise at 20 dB and 10 dB SNR: never an evaluation voice, never an
evaluation sentence (docs/voice.md, "How well it hears"). For another assistant (a real
Alexa in the room), call `adapt` with recordings of it and their transcripts.

Needs Debian's sphinxtrain, pocketsphinx and sphinxbase-utils (the tools, not the model:
the model is pocketsphinx's from PyPI, whose mixture weights ship only quantized in
`sendump`, so they are expanded back into the `mixture_weights` file `bw` reads).
"""

from __future__ import annotations

import argparse
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from vahr.speech.audio import SAMPLE_RATE, add_white_noise
from vahr.speech.errors import SpeechError
from vahr.speech.text import normalize

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    from vahr.speech.audio import Audio

BUNDLED = Path(__file__).with_name("data") / "espeak-ng.mllr"
# The hearing tuning set's voices (data/hearing-tuning.yaml), never the evaluation's.
VOICES = ("en-us+f2", "en-us+m2", "en-us+f3")
NOISE_SNR_DB = (20.0, 10.0)
NOISE_SEED = 5
SPHINXTRAIN = Path("/usr/lib/sphinxtrain")
_DEBIAN_PACKAGES = "sphinxtrain pocketsphinx sphinxbase-utils"
# pocketsphinx stores each mixture weight as an 8-bit -log in base 1.0001 ** 1024
# (ptm_mgau.c: the decoder's log base shifted by SENSCR_SHIFT = 10 bits).
_SENDUMP_LOG_STEP = np.log(1.0001) * 1024


def adapt(clips: Iterable[tuple[Audio, str]], out: Path) -> int:
    """Estimate a transform from `clips` (audio, what it says) into `out`; returns how
    many clips were used (those whose every word the dictionary knows)."""
    tools = _tools()
    from pocketsphinx import get_model_path

    model = Path(get_model_path()) / "en-us"
    dictionary = model / "cmudict-en-us.dict"
    known = {line.split(" ", 1)[0] for line in dictionary.read_text(encoding="utf-8").splitlines()}
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        (work / "wav").mkdir()
        ids, lines = [], []
        for number, (audio, text) in enumerate(clips):
            words = normalize(text).split()
            if not words or any(w not in known for w in words):
                continue
            name = f"clip{number:05d}"
            (work / "wav" / f"{name}.wav").write_bytes(audio.to_wav())
            ids.append(name)
            lines.append(f"<s> {' '.join(words)} </s> ({name})")
        if not ids:
            raise SpeechError("no clip to adapt on: every one has a word the dictionary lacks")
        (work / "clips.fileids").write_text("\n".join(ids) + "\n", encoding="utf-8")
        (work / "clips.transcription").write_text("\n".join(lines) + "\n", encoding="utf-8")
        _run(tools["sphinx_fe"], "-argfile", model / "en-us" / "feat.params",
             "-samprate", str(SAMPLE_RATE), "-c", work / "clips.fileids",
             "-di", work / "wav", "-ei", "wav", "-do", work / "mfc", "-eo", "mfc",
             "-mswav", "yes")  # fmt: skip
        _run(
            tools["pocketsphinx_mdef_convert"], "-text", model / "en-us" / "mdef", work / "mdef.txt"
        )
        write_mixture_weights(model / "en-us" / "sendump", work / "mixture_weights")
        (work / "counts").mkdir()
        _run(tools["bw"], "-moddeffn", work / "mdef.txt", "-mixwfn", work / "mixture_weights",
             "-meanfn", model / "en-us" / "means", "-varfn", model / "en-us" / "variances",
             "-tmatfn", model / "en-us" / "transition_matrices", "-ts2cbfn", ".ptm.",
             "-feat", "1s_c_d_dd", "-svspec", "0-12/13-25/26-38", "-cmn", "current",
             "-agc", "none", "-dictfn", dictionary, "-fdictfn", model / "en-us" / "noisedict",
             "-ctlfn", work / "clips.fileids", "-lsnfn", work / "clips.transcription",
             "-cepdir", work / "mfc", "-cepext", "mfc", "-accumdir", work / "counts",
             "-timing", "no")  # fmt: skip
        out.parent.mkdir(parents=True, exist_ok=True)
        _run(tools["mllr_solve"], "-meanfn", model / "en-us" / "means",
             "-varfn", model / "en-us" / "variances", "-outmllrfn", out,
             "-accumdir", work / "counts")  # fmt: skip
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
) -> list[tuple[Audio, str]]:
    """Every sentence in every voice, clean and at each SNR (seeded: the same every run)."""
    from vahr.speech.tts import EspeakSynthesizer

    noise = np.random.default_rng(NOISE_SEED)
    clips = []
    for voice in voices:
        synthesizer = EspeakSynthesizer(voice=voice)
        for sentence in sentences:
            clean = synthesizer.synthesize(sentence)
            clips.append((clean, sentence))
            clips += [(add_white_noise(clean, snr, noise), sentence) for snr in snr_db]
    return clips


def _tools() -> dict[str, Path]:
    found = {
        "sphinx_fe": shutil.which("sphinx_fe"),
        "pocketsphinx_mdef_convert": shutil.which("pocketsphinx_mdef_convert"),
        "bw": SPHINXTRAIN / "bw",
        "mllr_solve": SPHINXTRAIN / "mllr_solve",
    }
    missing = [name for name, path in found.items() if not path or not Path(path).is_file()]
    if missing:
        raise SpeechError(
            f"adaptation needs {', '.join(missing)}: apt-get install {_DEBIAN_PACKAGES}"
        )
    return {name: Path(str(path)) for name, path in found.items()}


def _run(*command: object) -> None:
    done = subprocess.run([str(part) for part in command], capture_output=True, text=True)
    if done.returncode != 0:
        last = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
        raise SpeechError(f"{Path(str(command[0])).name} failed: {last[0]}")


def main(argv: Sequence[str] | None = None) -> int:
    """Remake the bundled transform from `weather_answers.yaml` in the tuning voices."""
    from robot_agent.voice.answers import WeatherAnswers

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("--out", type=Path, default=BUNDLED, help=f"default: {BUNDLED}")
    args = parser.parse_args(argv)
    sentences = sorted({normalize(s) for s in WeatherAnswers.load().corpus()})
    try:
        used = adapt(synthesized_clips(sentences), args.out)
    except SpeechError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    print(f"{args.out}: from {used} clips ({len(sentences)} sentences, {len(VOICES)} voices)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
