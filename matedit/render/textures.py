"""Material textures on the GPU: upload (sRGB 8-bit or linear float, mips in linear space) and
the identity of a texture file (path, colour space, size and modification time), so that a value
edit naming the same unchanged file again reads and uploads nothing."""

from __future__ import annotations

import os

import moderngl
import numpy as np

GL_SRGB8_ALPHA8 = 0x8C43
READS = {"count": 0}  # files decoded for upload (tests: a slider drag reads none)


def file_stamp(path: str | None, space: str) -> tuple:
    """What identifies a texture's content: its file (size, modification time) and space."""
    if not path:
        return (None, space)
    try:
        st = os.stat(path)
    except OSError:
        return (str(path), space, None)
    return (os.path.realpath(path), space, st.st_size, st.st_mtime_ns)


def texture_from(ctx: moderngl.Context, path: str | None, space: str = "srgb"
                 ) -> moderngl.Texture:
    """sRGB 8-bit files go to an sRGB internal format (decoded before filtering), their
    mips built in linear space and encoded back; everything else is linear float RGBA,
    decoded on the CPU (matedit.shading.colorspace), mips in linear space."""
    from matedit.compiler.cpu_eval import checker_texture
    from matedit.shading.colorspace import linear_to_srgb, load_texture_cached, mip_chain

    image = None
    if path:
        try:
            image = load_texture_cached(path, space)
            READS["count"] += 1
        except (ValueError, OSError):
            image = None
    linear = image.linear if image is not None else checker_texture(8)
    levels = mip_chain(linear)
    size = (linear.shape[1], linear.shape[0])
    if image is not None and image.srgb8 is not None:
        tex = ctx.texture(size, 4, image.srgb8.tobytes(), dtype="f1",
                          internal_format=GL_SRGB8_ALPHA8)
        tex.build_mipmaps()  # allocates the chain; every level is rewritten below
        for i, lev in enumerate(levels[1:], start=1):
            codes = np.concatenate([linear_to_srgb(lev[..., :3]), lev[..., 3:]], axis=2)
            tex.write(np.rint(codes * 255.0).clip(0, 255).astype(np.uint8).tobytes(),
                      level=i)
    else:
        tex = ctx.texture(size, 4, np.ascontiguousarray(linear, "f4").tobytes(), dtype="f4")
        tex.build_mipmaps()
        for i, lev in enumerate(levels[1:], start=1):
            tex.write(np.ascontiguousarray(lev, "f4").tobytes(), level=i)
    tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    tex.repeat_x = tex.repeat_y = True
    return tex


class TextureCache:
    """A material's textures by name, each with the identity (`file_stamp`) of what it holds:
    naming the same unchanged file in the same space again reads nothing."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self._textures: dict[str, moderngl.Texture] = {}
        self._keys: dict[str, tuple[str | None, str]] = {}  # name: (path, space)
        self._stamps: dict[str, tuple] = {}  # name: file_stamp

    def __getitem__(self, name: str) -> moderngl.Texture:
        return self._textures[name]

    def __contains__(self, name: str) -> bool:
        return name in self._textures

    def set(self, name: str, path: str | None, space: str) -> bool:
        """Loads `path` as texture `name` unless it holds that file already; True if loaded."""
        stamp = file_stamp(path, space)
        if name in self._textures and self._stamps.get(name) == stamp:
            return False
        self._load(name, path, space, stamp)
        return True

    def sync(self, textures) -> None:
        """Keeps the textures of a newly compiled material (IR texture infos): drops the
        others, loads new names, and reloads a kept name whose colour space changed (from the
        path last set for it, which a value edit may have changed since the compile)."""
        from matedit.shading.colorspace import effective_space

        wanted = {t.name: t for t in textures}
        for name in [n for n in self._textures if n not in wanted]:
            self._textures.pop(name).release()
            self._keys.pop(name, None)
            self._stamps.pop(name, None)
        for name, info in wanted.items():
            space = effective_space(getattr(info, "color_space", ""), info.srgb)
            if name in self._textures and self._keys[name][1] == space:
                continue
            path = self._keys[name][0] if name in self._keys else info.path
            self._load(name, path, space, file_stamp(path, space))

    def _load(self, name: str, path: str | None, space: str, stamp: tuple) -> None:
        old = self._textures.pop(name, None)
        if old is not None:
            old.release()
        self._textures[name] = texture_from(self.ctx, path, space)
        self._keys[name] = (path, space)
        self._stamps[name] = stamp

    def release(self) -> None:
        for t in self._textures.values():
            t.release()
        self._textures.clear()
        self._keys.clear()
        self._stamps.clear()
