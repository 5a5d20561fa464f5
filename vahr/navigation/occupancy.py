"""A ROS map as VAHR reads it: map_server's YAML and image, to a grid of drivable cells.

The YAML is map_server's (ROS 1 `map_server`, ROS 2 `nav2_map_server`): `image` (PGM or
PNG, relative to the YAML), `resolution` (metres a cell), `origin` (`[x, y, yaw]`, the pose
of the image's lower-left pixel in the map frame), `negate`, `occupied_thresh`,
`free_thresh` and `mode`. Each pixel's shade (the mean of its colour channels, 0 to 255) is
read as map_server reads it:

- `trinary` (the default): occupancy p = (255 - shade) / 255, or shade / 255 with
  `negate`; occupied when p > occupied_thresh, free when p < free_thresh, else unknown.
- `scale`: as trinary, except that a cell between the thresholds is free (map_server
  writes a cost between 1 and 99 there, which Nav2's static layer with its default
  `trinary_costmap` reads as free space), and a fully transparent pixel is unknown.
- `raw`: the shade is the occupancy in percent: 100 occupied, above 100 unknown, below it
  free (the thresholds are not used, as in map_server).

A robot drives only on free cells: unknown space is not driven through. Pillow reads the
image. Rows are kept bottom first, so cell (row, column) has its centre at
`origin + ((column + 0.5), (row + 0.5)) * resolution`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import msgspec
import numpy as np

from vahr.errors import VahrError

if TYPE_CHECKING:
    import os


class MapError(VahrError):
    """A map that cannot be used, in one line naming the file and what is wrong."""


MapMode = Literal["trinary", "scale", "raw"]


class MapFile(msgspec.Struct, frozen=True, kw_only=True):
    """map_server's YAML. Keys it does not know are ignored, as map_server ignores them."""

    image: Annotated[str, msgspec.Meta(min_length=1)]
    resolution: Annotated[float, msgspec.Meta(gt=0)]
    origin: Annotated[list[float], msgspec.Meta(min_length=3, max_length=3)]
    occupied_thresh: float
    free_thresh: float
    negate: bool | Literal[0, 1] = 0
    mode: MapMode = "trinary"


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A map read: which cells are free, occupied or unknown, and where they lie.

    `free` and `occupied` are boolean arrays of `rows` x `columns`, row 0 at the bottom
    (the map frame's lowest y); a cell neither free nor occupied is unknown. `image` is the
    file the shades came from (the station serves a picture of it).
    """

    free: np.ndarray
    occupied: np.ndarray
    resolution: float
    origin_x: float
    origin_y: float
    source: Path
    image: Path
    mode: MapMode

    @property
    def rows(self) -> int:
        return int(self.free.shape[0])

    @property
    def columns(self) -> int:
        return int(self.free.shape[1])

    @property
    def width(self) -> float:
        """The map's extent along x, in metres."""
        return self.columns * self.resolution

    @property
    def height(self) -> float:
        return self.rows * self.resolution

    def cell(self, x: float, y: float) -> tuple[int, int] | None:
        """The (row, column) holding the point, None off the map."""
        column = math.floor((x - self.origin_x) / self.resolution)
        row = math.floor((y - self.origin_y) / self.resolution)
        if 0 <= row < self.rows and 0 <= column < self.columns:
            return row, column
        return None

    def centre(self, row: int, column: int) -> tuple[float, float]:
        """The map-frame point at the centre of a cell."""
        return (
            self.origin_x + (column + 0.5) * self.resolution,
            self.origin_y + (row + 0.5) * self.resolution,
        )

    def extent(self) -> str:
        """The map's rectangle in words, for errors: `x -10 to 9.2, y -10 to 9.2`."""
        x, y = self.origin_x, self.origin_y
        return f"x {x:g} to {x + self.width:g}, y {y:g} to {y + self.height:g}"


def load_map(path: str | os.PathLike[str]) -> OccupancyGrid:
    """Read a map_server YAML and its image; MapError in one line for anything unusable."""
    source = Path(path)
    try:
        text = source.read_bytes()
    except OSError as err:
        raise MapError(f"map {source}: cannot read it ({err.strerror})") from err
    try:
        spec = msgspec.yaml.decode(text, type=MapFile)
    except msgspec.ValidationError as err:
        raise MapError(f"map {source}: {_field_reason(err)}") from err
    except msgspec.DecodeError as err:
        raise MapError(f"map {source}: is not a map_server YAML ({_one_line(err)})") from err
    _check_spec(source, spec)
    image = (source.parent / spec.image).resolve()
    shade, transparent = _read_shades(source, image)
    occupied, free = _classify(spec, shade, transparent)
    # Image row 0 is the top of the map; the grid keeps the bottom row first.
    return OccupancyGrid(
        free=np.ascontiguousarray(np.flipud(free)),
        occupied=np.ascontiguousarray(np.flipud(occupied)),
        resolution=float(spec.resolution),
        origin_x=float(spec.origin[0]),
        origin_y=float(spec.origin[1]),
        source=source.resolve(),
        image=image,
        mode=spec.mode,
    )


def _check_spec(source: Path, spec: MapFile) -> None:
    for name in ("resolution", "occupied_thresh", "free_thresh"):
        if not math.isfinite(getattr(spec, name)):
            raise MapError(f"map {source}: {name} is not a finite number")
    if not all(math.isfinite(value) for value in spec.origin):
        raise MapError(f"map {source}: origin holds a value that is not a finite number")
    for name in ("occupied_thresh", "free_thresh"):
        value = getattr(spec, name)
        if not 0.0 <= value <= 1.0:
            raise MapError(f"map {source}: {name} {value:g} must be between 0 and 1")
    if spec.mode != "raw" and spec.free_thresh >= spec.occupied_thresh:
        raise MapError(
            f"map {source}: free_thresh {spec.free_thresh:g} must be below occupied_thresh "
            f"{spec.occupied_thresh:g}"
        )
    if abs(spec.origin[2]) > 1e-9:
        raise MapError(
            f"map {source}: origin yaw {spec.origin[2]:g} is not supported; VAHR plans and "
            "draws in the map's own axes (yaw 0)"
        )


def _read_shades(source: Path, image: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Each pixel's shade (0-255, the mean of its colour channels) and, where the image has
    an alpha channel, which pixels are fully transparent."""
    # Pillow is imported here: only a fleet with a map needs it.
    from PIL import Image, UnidentifiedImageError

    if not image.is_file():
        raise MapError(f"map {source}: image {image.name}: no such file (looked at {image})")
    try:
        with Image.open(image) as opened:
            opened.load()
            picture = opened.copy()
    except (UnidentifiedImageError, OSError, ValueError) as err:
        raise MapError(
            f"map {source}: image {image.name} is not a PGM or PNG image Pillow can read "
            f"({_one_line(err)})"
        ) from err
    if picture.mode == "P":
        picture = picture.convert("RGBA")
    elif picture.mode == "1":
        picture = picture.convert("L")
    pixels = np.asarray(picture)
    transparent = None
    if picture.mode in ("I", "I;16", "I;16B", "I;16L", "F"):
        # A 16-bit grey image: map_server scales it to the same 0..1 shade.
        top = 65535.0 if pixels.max(initial=0) > 255 else 255.0
        return pixels.astype(np.float32) * (255.0 / top), None
    if pixels.ndim == 2:
        return pixels.astype(np.float32), None
    bands = picture.getbands()
    if "A" in bands:
        transparent = pixels[..., bands.index("A")] == 0
        colour = [index for index, band in enumerate(bands) if band != "A"]
        pixels = pixels[..., colour]
    return pixels.astype(np.float32).mean(axis=2), transparent


def _classify(
    spec: MapFile, shade: np.ndarray, transparent: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """(occupied, free) as map_server and Nav2's static layer read the shades."""
    if spec.mode == "raw":
        percent = np.rint(shade)
        return percent == 100, percent < 100
    occupancy = shade / 255.0 if spec.negate else (255.0 - shade) / 255.0
    occupied = occupancy > spec.occupied_thresh
    if spec.mode == "scale":
        free = ~occupied
        if transparent is not None:
            occupied &= ~transparent
            free &= ~transparent
        return occupied, free
    return occupied, occupancy < spec.free_thresh


def _field_reason(err: msgspec.ValidationError) -> str:
    """msgspec's message as `field: reason`."""
    message = str(err)
    if " - at `$." in message:
        reason, _, path = message.partition(" - at `$.")
        return f"{path.rstrip('`')}: {reason[0].lower()}{reason[1:]}"
    if message.startswith("Object missing required field `"):
        name = message.split("`")[1]
        return f"{name}: is required"
    return _one_line(message)


def _one_line(err: object) -> str:
    return " ".join(str(err).split())
