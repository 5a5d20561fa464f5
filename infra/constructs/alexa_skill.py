"""The Alexa skill itself (`Alexa::ASK::Skill`), created from `skill-package/` (optional).

CloudFormation creates skills through the Alexa Skill Management API, which needs a
Login-with-Amazon client and refresh token; they are read from Secrets Manager at deploy
time (never stored in the template). The package is uploaded as an S3 asset that only the
Alexa service role can read, and the endpoint is overridden with the function's ARN, so the
`skill.json` in the repository needs no account-specific value.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import alexa_ask
from aws_cdk import aws_iam as iam
from aws_cdk import aws_s3_assets as s3_assets
from constructs import Construct

from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path

    from aws_cdk import aws_lambda as lambda_

# The keys of the JSON secret (see docs/deploy.md, "Login with Amazon").
SECRET_KEYS = ("clientId", "clientSecret", "refreshToken", "vendorId")


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
