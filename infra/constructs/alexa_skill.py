"""The Alexa skill itself (`Alexa::ASK::Skill`), created from `skill-package/` (optional).

CloudFormation creates skills through the Alexa Skill Management API, which needs a
Login-with-Amazon client and refresh token; they are read from Secrets Manager at deploy
time (never stored in the template). The package is uploaded as an S3 asset that only the
Alexa service role can read, and the endpoint is overridden with the function's ARN, so the
`skill.json` in the repository needs no account-specific value.

Given `skill_id_parameter` (the skill's id was not known at synth), it also locks the
function to this skill in the one deployment: Alexa checks at creation that it may invoke
the endpoint, before the skill's id exists, so an invocation grant without a skill id
(`AllowSkillCreation`, statement `CREATION_STATEMENT`) is added just before the skill is
created; then the permission carrying the new skill's id as `EventSourceToken`, the id
written to the SSM parameter the handler reads, and finally the creation grant removed
(`CloseSkillCreation`). From then on only this skill may invoke the function.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import alexa_ask
from aws_cdk import aws_iam as iam
from aws_cdk import aws_lambda as lambda_
from aws_cdk import aws_s3_assets as s3_assets
from aws_cdk import aws_ssm as ssm
from aws_cdk import custom_resources as cr
from constructs import Construct

from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path

    from aws_cdk import aws_logs as logs

# The keys of the JSON secret (see docs/deploy.md, "Login with Amazon").
SECRET_KEYS = ("clientId", "clientSecret", "refreshToken", "vendorId")
ALEXA = "alexa-appkit.amazon.com"
# The statement of the grant Alexa's creation check needs, removed once the skill exists.
CREATION_STATEMENT = "VahrAlexaSkillCreation"


class AlexaSkill(Construct):
    """The skill, its package asset, and the role Alexa uses to read that package."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        package_dir: Path,
        function: lambda_.IFunction,
        lwa_secret_name: str,
        vendor_id: str | None,
        skill_id_parameter: str | None = None,
        provider_logs: logs.ILogGroup | None = None,
    ) -> None:
        super().__init__(scope, construct_id)
        if not (package_dir / "skill.json").is_file():
            raise VahrError(
                f"skill=true needs {package_dir / 'skill.json'} (run `make skill-model` first)"
            )
        self.package = s3_assets.Asset(self, "Package", path=str(package_dir))
        self.package_role = iam.Role(
            self,
            "PackageReader",
            assumed_by=iam.ServicePrincipal("alexa-appkit.amazon.com"),
            description="Lets Alexa read the VAHR skill package from the CDK asset bucket",
        )
        # Exactly the one object (grant_read would add bucket listing and wildcards).
        self.package_role.add_to_policy(
            iam.PolicyStatement(
                actions=["s3:GetObject"],
                resources=[self.package.bucket.arn_for_objects(self.package.s3_object_key)],
            )
        )

        def secret(key: str) -> str:
            return cdk.SecretValue.secrets_manager(lwa_secret_name, json_field=key).unsafe_unwrap()

        self.skill = alexa_ask.CfnSkill(
            self,
            "Skill",
            vendor_id=vendor_id or secret("vendorId"),
            authentication_configuration=alexa_ask.CfnSkill.AuthenticationConfigurationProperty(
                client_id=secret("clientId"),
                client_secret=secret("clientSecret"),
                refresh_token=secret("refreshToken"),
            ),
            skill_package=alexa_ask.CfnSkill.SkillPackageProperty(
                s3_bucket=self.package.s3_bucket_name,
                s3_key=self.package.s3_object_key,
                s3_bucket_role=self.package_role.role_arn,
                overrides=alexa_ask.CfnSkill.OverridesProperty(
                    manifest={"apis": {"custom": {"endpoint": {"uri": function.function_arn}}}}
                ),
            ),
        )
        # Alexa checks at creation that it may invoke the endpoint.
        self.skill.node.add_dependency(function)
        self.skill_id: str = self.skill.ref
        self.skill_only: lambda_.CfnPermission | None = None
        self.skill_id_parameter: ssm.StringParameter | None = None
        if skill_id_parameter is not None:
            self._lock_to_this_skill(function, skill_id_parameter, provider_logs)

    def _lock_to_this_skill(
        self, function: lambda_.IFunction, parameter: str, provider_logs: logs.ILogGroup | None
    ) -> None:
        grant = {
            "FunctionName": function.function_arn,
            "StatementId": CREATION_STATEMENT,
            "Action": "lambda:InvokeFunction",
            "Principal": ALEXA,
        }
        remove = cr.AwsSdkCall(
            service="Lambda",
            action="removePermission",
            parameters={"FunctionName": function.function_arn, "StatementId": CREATION_STATEMENT},
            physical_resource_id=cr.PhysicalResourceId.of(CREATION_STATEMENT),
            ignore_error_codes_matching="ResourceNotFoundException",
        )
        policy = cr.AwsCustomResourcePolicy.from_statements(
            [
                iam.PolicyStatement(
                    actions=["lambda:AddPermission", "lambda:RemovePermission"],
                    resources=[function.function_arn],
                )
            ]
        )
        opened = cr.AwsCustomResource(
            self,
            "AllowSkillCreation",
            on_create=cr.AwsSdkCall(
                service="Lambda",
                action="addPermission",
                parameters=grant,
                physical_resource_id=cr.PhysicalResourceId.of(CREATION_STATEMENT),
            ),
            on_delete=remove,
            policy=policy,
            install_latest_aws_sdk=False,
            log_group=provider_logs,
        )
        self.skill.node.add_dependency(opened)
        self.skill_only = lambda_.CfnPermission(
            self,
            "InvokeByThisSkillOnly",
            action="lambda:InvokeFunction",
            function_name=function.function_arn,
            principal=ALEXA,
            event_source_token=self.skill.ref,
        )
        self.skill_id_parameter = ssm.StringParameter(
            self,
            "SkillId",
            parameter_name=parameter,
            string_value=self.skill.ref,
            description="The VAHR skill's id: the one skill its function serves",
        )
        closed = cr.AwsCustomResource(
            self,
            "CloseSkillCreation",
            on_create=remove,
            on_update=remove,
            policy=policy,
            install_latest_aws_sdk=False,
            log_group=provider_logs,
        )
        closed.node.add_dependency(self.skill_only, self.skill_id_parameter)
