"""Grid worlds: the paper's instance, the text format, distances."""

import pytest

from ara.coordination.world import GridWorld, WorldError


def test_paper_instance_matches_the_spec():
    """Tests the 8x8 grid with obstacles at rows {1,2,4,5,6} x cols {1,3,5}."""
    world = GridWorld.paper()
    assert (world.rows, world.cols, len(world.free_cells)) == (8, 8, 49)
    assert world.obstacles == {(r, c) for r in (1, 2, 4, 5, 6) for c in (1, 3, 5)}


def test_distances_go_around_obstacles():
    """Tests BFS distances, not Manhattan: (2,0) to (2,2) must detour through row 0 or 3."""
    world = GridWorld.paper()
    assert world.distance((2, 0), (2, 2)) == 4  # Manhattan would say 2
    assert world.distance((0, 0), (7, 7)) == 14
    assert world.distance((3, 3), (3, 3)) == 0


def test_unreachable_cells_have_no_distance():
    """Tests a walled-off cell."""
    world = GridWorld.from_text(".#.\n##.\n...")
    assert world.distance((0, 0), (2, 2)) is None


def test_nearest_free_neighbour_has_a_fixed_order():
    """Tests the deterministic drop cell of the help job: up, down, left, right."""
    world = GridWorld.paper()
    assert world.nearest_free_neighbour((3, 1)) == (3, 0)  # up and down are obstacles
    assert world.nearest_free_neighbour((3, 3)) == (3, 2)
    assert world.nearest_free_neighbour((0, 4)) == (1, 4)  # up is off the grid


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("..\n...", r"world:2: row has 3 cells, the first has 2"),  # ragged rows
        ("..\n.x", r"world:2:2: unexpected 'x'"),  # unknown character
        ("; only a comment\n", "no rows"),
        ("##\n##", "every cell is an obstacle"),
    ],
)
def test_bad_world_files_say_where(text, message):
    """Tests the messages for malformed world text."""
    with pytest.raises(WorldError, match=message):
        GridWorld.from_text(text, "world")


def test_missing_world_file(tmp_path):
    """Tests the message for a path that does not exist."""
    with pytest.raises(WorldError, match="world file not found"):
        GridWorld.from_file(tmp_path / "none.txt")


def test_a_world_file_that_is_not_text(tmp_path):
    """Tests that a picture given as --world is refused by name, not with a traceback."""
    png = tmp_path / "map.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")
    with pytest.raises(WorldError, match="map.png is not a text grid"):
        GridWorld.from_file(png)
