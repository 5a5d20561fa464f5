"""The CDK app's configuration: context values read once into a typed, validated object.

Context comes from `cdk.json` (JSON values) and from `-c key=value` on the command line
(always strings), so booleans and numbers are parsed from either form here, in one place.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Callable

REPO_ROOT = Path(__file__).resolve().parent.parent

Architecture = Literal["x86_64", "arm64"]

# Log retention periods CloudWatch Logs accepts (days), with their `logs.RetentionDays` names.
LOG_RETENTION_NAMES = {
    1: "ONE_DAY", 3: "THREE_DAYS", 5: "FIVE_DAYS", 7: "ONE_WEEK", 14: "TWO_WEEKS",
    30: "ONE_MONTH", 60: "TWO_MONTHS", 90: "THREE_MONTHS", 120: "FOUR_MONTHS",
    150: "FIVE_MONTHS", 180: "SIX_MONTHS", 365: "ONE_YEAR", 400: "THIRTEEN_MONTHS",
    545: "EIGHTEEN_MONTHS", 731: "TWO_YEARS", 1096: "THREE_YEARS", 1827: "FIVE_YEARS",
}  # fmt: skip
_SKILL_ID = re.compile(r"^amzn1\.ask\.skill\.[0-9a-f-]{36}$")
_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
_EMAIL = re.compile(r"^[^@\s]+@[^@\s]+\.[^@\s]+$")


@dataclass(frozen=True, kw_only=True)
class InfraConfig:
    """Everything the stacks need to know, validated. Build it with `from_context`."""

    stack_name: str = "Vahr"
    fleet_file: Path = REPO_ROOT / "fleet.yaml"
    architecture: Architecture = "x86_64"
    # A CPython 3.12 to precompile the function's bundle with (faster cold starts).
    lambda_python: Path | None = None
    log_retention_days: int = 30
    ack_timeout_s: float = 2.5
    log_level: str = "INFO"
    robot_policy_name: str = "vahr-robot-policy"
    # The operator station's and the experiment recorder's certificates, each its own.
    station_policy_name: str = "vahr-station-policy"
    recorder_policy_name: str = "vahr-recorder-policy"
    thing_group_name: str = "vahr-robots"
    presence_rule_name: str = "vahr_presence_to_shadow"
    # Known only after the skill exists (`ask deploy` prints it and keeps it in
    # .ask/ask-states.json, read when no skillId is given); when set, only that skill may
    # invoke the function and the handler checks the applicationId.
    skill_id: str | None = None
    # With no skill id and no skill in the stack, synth stops unless this says that any
    # Alexa skill may invoke the function (and the handler then serves any skill).
    allow_any_skill: bool = False
    skill: bool = False
    skill_package_dir: Path = REPO_ROOT / "skill-package"
    lwa_secret_name: str = "vahr/lwa"
    vendor_id: str | None = None
    lex: bool = False
    weather_answers_file: Path = REPO_ROOT / "robot_agent" / "voice" / "weather_answers.yaml"
    bot_name: str = "vahr-weather-answers"
    bot_alias_name: str = "live"
    role_alias_name: str = "vahr-robot-lex"
    # The announcer (infra/constructs/announcer.py): Alexa notifications of robots' troubles.
    announcer: bool = False
    announcer_secret_name: str = "vahr/skill-messaging"
    announcer_rule_prefix: str = "vahr_announcer"
    # Where the skill's users are (NA, EU, FE) and which Proactive Events stage to use.
    alexa_region: str = "NA"
    announcer_stage: str = "development"
    # vahr.announce.AnnounceSettings as JSON, checked at synth.
    announce_settings: str = "{}"
    # The fleet dispatcher (infra/constructs/dispatcher.py): the task table, the dispatcher
    # function, its rule on the robots' shadows, and fleet indexing, which is the account's
    # one thing-indexing configuration in the region (so it is off unless asked for).
    dispatcher: bool = False
    dispatcher_rule_name: str = "vahr_dispatcher_robot_freed"
    # On: the table survives `cdk destroy` and cannot be deleted by accident.
    task_table_deletion_protection: bool = False
    # What lets AWS see trouble (infra/constructs/iot_logging.py, device_audit.py,
    # alarms.py). Logging and the audit are the account's one configuration in the
    # region: off where another stack already owns it.
    iot_logging: bool = True
    device_audit: bool = True
    # Where the alarms are mailed (an SNS subscription to confirm); none: subscribe later.
    alarm_email: str | None = None
    # Who may do what (infra/constructs/people_tables.py): the users table, which the skill reads;
    # off, everyone may do everything. The audit table is always made; its deletion
    # protection is on unless said otherwise.
    people: bool = False
    audit_table_deletion_protection: bool = True

    def skill_invocation(self) -> SkillInvocation:
        """Which Alexa skill may invoke the skill function: the one whose id is given, the
        one the stack creates, or (said by name) any; a VahrError naming the flags when
        none of them is."""
        return _skill_invocation(self)

    @classmethod
    def from_context(cls, get: Callable[[str], Any]) -> InfraConfig:
        """Read every known key through `get` (e.g. `app.node.try_get_context`)."""
        defaults = cls()
        if get("operatorPolicyName") is not None:
            # One policy for the station and the recorder became one each.
            raise VahrError(
                "operatorPolicyName: the station and the recorder now have a policy each; "
                "give stationPolicyName and recorderPolicyName"
            )
        skill_id = _text(get, "skillId") or ask_states_skill_id(
            _path(get, "askStatesFile", REPO_ROOT / ".ask" / "ask-states.json"),
            _text(get, "askProfile") or "default",
        )
        if skill_id is not None and not _SKILL_ID.match(skill_id):
            raise VahrError(
                f"skillId: {skill_id!r} is not an Alexa skill id (amzn1.ask.skill.<uuid>)"
            )
        architecture = _text(get, "architecture") or defaults.architecture
        if architecture not in ("x86_64", "arm64"):
            raise VahrError(f"architecture: {architecture!r} must be x86_64 or arm64")
        retention = _number(get, "logRetentionDays", defaults.log_retention_days)
        if retention not in LOG_RETENTION_NAMES:
            raise VahrError(
                f"logRetentionDays: {retention:g} is not a CloudWatch Logs retention "
                f"({', '.join(str(d) for d in LOG_RETENTION_NAMES)})"
            )
        ack_timeout = _number(get, "ackTimeoutS", defaults.ack_timeout_s)
        if not 0 < ack_timeout <= 6:
            raise VahrError(
                f"ackTimeoutS: {ack_timeout:g} must be in (0, 6] (Alexa allows 8 s per answer)"
            )
        config = cls(
            stack_name=_text(get, "stackName") or defaults.stack_name,
            fleet_file=_path(get, "fleetFile", defaults.fleet_file),
            architecture=architecture,  # type: ignore[arg-type]
            lambda_python=_optional_path(get, "lambdaPython"),
            log_retention_days=int(retention),
            ack_timeout_s=ack_timeout,
            log_level=(_text(get, "logLevel") or defaults.log_level).upper(),
            robot_policy_name=_text(get, "robotPolicyName") or defaults.robot_policy_name,
            station_policy_name=(_text(get, "stationPolicyName") or defaults.station_policy_name),
            recorder_policy_name=(
                _text(get, "recorderPolicyName") or defaults.recorder_policy_name
            ),
            skill_id=skill_id,
            allow_any_skill=_flag(get, "allowAnySkill"),
            skill=_flag(get, "skill"),
            skill_package_dir=_path(get, "skillPackageDir", defaults.skill_package_dir),
            lwa_secret_name=_text(get, "lwaSecretName") or defaults.lwa_secret_name,
            vendor_id=_text(get, "vendorId"),
            lex=_flag(get, "lex"),
            weather_answers_file=_path(get, "weatherAnswersFile", defaults.weather_answers_file),
            role_alias_name=_text(get, "roleAliasName") or defaults.role_alias_name,
            announcer=_flag(get, "announcer"),
            announcer_secret_name=(
                _text(get, "announcerSecretName") or defaults.announcer_secret_name
            ),
            alexa_region=(_text(get, "alexaRegion") or defaults.alexa_region).upper(),
            announcer_stage=_text(get, "announcerStage") or defaults.announcer_stage,
            announce_settings=_announce_settings(get("announce")),
            dispatcher=_flag(get, "dispatcher"),
            task_table_deletion_protection=_flag(get, "taskTableDeletionProtection"),
            iot_logging=_flag(get, "iotLogging", default=True),
            device_audit=_flag(get, "deviceDefenderAudit", default=True),
            alarm_email=_text(get, "alarmEmail"),
            people=_flag(get, "people"),
            audit_table_deletion_protection=_flag(
                get, "auditTableDeletionProtection", default=True
            ),
        )
        config.skill_invocation()
        if config.alarm_email is not None and not _EMAIL.match(config.alarm_email):
            raise VahrError(f"alarmEmail: {config.alarm_email!r} is not an email address")
        if config.alexa_region not in ("NA", "EU", "FE"):
            raise VahrError(f"alexaRegion: {config.alexa_region!r} must be NA, EU or FE")
        if config.announcer_stage not in ("development", "live"):
            raise VahrError(
                f"announcerStage: {config.announcer_stage!r} must be development or live"
            )
        for key, value in (
            ("robotPolicyName", config.robot_policy_name),
            ("stationPolicyName", config.station_policy_name),
            ("recorderPolicyName", config.recorder_policy_name),
            ("roleAliasName", config.role_alias_name),
        ):
            if not _NAME.match(value):
                raise VahrError(f"{key}: {value!r} must be 1-64 letters, digits, '_' or '-'")
        if config.log_level not in ("DEBUG", "INFO", "WARNING", "ERROR"):
            raise VahrError(f"logLevel: {config.log_level!r} must be DEBUG, INFO, WARNING or ERROR")
        return config


SkillInvocation = Literal["skill_id", "stack_skill", "any_skill"]


def _skill_invocation(config: InfraConfig) -> SkillInvocation:
    if config.skill_id is not None:
        return "skill_id"
    if config.skill:
        return "stack_skill"
    if config.allow_any_skill:
        return "any_skill"
    raise VahrError(
        "skillId: none is known, so any Alexa skill could invoke the skill function; give "
        "-c skillId=amzn1.ask.skill... (ask deploy prints it), create the skill with the "
        "stack (-c skill=true), or accept that risk with -c allowAnySkill=true"
    )


def _announce_settings(value: Any) -> str:
    """The `announce` context (an object, or JSON text) checked as the announcer will read it."""
    from vahr.announce import settings_from
    from vahr.protocol import ProtocolError

    try:
        settings = settings_from(value if value is not None else {})
    except ProtocolError as err:
        raise VahrError(f"announce.{err}") from err
    import msgspec

    return msgspec.json.encode(settings).decode()


def ask_states_skill_id(states_file: Path, profile: str) -> str | None:
    """The skill id `ask deploy` recorded for `profile`, or None before the first deploy."""
    try:
        states = json.loads(states_file.read_text())
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as err:
        raise VahrError(f"{states_file}: cannot read the ASK CLI's state ({err})") from err
    skill_id = (
        states.get("profiles", {}).get(profile, {}).get("skillId")
        if isinstance(states, dict)
        else None
    )
    return skill_id if isinstance(skill_id, str) and skill_id else None


def _text(get: Callable[[str], Any], key: str) -> str | None:
    value = get(key)
    if value is None or value == "":
        return None
    return str(value)


def _flag(get: Callable[[str], Any], key: str, *, default: bool = False) -> bool:
    value = get(key)
    if value is None:
        return default
    if isinstance(value, bool):
        return value
    text = str(value).strip().lower()
    if text in ("true", "1", "yes", "on"):
        return True
    if text in ("false", "0", "no", "off", ""):
        return False
    raise VahrError(f"{key}: {value!r} is not true or false")


def _number(get: Callable[[str], Any], key: str, default: float) -> float:
    value = get(key)
    if value is None:
        return default
    try:
        return float(value)
    except (TypeError, ValueError) as err:
        raise VahrError(f"{key}: {value!r} is not a number") from err


def _optional_path(get: Callable[[str], Any], key: str) -> Path | None:
    value = _text(get, key)
    if value is None:
        return None
    path = Path(value).expanduser()
    if not path.is_file():
        raise VahrError(f"{key}: {value!r} is not a file")
    return path


def _path(get: Callable[[str], Any], key: str, default: Path) -> Path:
    value = _text(get, key)
    if value is None:
        return default
    path = Path(value)
    return path if path.is_absolute() else REPO_ROOT / path
