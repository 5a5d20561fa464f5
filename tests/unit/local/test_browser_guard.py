"""The data plane's checks against what a web page can make a browser send, one rule at a
time (the requests themselves, through a real server and a real browser, are in
tests/integration/local/test_dataplane_browsers.py)."""

from __future__ import annotations

import pytest

from vahr.twin.browser_guard import BrowserGuard, Refusal, host_name, is_json

# What boto3's iot-data client sends with a Publish (SigV4 signed, no Content-Type header).
BOTO3_PUBLISH = {
    "Host": "127.0.0.1:8180",
    "Authorization": "AWS4-HMAC-SHA256 Credential=x/20260101/us-east-1/iotdata/aws4_request, "
    "SignedHeaders=host;x-amz-date, Signature=0",
    "X-Amz-Date": "20260101T000000Z",
}


def refusal(
    method: str, headers: dict[str, str], hosts: frozenset[str] = frozenset()
) -> Refusal | None:
    return BrowserGuard(hosts).refusal(method, headers)


def test_boto3_and_the_repositorys_own_clients_are_served() -> None:
    assert refusal("POST", BOTO3_PUBLISH) is None
    assert refusal("GET", {"Host": "localhost:8180"}) is None
    assert refusal("POST", {"Host": "127.0.0.1:8180", "Content-Type": "application/json"}) is None
    assert refusal("DELETE", {**BOTO3_PUBLISH, "Host": "[::1]:8180"}) is None
    # boto3's `iot` client (fleet indexing) speaks rest-json, signed.
    assert refusal("POST", {**BOTO3_PUBLISH, "Content-Type": "application/json"}) is None


@pytest.mark.parametrize(
    "host",
    ["attacker.example:8180", "attacker.example", "127.0.0.1.nip.io:8180", "", "0.0.0.0:8180"],
)
def test_a_host_that_is_not_loopback_is_refused_as_rebinding(host: str) -> None:
    # A page whose name was rebound to 127.0.0.1 still sends its own name as Host.
    assert refusal("GET", {"Host": host}) == Refusal(
        421, f"this server does not answer to the host {host!r}"
    )


def test_a_configured_host_is_served() -> None:
    assert refusal("GET", {"Host": "robots.lab:443"}, frozenset({"robots.lab"})) is None
    assert refusal("GET", {"Host": "ROBOTS.LAB"}, frozenset({"robots.lab"})) is None


@pytest.mark.parametrize(
    "origin", ["http://attacker.example", "null", "http://127.0.0.1:8181", "http://localhost:8180"]
)
def test_an_origin_other_than_the_servers_own_is_refused(origin: str) -> None:
    headers = {"Host": "127.0.0.1:8180", "Origin": origin, "Content-Type": "application/json"}
    assert refusal("POST", headers) == Refusal(403, f"requests from {origin} are not accepted")
    assert refusal("GET", headers) == Refusal(403, f"requests from {origin} are not accepted")


def test_the_servers_own_origin_is_served() -> None:
    headers = {"Host": "127.0.0.1:8180", "Origin": "http://127.0.0.1:8180"}
    assert refusal("GET", headers) is None


@pytest.mark.parametrize("site", ["cross-site", "same-site", "Cross-Site"])
def test_a_fetch_from_another_site_is_refused_even_without_an_origin(site: str) -> None:
    assert refusal("GET", {"Host": "127.0.0.1:8180", "Sec-Fetch-Site": site}) == Refusal(
        403, f"requests a page makes from another origin ({site.lower()}) are refused"
    )


@pytest.mark.parametrize("site", ["none", "same-origin"])
def test_a_typed_url_or_a_same_origin_fetch_is_served(site: str) -> None:
    assert refusal("GET", {"Host": "127.0.0.1:8180", "Sec-Fetch-Site": site}) is None


@pytest.mark.parametrize(
    "content_type",
    [
        None,
        "text/plain",
        "text/plain;charset=UTF-8",
        "application/x-www-form-urlencoded",
        "multipart/form-data; boundary=x",
    ],
)
def test_a_write_a_form_or_a_no_cors_fetch_could_send_is_refused(content_type: str | None) -> None:
    # Exactly the content types a browser sends without a preflight, and none at all.
    headers = {"Host": "127.0.0.1:8180"}
    if content_type is not None:
        headers["Content-Type"] = content_type
    for method in ("POST", "PUT", "DELETE", "PATCH"):
        assert refusal(method, headers) == Refusal(
            415, "a write must send application/json or be signed with AWS SigV4"
        )


def test_an_authorization_that_is_not_sigv4_does_not_stand_for_json() -> None:
    headers = {"Host": "127.0.0.1:8180", "Authorization": "Basic dXNlcjpwYXNz"}
    assert refusal("POST", headers) is not None


def test_host_names_and_json_kinds() -> None:
    assert host_name("127.0.0.1:8180") == "127.0.0.1"
    assert host_name("[::1]:8180") == "::1"
    assert host_name("LocalHost") == "localhost"
    assert is_json("application/json; charset=utf-8")
    assert is_json("application/x-amz-json-1.1")
    assert is_json("application/merge-patch+json")
    assert not is_json("text/json")
    assert not is_json(None)
