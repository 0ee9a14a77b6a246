"""How much of a reference frame to draw before the editor's event loop runs again.

Reference (and difference) mode draws its frames in bands, each scissored: whole strips of
STRIP rows, or a run of cells (CELL pixels wide) along one strip where a whole strip is over
budget. A paint of the viewport then costs about `budget_ms` however slow a whole frame is,
and a frame is added to the average only once its last band is in, so every pixel of the
converged image has had the same samples as a frame drawn whole.

`BandPlanner` sizes the bands from the time bands took (measured with the GPU finished). It
remembers the cost of a pixel in every cell (cells on the mesh cost many times what
background cells do, and the next frame's cells cost what this frame's did), and costs
cells not measured yet at the dearest pixel measured so far (the first band's aside: the
driver compiles the program at its first draw), so that the first frame's bands err on the
small side; a band over cells measured before scales
their costs, as they were relative to each other, to what it took. No GL or Qt here: the
accumulator (matedit.render.frames) draws, the viewport asks for the next paint.

Cells are 32 x 32 pixels, whole tiles of a tiled rasteriser's: on llvmpipe (64 x 64 tiles)
a 770 x 279 reference frame of the sample layered material drawn as 64 x 64 cells cost 6 %
more than drawn whole, as 32 x 32 cells 27 % more, as strips of 4 full rows 57 % more (one
run each, 2 busy cores); smaller cells keep a paint near its budget on the mesh, where a
pixel costs most.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

DEFAULT_BUDGET_MS = 20.0  # per paint; the display pass and Qt's composition come on top
STRIP = 32  # rows a strip
CELL = 32  # pixels: the width of a cell, the smallest part of a strip drawn as a band
GROWTH = 2.0  # over cells not measured yet, a band at most this many times the last one

Band = tuple[int, int, int, int]  # x, y, width, height in pixels, GL's rows (bottom up)


@dataclass
class BandPlanner:
    """Sizes the next band to fit what is left of a paint's budget (the module docstring).

    `cost[s, c]` is the ms a pixel of cell c of strip s took when last drawn (NaN: not
    yet); `latest` the ms a pixel of the last band took (None before any band), `peak` the
    most a pixel took in a band after the first (what a cell not measured yet is costed at,
    `latest` until then). A slow band
    (the driver compiling a program at its first draw) is forgotten when its cells are
    drawn again.
    """

    budget_ms: float = DEFAULT_BUDGET_MS
    latest: float | None = None
    last_pixels: int = 0
    peak: float | None = None  # the dearest pixel of a band after the first
    cost: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    _size: tuple[int, int] = (0, 0)

    # --- the cell grid ----------------------------------------------------------------------
    def _fit(self, width: int, height: int) -> None:
        if self._size != (width, height):
            self._size = (width, height)
            self.cost = np.full((math.ceil(height / STRIP), math.ceil(width / CELL)), np.nan)

    def _cells(self, band: Band) -> tuple[slice, slice, np.ndarray]:
        """The strips and cells `band` covers, and the pixels it covers of each."""
        x, y, w, h = band
        s = slice(y // STRIP, math.ceil((y + h) / STRIP))
        c = slice(x // CELL, math.ceil((x + w) / CELL))
        rows = np.array([min(y + h, (i + 1) * STRIP) - max(y, i * STRIP)
                         for i in range(s.start, s.stop)], float)
        cols = np.array([min(x + w, (j + 1) * CELL) - max(x, j * CELL)
                         for j in range(c.start, c.stop)], float)
        return s, c, np.outer(rows, cols)

    def _rates(self, s: slice, c: slice) -> np.ndarray:
        r = self.cost[s, c]
        unknown = self.peak if self.peak is not None else (self.latest or 0.0)
        return np.where(np.isnan(r), unknown, r)

    def _pixels_cost(self, band: Band) -> float:
        s, c, px = self._cells(band)
        return float(np.sum(self._rates(s, c) * px))

    def _known(self, band: Band) -> bool:
        s, c, _ = self._cells(band)
        return not np.isnan(self.cost[s, c]).any()

    # --- planning ---------------------------------------------------------------------------
    def next_band(self, row: int, col: int, width: int, height: int,
                  left_ms: float | None = None) -> Band:
        """The next band from (col, row) of a width x height frame (`row` a multiple of
        STRIP, `col` of CELL): the rest of the strip at `row` when a part of it is drawn
        (col > 0), else as many whole strips as `left_ms` (default: the whole budget) allows,
        else a run of the strip's cells, at least one."""
        self._fit(width, height)
        left = self.budget_ms if left_ms is None else left_ms
        strip = min(STRIP, height - row)
        if self.latest is None:  # nothing measured yet: one strip (or its rest) to measure
            return (col, row, width - col, strip)
        cap = self.last_pixels * GROWTH if self.last_pixels else math.inf
        if col == 0:
            cost, n = 0.0, 0
            while row + n < height:
                h = min(STRIP, height - row - n)
                band = (0, row + n, width, h)
                if not self._known(band) and (n + h) * width > cap:
                    break
                c = self._pixels_cost(band)
                if cost + c > left:
                    break
                cost += c
                n += h
            if n:
                return (0, row, width, n)
        cost, w = 0.0, 0
        while col + w < width:
            cw = min(CELL, width - col - w)
            cell = (col + w, row, cw, strip)
            if w and not self._known(cell) and (w + cw) * strip > cap:
                break
            c = self._pixels_cost(cell)
            if w and cost + c > left:
                break
            cost += c
            w += cw
        return (col, row, w, strip)

    def predict(self, band: Band) -> float:
        """The band's expected cost (ms) from the costs remembered."""
        return self._pixels_cost(band)

    def fits(self, band: Band, left_ms: float) -> bool:
        """Whether `band` is expected to take no more than `left_ms`."""
        return self.latest is not None and self.predict(band) <= left_ms

    def record(self, band: Band, ms: float) -> None:
        """`band` took `ms` (GPU finished)."""
        x, y, w, h = band
        pixels = w * h
        if pixels <= 0:
            return
        ms = max(0.0, float(ms))
        s, c, _ = self._cells(band)
        if self.latest is not None:
            self.peak = max(self.peak or 0.0, ms / pixels)
        self.latest, self.last_pixels = ms / pixels, pixels
        if self._known(band):
            # cells measured before keep their costs relative to each other (a band across
            # the mesh's edge), scaled to what this band took
            predicted = self._pixels_cost(band)
            if predicted > 0:
                self.cost[s, c] *= ms / predicted
                return
        self.cost[s, c] = ms / pixels

    def forget(self) -> None:
        """Costs change: measure again from one strip."""
        self.latest, self.last_pixels, self.peak = None, 0, None
        self._size, self.cost = (0, 0), np.zeros((0, 0))
