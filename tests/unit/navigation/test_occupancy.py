"""A ROS map read as map_server reads it: the image's row 0 is the map's top and `origin` the
lower-left pixel's pose; occupancy p = (255 - shade) / 255 (shade / 255 with `negate`);
occupied above occupied_thresh, free below free_thresh, else unknown (trinary); `scale` and
`raw` as documented; and every unusable map is one line naming the file and the fault."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.support.floor_maps import FREE, OCCUPIED, UNKNOWN, write_map
from vahr.navigation import MapError, load_map

ROOT = Path(__file__).resolve().parents[3]
TURTLEBOT3 = ROOT / "docs/examples/turtlebot3_world/map.yaml"


def test_the_top_row_of_the_image_is_the_top_of_the_map_and_origin_its_lower_left(
    tmp_path: Path,
) -> None:
    # Given a 4 x 2 image: the top row free, the bottom row a wall but for its last pixel
    shades = np.array([[FREE] * 4, [OCCUPIED, OCCUPIED, OCCUPIED, UNKNOWN]], dtype=np.uint8)
    grid = load_map(write_map(tmp_path, shades, resolution=0.5, origin=(-1.0, 2.0)))
    # Then the lower-left pixel's cell holds the origin and is occupied
    assert grid.cell(-1.0, 2.0) == (0, 0) and grid.occupied[0, 0]
    # and the top row (y 2.5 to 3) is free, the last bottom pixel unknown
    assert grid.free[grid.cell(0.9, 2.9)] and not grid.occupied[grid.cell(0.9, 2.9)]
    unknown = grid.cell(0.9, 2.2)
    assert not grid.free[unknown] and not grid.occupied[unknown]
    # and points off the image are off the map
    assert grid.cell(-1.01, 2.0) is None and grid.cell(1.0, 2.0) is None
    assert (grid.width, grid.height, grid.extent()) == (2.0, 1.0, "x -1 to 1, y 2 to 3")


@pytest.mark.parametrize(
    ("shade", "negate", "expected"),
    [
        (0, 0, "occupied"),  # p = 1
        (80, 0, "occupied"),  # p = 0.686 > 0.65
        (100, 0, "unknown"),  # p = 0.608
        (205, 0, "unknown"),  # p = 0.196, not below free_thresh 0.196
        (206, 0, "free"),  # p = 0.192
        (254, 0, "free"),
        (254, 1, "occupied"),  # negate: p = shade / 255 = 0.996
        (0, 1, "free"),
    ],
)  # fmt: skip
def test_a_shade_is_occupied_free_or_unknown_by_the_thresholds(
    tmp_path: Path, shade: int, negate: int, expected: str
) -> None:
    yaml = write_map(tmp_path, np.full((1, 1), shade, dtype=np.uint8))
    yaml.write_text(yaml.read_text().replace("negate: 0", f"negate: {negate}"))
    grid = load_map(yaml)
    kind = "occupied" if grid.occupied[0, 0] else "free" if grid.free[0, 0] else "unknown"
    assert kind == expected


def test_scale_mode_drives_between_the_thresholds_and_a_clear_pixel_is_unknown(
    tmp_path: Path,
) -> None:
    # Given an RGBA PNG: a grey between the thresholds, a clear pixel, black, white
    pixels = np.array(
        [[[100, 100, 100, 255], [255, 255, 255, 0], [0, 0, 0, 255], [255, 255, 255, 255]]],
        dtype=np.uint8,
    )
    Image.fromarray(pixels, "RGBA").save(tmp_path / "map.png")
    yaml = tmp_path / "map.yaml"
    yaml.write_text(
        "image: map.png\nmode: scale\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    grid = load_map(yaml)
    assert grid.free[0].tolist() == [True, False, False, True]
    assert grid.occupied[0].tolist() == [False, False, True, False]


def test_raw_mode_reads_the_shade_as_percent_and_a_colour_as_its_mean(tmp_path: Path) -> None:
    # Given an RGB PNG whose channels average 0, 99, 100 and 101
    pixels = np.array([[[0, 0, 0], [99, 99, 99], [90, 100, 110], [101, 101, 101]]], np.uint8)
    Image.fromarray(pixels, "RGB").save(tmp_path / "map.png")
    yaml = tmp_path / "map.yaml"
    yaml.write_text(
        "image: map.png\nmode: raw\nresolution: 0.1\norigin: [0, 0, 0]\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    grid = load_map(yaml)
    assert grid.free[0].tolist() == [True, True, False, False]
    assert grid.occupied[0].tolist() == [False, False, True, False]


def test_the_turtlebot3_world_is_read_at_its_resolution() -> None:
    grid = load_map(TURTLEBOT3)
    assert (grid.rows, grid.columns, grid.resolution) == (384, 384, 0.05)
    assert (grid.origin_x, grid.origin_y) == (-10.0, -10.0)
    # The arena's middle pillar stands at the map frame's origin; the floor around it is free
    assert grid.free[grid.cell(0.55, 0.55)] and not grid.free[grid.cell(0.0, 0.0)]
    assert int(grid.free.sum()) == 7939 and int(grid.occupied.sum()) == 795


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        (("free_thresh: 0.196", "free_thresh: 0.7"), "free_thresh 0.7 must be below occupied_thresh 0.65"),
        (("occupied_thresh: 0.65", "occupied_thresh: 1.5"), "occupied_thresh 1.5 must be between 0 and 1"),
        (("resolution: 0.05", "resolution: 0"), "resolution: expected `float` > 0.0"),
        (("free_thresh: 0.196\n", ""), "free_thresh: is required"),
        (("origin: [0.0, 0.0, 0.0]", "origin: [0.0, 0.0, 0.5]"), "origin yaw 0.5 is not supported"),
        (("mode", "mode"), None),
    ],
)  # fmt: skip
def test_a_map_with_a_bad_setting_is_one_line_naming_it(
    tmp_path: Path, change: tuple[str, str], reason: str | None
) -> None:
    yaml = write_map(tmp_path, np.full((2, 2), FREE, dtype=np.uint8))
    yaml.write_text(yaml.read_text().replace(*change))
    if reason is None:
        assert load_map(yaml).free.all()
        return
    with pytest.raises(MapError) as raised:
        load_map(yaml)
    message = str(raised.value)
    assert message.startswith(f"map {yaml}: ") and "\n" not in message
    assert reason in message, message


def test_a_missing_or_unreadable_image_is_one_line(tmp_path: Path) -> None:
    yaml = write_map(tmp_path, np.full((2, 2), FREE, dtype=np.uint8))
    (tmp_path / "map.pgm").write_bytes(b"not an image at all")
    with pytest.raises(MapError, match=r"image map.pgm is not a PGM or PNG image Pillow can read"):
        load_map(yaml)
    (tmp_path / "map.pgm").unlink()
    with pytest.raises(MapError, match=r"image map.pgm: no such file"):
        load_map(yaml)
    with pytest.raises(MapError, match=r"cannot read it"):
        load_map(tmp_path / "nothing.yaml")
    (tmp_path / "list.yaml").write_text("- just\n- a list\n")
    with pytest.raises(MapError, match=r"^map .*list.yaml: "):
        load_map(tmp_path / "list.yaml")
