"""`vahr users`: check a users file, load it into the users table on AWS, make a station
token.

    vahr users check FILE                  what the file says, or its first fault
    vahr users import FILE --table NAME    put its people (and everyone else's role) in the
                                           DynamoDB users table the skill reads
    vahr users token                       a fresh station sign-in token and its SHA-256,
                                           for a person's `token_sha256` in the file
"""

from __future__ import annotations

import json
import secrets
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import argparse

    from vahr.domain.people import People

TOKEN_BYTES = 24


def configure(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", required=True, metavar="ACTION")
    check = actions.add_parser("check", help="read a users file and say what it holds")
    check.add_argument("file", type=Path)
    load = actions.add_parser("import", help="load a users file into the DynamoDB users table")
    load.add_argument("file", type=Path)
    load.add_argument("--table", required=True, help="the users table (the stack's output)")
    load.add_argument("--region", help="the table's AWS region (default: the environment's)")
    token = actions.add_parser("token", help="make a station sign-in token")
    token.add_argument("--json", action="store_true", help='print {"token", "token_sha256"}')


def run(args: argparse.Namespace) -> int:
    if args.action == "token":
        return _token(as_json=args.json)
    people = _read(args.file)
    if args.action == "check":
        print(_summary(people, args.file))
        return 0
    return _import(people, args.table, args.region)


def _read(path: Path) -> People:
    from vahr.domain.people import load_people
    from vahr.errors import VahrError
    from vahr.protocol import ProtocolError

    try:
        return load_people(path)
    except ProtocolError as err:
        raise VahrError(f"{path}: {err}") from err


def _summary(people: People, path: Path) -> str:
    from vahr.domain.people import ROLES

    counts = [f"{sum(p.role == role for p in people.users)} {role}" for role in reversed(ROLES)]
    signs_in = sum(p.token_sha256 is not None for p in people.users)
    count = len(people.users)
    return (
        f"{path}: {count} {'person' if count == 1 else 'people'} ({', '.join(counts)}); "
        f"anyone else is a {people.default_role}; {signs_in} may sign in at the station"
    )


def _import(people: People, table: str, region: str | None) -> int:
    from skill.errors import PeopleUnavailable
    from skill.users_table import write_people
    from vahr.errors import VahrError

    try:
        count = write_people(people, table, region=region)
    except PeopleUnavailable as err:
        raise VahrError(str(err)) from err
    print(f"{table}: {count} people, anyone else a {people.default_role}")
    return 0


def _token(*, as_json: bool) -> int:
    from vahr.domain.people import token_hash

    token = secrets.token_urlsafe(TOKEN_BYTES)
    digest = token_hash(token)
    if as_json:
        print(json.dumps({"token": token, "token_sha256": digest}))
    else:
        print(f"token: {token}")
        print(f"token_sha256: {digest}")
        print("Give the token to the person once; put token_sha256 in their entry of the file.")
    return 0
