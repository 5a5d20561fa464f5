"""The skill assembled: every request handler and interceptor on ask-sdk-core's
`SkillBuilder`, behind the skill-id check (`skill.skill_gate`: a refused request is
answered, logged, and sends nothing) and an answer for envelopes the SDK cannot read.
`make_lambda_handler` builds the handler for a configuration and a gateway; the Lambda
entry point, `skill.app.lambda_handler`, is the one for the environment.
"""

from __future__ import annotations

import contextvars
import logging
from typing import TYPE_CHECKING, Any

from ask_sdk_core.exceptions import SerializationException
from ask_sdk_core.skill_builder import SkillBuilder

from skill import logs, prompts
from skill.catalog import use_locale
from skill.config import SkillConfig
from skill.guard import AccessInterceptor, RefusedRequestHandler, TrailInterceptor
from skill.handlers.battery import BatteryIntentHandler, ChargeIntentHandler
from skill.handlers.built_in import (
    CancelIntentHandler,
    FallbackIntentHandler,
    HelpIntentHandler,
    LaunchRequestHandler,
    NavigateHomeIntentHandler,
    SessionEndedRequestHandler,
    StopIntentHandler,
)
from skill.handlers.catch_all import CatchAllExceptionHandler
from skill.handlers.confirmation import DeniedIntentHandler
from skill.handlers.correction import CorrectionIntentHandler, UndoIntentHandler
from skill.handlers.deliver import DeliverIntentHandler
from skill.handlers.emergency_stop import EmergencyStopIntentHandler
from skill.handlers.fleet_tasks import (
    CancelTaskIntentHandler,
    FleetDeliverHandler,
    FleetNavigateIntentHandler,
    IdleRobotsIntentHandler,
    TaskQueueIntentHandler,
    ZoneRobotsIntentHandler,
)
from skill.handlers.navigate import NavigateIntentHandler
from skill.handlers.sequential_delivery import SequentialDeliveryIntentHandler
from skill.handlers.service import BackInServiceIntentHandler, OutOfServiceIntentHandler
from skill.handlers.status import ProblemRobotsIntentHandler, StatusIntentHandler
from skill.handlers.weather_delivery import WeatherDeliveryIntentHandler
from skill.handlers.weather_question import WeatherIntentHandler
from skill.handlers.zone_closure import CloseZoneIntentHandler, OpenZoneIntentHandler
from skill.interceptors import (
    CorrelationIdInterceptor,
    LocaleInterceptor,
    RequestLogInterceptor,
    ResponseLogInterceptor,
)
from skill.iot_data import IotDataGateway
from skill.logs import correlation_id, log_event
from skill.runtime import SkillRuntime
from skill.skill_gate import SkillGate, application_ids
from skill.skill_id_source import SkillIdSource
from skill.task_desk import task_desk

if TYPE_CHECKING:
    from collections.abc import Callable

    from ask_sdk_core.dispatch_components import AbstractRequestHandler

    from skill.gateway import RobotGateway


def request_handlers(runtime: SkillRuntime) -> list[AbstractRequestHandler]:
    """Every request handler, one per intent or request type.

    No two handlers claim the same request, so the order only reads from the most to the
    least frequent; SessionEndedRequest comes last as it never speaks.
    """
    desk = task_desk(runtime.config)
    return [
        # What the speaker's role does not allow is refused before anything else.
        RefusedRequestHandler(),
        # A denied intent is answered before its own handler could act on it.
        DeniedIntentHandler(),
        # A command naming a robot asks the dispatcher (`desk`) whether its zone is closed.
        NavigateIntentHandler(runtime, desk),
        # A delivery naming no robot goes to the fleet; one naming a robot, as before.
        FleetDeliverHandler(runtime, desk, named=DeliverIntentHandler(runtime, desk)),
        WeatherDeliveryIntentHandler(runtime, desk),
        SequentialDeliveryIntentHandler(runtime, desk),
        StatusIntentHandler(runtime),
        ProblemRobotsIntentHandler(runtime),
        EmergencyStopIntentHandler(runtime),
        WeatherIntentHandler(runtime),
        FleetNavigateIntentHandler(runtime, desk),
        ZoneRobotsIntentHandler(runtime, desk),
        IdleRobotsIntentHandler(runtime, desk),
        TaskQueueIntentHandler(runtime, desk),
        CancelTaskIntentHandler(runtime, desk),
        CloseZoneIntentHandler(runtime, desk),
        OpenZoneIntentHandler(runtime, desk),
        BatteryIntentHandler(runtime),
        ChargeIntentHandler(runtime, desk),
        OutOfServiceIntentHandler(runtime, desk),
        BackInServiceIntentHandler(runtime, desk),
        CorrectionIntentHandler(runtime, desk),
        UndoIntentHandler(runtime),
        LaunchRequestHandler(runtime),
        HelpIntentHandler(runtime),
        CancelIntentHandler(),
        StopIntentHandler(),
        NavigateHomeIntentHandler(),
        FallbackIntentHandler(runtime),
        SessionEndedRequestHandler(),
    ]


def build_skill_builder(runtime: SkillRuntime) -> SkillBuilder:
    # The skill id is checked by `skill.skill_gate` before the SDK sees the request (the
    # SDK's own check would fail the invocation instead of answering).
    builder = SkillBuilder()
    for handler in request_handlers(runtime):
        builder.add_request_handler(handler)
    # The correlation id is set before anything is logged.
    # First: every reply of the request, errors included, is in the request's locale.
    builder.add_global_request_interceptor(LocaleInterceptor())
    builder.add_global_request_interceptor(CorrelationIdInterceptor())
    builder.add_global_request_interceptor(RequestLogInterceptor())
    # Who is speaking and what their role allows, before any handler (skill.guard).
    builder.add_global_request_interceptor(AccessInterceptor(runtime))
    builder.add_global_response_interceptor(ResponseLogInterceptor())
    builder.add_global_response_interceptor(TrailInterceptor(runtime))
    builder.add_exception_handler(CatchAllExceptionHandler(runtime))
    return builder


def make_lambda_handler(
    config: SkillConfig | None = None, gateway: RobotGateway | None = None
) -> Callable[[dict[str, Any], Any], dict[str, Any]]:
    """A Lambda handler for `config` (default: the environment) and `gateway` (default:
    boto3's iot-data client for that configuration)."""
    config = config or SkillConfig.from_env()
    logs.configure(config.log_level)
    runtime = SkillRuntime.create(config, gateway or IotDataGateway.from_config(config))
    handler: Callable[[dict[str, Any], Any], dict[str, Any]]
    handler = build_skill_builder(runtime).lambda_handler()  # type: ignore[assignment]
    if config.on_lambda and config.skill_id is None and config.skill_id_parameter is None:
        log_event(
            "any_skill_allowed" if config.allow_any_skill else "no_skill_id",
            logging.WARNING,
            detail="any Alexa skill may call this function"
            if config.allow_any_skill
            else "every request is refused until VAHR_SKILL_ID is set",
        )
    source = SkillIdSource(config.skill_id, config.skill_id_parameter)
    return _answering_malformed(_gated(handler, config, source))


def _gated(
    handler: Callable[[dict[str, Any], Any], dict[str, Any]],
    config: SkillConfig,
    skill_id: Callable[[], str | None],
) -> Callable[[dict[str, Any], Any], dict[str, Any]]:
    """`handler` behind the skill-id check: a refused request is logged and answered with a
    sentence saying nothing was sent, before any handler (or the robots) sees it."""

    def gated(event: dict[str, Any], context: Any) -> dict[str, Any]:
        gate = SkillGate(skill_id(), config.allow_any_skill, config.on_lambda)
        reason = gate.refusal(event)
        if reason is None:
            return handler(event, context)
        request = event.get("request") if isinstance(event, dict) else None
        request = request if isinstance(request, dict) else {}
        correlation_id.set(str(request.get("requestId") or "-"))
        use_locale(request.get("locale") if isinstance(request.get("locale"), str) else None)
        log_event(
            "request_refused",
            logging.WARNING,
            reason=reason,
            application_id=next(iter(application_ids(event)), None),
        )
        return _spoken(prompts.NOT_THIS_SKILL)

    return gated


def _answering_malformed(
    handler: Callable[[dict[str, Any], Any], dict[str, Any]],
) -> Callable[[dict[str, Any], Any], dict[str, Any]]:
    """`handler`, answering an envelope the ASK SDK cannot read with the safe sentence.

    The SDK reads the envelope before any exception handler exists, so a malformed one
    (a request `type` it does not know, a field of the wrong type) would fail the Lambda
    invocation, and Alexa would speak its own vague error. A request for another skill
    never reaches the SDK: `_gated` answers it.
    """

    def lambda_handler(event: dict[str, Any], context: Any) -> dict[str, Any]:
        try:
            # In a context of its own, so that what a request sets for itself (its
            # language, `skill.catalog.use_locale`) ends with it: the local stack and the
            # tests run many requests in one thread, and a German one must not leave the
            # next English one speaking German.
            return contextvars.copy_context().run(handler, event, context)
        except SerializationException as err:
            log_event("malformed_request", logging.ERROR, error=str(err)[:300])
            return _safe_answer()

    return lambda_handler


def _safe_answer() -> dict[str, Any]:
    return _spoken(prompts.GENERIC_ERROR)


def _spoken(sentence: str) -> dict[str, Any]:
    """A whole Alexa response that says `sentence` and ends the session."""
    return {
        "version": "1.0",
        "response": {
            "outputSpeech": {"type": "SSML", "ssml": f"<speak>{sentence}</speak>"},
            "shouldEndSession": True,
        },
    }
