"""The interaction model: generated from fleet.yaml without drift, valid for ASK, and in
step with the handlers."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import pytest
from ask_sdk_core.attributes_manager import AttributesManager
from ask_sdk_core.serialize import DefaultSerializer
from skill_testkit import speech

from skill.app import request_handlers
from skill.config import SkillConfig
from skill.guard import ACCESS, Access
from skill.runtime import SkillRuntime
from skill.vocabulary import FLEET
from tests.conftest import EVENTS_DIR, load_event
from vahr.domain import Fleet
from vahr.domain.people import Person
from vahr.protocol import ProtocolError
from vahr.skill_model import FLEET_ROBOT_ID, ModelError, build_files, build_interaction_model
from vahr.skill_model.__main__ import main as skill_model_main
from vahr.skill_model.generator import (
    FLEET_TWIN_PATH,
    MANIFEST_PATH,
    MODEL_PATH,
    deployed_endpoint,
    utterance_shape,
)
from vahr.skill_model.intents import CUSTOM_INTENTS, IntentSpec, SlotSpec

if TYPE_CHECKING:
    from ask_sdk_core.dispatch_components import AbstractRequestHandler

ROOT = Path(__file__).resolve().parents[3]
FLEET_FILE = ROOT / "fleet.yaml"
MODEL_TYPE = (
    "ask_smapi_model.v1.skill.interaction_model.interaction_model_data.InteractionModelData"
)
MANIFEST_TYPE = "ask_smapi_model.v1.skill.manifest.skill_manifest_envelope.SkillManifestEnvelope"


@pytest.fixture(scope="module")
def model() -> dict[str, Any]:
    loaded: dict[str, Any] = json.loads((ROOT / MODEL_PATH).read_text())
    return loaded


def language_model(model: dict[str, Any]) -> dict[str, Any]:
    result: dict[str, Any] = model["interactionModel"]["languageModel"]
    return result


def test_committed_skill_package_matches_the_generator(fleet: Fleet) -> None:
    # Given fleet.yaml and the intent definitions, when the generator runs, then it would
    # write exactly the committed files (run `make skill-model` after editing either)
    endpoint = deployed_endpoint(ROOT)
    for relative, text in build_files(fleet, FLEET_FILE.read_bytes(), endpoint).items():
        assert (ROOT / relative).read_text() == text, f"{relative} drifted from fleet.yaml"


def test_check_flag_reports_drift_and_exits_non_zero(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given a copy of the package and a fleet with one more zone
    fleet_file = tmp_path / "fleet.yaml"
    text = FLEET_FILE.read_text()
    fleet_file.write_text(
        text.replace(
            "\ngroups:",
            "  - id: E\n    spoken: [zone e, echo]\n    pose: {x: 5.0, y: 7.0}\n\ngroups:",
        )
    )
    out = tmp_path / "checkout"
    assert skill_model_main(["--fleet", str(FLEET_FILE), "--root", str(out)]) == 0
    # When --check runs against the changed fleet
    assert skill_model_main(["--fleet", str(fleet_file), "--root", str(out), "--check"]) == 1
    # Then it names the stale files, and regenerating makes the check pass
    err = capsys.readouterr().err
    assert "en-US.json is out of date" in err and "fleet.json is out of date" in err
    assert "skill.json" not in err
    assert skill_model_main(["--fleet", str(fleet_file), "--root", str(out)]) == 0
    assert skill_model_main(["--fleet", str(fleet_file), "--root", str(out), "--check"]) == 0
    zones = json.loads((out / MODEL_PATH).read_text())["interactionModel"]["languageModel"]
    assert "E" in [value["id"] for value in zones["types"][1]["values"]]


def test_a_deployed_endpoint_in_skill_json_survives_regeneration(tmp_path: Path) -> None:
    # Given a checkout whose skill.json got the deployed function's ARN
    out = tmp_path / "checkout"
    assert skill_model_main(["--root", str(out)]) == 0
    manifest_file = out / MANIFEST_PATH
    manifest = json.loads(manifest_file.read_text())
    endpoint = {"uri": "arn:aws:lambda:us-east-1:123456789012:function:vahr-skill"}
    manifest["manifest"]["apis"]["custom"]["endpoint"] = endpoint
    # (as infra.skill_endpoint writes it: UTF-8, the German store entry unescaped)
    manifest_file.write_text(json.dumps(manifest, indent=2, ensure_ascii=False) + "\n")
    # When the generator checks and runs again
    assert skill_model_main(["--root", str(out), "--check"]) == 0
    assert skill_model_main(["--root", str(out)]) == 0
    # Then the endpoint is still there
    assert (
        json.loads(manifest_file.read_text())["manifest"]["apis"]["custom"]["endpoint"] == endpoint
    )


def test_bad_fleet_file_is_one_line_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    missing = tmp_path / "nope.yaml"
    assert skill_model_main(["--fleet", str(missing), "--root", str(tmp_path), "--check"]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("python -m vahr.skill_model: error: fleet: cannot read")


def test_interaction_model_deserializes_with_ask_smapi_model_classes(model: dict[str, Any]) -> None:
    serializer = DefaultSerializer()
    parsed = serializer.deserialize(json.dumps(model), MODEL_TYPE)
    # A round trip loses any field the ASK schema does not know, so equality proves every
    # key and enum value is one ASK accepts.
    assert serializer.serialize(parsed) == model


def test_a_misspelled_field_would_not_survive_the_round_trip(model: dict[str, Any]) -> None:
    broken = copy.deepcopy(model)
    broken["interactionModel"]["languageModel"]["invocationNmae"] = "robot fleet"
    serializer = DefaultSerializer()
    assert serializer.serialize(serializer.deserialize(json.dumps(broken), MODEL_TYPE)) != broken


def test_manifest_deserializes_with_ask_smapi_model_classes() -> None:
    manifest = json.loads((ROOT / MANIFEST_PATH).read_text())
    serializer = DefaultSerializer()
    assert (
        serializer.serialize(serializer.deserialize(json.dumps(manifest), MANIFEST_TYPE))
        == manifest
    )
    assert manifest["manifest"]["apis"]["custom"]["interfaces"] == []


def test_invocation_name_is_two_speakable_words(model: dict[str, Any]) -> None:
    name = language_model(model)["invocationName"]
    assert name == "robot fleet"
    assert re.fullmatch(r"[a-z]+ [a-z]+", name)


def test_slot_types_come_from_the_fleet(model: dict[str, Any], fleet: Fleet) -> None:
    types = {slot_type["name"]: slot_type["values"] for slot_type in language_model(model)["types"]}
    robots = {
        value["id"]: [value["name"]["value"], *value["name"]["synonyms"]]
        for value in types["ROBOT"]
    }
    assert robots == {
        **{robot.thing: robot.spoken for robot in fleet.robots},
        FLEET_ROBOT_ID: next(group.spoken for group in fleet.groups if group.id == "all"),
    }
    zones = {
        value["id"]: [value["name"]["value"], *value["name"]["synonyms"]] for value in types["ZONE"]
    }
    assert zones == {zone.id: zone.spoken for zone in fleet.zones}
    # The skill cannot import the generator (it is not in the Lambda bundle), so the two
    # spellings of the fleet value are held equal here.
    from skill import vocabulary
    from vahr.skill_model import generator

    assert FLEET == FLEET_ROBOT_ID
    assert vocabulary.DEFAULT_FLEET_NAMES == generator.DEFAULT_FLEET_NAMES
    assert vocabulary.FLEET_GROUP == generator.FLEET_GROUP_ID


def test_robot_command_intents_have_at_least_sixty_samples(model: dict[str, Any]) -> None:
    intents = {intent["name"]: intent for intent in language_model(model)["intents"]}
    for name in (
        "NavigateIntent",
        "DeliverIntent",
        "WeatherDeliveryIntent",
        "SequentialDeliveryIntent",
        "EmergencyStopIntent",
    ):
        samples = intents[name]["samples"]
        assert len(set(samples)) >= 60, name


def test_no_utterance_is_shared_between_intents(model: dict[str, Any]) -> None:
    owners: dict[str, str] = {}
    for intent in language_model(model)["intents"]:
        types = {slot["name"]: slot["type"] for slot in intent.get("slots", [])}
        for sample in intent["samples"]:
            shape = sample
            for name, slot_type in types.items():
                shape = shape.replace("{" + name + "}", "{" + slot_type + "}")
            assert owners.setdefault(shape, intent["name"]) == intent["name"], shape


def test_samples_follow_alexas_rules(model: dict[str, Any]) -> None:
    for intent in language_model(model)["intents"]:
        slot_names = {slot["name"] for slot in intent.get("slots", [])}
        for sample in intent["samples"]:
            assert re.fullmatch(r"(?:[a-z']+|\{\w+\})(?: (?:[a-z']+|\{\w+\}))*", sample), sample
            assert set(re.findall(r"\{(\w+)\}", sample)) <= slot_names, sample


def test_every_model_intent_has_exactly_one_handler_and_every_handler_an_intent(
    model: dict[str, Any], aws: None
) -> None:
    runtime = SkillRuntime.create(SkillConfig(), gateway=None)  # type: ignore[arg-type]
    handlers = request_handlers(runtime)
    template = load_event("alexa_weather")
    used: set[type[AbstractRequestHandler]] = set()
    from ask_sdk_core.handler_input import HandlerInput

    serializer = DefaultSerializer()
    for intent in language_model(model)["intents"]:
        event = copy.deepcopy(template)
        event["request"]["intent"]["name"] = intent["name"]
        envelope = serializer.deserialize(json.dumps(event), "ask_sdk_model.RequestEnvelope")
        claimed = [h for h in handlers if h.can_handle(HandlerInput(request_envelope=envelope))]
        assert len(claimed) == 1, (intent["name"], claimed)
        used.add(type(claimed[0]))
    for request_type in ("alexa_launch", "alexa_session_ended"):
        envelope = serializer.deserialize(
            json.dumps(load_event(request_type)), "ask_sdk_model.RequestEnvelope"
        )
        claimed = [h for h in handlers if h.can_handle(HandlerInput(request_envelope=envelope))]
        assert len(claimed) == 1
        used.add(type(claimed[0]))
    # A denied intent is answered by the handler registered first for it, before the
    # intent's own handler could act on it.
    envelope = serializer.deserialize(
        json.dumps(load_event("alexa_dialog_confirm_intent_denied")),
        "ask_sdk_model.RequestEnvelope",
    )
    claimed = [h for h in handlers if h.can_handle(HandlerInput(request_envelope=envelope))]
    assert type(claimed[0]).__name__ == "DeniedIntentHandler"
    used.add(type(claimed[0]))
    # A request the speaker's role does not allow is refused before any other handler.
    envelope = serializer.deserialize(
        json.dumps(load_event("alexa_navigate")), "ask_sdk_model.RequestEnvelope"
    )
    refused = HandlerInput(
        request_envelope=envelope, attributes_manager=AttributesManager(envelope)
    )
    viewer = Person(id="amzn1.ask.account.V", name="Vera", role="viewer")
    refused.attributes_manager.request_attributes[ACCESS] = Access(
        person=viewer, kind="command", allowed=False
    )
    claimed = [h for h in handlers if h.can_handle(refused)]
    assert type(claimed[0]).__name__ == "RefusedRequestHandler"
    used.add(type(claimed[0]))
    assert {type(handler) for handler in handlers} == used


def test_every_event_has_the_full_ask_shape_and_a_known_intent(model: dict[str, Any]) -> None:
    known = {intent["name"] for intent in language_model(model)["intents"]}
    for path in sorted(EVENTS_DIR.glob("alexa_*.json")):
        event = json.loads(path.read_text())
        system = event["context"]["System"]
        assert system["application"]["applicationId"].startswith("amzn1.ask.skill.")
        assert {"user", "device", "apiEndpoint", "apiAccessToken"} <= system.keys()
        assert event["request"]["requestId"].startswith("amzn1.echo-api.request.")
        # English events, and German ones (named *_de) for the skill's German replies.
        assert event["request"]["locale"] == ("de-DE" if path.stem.endswith("_de") else "en-US")
        if event["request"]["type"] == "IntentRequest" and path.stem != "alexa_unknown_intent":
            assert event["request"]["intent"]["name"] in known, path.name


def test_generator_refuses_an_utterance_shared_between_intents(fleet: Fleet) -> None:
    robot = SlotSpec("robot", "ROBOT")
    first = IntentSpec("GoIntent", (robot,), ("move {robot}",))
    other = SlotSpec("who", "ROBOT")
    second = IntentSpec("HaltIntent", (other,), ("move {who}",))
    with pytest.raises(
        ModelError, match="'move \\{ROBOT\\}' appears in both GoIntent and HaltIntent"
    ):
        build_interaction_model(fleet, (first, second))


def test_generator_refuses_a_sample_with_digits_or_punctuation(fleet: Fleet) -> None:
    bad = IntentSpec("GoIntent", (SlotSpec("robot", "ROBOT"),), ("send {robot} to zone 5!",))
    with pytest.raises(ModelError, match="lower-case words"):
        build_interaction_model(fleet, (bad,))


def test_generator_refuses_a_name_given_to_two_zones(fleet: Fleet) -> None:
    text = FLEET_FILE.read_text().replace("[zone b, b,", "[zone b, a,")
    # The fleet file itself is refused, naming the entry
    with pytest.raises(ProtocolError, match=r"^zones.2.spoken.1: 'a' is used twice \(also zones"):
        Fleet.from_yaml(text)
    # and so is a fleet that was never validated, by the generator
    unchecked = msgspec.yaml.decode(text, type=Fleet)
    with pytest.raises(ModelError, match="the name 'a' is used by both 'A' and 'B'"):
        build_interaction_model(unchecked, CUSTOM_INTENTS)


def test_elicitation_answers_never_read_as_another_intent() -> None:
    shapes = {
        utterance_shape(intent, sample): intent.name
        for intent in CUSTOM_INTENTS
        for sample in intent.samples
    }
    for intent in CUSTOM_INTENTS:
        for slot in intent.slots:
            for answer in slot.answers:
                assert shapes.get(utterance_shape(intent, answer), intent.name) == intent.name


def test_weather_answer_is_the_sentence_robots_listen_for(skill: Any, aws: None) -> None:
    # The robots' interpreter recognises answers that start with exactly this sentence.
    text = speech(skill(load_event("alexa_weather"), None))
    assert text in ("The weather is sunny.", "The weather is rainy.")


def test_the_fleet_twin_is_the_bundled_fleet(fleet: Fleet) -> None:
    from skill import fleet_source

    assert fleet_source.load() == fleet


def test_a_stale_fleet_twin_is_ignored(tmp_path: Path, fleet: Fleet) -> None:
    # Given a twin written from another fleet file than the bundled one
    from skill import fleet_source

    other = FLEET_FILE.read_bytes().replace(b"[zone d, d,", b"[zone d, dee, d,")
    twin = tmp_path / "fleet.json"
    twin.write_text(build_files(Fleet.from_yaml(other), other)[FLEET_TWIN_PATH])
    # When the skill loads its fleet
    loaded = fleet_source.load(twin_file=str(twin))
    # Then it reads the bundled fleet.yaml itself
    assert loaded == fleet
    assert "dee" not in loaded.zone("D").spoken


def test_a_missing_fleet_twin_falls_back_to_the_yaml(tmp_path: Path, fleet: Fleet) -> None:
    from skill import fleet_source

    assert fleet_source.load(twin_file=str(tmp_path / "none.json")) == fleet


def test_a_configured_fleet_file_wins(tmp_path: Path) -> None:
    from skill import fleet_source

    custom = tmp_path / "fleet.yaml"
    custom.write_text(FLEET_FILE.read_text().replace("placebot2", "placebot9"))
    assert fleet_source.load(str(custom)).robot_things == ("placebot1", "placebot9")


def test_example_phrases_are_sample_utterances(model: dict[str, Any]) -> None:
    # Certification rejects example phrases the model does not understand.
    lm = language_model(model)
    names = {
        slot_type["name"]: "|".join(
            re.escape(name)
            for value in slot_type["values"]
            for name in [value["name"]["value"], *value["name"]["synonyms"]]
        )
        for slot_type in lm["types"]
    }

    def is_sample(spoken: str, sample: str, types: dict[str, str]) -> bool:
        # Only a sample whose own words are all in the phrase is made a pattern: the model
        # has thousands, and compiling each took seconds.
        if not all(words.strip() in spoken for words in re.split(r"\{\w+\}", sample)):
            return False
        regex = re.escape(sample)
        for slot, slot_type in types.items():
            regex = regex.replace(re.escape("{" + slot + "}"), f"(?:{names[slot_type]})")
        return re.match(f"^{regex}$", spoken) is not None

    samples = [
        (sample, {slot["name"]: slot["type"] for slot in intent.get("slots", [])})
        for intent in lm["intents"]
        for sample in intent["samples"]
    ]
    manifest = json.loads((ROOT / MANIFEST_PATH).read_text())
    phrases = manifest["manifest"]["publishingInformation"]["locales"]["en-US"]["examplePhrases"]
    assert phrases[0] == f"Alexa, open {lm['invocationName']}"
    for phrase in phrases[1:]:
        spoken = re.sub(rf"^Alexa, ask {lm['invocationName']} (to )?", "", phrase)
        assert spoken != phrase
        assert any(is_sample(spoken, sample, types) for sample, types in samples), phrase


def test_the_robots_weather_question_is_a_weather_intent_sample(model: dict[str, Any]) -> None:
    # The robots ask the assistant themselves (task II); the skill must understand them.
    from vahr.domain.invocation import WEATHER_QUESTION

    invocation = language_model(model)["invocationName"]
    asked = re.sub(rf"^Alexa, ask {invocation} (to )?", "", WEATHER_QUESTION).rstrip("?.").lower()
    [weather] = [i for i in language_model(model)["intents"] if i["name"] == "WeatherIntent"]
    assert asked in weather["samples"]
