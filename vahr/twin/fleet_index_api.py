"""The IoT control plane's fleet-indexing calls, answered from the local fleet index.

boto3's `iot` client, pointed at the local data plane (`endpoint_url=` or
`AWS_ENDPOINT_URL_IOT`), sends these; the answers have the shapes of botocore's service
model, so the same client code runs against AWS and against `vahr up`:

| call | request | answer |
| --- | --- | --- |
| `search_index` | `POST /indices/search` | `{"things": [ThingDocument], "nextToken"?}` |
| `get_buckets_aggregation` | `POST /indices/buckets` | `{"totalCount", "buckets": [...]}` |
| `get_statistics` | `POST /indices/statistics` | `{"statistics": {"count"}}` |
| `describe_index` | `GET /indices/AWS_Things` | `{"indexName", "indexStatus", "schema"}` |

The only index is `AWS_Things` (AWS's name for thing indexing). A query the index cannot
answer is AWS's `InvalidQueryException` (400) with a one-line message; an aggregation
field it does not keep is `InvalidAggregationException`; another index name is
`ResourceNotFoundException`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import msgspec

from vahr.twin.fleet_index import AggregationError, FleetIndex, IndexedThing
from vahr.twin.fleet_query import QueryError

if TYPE_CHECKING:
    from collections.abc import Mapping

INDEX_NAME = "AWS_Things"
# AWS: "This maximum number cannot exceed 100" (SearchIndex maxResults).
SEARCH_PAGE_MAX = 100
BUCKETS_DEFAULT = 10  # AWS's default for termsAggregation.maxBuckets
BUCKETS_MAX = 10_000

Answer = tuple[int, bytes, str | None]


class _RequestError(Exception):
    def __init__(self, status: int, error_type: str, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.error_type = error_type
        self.message = message


class _Terms(msgspec.Struct):
    maxBuckets: int = BUCKETS_DEFAULT  # noqa: N815 - AWS's field name


class _AggregationType(msgspec.Struct):
    termsAggregation: _Terms | None = None  # noqa: N815


class _Search(msgspec.Struct):
    queryString: str  # noqa: N815
    indexName: str = INDEX_NAME  # noqa: N815
    nextToken: str | None = None  # noqa: N815
    maxResults: int = SEARCH_PAGE_MAX  # noqa: N815
    queryVersion: str | None = None  # noqa: N815


class _Buckets(msgspec.Struct):
    queryString: str  # noqa: N815
    aggregationField: str  # noqa: N815
    bucketsAggregationType: _AggregationType  # noqa: N815
    indexName: str = INDEX_NAME  # noqa: N815
    queryVersion: str | None = None  # noqa: N815


class _Statistics(msgspec.Struct):
    queryString: str  # noqa: N815
    indexName: str = INDEX_NAME  # noqa: N815
    aggregationField: str | None = None  # noqa: N815
    queryVersion: str | None = None  # noqa: N815


def _decode(body: bytes, kind: type[Any]) -> Any:
    try:
        return msgspec.json.decode(body or b"{}", type=kind)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise _RequestError(400, "InvalidRequestException", str(err)) from None


def _check_index(name: str) -> None:
    if name != INDEX_NAME:
        raise _RequestError(404, "ResourceNotFoundException", f"Index {name} does not exist")


def thing_document(entry: IndexedThing) -> dict[str, Any]:
    """A ThingDocument as SearchIndex returns it: the shadow as a JSON string."""
    shadow = {"reported": entry.reported, "version": entry.version, "hasDelta": False}
    return {
        "thingName": entry.thing,
        "thingId": entry.thing,
        "thingGroupNames": [],
        "attributes": {},
        "shadow": msgspec.json.encode(shadow).decode(),
        "connectivity": {"connected": entry.connected, "timestamp": entry.connected_since * 1000},
    }


class FleetIndexApi:
    """Answer the fleet-indexing routes under `/indices` from one `FleetIndex`."""

    def __init__(self, index: FleetIndex) -> None:
        self.index = index

    def respond(
        self, method: str, path: str, body: bytes, headers: Mapping[str, str] | None = None
    ) -> Answer:
        """(status, JSON body, AWS error type or None) for a request under /indices (its
        headers say nothing these calls need)."""
        try:
            return 200, msgspec.json.encode(self._route(method, path, body)), None
        except _RequestError as err:
            return _error(err.status, err.error_type, err.message)
        except AggregationError as err:
            return _error(400, "InvalidAggregationException", str(err))
        except QueryError as err:
            return _error(400, "InvalidQueryException", str(err))

    def _route(self, method: str, path: str, body: bytes) -> dict[str, Any]:
        routes = {
            "/indices/search": self._search,
            "/indices/buckets": self._buckets,
            "/indices/statistics": self._statistics,
        }
        if method == "POST" and path in routes:
            return routes[path](body)
        if method == "GET" and path.startswith("/indices/") and path.count("/") == 2:
            _check_index(path.rsplit("/", 1)[1])
            return {
                "indexName": INDEX_NAME,
                "indexStatus": "ACTIVE",
                "schema": "REGISTRY_AND_SHADOW_AND_CONNECTIVITY_STATUS",
            }
        raise _RequestError(404, "ResourceNotFoundException", f"No route for {method} {path}")

    def _search(self, body: bytes) -> dict[str, Any]:
        request: _Search = _decode(body, _Search)
        _check_index(request.indexName)
        if not 1 <= request.maxResults <= SEARCH_PAGE_MAX:
            raise _RequestError(
                400, "InvalidRequestException", f"maxResults must be 1 to {SEARCH_PAGE_MAX}"
            )
        try:
            start = int(request.nextToken or "0")
        except ValueError:
            raise _RequestError(400, "InvalidRequestException", "Invalid nextToken") from None
        found = self.index.search(request.queryString)
        page = found[start : start + request.maxResults]
        answer: dict[str, Any] = {"things": [thing_document(entry) for entry in page]}
        if start + request.maxResults < len(found):
            answer["nextToken"] = str(start + request.maxResults)
        return answer

    def _buckets(self, body: bytes) -> dict[str, Any]:
        request: _Buckets = _decode(body, _Buckets)
        _check_index(request.indexName)
        terms = request.bucketsAggregationType.termsAggregation or _Terms()
        if not 1 <= terms.maxBuckets <= BUCKETS_MAX:
            raise _RequestError(
                400, "InvalidRequestException", f"maxBuckets must be 1 to {BUCKETS_MAX}"
            )
        total, buckets = self.index.buckets(
            request.queryString, request.aggregationField, terms.maxBuckets
        )
        return {
            "totalCount": total,
            "buckets": [{"keyValue": value, "count": count} for value, count in buckets],
        }

    def _statistics(self, body: bytes) -> dict[str, Any]:
        request: _Statistics = _decode(body, _Statistics)
        _check_index(request.indexName)
        count = self.index.statistics(request.queryString, request.aggregationField)
        return {"statistics": {"count": count}}


def _error(status: int, error_type: str, message: str) -> Answer:
    return status, msgspec.json.encode({"message": message}), error_type
