"""boto3's default session with AWS's service models read once per process, for tests under
moto.

moto replaces boto3's default session at every start (its `reset_boto3_session`), so each
test's first client made a new botocore session, whose loader parsed the service's JSON
model again: a third of the skill's unit tests' time. `default_session()` makes the new
default session with one loader kept for the process (botocore's `data_loader` component,
which caches what it has read); credentials and configuration are still the session's own.
"""

from __future__ import annotations

import boto3
import botocore.loaders
import botocore.session

_LOADER = botocore.loaders.create_loader()


def default_session() -> None:
    """A new boto3 default session (as moto leaves it) that reads models through `_LOADER`."""
    session = botocore.session.get_session()
    session.register_component("data_loader", _LOADER)
    boto3.setup_default_session(botocore_session=session)
