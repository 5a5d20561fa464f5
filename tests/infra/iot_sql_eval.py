"""A small evaluator of the AWS IoT SQL the stack's rules use (version 2016-03-23), so tests
can check which messages a rule selects and what it passes on, without AWS.

It knows what the rules are written in: `SELECT` of `*` or expressions `AS` names, `FROM`
a topic filter (`+`, `#`), `WHERE` with `=`, `<>`, `AND`, `OR`, `NOT`, parentheses,
string, number and boolean literals, dotted paths into the message, `CASE v WHEN t THEN r
... ELSE e END`, and the functions `topic(n)` and `isUndefined(x)`. It keeps AWS's
three-valued logic as the IoT SQL reference states it: a path that is missing is
Undefined, a comparison with Undefined is Undefined, AND, OR and NOT on anything but
Booleans (or the strings "true"/"false") are Undefined, and a WHERE that is not true
selects nothing. An Undefined value in the SELECT list is left out of the result.

What it does not know, and AWS does: every other function and operator, type coercions
beyond those above, and `SELECT VALUE`. It raises on them rather than guess.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any


class _Undefined:
    def __repr__(self) -> str:
        return "Undefined"


UNDEFINED: Any = _Undefined()

_TOKEN = re.compile(
    r"\s*(?:(?P<string>'(?:[^']|'')*')|(?P<number>\d+(?:\.\d+)?)|(?P<op><>|=|\(|\)|,|\*|\.)"
    r"|(?P<word>[A-Za-z_$][A-Za-z0-9_$]*))"
)
_KEYWORDS = {"SELECT", "FROM", "WHERE", "AS", "AND", "OR", "NOT", "CASE", "WHEN", "THEN",
             "ELSE", "END", "TRUE", "FALSE"}  # fmt: skip


def _tokens(text: str) -> list[tuple[str, str]]:
    found, position = [], 0
    text = text.rstrip()
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None or match.end() == position:
            raise ValueError(f"cannot read the SQL at {text[position : position + 20]!r}")
        kind = match.lastgroup or ""
        value = match.group(kind)
        if kind == "word" and value.upper() in _KEYWORDS:
            kind, value = "keyword", value.upper()
        found.append((kind, value))
        position = match.end()
    return found


@dataclass
class Rule:
    select: list[tuple[Any, str | None]]  # (expression or "*", name)
    topic_filter: str
    where: Any | None


class _Parser:
    def __init__(self, text: str) -> None:
        self.tokens = _tokens(text)
        self.at = 0

    def peek(self) -> tuple[str, str]:
        return self.tokens[self.at] if self.at < len(self.tokens) else ("end", "")

    def take(self, value: str | None = None) -> tuple[str, str]:
        token = self.peek()
        if value is not None and token[1] != value:
            raise ValueError(f"expected {value!r}, found {token[1]!r}")
        self.at += 1
        return token

    def rule(self) -> Rule:
        self.take("SELECT")
        select: list[tuple[Any, str | None]] = []
        while True:
            if self.peek()[1] == "*":
                self.take()
                select.append(("*", None))
            else:
                expression = self.expression()
                name = None
                if self.peek()[1] == "AS":
                    self.take()
                    name = self.take()[1]
                select.append((expression, name))
            if self.peek()[1] != ",":
                break
            self.take()
        self.take("FROM")
        kind, topic = self.take()
        if kind != "string":
            raise ValueError("FROM takes a quoted topic filter")
        where = None
        if self.peek()[1] == "WHERE":
            self.take()
            where = self.expression()
        if self.peek()[0] != "end":
            raise ValueError(f"unexpected {self.peek()[1]!r}")
        return Rule(select, topic[1:-1].replace("''", "'"), where)

    def expression(self) -> Any:
        left = self.conjunction()
        while self.peek()[1] == "OR":
            self.take()
            left = ("or", left, self.conjunction())
        return left

    def conjunction(self) -> Any:
        left = self.negation()
        while self.peek()[1] == "AND":
            self.take()
            left = ("and", left, self.negation())
        return left

    def negation(self) -> Any:
        if self.peek()[1] == "NOT":
            self.take()
            return ("not", self.negation())
        return self.comparison()

    def comparison(self) -> Any:
        left = self.primary()
        if self.peek()[1] in ("=", "<>"):
            operator = self.take()[1]
            return (operator, left, self.primary())
        return left

    def primary(self) -> Any:
        kind, value = self.take()
        if kind == "string":
            return ("literal", value[1:-1].replace("''", "'"))
        if kind == "number":
            return ("literal", float(value) if "." in value else int(value))
        if value in ("TRUE", "FALSE"):
            return ("literal", value == "TRUE")
        if value == "(":
            inner = self.expression()
            self.take(")")
            return inner
        if value == "CASE":
            subject = self.expression()
            branches = []
            while self.peek()[1] == "WHEN":
                self.take()
                test = self.expression()
                self.take("THEN")
                branches.append((test, self.expression()))
            otherwise = None
            if self.peek()[1] == "ELSE":
                self.take()
                otherwise = self.expression()
            self.take("END")
            return ("case", subject, branches, otherwise)
        if kind == "word":
            if self.peek()[1] == "(":
                self.take()
                arguments = []
                while self.peek()[1] != ")":
                    arguments.append(self.expression())
                    if self.peek()[1] == ",":
                        self.take()
                self.take(")")
                return ("call", value, arguments)
            path = [value]
            while self.peek()[1] == ".":
                self.take()
                path.append(self.take()[1])
            return ("path", path)
        raise ValueError(f"unexpected {value!r}")


def parse(sql: str) -> Rule:
    return _Parser(sql).rule()


def topic_matches(topic_filter: str, topic: str) -> bool:
    """MQTT topic filter matching (`+` one level, `#` the rest)."""
    wanted, levels = topic_filter.split("/"), topic.split("/")
    for index, part in enumerate(wanted):
        if part == "#":
            return True
        if index >= len(levels) or (part != "+" and part != levels[index]):
            return False
    return len(wanted) == len(levels)


def _boolean(value: Any) -> Any:
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.lower() in ("true", "false"):
        return value.lower() == "true"
    return UNDEFINED


def _evaluate(node: Any, message: dict[str, Any], topic: str) -> Any:
    kind = node[0]
    if kind == "literal":
        return node[1]
    if kind == "path":
        value: Any = message
        for part in node[1]:
            if not isinstance(value, dict) or part not in value:
                return UNDEFINED
            value = value[part]
        return value
    if kind in ("=", "<>"):
        left, right = (_evaluate(side, message, topic) for side in node[1:])
        if left is UNDEFINED or right is UNDEFINED:
            return UNDEFINED
        same = left == right and type(left) is type(right)
        return same if kind == "=" else not same
    if kind in ("and", "or"):
        left, right = (_boolean(_evaluate(side, message, topic)) for side in node[1:])
        if left is UNDEFINED or right is UNDEFINED:
            return UNDEFINED
        return (left and right) if kind == "and" else (left or right)
    if kind == "not":
        value = _boolean(_evaluate(node[1], message, topic))
        return UNDEFINED if value is UNDEFINED else not value
    if kind == "case":
        subject = _evaluate(node[1], message, topic)
        for test, result in node[2]:
            if subject is not UNDEFINED and subject == _evaluate(test, message, topic):
                return _evaluate(result, message, topic)
        return UNDEFINED if node[3] is None else _evaluate(node[3], message, topic)
    if kind == "call":
        name, arguments = node[1], node[2]
        if name == "topic":
            [level] = [_evaluate(argument, message, topic) for argument in arguments]
            levels = topic.split("/")
            return levels[level - 1] if 1 <= level <= len(levels) else UNDEFINED
        if name == "isUndefined":
            [value] = [_evaluate(argument, message, topic) for argument in arguments]
            return value is UNDEFINED
        raise ValueError(f"the evaluator does not know the function {name}()")
    raise ValueError(f"cannot evaluate {node!r}")


def run(sql: str, topic: str, message: dict[str, Any]) -> dict[str, Any] | None:
    """What a rule with `sql` passes to its actions for `message` on `topic`; None when the
    rule does not select it (the topic does not match, or WHERE is not true)."""
    rule = parse(sql)
    if not topic_matches(rule.topic_filter, topic):
        return None
    if rule.where is not None and _evaluate(rule.where, message, topic) is not True:
        return None
    result: dict[str, Any] = {}
    for expression, name in rule.select:
        if expression == "*":
            result.update(message)
            continue
        value = _evaluate(expression, message, topic)
        if value is UNDEFINED:
            continue
        result[name or (expression[1][-1] if expression[0] == "path" else "_")] = value
    return result
