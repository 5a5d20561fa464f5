"""One way to make VAHR's Python Lambda functions: the runtime the bundle is built for, the
configured architecture, a log group of its own with the configured retention, and the
role's right to write it.

The skill, the announcer and the dispatcher all run from the one bundle
(infra/lambda_asset.py), whose compiled wheels are cross-built for CPython 3.12; the
runtime is pinned here, once, for that reason.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
from aws_cdk import aws_lambda as lambda_
from aws_cdk import aws_logs as logs

from infra.config import LOG_RETENTION_NAMES

if TYPE_CHECKING:
    from aws_cdk import aws_iam as iam
    from constructs import Construct

    from infra.config import InfraConfig

RUNTIME = lambda_.Runtime.PYTHON_3_12


def function_logs(scope: Construct, config: InfraConfig) -> logs.LogGroup:
    """The function's own log group (construct id `Logs`), kept for the configured days."""
    return logs.LogGroup(
        scope,
        "Logs",
        retention=logs.RetentionDays[LOG_RETENTION_NAMES[config.log_retention_days]],
        removal_policy=cdk.RemovalPolicy.DESTROY,
    )


def python_function(
    scope: Construct,
    *,
    config: InfraConfig,
    code: lambda_.Code,
    handler: str,
    description: str,
    role: iam.IRole,
    memory_mb: int,
    timeout: cdk.Duration,
    environment: dict[str, str],
    **options: Any,
) -> tuple[lambda_.Function, logs.LogGroup]:
    """The function (construct id `Function`) and its log group, which `role` may write.
    `options` go to `lambda_.Function` as they are (dead-letter queue, retries)."""
    log_group = function_logs(scope, config)
    function = lambda_.Function(
        scope,
        "Function",
        description=description,
        runtime=RUNTIME,
        architecture=(
            lambda_.Architecture.ARM_64
            if config.architecture == "arm64"
            else lambda_.Architecture.X86_64
        ),
        handler=handler,
        code=code,
        memory_size=memory_mb,
        timeout=timeout,
        role=role,
        log_group=log_group,
        environment=environment,
        **options,
    )
    log_group.grant_write(role)
    return function, log_group
