"""The robot's voice: text-to-speech, speech recognition and interpretation of the
assistant's answers, behind the `Voice` port the executor calls (see `port`)."""
