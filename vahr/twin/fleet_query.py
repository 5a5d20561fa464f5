"""The subset of AWS IoT fleet indexing's query syntax the local fleet index answers.

A query is terms `field:value` joined by `AND`, `OR` and `NOT` (and parentheses); terms
side by side without an operator are joined by `AND`, as AWS does. A value ending in `*`
matches by prefix, so `field:*` matches every thing that has the field. Values may be
quoted ("zone C"). A number field is also matched by range, in AWS's two forms:
`field<20` (or `<=`, `>`, `>=`) and `field:[0 TO 19]` (a `{` or `}` leaves its bound out,
`*` leaves a side open). The fields are the ones VAHR's robots report and the skill and the
dispatcher ask about:

| field | what it holds |
| --- | --- |
| `thingName` | the thing's name |
| `shadow.reported.status` | the robot's status (`idle`, `navigating`, `stuck`, ...) |
| `shadow.reported.zone` | the zone the robot reports being in |
| `connectivity.connected` / `shadow.reported.connected` | `true` or `false` |
| `shadow.reported.last_command.id` | the id of the last command the robot saw |
| `shadow.reported.last_command.result` | what became of it (`accepted`, `done`, `rejected`, ...) |
| `shadow.reported.battery.percent` | the charge, a number from 0 to 100 |
| `shadow.reported.battery.charging` | `true` or `false` |

Anything else is a `QueryError` whose message is one line, which the data plane returns
as AWS's `InvalidQueryException` (AWS also ranges over text; here only numbers are).
Parsing is pure: `parse` gives a tree of `Term`, `Range`, `Not`, `And` and `Or` that the
index evaluates.
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
# The robot's charge (the dispatcher finds the low ones, the skill counts them).
BATTERY_PERCENT = "shadow.reported.battery.percent"
BATTERY_CHARGING = "shadow.reported.battery.charging"
FIELDS = (
    THING_NAME, STATUS, ZONE, CONNECTED, REPORTED_CONNECTED, COMMAND_ID, COMMAND_RESULT,
    BATTERY_PERCENT, BATTERY_CHARGING,
)  # fmt: skip
# The fields whose values are true or false, and those holding a number.
BOOLEAN_FIELDS = (CONNECTED, REPORTED_CONNECTED, BATTERY_CHARGING)
NUMBER_FIELDS = (BATTERY_PERCENT,)
# AWS's limit on a query string's length.
MAX_QUERY_CHARS = 1000

_FIELD = r"[A-Za-z][A-Za-z0-9_.]*"
_TOKEN = re.compile(
    rf"""\s*(?:
        (?P<open>\()|(?P<close>\))
      | (?P<range>{_FIELD}:[\[{{][^\]}}()]*[\]}}])
      | (?P<term>{_FIELD}:(?:"[^"]*"|[^\s()"]*))
      | (?P<word>[^\s()]+)
    )""",
    re.VERBOSE,
)
_COMPARISON = re.compile(rf"(?P<field>{_FIELD})(?P<operator><=|>=|<|>)(?P<value>.*)")
_SPAN = re.compile(
    rf"""(?P<field>{_FIELD}):(?P<open>[\[{{])\s*(?P<low>\S+)
         \s+TO\s+(?P<high>[^\s\]}}]+)\s*(?P<close>[\]}}])""",
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
class Range:
    """A number field's values between two bounds (None: open on that side)."""

    field: str
    low: float | None
    high: float | None
    low_inclusive: bool = True
    high_inclusive: bool = True

    def holds(self, value: float) -> bool:
        low, high = self.low, self.high
        if low is not None and (value < low or (value == low and not self.low_inclusive)):
            return False
        return high is None or value < high or (value == high and self.high_inclusive)


@dataclass(frozen=True)
class Not:
    operand: Query


@dataclass(frozen=True)
class And:
    operands: tuple[Query, ...]


@dataclass(frozen=True)
class Or:
    operands: tuple[Query, ...]


Query = Term | Range | Not | And | Or


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


def _leaf(token: str) -> Term | Range:
    """One term: `field:value`, `field<number` (and its kin) or `field:[low TO high]`."""
    if span := _SPAN.fullmatch(token):
        field = _known(span["field"])
        return Range(
            _number_field(field),
            _bound(field, span["low"]),
            _bound(field, span["high"]),
            low_inclusive=span["open"] == "[",
            high_inclusive=span["close"] == "]",
        )
    if comparison := _COMPARISON.fullmatch(token):
        field = _number_field(_known(comparison["field"]))
        operator, value = comparison["operator"], _number(field, comparison["value"])
        if operator.startswith("<"):
            return Range(field, None, value, high_inclusive=operator == "<=")
        return Range(field, value, None, low_inclusive=operator == ">=")
    if ":" not in token or token in ("AND", "OR", "NOT", ")"):
        raise QueryError(f"Syntax error in query near '{token}': expected field:value")
    if token.partition(":")[2].startswith(("[", "{")):
        raise QueryError(f"Syntax error in range '{token}': expected [low TO high]")
    return _term(token)


def _known(field: str) -> str:
    if field not in FIELDS:
        raise QueryError(f"Unsupported field '{field}' in query; supported: {', '.join(FIELDS)}")
    return field


def _number_field(field: str) -> str:
    if field not in NUMBER_FIELDS:
        raise QueryError(
            f"Field '{field}' is not ranged over here; ranges are answered on "
            f"{', '.join(NUMBER_FIELDS)}"
        )
    return field


def _number(field: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise QueryError(f"Field '{field}' takes a number, not '{text}'") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise QueryError(f"Field '{field}' takes a number, not '{text}'")
    return value


def _bound(field: str, text: str) -> float | None:
    return None if text == "*" else _number(field, text)


def _term(token: str) -> Term | Range:
    field, _, value = token.partition(":")
    _known(field)
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
    if field in BOOLEAN_FIELDS and not prefix and value not in ("true", "false"):
        raise QueryError(f"Field '{field}' takes true or false, not '{value}'")
    if field in NUMBER_FIELDS and not (prefix and not value):
        if prefix:
            raise QueryError(f"Field '{field}' takes a number, not '{value}*'")
        exactly = _number(field, value)
        return Range(field, exactly, exactly)
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
        return _leaf(token)


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
