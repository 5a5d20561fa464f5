"""Speech, the bottom layer every voice in VAHR uses: the robot, the room assistant and the
station.

- `audio`: 16 kHz mono 16-bit PCM, WAV in and out, energy-based speech detection;
- `tts`: text-to-speech (espeak-ng offline; Amazon Polly and gTTS optional);
- `stt`: speech-to-text (pocketsphinx with a grammar of the phrases to expect, which the
  caller supplies: the robot's weather answers, the room's questions, an interaction model);
- `lm_stt`: speech-to-text in open phrasing (pocketsphinx with a language model built from
  the caller's example sentences, and each word's posterior);
- `scoring`: the `OutcomeTally` the NLU's and the hearing's evaluations count outcomes in;
- `room`: the room channel, speech as audio over a `vahr.protocol.link.Link`, and its message;
- `errors`: `SpeechError`, the one error this package raises.

Phrases are compared as `vahr.domain.text.normalize` writes them. It imports
`vahr.protocol` and its own libraries (numpy, pocketsphinx, sox and espeak-ng as
processes), nothing above them.
"""
