"""Device shadow documents with AWS IoT's semantics, free of any transport.

`ShadowStore` implements what the AWS IoT Device Shadow service does with a request:
update (merge, `null` deletes, versions and optimistic locking, per-key metadata, delta),
get, delete and list of named shadows, with AWS's error codes, messages and limits. The
MQTT adapter (`shadow_service`) and the HTTP data plane (`dataplane`) both call it, so the
two paths cannot drift. Documents persist in SQLite and survive restarts.

Every change of a classic shadow is also recorded in the store's `FleetIndex` (`index`),
so fleet queries see what the shadows hold, by either path, at once.
"""

from __future__ import annotations

import json
import sqlite3
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.twin.fleet_index import FleetIndex

if TYPE_CHECKING:
    from collections.abc import Callable

MAX_REQUEST_BYTES = 8 * 1024
MAX_STATE_BYTES = 8 * 1024
MAX_DEPTH = 6
# A local bound on objects and arrays together (AWS states none for arrays): the merge and
# metadata stamping recurse, and a document nested thousands deep must be refused, not crash.
MAX_NESTING = 32
MAX_CLIENT_TOKEN_BYTES = 64
SECTIONS = ("desired", "reported")

Json = dict[str, Any]


class ShadowError(Exception):
    """A rejected request: AWS's HTTP-style code and message (the `*/rejected` payload)."""

    def __init__(self, code: int, message: str, client_token: str | None = None) -> None:
        super().__init__(f"{code} {message}")
        self.code = code
        self.message = message
        self.client_token = client_token

    def payload(self, timestamp: int) -> Json:
        body: Json = {"code": self.code, "message": self.message, "timestamp": timestamp}
        if self.client_token is not None:
            body["clientToken"] = self.client_token
        return body


def not_found(thing: str, name: str | None) -> ShadowError:
    return ShadowError(404, f"No shadow exists with name: '{name or thing}'")


@dataclass(frozen=True)
class UpdateResult:
    """What an accepted update publishes: `accepted`, `delta` (if any) and `documents`.

    Read-only: `documents` shares the stored documents (copying them for every update
    cost more than the rest of the update)."""

    accepted: Json
    delta: Json | None
    documents: Json


@dataclass(frozen=True)
class _Stored:
    state: Json
    metadata: Json
    version: int
    exists: bool


def _view(stored: _Stored) -> Json:
    return {"state": stored.state, "metadata": stored.metadata, "version": stored.version}


def _reported(stored: _Stored) -> Json:
    reported = stored.state.get("reported")
    return reported if isinstance(reported, dict) else {}


def _decode(data: str | bytes) -> Json:
    decoded: Json = msgspec.json.decode(data)
    return decoded


def _depth(value: Any) -> tuple[int, int]:
    """(levels of objects, levels of objects and arrays) in `value`. AWS's limit counts
    objects; the second bounds what the store's recursive merge may meet. Iterative: a
    hostile document may be nested deeper than Python's recursion limit."""
    deepest, nesting, pending = 0, 0, [(value, 0, 0)]
    while pending:
        item, objects, levels = pending.pop()
        if isinstance(item, dict):
            deepest, nesting = max(deepest, objects + 1), max(nesting, levels + 1)
            pending.extend((inner, objects + 1, levels + 1) for inner in item.values())
        elif isinstance(item, list):
            nesting = max(nesting, levels + 1)
            pending.extend((inner, objects, levels + 1) for inner in item)
    return deepest, nesting


def _stamp(value: Any, timestamp: int) -> Any:
    """Metadata for a value: a timestamp per leaf, mirroring objects and arrays."""
    if isinstance(value, dict):
        return {k: _stamp(v, timestamp) for k, v in value.items()}
    if isinstance(value, list):
        return [_stamp(v, timestamp) for v in value]
    return {"timestamp": timestamp}


def _merge(state: Json, metadata: Json, update: Json, timestamp: int) -> tuple[Json, Json]:
    """Merge `update` into one section; `null` deletes; only touched keys are restamped."""
    state, metadata = dict(state), dict(metadata)
    for key, value in update.items():
        if value is None:
            state.pop(key, None)
            metadata.pop(key, None)
        elif isinstance(value, dict) and isinstance(state.get(key), dict):
            old_meta = metadata.get(key)
            merged, merged_meta = _merge(
                state[key], old_meta if isinstance(old_meta, dict) else {}, value, timestamp
            )
            if merged:
                state[key], metadata[key] = merged, merged_meta
            else:
                state.pop(key, None)
                metadata.pop(key, None)
        else:
            cleaned = _without_nulls(value)
            if cleaned == {}:
                state.pop(key, None)
                metadata.pop(key, None)
                continue
            state[key] = cleaned
            metadata[key] = _stamp(cleaned, timestamp)
    return state, metadata


def _without_nulls(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _without_nulls(v) for k, v in value.items() if v is not None}
    return value


def delta_of(desired: Json, reported: Json) -> Json:
    """The desired keys whose values differ from reported (objects compared key by key)."""
    delta: Json = {}
    for key, want in desired.items():
        have = reported.get(key)
        if isinstance(want, dict) and isinstance(have, dict):
            inner = delta_of(want, have)
            if inner:
                delta[key] = inner
        elif want != have:
            delta[key] = want
    return delta


def _metadata_for(delta: Json, metadata: Json) -> Json:
    """The slice of `metadata` that covers the keys of `delta`."""
    out: Json = {}
    for key, value in delta.items():
        meta = metadata.get(key)
        if isinstance(value, dict) and isinstance(meta, dict):
            out[key] = _metadata_for(value, meta)
        elif meta is not None:
            out[key] = meta
    return out


def _decode_request(payload: bytes, *, required_state: bool) -> Json:
    if len(payload) > MAX_REQUEST_BYTES:
        raise ShadowError(413, "The payload exceeds the maximum size allowed")
    try:
        text = payload.decode("utf-8")
    except UnicodeDecodeError:
        raise ShadowError(
            415, "Unsupported documented encoding; supported encoding is UTF-8"
        ) from None
    if not text.strip() and not required_state:
        return {}
    try:
        request = json.loads(text)
    except ValueError:
        raise ShadowError(400, "Invalid JSON") from None
    except RecursionError:
        # Deeper than the parser goes, so far deeper than AWS's limit of MAX_DEPTH.
        raise ShadowError(
            400, f"JSON contains too many levels of nesting; maximum is {MAX_DEPTH}"
        ) from None
    if not isinstance(request, dict):
        raise ShadowError(400, "Invalid JSON")
    token = request.get("clientToken")
    if token is not None and (
        not isinstance(token, str) or len(token.encode("utf-8")) > MAX_CLIENT_TOKEN_BYTES
    ):
        raise ShadowError(400, "Invalid clientToken")
    if "version" in request and (
        not isinstance(request["version"], int) or isinstance(request["version"], bool)
    ):
        raise ShadowError(400, "Invalid version", token)
    return request


class ShadowStore:
    """Classic and named shadows of any thing, persisted in SQLite (or in memory).

    Every document lives in memory and is written to SQLite by `commit()`, one transaction
    for all the changes since the last one. An operation called with `commit=True` (the
    default) commits before it returns; the MQTT shadow service passes `commit=False` for
    a burst of requests, commits once, and only then publishes the answers, so an accepted
    update is on disk before anyone hears of it (group commit).
    """

    def __init__(
        self, database: Path | None = None, *, clock: Callable[[], float] = time.time
    ) -> None:
        self._clock = clock
        # Guards the documents in memory; never held while SQLite works.
        self._lock = threading.Lock()
        # Serializes commits, so a later commit can never be overtaken by an earlier one.
        self._commit_lock = threading.Lock()
        target = ":memory:" if database is None else str(database)
        if database is not None:
            Path(database).parent.mkdir(parents=True, exist_ok=True)
        # Only `commit` (under `_commit_lock`) touches the connection after the start.
        self._db = sqlite3.connect(target, check_same_thread=False, isolation_level=None)
        self._db.execute("PRAGMA journal_mode=WAL")
        # With WAL, NORMAL survives a crash of this process (only an OS crash or power loss
        # can lose the last commits) and skips an fsync per commit.
        self._db.execute("PRAGMA synchronous=NORMAL")
        self._db.execute(
            "CREATE TABLE IF NOT EXISTS shadows (thing TEXT NOT NULL, name TEXT NOT NULL,"
            " state TEXT NOT NULL, metadata TEXT NOT NULL, version INTEGER NOT NULL,"
            " present INTEGER NOT NULL, PRIMARY KEY (thing, name))"
        )
        # Every document is read once, here, and then served from memory: an update costs
        # no SELECT, and reads never wait for a commit (10,000 shadows load in well under a
        # second).
        self._cache: dict[tuple[str, str], _Stored] = {
            (thing, name): _Stored(_decode(state), _decode(metadata), version, bool(present))
            for thing, name, state, metadata, version, present in self._db.execute(
                "SELECT thing, name, state, metadata, version, present FROM shadows"
            )
        }
        # Changed since the last commit, in order of change.
        self._dirty: dict[tuple[str, str], _Stored] = {}
        self.index = FleetIndex()
        loaded_at = self.now()
        for (thing, name), stored in self._cache.items():
            if not name and stored.exists:
                self.index.record(thing, _reported(stored), stored.version, loaded_at)

    def close(self) -> None:
        with self._commit_lock:
            self._write_dirty()
            self._db.close()

    def now(self) -> int:
        return int(self._clock())

    def commit(self) -> int:
        """Write every change not yet on disk in one transaction; returns how many."""
        with self._commit_lock:
            return self._write_dirty()

    def _write_dirty(self) -> int:
        with self._lock:
            dirty, self._dirty = self._dirty, {}
        if not dirty:
            return 0
        encode = msgspec.json.encode
        rows = [
            (
                thing,
                name,
                encode(stored.state).decode(),
                encode(stored.metadata).decode(),
                stored.version,
                int(stored.exists),
            )
            for (thing, name), stored in dirty.items()
        ]
        # One transaction (the connection is in autocommit mode otherwise).
        self._db.execute("BEGIN")
        try:
            self._db.executemany(
                "INSERT INTO shadows (thing, name, state, metadata, version, present)"
                " VALUES (?, ?, ?, ?, ?, ?) ON CONFLICT (thing, name) DO UPDATE SET"
                " state=excluded.state, metadata=excluded.metadata, version=excluded.version,"
                " present=excluded.present",
                rows,
            )
            self._db.execute("COMMIT")
        except BaseException:
            self._db.execute("ROLLBACK")
            with self._lock:
                # Not written: keep what changed since for the next commit, else these.
                self._dirty = {**dirty, **self._dirty}
            raise
        return len(rows)

    def _load(self, thing: str, name: str | None) -> _Stored:
        return self._cache.get((thing, name or "")) or _Stored({}, {}, 0, False)

    def _save(self, thing: str, name: str | None, stored: _Stored) -> None:
        # Stored documents are never changed in place (updates build new dicts), so the
        # one in memory can be written later and shared with the answers meanwhile.
        key = (thing, name or "")
        self._cache[key] = stored
        self._dirty[key] = stored
        if not name:
            reported = _reported(stored) if stored.exists else None
            self.index.record(thing, reported, stored.version, self.now())

    # -- operations -------------------------------------------------------------------

    def get(self, thing: str, name: str | None = None, payload: bytes = b"") -> Json:
        """The whole document (`get/accepted`, GetThingShadow), with `delta` when any."""
        token = _decode_request(payload, required_state=False).get("clientToken")
        with self._lock:
            stored = self._load(thing, name)
        if not stored.exists:
            error = not_found(thing, name)
            error.client_token = token
            raise error
        document = self._document(stored)
        delta = delta_of(stored.state.get("desired", {}), stored.state.get("reported", {}))
        if delta:
            document["state"]["delta"] = delta
        document["timestamp"] = self.now()
        if token is not None:
            document["clientToken"] = token
        return document

    def update(
        self, thing: str, name: str | None, payload: bytes, *, commit: bool = True
    ) -> UpdateResult:
        """Merge the request into the shadow (see the module docstring); with
        `commit=False` the change waits for the caller's `commit()`."""
        request = _decode_request(payload, required_state=True)
        token = request.get("clientToken")
        if "state" not in request:
            raise ShadowError(400, "Missing required node: state", token)
        state = request["state"]
        if not isinstance(state, dict):
            raise ShadowError(400, "State node must be an object", token)
        for key, section in state.items():
            if key not in SECTIONS:
                raise ShadowError(400, "State contains an invalid node", token)
            if section is not None and not isinstance(section, dict):
                raise ShadowError(400, f"{key.capitalize()} node must be an object", token)
            objects, nesting = _depth(section) if section is not None else (0, 0)
            if objects > MAX_DEPTH:
                raise ShadowError(
                    400, f"JSON contains too many levels of nesting; maximum is {MAX_DEPTH}", token
                )
            if nesting > MAX_NESTING:
                raise ShadowError(
                    400, f"JSON nests arrays too deeply; maximum is {MAX_NESTING} levels", token
                )
        now = self.now()
        with self._lock:
            before = self._load(thing, name)
            if "version" in request and request["version"] != before.version:
                raise ShadowError(409, "Version conflict", token)
            new_state = dict(before.state) if before.exists else {}
            new_meta = dict(before.metadata) if before.exists else {}
            for key, section in state.items():
                if section is None:
                    # `"desired": null` clears the whole section.
                    new_state.pop(key, None)
                    new_meta.pop(key, None)
                    continue
                merged, merged_meta = _merge(
                    new_state.get(key, {}), new_meta.get(key, {}), section, now
                )
                if merged:
                    new_state[key], new_meta[key] = merged, merged_meta
                else:
                    new_state.pop(key, None)
                    new_meta.pop(key, None)
            if len(msgspec.json.encode(new_state)) > MAX_STATE_BYTES:
                raise ShadowError(413, "The payload exceeds the maximum size allowed", token)
            after = _Stored(new_state, new_meta, before.version + 1, True)
            self._save(thing, name, after)
        if commit:
            self.commit()
        accepted: Json = {
            "state": state,
            "metadata": {key: _stamp(section, now) for key, section in state.items()},
            "version": after.version,
            "timestamp": now,
        }
        delta = None
        if isinstance(state.get("desired"), dict):
            changed = delta_of(new_state.get("desired", {}), new_state.get("reported", {}))
            if changed:
                delta = {
                    "state": changed,
                    "metadata": _metadata_for(changed, new_meta.get("desired", {})),
                    "version": after.version,
                    "timestamp": now,
                }
        # The stored documents themselves, not copies: `UpdateResult` is read-only.
        previous = _view(before) if before.exists else None
        documents: Json = {"current": _view(after), "timestamp": now}
        if previous is not None:
            documents = {"previous": previous, **documents}
        if token is not None:
            for body in (accepted, delta, documents):
                if body is not None:
                    body["clientToken"] = token
        return UpdateResult(accepted=accepted, delta=delta, documents=documents)

    def delete(
        self, thing: str, name: str | None = None, payload: bytes = b"", *, commit: bool = True
    ) -> Json:
        """Delete a shadow; its version number carries on if it is created again."""
        token = _decode_request(payload, required_state=False).get("clientToken")
        with self._lock:
            stored = self._load(thing, name)
            if not stored.exists:
                error = not_found(thing, name)
                error.client_token = token
                raise error
            self._save(thing, name, _Stored({}, {}, stored.version, False))
        if commit:
            self.commit()
        body: Json = {"version": stored.version, "timestamp": self.now()}
        if token is not None:
            body["clientToken"] = token
        return body

    def list_named(self, thing: str) -> list[str]:
        """Names of the named shadows of `thing` that exist, sorted."""
        with self._lock:
            return sorted(
                name
                for (owner, name), stored in self._cache.items()
                if owner == thing and name and stored.exists
            )

    @staticmethod
    def _document(stored: _Stored) -> Json:
        return {
            # Copies: callers may change what they are given; the cache must not change.
            "state": _decode(msgspec.json.encode(stored.state)),
            "metadata": _decode(msgspec.json.encode(stored.metadata)),
            "version": stored.version,
        }
