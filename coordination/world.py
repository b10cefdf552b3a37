"""Grid worlds: free cells, obstacles, shortest-path distances.

Robots move one 4-connected cell per step and may wait; several robots may share a
cell. Distances are BFS shortest paths around obstacles, never Manhattan distances.

A world file is text, one row per line: ``.`` a free cell, ``#`` an obstacle; blank
lines and lines starting with ``;`` are ignored. The paper's instance::

    ........
    .#.#.#..
    .#.#.#..
    ........
    .#.#.#..
    .#.#.#..
    .#.#.#..
    ........
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

from ara.errors import AraError

Cell = tuple[int, int]

PAPER_8X8 = """\
........
.#.#.#..
.#.#.#..
........
.#.#.#..
.#.#.#..
.#.#.#..
........
"""


class WorldError(AraError, ValueError):
    """A world description that makes no grid."""


@dataclass(frozen=True)
class GridWorld:
    """A rectangular grid with obstacles.

    Args:
        rows: Number of rows, >= 1.
        cols: Number of columns, >= 1.
        obstacles: Blocked cells, as (row, col), 0-based.
    """

    rows: int
    cols: int
    obstacles: frozenset[Cell] = field(default_factory=frozenset)

    def __post_init__(self) -> None:
        if self.rows < 1 or self.cols < 1:
            raise WorldError(
                f"a grid needs at least one row and column, got {self.rows}x{self.cols}")
        outside = [c for c in self.obstacles if not self.in_bounds(c)]
        if outside:
            raise WorldError(f"obstacles outside the {self.rows}x{self.cols} grid: {outside}")
        if not self.free_cells:
            raise WorldError("every cell is an obstacle")

    @classmethod
    def from_text(cls, text: str, source: str = "<text>") -> GridWorld:
        """Parse the text format (see the module doc).

        Raises:
            WorldError: Naming the line and column of the first bad character, or ragged rows.
        """
        lines = [ln.rstrip() for ln in text.splitlines()]
        numbered = [(i + 1, ln) for i, ln in enumerate(lines) if ln and not ln.startswith(";")]
        if not numbered:
            raise WorldError(f"{source}: no rows; write '.' for free cells and '#' for obstacles")
        width = len(numbered[0][1])
        obstacles = set()
        for r, (lineno, line) in enumerate(numbered):
            if len(line) != width:
                raise WorldError(f"{source}:{lineno}: row has {len(line)} cells, the first has "
                                 f"{width}; rows must be equally long")
            for c, ch in enumerate(line):
                if ch == "#":
                    obstacles.add((r, c))
                elif ch != ".":
                    raise WorldError(f"{source}:{lineno}:{c + 1}: unexpected {ch!r}; use '.' "
                                     "(free) or '#' (obstacle)")
        return cls(len(numbered), width, frozenset(obstacles))

    @classmethod
    def from_file(cls, path: str | Path) -> GridWorld:
        path = Path(path)
        if not path.is_file():
            raise WorldError(f"world file not found: {path}")
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            raise WorldError(f"{path} is not a text grid: one line a row, '.' free, "
                             "'#' obstacle") from None
        return cls.from_text(text, str(path))

    @classmethod
    def paper(cls) -> GridWorld:
        """The 8x8 instance of the paper's Experiment 2 (49 free cells)."""
        return cls.from_text(PAPER_8X8, "paper-8x8")

    def in_bounds(self, cell: Cell) -> bool:
        return 0 <= cell[0] < self.rows and 0 <= cell[1] < self.cols

    def is_free(self, cell: Cell) -> bool:
        return self.in_bounds(cell) and cell not in self.obstacles

    def require_free(self, cell: Cell, what: str) -> None:
        """Refuse a cell a robot cannot stand on, saying why.

        Raises:
            WorldError: ``cell`` is outside the grid or an obstacle.
        """
        if not self.in_bounds(cell):
            raise WorldError(f"{what} {cell} is outside the {self.rows}x{self.cols} grid "
                             f"(rows 0-{self.rows - 1}, columns 0-{self.cols - 1})")
        if cell in self.obstacles:
            near = sorted(self.free_cells, key=lambda f: abs(f[0] - cell[0]) + abs(f[1] - cell[1]))
            raise WorldError(f"{what} {cell} is an obstacle of this world; free cells near it: "
                             f"{', '.join(map(str, near[:3]))}")

    @cached_property
    def free_cells(self) -> tuple[Cell, ...]:
        """Free cells in row-major order."""
        return tuple((r, c) for r in range(self.rows) for c in range(self.cols)
                     if (r, c) not in self.obstacles)

    def neighbors(self, cell: Cell) -> list[Cell]:
        """Free 4-neighbours, in the fixed order up, down, left, right."""
        r, c = cell
        return [n for n in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)) if self.is_free(n)]

    def distances_from(self, source: Cell) -> dict[Cell, int]:
        """BFS distance from ``source`` to every reachable free cell."""
        return dict(self._bfs(source))

    def distance(self, a: Cell, b: Cell) -> int | None:
        """Steps of a shortest path from ``a`` to ``b``; ``None`` if unreachable."""
        return self._bfs(a).get(b)

    def _bfs(self, source: Cell) -> dict[Cell, int]:
        cache = self.__dict__.setdefault("_bfs_cache", {})
        if source not in cache:
            if not self.is_free(source):
                raise WorldError(f"{source} is not a free cell of this world")
            dist = {source: 0}
            queue = deque([source])
            while queue:
                cell = queue.popleft()
                for n in self.neighbors(cell):
                    if n not in dist:
                        dist[n] = dist[cell] + 1
                        queue.append(n)
            cache[source] = dist
        return cache[source]

    def path(self, a: Cell, b: Cell) -> list[Cell]:
        """A shortest path from ``a`` to ``b``, both ends included (BFS order, so the
        same every time).

        Raises:
            WorldError: No path.
        """
        dist = self._bfs(b)
        if a not in dist:
            raise WorldError(f"no path from {a} to {b}")
        out = [a]
        while out[-1] != b:  # step to any neighbour one closer to b, in the fixed order
            out.append(next(n for n in self.neighbors(out[-1]) if dist.get(n) == dist[out[-1]] - 1))
        return out

    def nearest_free_neighbour(self, cell: Cell) -> Cell:
        """The first free 4-neighbour in the order up, down, left, right.

        The paper's help job places the blocking pallet here; the authors' code drew a
        random neighbour, this project fixes the order so trials are reproducible.
        """
        found = self.neighbors(cell)
        if not found:
            raise WorldError(f"{cell} has no free neighbour to move the pallet to")
        return found[0]
