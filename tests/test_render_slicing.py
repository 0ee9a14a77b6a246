"""Reference accumulation in bands (matedit.render.slicing, Accumulator.draw_sliced): the band
sizes follow the measured cost to a budget, and the banded frames add up to the image whole
frames give. No timing is asserted here: the clock is a fake one driven by a cost model."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.compiler import compile_document
from matedit.ibl import BakeSettings
from matedit.io.document import FileResolver
from matedit.render import Renderer
from matedit.render.frames import Accumulator
from matedit.render.fullscreen import FullscreenQuad
from matedit.render.slicing import CELL, GROWTH, STRIP, BandPlanner
from matedit.shading.ibl import IBL_MODE_REFERENCE, IBL_MODE_SPLIT_SUM

SMALL = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)


# --- the planner ------------------------------------------------------------------------------
W, H = 10 * CELL, 6 * STRIP  # a frame of 10 x 6 cells


def test_first_band_is_one_strip_then_bands_fill_the_budget():
    p = BandPlanner(budget_ms=30.0)
    assert p.next_band(0, 0, W, H) == (0, 0, W, STRIP)  # nothing measured: one strip
    p.record((0, 0, W, STRIP), 5.0)  # 5 ms a strip
    # over strips not measured yet, at most GROWTH times the last band's pixels
    assert p.next_band(STRIP, 0, W, H) == (0, STRIP, W, int(GROWTH) * STRIP)
    p.record((0, STRIP, W, 2 * STRIP), 10.0)
    assert p.next_band(3 * STRIP, 0, W, H) == (0, 3 * STRIP, W, 3 * STRIP)  # the last three
    p.record((0, 3 * STRIP, W, 3 * STRIP), 15.0)
    # the next frame: every strip measured, as many as the budget allows
    assert p.next_band(0, 0, W, H) == (0, 0, W, 6 * STRIP)
    assert p.next_band(0, 0, W, H, left_ms=12.0) == (0, 0, W, 2 * STRIP)
    assert p.predict((0, 0, W, 2 * STRIP)) == pytest.approx(10.0)


def test_a_strip_over_budget_is_drawn_in_cells():
    p = BandPlanner(budget_ms=10.0)
    p.next_band(0, 0, W, H)
    p.record((0, 0, W, STRIP), 40.0)  # 4 ms a cell
    assert p.next_band(0, 0, W, H) == (0, 0, 2 * CELL, STRIP)
    p.record((0, 0, 2 * CELL, STRIP), 8.0)
    assert p.next_band(0, 2 * CELL, W, H) == (2 * CELL, 0, 2 * CELL, STRIP)  # its rest
    assert p.next_band(0, 9 * CELL, W, H) == (9 * CELL, 0, CELL, STRIP)  # never past its end
    assert p.next_band(0, 2 * CELL, W, H, left_ms=0.0) == (2 * CELL, 0, CELL, STRIP)  # >= 1
    assert p.fits((2 * CELL, 0, 2 * CELL, STRIP), 8.0)
    assert not p.fits((2 * CELL, 0, 3 * CELL, STRIP), 8.0)


def test_each_cell_is_costed_from_its_own_last_draw():
    """Cells on the mesh cost more than background cells, frame after frame; a slow first
    band (the driver compiling the program) is forgotten once its cells are drawn again; a
    band over cells measured before keeps their costs relative to each other."""
    p = BandPlanner(budget_ms=30.0)
    p.next_band(0, 0, W, H)
    p.record((0, 0, W, STRIP), 900.0)  # the compile
    p.record((0, STRIP, W, STRIP), 10.0)  # background: 1 ms a cell
    for x in range(0, W, CELL):  # the next strip: the mesh in cells 4..5, 10 ms each
        p.record((x, 2 * STRIP, CELL, STRIP), 10.0 if 4 * CELL <= x < 6 * CELL else 1.0)
    assert p.next_band(0, 0, W, H) == (0, 0, CELL, STRIP)  # the compile's strip: one cell
    p.record((0, 0, CELL, STRIP), 1.0)  # measured again: 1 ms
    assert p.next_band(0, CELL, W, H) == (CELL, 0, CELL, STRIP)  # its neighbours not yet
    assert p.next_band(STRIP, 0, W, H) == (0, STRIP, W, STRIP)  # 10 ms; the next strip 28
    assert p.next_band(2 * STRIP, 0, W, H) == (0, 2 * STRIP, W, STRIP)  # 28 ms
    assert p.next_band(2 * STRIP, 0, W, H, left_ms=25.0) == (0, 2 * STRIP, 7 * CELL, STRIP)
    assert p.predict((0, 2 * STRIP, 7 * CELL, STRIP)) == pytest.approx(4.0 + 20.0 + 1.0)
    # the mesh strip took twice what it was expected to: each cell's cost doubles
    p.record((0, 2 * STRIP, W, STRIP), 56.0)
    assert p.predict((4 * CELL, 2 * STRIP, CELL, STRIP)) == pytest.approx(20.0)
    assert p.predict((0, 2 * STRIP, CELL, STRIP)) == pytest.approx(2.0)
    p.forget()
    assert p.next_band(STRIP, 0, W, H) == (0, STRIP, W, STRIP)


def test_cells_at_the_frames_edges_are_partial():
    w, h = 3 * CELL + 5, STRIP + 7
    p = BandPlanner(budget_ms=10.0)
    assert p.next_band(0, 0, w, h) == (0, 0, w, STRIP)
    p.record((0, 0, w, STRIP), 100.0)
    assert p.next_band(STRIP, 0, w, h) == (0, STRIP, CELL, 7)  # the last strip's 7 rows
    band = p.next_band(STRIP, 3 * CELL, w, h)
    assert band == (3 * CELL, STRIP, 5, 7)  # and its last 5 columns
    rate = 100.0 / (w * STRIP)
    assert p.predict(band) == pytest.approx(rate * 5 * 7)


# --- the accumulator's paints ------------------------------------------------------------------
class CostClock:
    """A clock that advances by a cost model as bands are drawn: `per_px(i, row)` ms a pixel
    of `row` in the i-th band."""

    def __init__(self, per_px):
        self.t, self.per_px, self.bands = 0.0, per_px, []

    def __call__(self):
        return self.t

    def scene(self, fbo, frames):
        def draw(ibl_mode, offset, band):
            self.bands.append((ibl_mode, offset, band, frames()))
            x, y, w, h = band
            self.t += sum(w * self.per_px(len(self.bands), row) for row in range(y, y + h)) / 1e3
            fbo.use()
            fbo.scissor = band  # the rows of the band, as the scene pass scissors them
            gl = fbo.ctx
            gl.clear(1.0 if ibl_mode == IBL_MODE_REFERENCE else 0.5, 0.0, 0.0, 1.0)
            fbo.scissor = None
        return draw


def test_each_paint_keeps_to_the_budget_and_frames_complete_whole(ctx):
    size = (4 * CELL, 6 * STRIP)
    quad = FullscreenQuad(ctx)
    acc = Accumulator(ctx, quad)
    resolved = ctx.framebuffer([ctx.texture(size, 4, dtype="f4")])

    def per_px(i, row):  # the first band is a compile; strips 2 and 3 are the mesh
        if i == 1:
            return 0.5
        return 0.005 if 2 * STRIP <= row < 4 * STRIP else 0.0005

    clock = CostClock(per_px)  # a cell: 5 ms on the mesh, 0.5 ms off it
    planner = BandPlanner(budget_ms=8.0)
    try:
        acc.resize(size)
        scene = clock.scene(resolved, lambda: acc.frames)
        paints = []
        while acc.pending("reference", 3) and len(paints) < 1000:
            n = len(clock.bands)
            t0 = clock.t
            acc.draw_sliced("reference", 3, scene, resolved, None, 0.0, planner, clock)
            paints.append(((clock.t - t0) * 1e3, clock.bands[n:]))
        assert acc.frames == 3 and not acc.pending("reference", 3)
        assert len(paints[0][1]) == 1  # the compile, alone
        # over the first frame's cells not yet measured, a band may cost up to GROWTH times
        # what the planner expected, times the cost step where the mesh starts; a band
        # across that step blurs its cells' costs, which the next frame sharpens again (each
        # band rescales its cells as they were relative to each other): the third frame's
        # paints all keep to the budget
        by_frame = [[ms for ms, bands in paints if bands[0][3] == f] for f in range(3)]
        assert max(by_frame[0][1:]) <= planner.budget_ms * GROWTH * 10  # 10: mesh / bg
        assert max(by_frame[1]) <= planner.budget_ms * 3
        assert by_frame[2] and max(by_frame[2]) <= planner.budget_ms + 1e-9
        # a mesh strip (20 ms) is drawn in cells, background strips (2 ms) whole, several
        # a band
        assert any(b[2] == CELL and b[1] == 2 * STRIP for m, o, b, f in clock.bands)
        assert any(b[3] > STRIP for m, o, b, f in clock.bands)
        # every frame's bands cover each pixel once, with that frame's sample offset
        for frame in range(3):
            cover = np.zeros(size[::-1], int)
            for _m, _o, (x, y, w, h), f in clock.bands:
                if f == frame:
                    cover[y:y + h, x:x + w] += 1
            assert np.all(cover == 1)
            assert len({o for m, o, b, f in clock.bands if f == frame}) == 1
        assert all(m == IBL_MODE_REFERENCE for m, *_ in clock.bands)
        ref = acc.read_hdr("reference", "reference", resolved)
        assert np.allclose(ref[..., 0], 1.0, atol=0)
        # a reset restarts the frame under way
        acc.row, acc.col = 5, 3
        acc.frames = 0
        assert (acc.row, acc.col) == (0, 0) and acc.pending("reference", 3)
    finally:
        ctx.detect_framebuffer(0).use()
        resolved.release()
        acc.release()
        quad.release()


def test_difference_mode_keeps_its_split_sum_frame_once_then_accumulates(ctx):
    size = (3 * CELL, 2 * STRIP)
    quad = FullscreenQuad(ctx)
    acc = Accumulator(ctx, quad)
    resolved = ctx.framebuffer([ctx.texture(size, 4, dtype="f4")])
    clock = CostClock(lambda i, row: 0.002)  # a cell: 2 ms
    planner = BandPlanner(budget_ms=5.0)
    try:
        acc.resize(size)
        scene = clock.scene(resolved, lambda: acc.frames)
        for _ in range(200):
            if not acc.pending("difference", 2):
                break
            acc.draw_sliced("difference", 2, scene, resolved, None, 0.0, planner, clock)
        modes = [m for m, *_ in clock.bands]
        split_px = sum(b[2] * b[3] for m, o, b, f in clock.bands if m == IBL_MODE_SPLIT_SUM)
        assert split_px == size[0] * size[1]  # one split-sum frame, before any reference band
        assert modes[:modes.index(IBL_MODE_REFERENCE)] == [IBL_MODE_SPLIT_SUM] * \
            modes.index(IBL_MODE_REFERENCE)
        assert acc.frames == 2
        diff = acc.read_linear("difference", resolved)
        assert np.allclose(diff[..., 0], 0.5 - 1.0, atol=1e-6)
        n = len(clock.bands)
        acc.draw_sliced("difference", 2, scene, resolved, None, 0.0, planner, clock)
        assert len(clock.bands) == n  # converged: the display only
    finally:
        ctx.detect_framebuffer(0).use()
        resolved.release()
        acc.release()
        quad.release()


# --- the renderer: banded frames add up to whole frames ------------------------------------------
def _material():
    d = material()
    node(d, "r", "scalar_parameter", {"name": "rough"}, {"value": 0.35})
    node(d, "make", "make_attributes", values={"baseColor": [0.9, 0.6, 0.3], "metallic": 1.0})
    node(d, "out", "material_output")
    link(d, "r", "value", "make", "roughness")
    link(d, "make", "attributes", "out", "attributes")
    return compile_document(d, FileResolver())


def _resolved(r):
    w, h = r.size
    return np.frombuffer(r.targets.resolved.read(components=4, dtype="f4"),
                         np.float32).reshape(h, w, 4).copy()


@pytest.mark.parametrize("deferred", [True, False], ids=["deferred", "forward"])
@pytest.mark.parametrize("mode", ["reference", "difference"])
def test_banded_reference_frames_equal_whole_frames(ctx, deferred, mode):
    """The same frames (sample offsets) reach every pixel: the converged image is the one
    whole frames give, to float32 rounding of the same sums (1e-5 relative)."""
    r = Renderer(ctx, (CELL + 16, STRIP + 8), samples=4, environment="studio", bake_settings=SMALL,
                 deferred=deferred)
    try:
        r.set_material(_material())
        r.reference_samples, r.reference_frames = 4, 3
        r.mode = mode
        r.render_converged()
        whole = r.read_linear()
        r.reset_accumulation()
        r.mode = "reference"
        r.render()
        first = _resolved(r)  # the first reference frame, whole
        r.mode = "splitsum"
        r.render()
        before = _resolved(r)
        assert not np.array_equal(first, before)  # the mesh differs between the two
        r.mode = mode
        r.reset_accumulation()
        r.slice_budget_ms = 1e-3  # every band over budget: one band a paint
        r.planner = BandPlanner()
        r.render()  # the first band: the first strip, whole (nothing measured)
        r.render()  # then a cell of the second (over budget: one cell at least)
        after = _resolved(r)  # GL rows bottom up
        drawn = np.zeros(after.shape[:2], bool)
        drawn[:STRIP], drawn[STRIP:, :CELL] = True, True
        if mode == "reference":  # only the bands were drawn (difference: its split sum)
            assert np.array_equal(after[~drawn], before[~drawn])
            assert np.array_equal(after[drawn], first[drawn])
        else:
            assert np.array_equal(after, before)
        paints = 2
        while r.needs_redraw and paints < 2000:
            r.render()
            paints += 1
        assert r.converged and r.accumulated_frames == 3
        frames = 3 + (mode == "difference")  # difference: its split-sum frame first
        assert paints >= 3 + (frames - 1) * 4  # a band a paint: cells, and strips at first
        banded = r.read_linear()
        scale = float(np.abs(whole).max())
        assert scale > 0
        np.testing.assert_allclose(banded, whole, rtol=0, atol=1e-5 * scale)
    finally:
        r.release()


def test_cells_not_measured_are_costed_at_the_dearest_pixel_seen_after_the_first_band():
    """The first frame: a cell not drawn yet may be on the mesh; it is costed at the most a
    pixel has cost so far (not counting the first band, the driver's compile), so the first
    frame's bands err on the small side."""
    p = BandPlanner(budget_ms=10.0)
    p.next_band(0, 0, W, H)
    p.record((0, 0, W, STRIP), 900.0)  # the compile: not a pixel's cost
    assert p.peak is None
    p.record((0, STRIP, CELL, STRIP), 4.0)  # a mesh cell: 4 ms
    p.record((CELL, STRIP, CELL, STRIP), 0.5)  # a background cell
    assert p.latest == pytest.approx(0.5 / (CELL * STRIP))
    assert p.predict((2 * CELL, STRIP, CELL, STRIP)) == pytest.approx(4.0)  # the peak
    assert p.next_band(STRIP, 2 * CELL, W, H) == (2 * CELL, STRIP, 2 * CELL, STRIP)
    assert p.predict((CELL, STRIP, CELL, STRIP)) == pytest.approx(0.5)  # measured: its own


def test_a_split_sum_frame_between_slices_restarts_the_frame_under_way(ctx):
    """Split-sum mode draws whole frames into the target the sliced reference frame is
    being drawn in: back in reference mode the frame starts again, never mixing the two."""
    r = Renderer(ctx, (2 * CELL, 2 * STRIP), samples=4, environment="studio",
                 bake_settings=SMALL)
    try:
        r.set_material(_material())
        r.reference_samples, r.reference_frames = 4, 2
        r.slice_budget_ms = 1e-3
        r.mode = "reference"
        r.render()
        r.render()
        assert (r.accumulator.row, r.accumulator.col) != (0, 0) and r.accumulated_frames == 0
        r.mode = "splitsum"
        r.render()
        assert (r.accumulator.row, r.accumulator.col) == (0, 0)
    finally:
        r.release()
