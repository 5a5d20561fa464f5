"""The CDK app: `npx cdk synth|deploy` runs `python -m infra.app` (see cdk.json).

Context flags (cdk.json or `-c key=value`): `skill=true` adds the Alexa skill, `lex=true`
the Lex bot and the robots' role alias, `announcer=true` the announcer, `dispatcher=true`
the fleet dispatcher with fleet indexing (`taskTableDeletionProtection`); `skillId`,
`vendorId`, `lwaSecretName`, `architecture`, `fleetFile`, `logRetentionDays`, `ackTimeoutS`,
`logLevel`, `stackName`, `robotPolicyName`, `stationPolicyName`, `recorderPolicyName`,
`roleAliasName`, `allowAnySkill`, `alarmEmail`, `iotLogging`, `deviceDefenderAudit`,
`weatherAnswersFile` (docs/deploy.md lists them all).
cdk-nag's AwsSolutions checks run on the whole app; synth fails on any finding that the
stack has not acknowledged with a reason.
"""

from __future__ import annotations

import os
import sys

import aws_cdk as cdk
from cdk_nag import AwsSolutionsChecks

from infra.config import InfraConfig
from infra.stacks.vahr_stack import VahrStack
from vahr.domain import load_fleet
from vahr.errors import VahrError
from vahr.protocol import ProtocolError


def build_app(app: cdk.App) -> VahrStack:
    """Add the VAHR stack (and the cdk-nag checks) to `app`; return the stack."""
    config = InfraConfig.from_context(app.node.try_get_context)
    try:
        fleet = load_fleet(config.fleet_file)
    except ProtocolError as err:
        raise VahrError(f"{config.fleet_file}: {err}") from err
    account, region = os.environ.get("CDK_DEFAULT_ACCOUNT"), os.environ.get("CDK_DEFAULT_REGION")
    stack = VahrStack(
        app,
        config.stack_name,
        config=config,
        fleet=fleet,
        description="VAHR: voice control of a robot fleet (AWS IoT Core, Alexa skill, Lex)",
        # Environment-agnostic unless the CLI knows the account, so synth works offline.
        env=cdk.Environment(account=account, region=region) if account and region else None,
    )
    cdk.Validations.of(app).add_plugins(AwsSolutionsChecks(app))
    return stack


def main() -> int:
    app = cdk.App()
    try:
        build_app(app)
    except VahrError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    app.synth()
    return 0


if __name__ == "__main__":
    sys.exit(main())
