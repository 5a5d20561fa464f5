"""The Alexa simulator: NLU from the skill package, ASK request envelopes, and the skill
handler invoked in-process, as Alexa would drive it.

What the rest of the house uses (the operator station among it) is exported here; the
modules behind it are the simulator's own, and import-linter keeps the station and the
experiment out of them (pyproject.toml, docs/architecture.md):

- `AlexaSimulator` (the simulated Echo), `Turn` (one exchange with it) and
  `SimulatorAssistant` (the simulator as an `Assistant`, `vahr.plumbing.client`);
- `InteractionModel` (the NLU built from an interaction model; `DEFAULT_MODEL`, the one
  that ships with the package), `load_skill_handler` (the skill's Lambda handler
  in-process) and `CommandLog` (the commands the skill published during a turn): what a
  simulator is built from, with the `Identity` (skill, user, device) its envelopes carry,
  whose skill id the handler is given to serve;
- `built_in_phrases` (what the simulator knows Alexa's built-in intents by),
  `confirmation_phrases` (the yes and no it takes) and `RULE_SLOTS` (the weather rule's
  slots): what a vocabulary of the model is made from;
- `weigh_recognition`, `Weighed` and `Weighing` (`nbest`): a recognizer's N best weighed
  into one understanding, unsure robots and zones asked about; `agreement`: two
  recognizers' readings acted on when they agree, and `disputed`: the values they heard
  differently asked about; `stop_heard`: a stop either ear heard clearly, acted on;
  `request_reader` reads words as a
  request, and `Understanding` is what any reading gives.
"""

from vahr.assistant.background import built_in_phrases
from vahr.assistant.commands_seen import CommandLog
from vahr.assistant.envelope import Identity
from vahr.assistant.nbest import (
    STOP_INTENT,
    Weighed,
    Weighing,
    agreement,
    disputed,
    request_reader,
    stop_heard,
    weigh_recognition,
)
from vahr.assistant.nlu import DEFAULT_MODEL, InteractionModel, Understanding
from vahr.assistant.simulator import (
    AlexaSimulator,
    SimulatorAssistant,
    Turn,
    confirmation_phrases,
)
from vahr.assistant.skill import load_skill_handler
from vahr.skill_model.intents import RAINY_ZONE, SUNNY_ZONE

# The weather delivery's rule: the slot that holds the zone for each weather.
RULE_SLOTS = {"sunny": SUNNY_ZONE.name, "rainy": RAINY_ZONE.name}

__all__ = [
    "DEFAULT_MODEL",
    "RULE_SLOTS",
    "STOP_INTENT",
    "AlexaSimulator",
    "CommandLog",
    "Identity",
    "InteractionModel",
    "SimulatorAssistant",
    "Turn",
    "Understanding",
    "Weighed",
    "Weighing",
    "agreement",
    "disputed",
    "request_reader",
    "stop_heard",
    "built_in_phrases",
    "confirmation_phrases",
    "load_skill_handler",
    "weigh_recognition",
]
