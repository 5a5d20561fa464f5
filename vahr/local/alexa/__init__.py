"""The Alexa simulator: NLU from the skill package, ASK request envelopes, and the skill
handler invoked in-process, as Alexa would drive it."""
