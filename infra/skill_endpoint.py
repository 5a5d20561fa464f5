"""Write the deployed skill function's ARN into `skill.json`, for the `ask deploy` path.

    npx cdk deploy --outputs-file cdk-outputs.json
    python -m infra.skill_endpoint --outputs cdk-outputs.json [--skill-json FILE] [--stack NAME]

It sets `manifest.apis.custom.endpoint.uri` and changes nothing else in the file.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Sequence

OUTPUT_KEY = "SkillFunctionArn"
DEFAULT_SKILL_JSON = Path("skill-package") / "skill.json"
_LAMBDA_ARN = re.compile(
    r"^arn:aws(-[a-z]+)*:lambda:[a-z]{2}(-[a-z]+)+-\d:\d{12}:function:[A-Za-z0-9_-]{1,64}"
    r"(:[A-Za-z0-9_$-]{1,128})?$"
)


def function_arn(outputs: dict[str, Any], stack: str | None = None) -> str:
    """The skill function ARN from a `cdk deploy --outputs-file` document."""
    if not isinstance(outputs, dict):
        raise VahrError("the outputs file is not a JSON object of stacks")
    if stack is not None:
        if stack not in outputs:
            raise VahrError(f"stack {stack!r} is not in the outputs file ({', '.join(outputs)})")
        candidates = {stack: outputs[stack]}
    else:
        candidates = {
            name: values
            for name, values in outputs.items()
            if isinstance(values, dict) and OUTPUT_KEY in values
        }
        if len(candidates) > 1:
            raise VahrError(
                f"several stacks have {OUTPUT_KEY} ({', '.join(candidates)}): pass --stack"
            )
    if not candidates or not isinstance(next(iter(candidates.values())), dict):
        raise VahrError(f"no stack in the outputs file has {OUTPUT_KEY}: was it deployed?")
    name, values = next(iter(candidates.items()))
    arn = values.get(OUTPUT_KEY)
    if not isinstance(arn, str) or not _LAMBDA_ARN.match(arn):
        raise VahrError(f"{name}.{OUTPUT_KEY} is {arn!r}, not a Lambda function ARN")
    return arn


def set_endpoint(manifest_document: dict[str, Any], arn: str) -> bool:
    """Point the custom skill's endpoint at `arn`; True when the document changed."""
    custom: Any = manifest_document
    for key in ("manifest", "apis", "custom"):
        custom = custom.get(key) if isinstance(custom, dict) else None
    if not isinstance(custom, dict):
        raise VahrError("skill.json has no manifest.apis.custom: it is not a custom skill")
    endpoint = custom.setdefault("endpoint", {})
    changed = endpoint.get("uri") != arn or "sslCertificateType" in endpoint
    endpoint["uri"] = arn
    # A certificate type applies to HTTPS endpoints only; Alexa rejects it for a Lambda ARN.
    endpoint.pop("sslCertificateType", None)
    return changed


def _read_json(path: Path, what: str) -> Any:
    try:
        return json.loads(path.read_text())
    except OSError as err:
        raise VahrError(f"cannot read the {what} {path}: {err.strerror}") from err
    except json.JSONDecodeError as err:
        raise VahrError(f"the {what} {path} is not JSON (line {err.lineno}: {err.msg})") from err


def write_endpoint(*, outputs_file: Path, skill_json: Path, stack: str | None = None) -> str:
    """Update `skill_json` in place (atomically) from `outputs_file`; return the ARN."""
    arn = function_arn(_read_json(outputs_file, "outputs file"), stack)
    document = _read_json(skill_json, "skill manifest")
    if not isinstance(document, dict):
        raise VahrError(f"the skill manifest {skill_json} is not a JSON object")
    if set_endpoint(document, arn):
        handle, temporary = tempfile.mkstemp(prefix=".skill-", dir=skill_json.parent)
        with os.fdopen(handle, "w") as stream:
            json.dump(document, stream, indent=2, ensure_ascii=False)
            stream.write("\n")
        Path(temporary).replace(skill_json)
    return arn


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m infra.skill_endpoint",
        description="Write the deployed skill function ARN into skill.json's endpoint.",
    )
    parser.add_argument(
        "--outputs", type=Path, required=True, help="file from `cdk deploy --outputs-file`"
    )
    parser.add_argument(
        "--skill-json", type=Path, default=DEFAULT_SKILL_JSON, help="default %(default)s"
    )
    parser.add_argument("--stack", help="stack name, when the outputs hold several")
    args = parser.parse_args(argv)
    try:
        arn = write_endpoint(
            outputs_file=args.outputs, skill_json=args.skill_json, stack=args.stack
        )
    except VahrError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(f"{args.skill_json}: endpoint {arn}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
