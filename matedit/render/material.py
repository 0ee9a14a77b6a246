"""A material's GPU resources: its parameter values in the MaterialParams uniform buffer (a
parameter edit rewrites the buffer, never a program) and its textures (`TextureCache`)."""

from __future__ import annotations

from typing import Any

import moderngl

from matedit.compiler.api import CompiledMaterial
from matedit.glsl.layout import BINDINGS
from matedit.render.fullscreen import set_uniform
from matedit.render.paths import may_be_translucent
from matedit.render.textures import TextureCache

MIN_PARAMS_BYTES = 16  # a material without parameters still binds a buffer


class MaterialResources:
    """The resources of `compiled` (None before the first material): `values` by uniform name."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.compiled: CompiledMaterial | None = None
        self.values: dict[str, Any] = {}
        self.textures = TextureCache(ctx)
        self._params: moderngl.Buffer | None = None
        self._opaque: bool | None = None  # `opaque`, until the material or a value changes

    def load(self, compiled: CompiledMaterial, values: dict[str, Any]) -> None:
        """A newly compiled material with these uniform values: its buffer, its textures."""
        self.compiled = compiled
        self.values = dict(values)
        self._opaque = None
        size = max(MIN_PARAMS_BYTES, len(compiled.pack_uniforms()))
        if self._params is None or self._params.size != size:
            if self._params is not None:
                self._params.release()
            self._params = self.ctx.buffer(reserve=size)
        self._params.write(compiled.pack_uniforms(self.values))
        self.textures.sync(compiled.ir.textures)

    def set_values(self, values: dict[str, Any]) -> None:
        """Updates the material's uniforms among `values` (others are ignored) in the buffer."""
        known = {u.name for u in self.compiled.ir.uniforms}
        self.values.update({k: v for k, v in values.items() if k in known})
        self._opaque = None
        self._params.write(self.compiled.pack_uniforms(self.values))

    @property
    def opaque(self) -> bool:
        """Whether every fragment the material draws has opacity 1 with the current values
        (matedit.render.paths.may_be_translucent, conservative): then the nearest surface
        alone shows, as in the G-buffer. False before the first material."""
        if self._opaque is None:
            self._opaque = self.compiled is not None and \
                not may_be_translucent(self.compiled.ir, self.values)
        return self._opaque

    def texture_space(self, name: str) -> str:
        """The colour space the material sets for texture `name` (srgb when it has none)."""
        from matedit.shading.colorspace import effective_space

        for t in (self.compiled.ir.textures if self.compiled is not None else ()):
            if t.name == name:
                return effective_space(getattr(t, "color_space", ""), t.srgb)
        return "srgb"

    def set_texture(self, name: str, path: str | None, space: str | None = None) -> bool:
        """Texture `name` from `path` (space: the material's by default); True if it loaded."""
        return self.textures.set(name, path, space or self.texture_space(name))

    def bind(self, program: moderngl.Program) -> None:
        """Binds the parameter buffer and the textures, a unit each, for `program`."""
        self._params.bind_to_uniform_block(BINDINGS["MATERIAL"])
        for i, t in enumerate(self.compiled.ir.textures):
            unit = BINDINGS["FIRST_TEXTURE"] + i
            self.textures[t.name].use(location=unit)
            set_uniform(program, t.name, unit)

    def release(self) -> None:
        self.textures.release()
        if self._params is not None:
            self._params.release()
            self._params = None
