"""The data-plane API under requests no SDK would send (regressions from tests/fuzz/):
each gets a status line and AWS's JSON error shape, never a dropped connection."""

from __future__ import annotations

import http.client
import json
import socket
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack


def _raw(stack: LocalStack, request: bytes) -> tuple[int, dict[str, str], bytes]:
    with socket.create_connection(("127.0.0.1", stack.config.api_port), timeout=10) as sock:
        sock.sendall(request)
        response = http.client.HTTPResponse(sock, method="GET")
        response.begin()
        return response.status, dict(response.getheaders()), response.read()


def test_a_content_length_that_is_not_a_number_is_a_400(local_stack: LocalStack) -> None:
    status, headers, body = _raw(
        local_stack,
        b"POST /things/placebot1/shadow HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\nContent-Length: abc\r\n\r\n{}",
    )
    assert status == 400
    assert json.loads(body) == {
        "code": 400, "message": "Content-Length must be a whole number of bytes",
    }  # fmt: skip
    assert headers["x-amzn-ErrorType"] == "InvalidRequestException"


def test_a_body_larger_than_aws_allows_is_refused_before_it_is_read(
    local_stack: LocalStack,
) -> None:
    status, _, body = _raw(
        local_stack,
        b"POST /topics/t?qos=1 HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\nContent-Length: 999999999\r\n\r\n",
    )
    assert status == 413
    assert json.loads(body)["message"] == "The payload exceeds the maximum size allowed"


def test_a_method_the_api_does_not_know_is_a_405_in_aws_shape(local_stack: LocalStack) -> None:
    status, headers, body = _raw(
        local_stack,
        b"BREW /things/placebot1/shadow HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n\r\n",
    )
    assert status == 405
    assert json.loads(body) == {"code": 405, "message": "BREW is not allowed on a shadow"}
    assert headers["x-amzn-ErrorType"] == "MethodNotAllowedException"


def test_a_request_line_broken_by_a_line_feed_gets_an_http_11_answer(
    local_stack: LocalStack,
) -> None:
    status, _, body = _raw(
        local_stack,
        b"GET /vahr/health?a=\n HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n\r\n",
    )
    assert status == 400
    assert json.loads(body)["message"] == "Bad request line: HTTP/1.1 is required"


def test_a_shadow_nested_deeper_than_the_parser_goes_is_a_400_not_a_500(
    local_stack: LocalStack,
) -> None:
    deep = b"[" * 4000 + b"]" * 4000
    document = b'{"state":{"reported":{"a":' + deep + b"}}}"
    status, _, body = _raw(
        local_stack,
        b"POST /things/placebot1/shadow HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\nContent-Length: %d\r\n\r\n"
        % len(document)
        + document,
    )
    assert status == 400
    assert json.loads(body) == {
        "code": 400, "message": "JSON contains too many levels of nesting; maximum is 6",
    }  # fmt: skip
