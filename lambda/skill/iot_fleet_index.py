"""The FleetIndex port and its boto3 `iot` adapter: questions about the whole fleet answered
by AWS IoT fleet indexing, without reading every robot's shadow.

`IotFleetIndex` asks `get_buckets_aggregation` for the counts by reported status,
`get_statistics` for how many robots are offline and `search_index` for the few robots a
summary names. On AWS these need thing indexing with the classic shadow and the custom
fields `shadow.reported.status`, `shadow.reported.zone` (String) and
`shadow.reported.connected` (Boolean); on the local stack the data plane answers the same
calls from its own index. The client goes to `SkillConfig.index_endpoint` (boto3's own
IoT endpoint on AWS). Library errors become `GatewayError` here and nowhere else.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

import boto3
import msgspec
from botocore.exceptions import BotoCoreError, ClientError, NoRegionError

from skill.errors import GatewayError
from skill.iot_data import CLIENT_CONFIG
from vahr.protocol import Reported
from vahr.protocol.decoding import LazyDecoder

if TYPE_CHECKING:
    from skill.config import SkillConfig

INDEX_NAME = "AWS_Things"
STATUS_FIELD = "shadow.reported.status"
# The charge, a Number custom field (searched by range), and whether it charges.
BATTERY_PERCENT_FIELD = "shadow.reported.battery.percent"
BATTERY_CHARGING_FIELD = "shadow.reported.battery.charging"
# AWS's page limit for search_index.
SEARCH_MAX = 100
# Every reported status has a bucket (there are eight; room for statuses added later).
STATUS_BUCKETS = 20


class IndexedRobot(msgspec.Struct, frozen=True):
    """A robot as the index returns it: its name and its reported state."""

    thing: str
    reported: Reported


class FleetIndex(Protocol):
    """What the skill asks the fleet index. Every method raises `GatewayError` on failure."""

    def status_counts(self) -> dict[str, int]:
        """How many robots report each status."""

    def count(self, query: str) -> int:
        """How many things match a fleet-indexing query."""

    def search(self, query: str, limit: int) -> list[IndexedRobot]:
        """At most `limit` robots matching the query, by thing name."""


class _Shadow(msgspec.Struct):
    reported: dict[str, Any] = {}


_shadow_decoder: LazyDecoder[_Shadow] = LazyDecoder(_Shadow)


def _robot(document: dict[str, Any]) -> IndexedRobot:
    """A search result's ThingDocument; a state breaking the contract keeps what it can."""
    thing = str(document.get("thingName", ""))
    try:
        fields = _shadow_decoder.decode(document.get("shadow") or "{}").reported
    except (msgspec.DecodeError, msgspec.ValidationError):
        fields = {}
    try:
        reported = msgspec.convert(fields, Reported)
    except msgspec.ValidationError:
        reported = Reported(connected=fields.get("connected") is True)
    return IndexedRobot(thing=thing, reported=reported)


class IotFleetIndex:
    """FleetIndex over boto3's `iot` client (thread-safe, as boto3 clients are)."""

    def __init__(self, client: Any) -> None:
        self._client = client

    @classmethod
    def from_config(cls, config: SkillConfig) -> IotFleetIndex:
        endpoint = config.index_endpoint
        try:
            client = boto3.client("iot", endpoint_url=endpoint, config=CLIENT_CONFIG)
        except NoRegionError:
            # A local data plane ignores the region, but SigV4 signing needs one.
            client = boto3.client(
                "iot",
                endpoint_url=endpoint,
                region_name=config.fallback_region,
                config=CLIENT_CONFIG,
            )
        return cls(client)

    def status_counts(self) -> dict[str, int]:
        answer = self._call(
            "counting the robots by status",
            self._client.get_buckets_aggregation,
            indexName=INDEX_NAME,
            queryString="thingName:*",
            aggregationField=STATUS_FIELD,
            bucketsAggregationType={"termsAggregation": {"maxBuckets": STATUS_BUCKETS}},
        )
        return {bucket["keyValue"]: int(bucket["count"]) for bucket in answer["buckets"]}

    def count(self, query: str) -> int:
        answer = self._call(
            "counting robots", self._client.get_statistics, indexName=INDEX_NAME, queryString=query
        )
        return int(answer["statistics"]["count"])

    def search(self, query: str, limit: int) -> list[IndexedRobot]:
        """Page by page (at most `SEARCH_MAX` a call) until `limit` robots or the end."""
        found: list[IndexedRobot] = []
        token: str | None = None
        while len(found) < limit:
            page: dict[str, Any] = {"nextToken": token} if token else {}
            answer = self._call(
                "searching the fleet",
                self._client.search_index,
                indexName=INDEX_NAME,
                queryString=query,
                maxResults=max(1, min(limit - len(found), SEARCH_MAX)),
                **page,
            )
            found += [_robot(document) for document in answer.get("things", [])]
            token = answer.get("nextToken")
            if not token:
                break
        return found[:limit]

    @staticmethod
    def _call(what: str, call: Any, **arguments: Any) -> Any:
        try:
            return call(**arguments)
        except (ClientError, BotoCoreError) as err:
            if isinstance(err, ClientError):
                error = err.response.get("Error", {})
                detail = f"{error.get('Code', '')} {error.get('Message', '')}".strip()
            else:
                detail = str(err)
            raise GatewayError(f"{what} failed: {detail}") from err
