"""The renderer's program cache: (structure hash of an entry variant) -> linked program, which
variant a material draws with, and the location of a failed link on the graph's nodes.

A material is linked through one of its entry variants (matedit.compiler.emit.Entry, with the
preview's extra defines); the variant's structure hash covers its whole text, so it is the key.
Deferred, a material draws its GBUFFER entry; forward, its FORWARD entry with split sum only
(the reference estimator is a third of llvmpipe's work) and, in reference mode, the full one.
"""

from __future__ import annotations

import moderngl

from matedit.compiler.api import CompiledMaterial
from matedit.compiler.emit import PREVIEW_DEFINES, SKIP_HIDDEN_LAYERS, Entry
from matedit.glsl.layout import BINDINGS
from matedit.render.deferred import ENERGY_COMPENSATION, SPLIT_SUM_ONLY
from matedit.render.fullscreen import set_uniform
from matedit.render.paths import MaterialStatus
from matedit.shading.views import view_defines

# uniform blocks and samplers a program may declare -> their binding (matedit/glsl/layout.py)
_BLOCKS = (("LightsBlock", "LIGHTS"), ("IblBlock", "IBL"), ("FrameBlock", "FRAME"),
           ("MaterialParams", "MATERIAL"))
_SAMPLERS = (("uPrefilteredEnv", "PREFILTERED_ENV"), ("uBrdfLut", "BRDF_LUT"),
             ("uEnvironment", "ENVIRONMENT"), ("uEnvDistribution", "ENV_DISTRIBUTION"),
             ("uAnisotropyLut", "ANISOTROPY_LUT"))


def failure(compiled: CompiledMaterial, exc: Exception) -> MaterialStatus:
    """The status of a failed link, its errors located on nodes where the log allows."""
    log = str(exc)
    located = compiled.locate_error(log)
    errors = [(node, msg) for node, _, _, msg in located if node and "error" in msg.lower()]
    if not errors:
        errors = [("", next((m for _, _, _, m in located if "error" in m.lower()),
                            log.strip().splitlines()[-1] if log.strip() else log))]
    return MaterialStatus(False, errors, log)


def bind_program(prog: moderngl.Program) -> None:
    """Assigns a new program's uniform blocks and environment samplers their bindings."""
    for block, key in _BLOCKS:
        if block in prog:
            prog[block].binding = BINDINGS[key]
    for sampler, key in _SAMPLERS:
        set_uniform(prog, sampler, BINDINGS[key])


def forward_defines(split_sum_only: bool, compensation: bool) -> tuple[str, ...]:
    """The preview's defines of a FORWARD variant (its layers guarded as the G-buffer's are:
    matedit.compiler.schedule.hidden_layer_guards)."""
    return ((SPLIT_SUM_ONLY,) if split_sum_only else ()) + \
        ((ENERGY_COMPENSATION,) if compensation else ()) + PREVIEW_DEFINES


class ProgramCache:
    """Linked material programs; `bind` assigns a new program's block bindings and units."""

    def __init__(self, ctx: moderngl.Context, bind=bind_program) -> None:
        self.ctx = ctx
        self.table: dict[str, moderngl.Program] = {}
        self.link_count = 0
        self._bind = bind

    def get(self, compiled: CompiledMaterial, entry: Entry,
            defines: tuple[str, ...] = ()) -> tuple[moderngl.Program, CompiledMaterial]:
        """The program of one variant (linked on first use; raises moderngl.Error) and the
        variant itself (for locating errors)."""
        variant = compiled.variant(entry, tuple(defines))
        prog = self.table.get(variant.structure_hash)
        if prog is None:
            try:
                prog = self.ctx.program(vertex_shader=variant.vertex_text,
                                        fragment_shader=variant.fragment_text)
            except moderngl.Error as exc:
                if SKIP_HIDDEN_LAYERS not in defines:
                    raise
                # a driver that names GL_ARB_derivative_control at GLSL 3.30 but refuses
                # its functions there (the extension asks for 4.00): every layer evaluated.
                # A material that fails either way reports this variant's log, which its
                # caller locates in this variant's text.
                try:
                    return self.get(compiled, entry,
                                    tuple(d for d in defines if d != SKIP_HIDDEN_LAYERS))
                except moderngl.Error:
                    raise exc from None
            self.link_count += 1
            self._bind(prog)
            self.table[variant.structure_hash] = prog
        return prog, variant

    def drawn_variant(self, compiled: CompiledMaterial, forward: bool,
                      compensation: bool = False, view: str = "lit") -> CompiledMaterial:
        """The entry variant `material` links for these settings (its text, for reports)."""
        return compiled.variant(*self._variant(forward, compensation, view))

    def material(self, compiled: CompiledMaterial, forward: bool, compensation: bool = False,
                 view: str = "lit") -> moderngl.Program:
        """The program a material draws with (raises moderngl.Error): its GBUFFER entry, or
        forward its split-sum FORWARD variant (with the preview's compensation option and the
        viewport's view, matedit.shading.views; the deferred path's lobe views are the
        lighting pass's)."""
        return self.get(compiled, *self._variant(forward, compensation, view))[0]

    def reference(self, compiled: CompiledMaterial, compensation: bool = False,
                  fallback: moderngl.Program | None = None, view: str = "lit"
                  ) -> moderngl.Program | None:
        """The FORWARD variant with the reference estimator (reference mode, forward path), or
        `fallback` if it fails to link (which the split-sum variant linking rules out)."""
        try:
            return self.get(compiled, Entry.FORWARD,
                            forward_defines(False, compensation) + view_defines(view))[0]
        except moderngl.Error:
            return fallback

    def link(self, compiled: CompiledMaterial, forward: bool, compensation: bool = False,
             view: str = "lit") -> moderngl.Program | MaterialStatus:
        """`material`, or the failed status located in the variant that failed."""
        try:
            return self.material(compiled, forward, compensation, view)
        except moderngl.Error as exc:
            return failure(compiled.variant(*self._variant(forward, compensation, view)), exc)

    @staticmethod
    def _variant(forward: bool, compensation: bool, view: str = "lit"
                 ) -> tuple[Entry, tuple[str, ...]]:
        if forward:
            return Entry.FORWARD, forward_defines(True, compensation) + view_defines(view)
        return Entry.GBUFFER, PREVIEW_DEFINES

    def release(self, forget=None) -> None:
        for p in self.table.values():
            if forget is not None:
                forget(p)
            p.release()
        self.table.clear()
