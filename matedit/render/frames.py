"""The frame's render targets, reference-mode accumulation and the display pass.

A frame is drawn into the multisampled linear-HDR target (`SceneTargets`) and resolved. In
reference and difference modes, `Accumulator` adds the resolved frames (each with a rotated
sample set, `r2_offset`) into a float sum; difference mode keeps the split-sum frame beside it.
The display pass writes exposure, ACES and sRGB, or the difference heat map, into the caller's
framebuffer (by default an internal sRGB8 image).

`Accumulator.draw` takes whole frames (the CLI, the tests, `render_converged`). The editor's
viewport uses `Accumulator.draw_sliced` instead: a reference frame (and difference mode's
split-sum frame) is drawn in bands (`SceneTargets.scissor`: whole rows, or part of a row),
sized by a `matedit.render.slicing.BandPlanner` to a budget per paint, and added to the sum
only when its last band is in; until the first frame is complete the partly drawn frame is
shown.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import moderngl
import numpy as np

from matedit.render.deferred import GBuffer
from matedit.render.fullscreen import FullscreenQuad, render_program, set_uniform
from matedit.render.slicing import BandPlanner
from matedit.shading.ibl import IBL_MODE_REFERENCE, IBL_MODE_SPLIT_SUM

HEAT_RANGE = 0.1  # |split sum - reference| shown at full heat, linear HDR


def r2_offset(frame: int) -> tuple[float, float]:
    """Per-frame rotation of the reference sample set: the R2 sequence (Roberts 2018)."""
    g = 1.32471795724474602596
    return ((0.5 + frame / g) % 1.0, (0.5 + frame / (g * g)) % 1.0)


def _float_target(ctx: moderngl.Context, size: tuple[int, int]) -> moderngl.Framebuffer:
    return ctx.framebuffer([ctx.texture(size, 4, dtype="f4")])


def _release_fbo(fbo: moderngl.Framebuffer | None) -> None:
    if fbo is None:
        return
    for a in fbo.color_attachments:
        a.release()
    if fbo.depth_attachment is not None:
        fbo.depth_attachment.release()
    fbo.release()


class SceneTargets:
    """The targets of one size: `msaa` (multisampled HDR colour and depth), deferred also
    `gbuffer` (sharing that depth) and `background` (one sample, read by the lighting pass), and
    `resolved` (one sample, what the later passes read)."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], samples: int,
                 deferred: bool) -> None:
        depth = ctx.depth_renderbuffer(size, samples=samples)
        self.msaa = ctx.framebuffer(
            [ctx.renderbuffer(size, 4, samples=samples, dtype="f4")], depth)
        self.gbuffer = GBuffer(ctx, size, samples, depth) if deferred else None
        self.background = _float_target(ctx, size) if deferred else None
        self.resolved = _float_target(ctx, size)
        self.ctx, self.size = ctx, size
        # (x, y, width, height) of the band the next scene draws (clears, passes and resolve
        # scissored to it), None for the whole frame
        self.scissor: tuple[int, int, int, int] | None = None

    def _begin(self, fbo: moderngl.Framebuffer, clear: tuple[float, ...] | None) -> None:
        fbo.use()
        fbo.viewport = (0, 0, *self.size)
        fbo.scissor = self.scissor  # the current framebuffer's: GL's scissor test follows
        if clear is not None:
            self.ctx.clear(*clear, depth=1.0)

    def begin_background(self, deferred: bool) -> None:
        """Binds and clears where the background goes: the HDR target itself (forward), or the
        one-sample texture that the lighting pass reads where the mesh is not (deferred)."""
        self._begin(self.background if deferred else self.msaa, (0.0, 0.0, 0.0, 1.0))

    def begin_gbuffer(self) -> None:
        self._begin(self.gbuffer.fbo, (0.0, 0.0, 0.0, 0.0))

    def begin_lighting(self) -> None:
        """Binds the HDR target for the lighting pass: no clear, the pass writes every sample,
        and the depth of the G-buffer pass is kept (for the gizmos)."""
        self._begin(self.msaa, None)

    def narrow(self, rect: tuple[int, int, int, int]) -> bool:
        """Scissors the multisampled target (bound by begin_lighting) to `rect` (x, y,
        width, height in pixels) within the band being drawn; whether anything is left."""
        x, y, w, h = rect
        if self.scissor is not None:
            bx, by, bw, bh = self.scissor
            x0, y0 = max(x, bx), max(y, by)
            x1, y1 = min(x + w, bx + bw), min(y + h, by + bh)
            x, y, w, h = x0, y0, x1 - x0, y1 - y0
        if w <= 0 or h <= 0:
            return False
        self.msaa.scissor = (x, y, w, h)
        return True

    def widen(self) -> None:
        """The multisampled target's scissor back to the band (after `narrow`)."""
        self.msaa.scissor = self.scissor

    def resolve(self) -> None:
        """The multisampled target into `resolved` (within the scissor band, if any: the
        blit follows GL's scissor test, which the last `_begin` set)."""
        self.ctx.copy_framebuffer(self.resolved, self.msaa)

    def release(self) -> None:
        """Framebuffer 0 is bound first: moderngl would otherwise bind a released framebuffer
        again later (GL_INVALID_OPERATION)."""
        self.ctx.detect_framebuffer(0).use()
        if self.gbuffer is not None:
            self.gbuffer.release()  # before the depth it shares with msaa
        for fbo in (self.msaa, self.background, self.resolved):
            _release_fbo(fbo)


class Accumulator:
    """Reference frames summed (`frames` of them so far), the split-sum frame of difference
    mode, the display pass and the internal output image."""

    def __init__(self, ctx: moderngl.Context, quad: FullscreenQuad) -> None:
        self.ctx = ctx
        self._quad = quad
        self._accumulate = render_program(ctx, "fullscreen.vert", "accumulate.frag")
        self._display = render_program(ctx, "fullscreen.vert", "display.frag")
        self._frames = 0
        # where the next band starts in the frame being drawn in slices: row, and the
        # column within it when only a part of the row is drawn
        self.row = self.col = 0
        self.split_ready = False  # difference mode's split-sum frame is kept (draw_sliced)
        self.drawn = 0  # frames displayed (keys the difference mean read back)
        self._difference: tuple[int, float] | None = None
        self.sum: moderngl.Framebuffer | None = None
        self.split: moderngl.Framebuffer | None = None
        self._out: moderngl.Framebuffer | None = None
        self._size = (0, 0)

    def resize(self, size: tuple[int, int]) -> None:
        """New targets (call release_targets first) and no frames."""
        self._size = size
        self.sum = _float_target(self.ctx, size)
        self.split = _float_target(self.ctx, size)
        self.frames = 0  # and the sliced frame restarts

    @property
    def frames(self) -> int:
        """Reference frames in the sum; set to 0 for a reset (the sliced frame restarts)."""
        return self._frames

    @frames.setter
    def frames(self, n: int) -> None:
        self._frames = int(n)
        if self._frames == 0:
            self.row = self.col = 0
            self.split_ready = False

    def draw(self, mode: str, reference_frames: int, scene, resolved: moderngl.Framebuffer,
             target: moderngl.Framebuffer | None, exposure: float) -> None:
        """One frame of `mode` into `target` (None: the internal image). `scene(ibl_mode,
        offset)` draws and resolves a scene into `resolved`: split sum each frame; reference a
        new frame added until `reference_frames` are; difference both."""
        if mode == "splitsum":
            scene(IBL_MODE_SPLIT_SUM, (0.0, 0.0))
            self.row = self.col = 0  # a sliced frame under way is overwritten: restart it
        else:
            if self.frames < reference_frames:
                scene(IBL_MODE_REFERENCE, r2_offset(self.frames))
                self.add(resolved)
                self.row = self.col = 0  # a sliced frame under way restarts
            if mode == "difference":
                scene(IBL_MODE_SPLIT_SUM, (0.0, 0.0))
                self.keep_split_sum(resolved)
                self.split_ready = True
        self.display(target if target is not None else self.output(), mode, resolved, exposure)
        self.drawn += 1

    def pending(self, mode: str, reference_frames: int) -> bool:
        """Whether draw_sliced has a band to draw: a split-sum frame to keep (difference) or
        reference frames to add."""
        if mode == "splitsum":
            return False
        return (mode == "difference" and not self.split_ready) or \
            self.frames < reference_frames

    def draw_sliced(self, mode: str, reference_frames: int, scene,
                    resolved: moderngl.Framebuffer, target: moderngl.Framebuffer | None,
                    exposure: float, planner: BandPlanner,
                    clock: Callable[[], float] = time.perf_counter) -> int:
        """One paint of `mode`: split sum a whole frame (as `draw`); reference and difference
        `advance` by a budget's worth of bands, then the display (until the first frame is
        complete, of the frame as far as it is drawn). Returns the bands drawn."""
        if mode == "splitsum":
            self.draw(mode, reference_frames, lambda m, o: scene(m, o, None), resolved, target,
                      exposure)
            return 0
        bands = self.advance(mode, reference_frames, scene, resolved, planner, clock)
        out = target if target is not None else self.output()
        self.display(out, "splitsum" if self.frames == 0 else mode, resolved, exposure)
        self.drawn += 1
        return bands

    def advance(self, mode: str, reference_frames: int, scene,
                resolved: moderngl.Framebuffer, planner: BandPlanner,
                clock: Callable[[], float] = time.perf_counter) -> int:
        """Bands of reference or difference mode's next frames until `planner`'s budget is
        spent (at least one band while any is pending); no display. `scene(ibl_mode, offset,
        band)` draws and resolves the pixels of `band` (x, y, w, h). A reference frame is
        added to the sum when its last band is in, so every pixel gets the frames `draw`
        would give it; difference mode first keeps its split-sum frame, drawn once per
        accumulation (nothing it shows changes until a reset). Returns the bands drawn."""
        w, h = self._size
        spent, bands = 0.0, 0
        while self.pending(mode, reference_frames):
            left = planner.budget_ms - spent
            band = planner.next_band(self.row, self.col, w, h, left)
            if bands and not planner.fits(band, left):
                break
            split_pass = mode == "difference" and not self.split_ready
            t0 = clock()
            if split_pass:
                scene(IBL_MODE_SPLIT_SUM, (0.0, 0.0), band)
            else:
                scene(IBL_MODE_REFERENCE, r2_offset(self.frames), band)
            self.ctx.finish()  # the band's real cost (the driver works asynchronously)
            ms = (clock() - t0) * 1e3
            planner.record(band, ms)
            spent += ms
            bands += 1
            x, y, bw, bh = band
            self.row, self.col = (y + bh, 0) if x + bw >= w else (y, x + bw)
            if self.row >= h:
                self.row = 0
                if split_pass:
                    self.keep_split_sum(resolved)
                    self.split_ready = True
                else:
                    self.add(resolved)
        return bands

    def add(self, resolved: moderngl.Framebuffer) -> None:
        """Adds a resolved reference frame to the sum."""
        self.sum.use()
        if self.frames == 0:
            self.ctx.clear(0.0, 0.0, 0.0, 0.0)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = moderngl.ONE, moderngl.ONE
        resolved.color_attachments[0].use(location=0)
        self._accumulate["uFrame"].value = 0
        self._quad.draw(self._accumulate)
        self.ctx.disable(moderngl.BLEND)
        self._frames += 1

    def keep_split_sum(self, resolved: moderngl.Framebuffer) -> None:
        """Keeps the resolved split-sum frame of difference mode."""
        self.split.use()
        self.ctx.copy_framebuffer(self.split, resolved)

    @property
    def scale(self) -> float:
        return 1.0 / max(self.frames, 1)

    def display(self, target: moderngl.Framebuffer, mode: str,
                resolved: moderngl.Framebuffer, exposure: float) -> None:
        """The display pass of `mode` into `target`: split sum shows `resolved`, reference the
        average, difference the heat map of the kept split-sum frame against the average."""
        target.use()
        target.viewport = (0, 0, *self._size)
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        d = self._display
        if mode == "difference":
            self.split.color_attachments[0].use(location=0)
            self.sum.color_attachments[0].use(location=1)
            d["uImage"].value = 0
            d["uReference"].value = 1
            d["uScale"].value = 1.0
            d["uReferenceScale"].value = self.scale
            d["uMode"].value = 1
            d["uHeatRange"].value = HEAT_RANGE
        else:
            source, scale = (resolved, 1.0) if mode == "splitsum" else (self.sum, self.scale)
            source.color_attachments[0].use(location=0)
            d["uImage"].value = 0
            set_uniform(d, "uReference", 0)
            d["uScale"].value = scale
            set_uniform(d, "uReferenceScale", 1.0)
            d["uMode"].value = 0
        d["uExposure"].value = float(exposure)
        target.use()
        self._quad.draw(d)

    def output(self) -> moderngl.Framebuffer:
        """The internal sRGB8 image of the current size."""
        if self._out is None or self._out.size != self._size:
            _release_fbo(self._out)
            self._out = self.ctx.framebuffer([self.ctx.texture(self._size, 4)])
        return self._out

    def read_image(self) -> np.ndarray:
        """The internal image: (H, W, 3) float sRGB, top row first."""
        w, h = self._size
        raw = self.output().read(components=3, alignment=1)
        return np.frombuffer(raw, np.uint8).reshape(h, w, 3)[::-1].astype(np.float32) / 255.0

    def read_hdr(self, which: str, mode: str, resolved: moderngl.Framebuffer) -> np.ndarray:
        """Linear HDR (H, W, 3), top row first: the reference average, or the split-sum frame
        (kept beside it in difference mode, else the resolved frame)."""
        if which == "reference":
            fbo, scale = self.sum, self.scale
        else:
            fbo, scale = (self.split if mode == "difference" else resolved), 1.0
        w, h = self._size
        raw = fbo.read(components=4, dtype="f4")
        return np.frombuffer(raw, np.float32).reshape(h, w, 4)[::-1, :, :3] * scale

    def read_linear(self, mode: str, resolved: moderngl.Framebuffer) -> np.ndarray:
        """The linear radiance of `mode`'s frame: split sum, the reference average, or in
        difference mode split sum minus reference (signed)."""
        if mode == "difference":
            return self.read_hdr("splitsum", mode, resolved) - \
                self.read_hdr("reference", mode, resolved)
        return self.read_hdr("splitsum" if mode == "splitsum" else "reference", mode, resolved)

    def difference_mean(self, mode: str, resolved: moderngl.Framebuffer) -> float | None:
        """Mean |split sum - reference| of the last difference frame (read back once per frame
        drawn); None in the other modes and before a reference frame."""
        if mode != "difference" or self.frames == 0:
            return None
        if self._difference is None or self._difference[0] != self.drawn:
            mean = float(np.mean(np.abs(self.read_linear("difference", resolved))))
            self._difference = (self.drawn, mean)
        return self._difference[1]

    def release_targets(self) -> None:
        if self.sum is not None:  # framebuffer 0 first, as in SceneTargets.release
            self.ctx.detect_framebuffer(0).use()
        for fbo in (self.sum, self.split, self._out):
            _release_fbo(fbo)
        self.sum = self.split = self._out = None

    def release(self) -> None:
        self.release_targets()
        self._accumulate.release()
        self._display.release()
