"""The subset of AWS IoT fleet indexing's query syntax the local fleet index answers.

A query is terms `field:value` joined by `AND`, `OR` and `NOT` (and parentheses); terms
side by side without an operator are joined by `AND`, as AWS does. A value ending in `*`
matches by prefix, so `field:*` matches every thing that has the field. Values may be
quoted ("zone C"). The fields are the ones VAHR's robots report and the skill asks about:

| field | what it holds |
| --- | --- |
| `thingName` | the thing's name |
| `shadow.reported.status` | the robot's status (`idle`, `navigating`, `stuck`, ...) |
| `shadow.reported.zone` | the zone the robot reports being in |
| `connectivity.connected` / `shadow.reported.connected` | `true` or `false` |
| `shadow.reported.last_command.id` | the id of the last command the robot saw |
| `shadow.reported.last_command.result` | what became of it (`accepted`, `done`, `rejected`, ...) |

Anything else is a `QueryError` whose message is one line, which the data plane returns
as AWS's `InvalidQueryException`. Parsing is pure: `parse` gives a tree of `Term`, `Not`,
`And` and `Or` that the index evaluates.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

THING_NAME = "thingName"
STATUS = "shadow.reported.status"
ZONE = "shadow.reported.zone"
CONNECTED = "connectivity.connected"
# The robots' own report of the same flag (the local presence rule writes it).
REPORTED_CONNECTED = "shadow.reported.connected"
# Which robots acknowledged a command, without reading every shadow (the skill's fleet
# commands).
COMMAND_ID = "shadow.reported.last_command.id"
COMMAND_RESULT = "shadow.reported.last_command.result"
FIELDS = (THING_NAME, STATUS, ZONE, CONNECTED, REPORTED_CONNECTED, COMMAND_ID, COMMAND_RESULT)
# AWS's limit on a query string's length.
MAX_QUERY_CHARS = 1000

_TOKEN = re.compile(
    r"""\s*(?:
        (?P<open>\()|(?P<close>\))
      | (?P<term>[A-Za-z][A-Za-z0-9_.]*:(?:"[^"]*"|[^\s()"]*))
      | (?P<word>[^\s()]+)
    )""",
    re.VERBOSE,
)


class QueryError(ValueError):
    """A query the index cannot answer; the message is one line for the caller."""


@dataclass(frozen=True)
class Term:
    field: str
    value: str
    prefix: bool


@dataclass(frozen=True)
class Not:
    operand: Query


@dataclass(frozen=True)
class And:
    operands: tuple[Query, ...]


@dataclass(frozen=True)
class Or:
    operands: tuple[Query, ...]


Query = Term | Not | And | Or


def _tokens(text: str) -> list[str]:
    tokens: list[str] = []
    position = 0
    text = text.rstrip()
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None:  # pragma: no cover - every character is some token
            raise QueryError(f"Syntax error in query at character {position + 1}")
        tokens.append(match.group(match.lastgroup or "word"))
        position = match.end()
    return tokens


def _term(token: str) -> Term:
    field, _, value = token.partition(":")
    if field not in FIELDS:
        raise QueryError(f"Unsupported field '{field}' in query; supported: {', '.join(FIELDS)}")
    if value.startswith('"'):
        value = value[1:-1]
        prefix = False
    else:
        prefix = value.endswith("*")
        value = value[:-1] if prefix else value
        if "*" in value or "?" in value:
            raise QueryError(f"Wildcards are supported only at the end of a value: '{token}'")
    if not value and not prefix:
        raise QueryError(f"Missing value for field '{field}' in query")
    if field in (CONNECTED, REPORTED_CONNECTED) and not prefix and value not in ("true", "false"):
        raise QueryError(f"Field '{field}' takes true or false, not '{value}'")
    return Term(field, value, prefix)


class _Parser:
    def __init__(self, tokens: list[str]) -> None:
        self.tokens = tokens
        self.position = 0

    def peek(self) -> str | None:
        return self.tokens[self.position] if self.position < len(self.tokens) else None

    def take(self) -> str:
        token = self.tokens[self.position]
        self.position += 1
        return token

    def any_of(self) -> Query:
        operands = [self.all_of()]
        while self.peek() == "OR":
            self.take()
            operands.append(self.all_of())
        return operands[0] if len(operands) == 1 else Or(tuple(operands))

    def all_of(self) -> Query:
        operands = [self.negation()]
        while (token := self.peek()) is not None and token not in ("OR", ")"):
            if token == "AND":
                self.take()
            operands.append(self.negation())
        return operands[0] if len(operands) == 1 else And(tuple(operands))

    def negation(self) -> Query:
        if self.peek() == "NOT":
            self.take()
            return Not(self.negation())
        return self.primary()

    def primary(self) -> Query:
        token = self.peek()
        if token is None:
            raise QueryError("Syntax error in query: it ends where a term was expected")
        self.take()
        if token == "(":
            inner = self.any_of()
            if self.peek() != ")":
                raise QueryError("Syntax error in query: a '(' is never closed")
            self.take()
            return inner
        if ":" not in token or token in ("AND", "OR", "NOT", ")"):
            raise QueryError(f"Syntax error in query near '{token}': expected field:value")
        return _term(token)


def parse(text: str) -> Query:
    """The tree of a query string; `QueryError` (one line) when it is not one."""
    if not isinstance(text, str) or not text.strip():
        raise QueryError("The query string is empty")
    if len(text) > MAX_QUERY_CHARS:
        raise QueryError(f"The query string is longer than {MAX_QUERY_CHARS} characters")
    parser = _Parser(_tokens(text))
    query = parser.any_of()
    if parser.peek() is not None:
        raise QueryError(f"Syntax error in query near '{parser.peek()}'")
    return query
