"""Write a robot's credential bundle: private files (0600) in a private directory (0700)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import yaml

from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path


@dataclass(frozen=True)
class Bundle:
    """What `robot-agent provision` wrote; `config` is ready for `robot-agent run --config`."""

    thing: str
    cert: Path
    key: Path
    ca: Path | None
    config: Path
    endpoint: str
    port: int
    note: str | None = None
    # The id of the certificate this one replaced and deactivated (`--aws --force`).
    replaced: str | None = None

    def to_json(self) -> dict[str, Any]:
        return {
            "thing": self.thing,
            "cert": str(self.cert),
            "key": str(self.key),
            "ca": str(self.ca) if self.ca else None,
            "config": str(self.config),
            "endpoint": self.endpoint,
            "port": self.port,
            "note": self.note,
            "replaced": self.replaced,
        }


def prepare_out_dir(out_dir: Path, names: tuple[str, ...], *, force: bool) -> None:
    """Create `out_dir` (0700); refuse to overwrite the files `names` unless `force`."""
    existing = [name for name in names if (out_dir / name).exists()]
    if existing and not force:
        raise VahrError(
            f"{out_dir} already holds {', '.join(existing)}; pass --force to replace them "
            "(with --aws, the old certificate is then deactivated)"
        )
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        out_dir.chmod(0o700)
    except OSError as err:
        raise VahrError(f"cannot make the directory {out_dir}: {err.strerror or err}") from err


def write_private(path: Path, content: str | bytes) -> Path:
    """Write `content` so that only the owner can ever read it (no window at 0644)."""
    data = content.encode() if isinstance(content, str) else content
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC
    descriptor = os.open(path, flags, 0o600)
    with os.fdopen(descriptor, "wb") as stream:
        stream.write(data)
    path.chmod(0o600)
    return path


def write_config(
    out_dir: Path, *, thing: str, endpoint: str, port: int, cert: Path, key: Path, ca: Path | None
) -> Path:
    settings: dict[str, Any] = {
        "thing": thing,
        "endpoint": endpoint,
        "port": port,
        "cert": str(cert.resolve()),
        "key": str(key.resolve()),
    }
    if ca is not None:
        settings["ca"] = str(ca.resolve())
    header = "# robot-agent run --config this-file  (written by robot-agent provision)\n"
    return write_private(out_dir / "agent.yaml", header + yaml.safe_dump(settings, sort_keys=False))
