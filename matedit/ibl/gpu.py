"""The GPU half of the bake: resampling to a cube, GGX prefiltering, the BRDF LUT.

Everything renders with one full-screen triangle into a float32 target and reads the
texels back as numpy arrays, so the results can be cached and tested without a window.
Shaders live in shaders/bake/ and are assembled with `matedit.glsl.include`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import moderngl
import numpy as np

from matedit.glsl.include import assemble
from matedit.resources import shaders_dir
from matedit.shading.sampling import hammersley

GL_TEXTURE_CUBE_MAP_SEAMLESS = 0x884F

# Gauss-Legendre orders of the LUT quadrature (see matedit/ibl/lut.py); the shader's arrays.
LUT_S_NODES = 4
LUT_PHI_NODES = 8

Progress = Callable[[float, str], None]

# Rows of prefilter_ggx.frag's sample table (a std140 block of vec4: 16 KiB, the least
# GL_MAX_UNIFORM_BLOCK_SIZE that OpenGL 3.3 allows); larger sample sets take several draws.
TABLE_ROWS = 1024
# Part of the bake cache's key (matedit/ibl/bake.py): bump when the prefilter's numerics
# change in Python (the sample table, the sample counts) rather than in a shader's text.
PREFILTER_SCHEME = 4
# BakeSettings' default source-mip offset of each sample (ggx_sample_table). Mean relative
# error over the levels against brute force on the studio of benchmarks/bench_ibl.py (256
# samples at mip 1, growth (2, 4); worst texel in brackets): bias 0.5 0.017 (0.47), 0.25
# 0.012 (0.38), 0 0.0095 (0.30). Less blur helps there, but a small bright source (a sun)
# wants some: on a Gaussian spot of 0.03 rad, 0.25 keeps every level's error within 5 % of
# the peak, like 0.5.
DEFAULT_LOD_BIAS = 0.25
# Mips up to this roughness read the nearest source mip of each sample's lod (bilinearly)
# instead of two (trilinear): on llvmpipe 40 % less time for mip 1, about 70 % of the work.
# A narrow lobe's samples mostly sit at lods near 0, and the error hardly moved (studio,
# roughness 1/6: mean 0.044 vs 0.042; the Gaussian spot of test_ibl_prefilter.py, roughness
# 1/5: 2.9 % vs 2.7 % of its peak); at roughness 0.4 and beyond nearest made the spot's
# error up to three times larger.
NEAREST_MIP_ROUGHNESS = 0.2


class BakeShaderError(RuntimeError):
    """A bake shader failed to compile: an internal error, never bad user input."""


def _gauss_legendre01(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return ((x + 1.0) * 0.5).astype(np.float32), (w * 0.5).astype(np.float32)


def samples_for_mip(samples: int, mip: int, growth: int = 4, max_growth: int = 16,
                    grow_after: int = 1) -> int:
    """GGX samples a texel at prefiltered mip `mip` >= 1 (see `Baker.prefilter`)."""
    return int(samples * min(growth ** max(mip - grow_after, 0), max_growth))


def ggx_sample_table(samples: int, roughness: float, source_size: int,
                     lod_bias: float) -> tuple[np.ndarray, float]:
    """The GGX sample set of one prefiltered mip, for prefilter_ggx.frag.

    Returns (rows, nol_sum): rows (k, 4) float32, one per sample of the `samples`-point
    Hammersley set whose L is above the horizon, (L.x, L.y, L.z, lod0) with L in the tangent
    frame of N (L.z = NoL, the sample's weight), and the float64 sum of those weights.
    With N = V = R (docs/shading.md#image-based-lighting) the half vector H of a point is
    importanceSampleGGX's around N and L = reflect(-N, H), the same in every texel's frame.

    lod0 is the sample's source mip (filtered importance sampling, Colbert and Krivanek,
    GPU Gems 3, ch. 20) where the source texel is a face centre's, (2 / source_size)^2 sr:
    0.5 log2(omega_s / omega_p) + lod_bias with omega_s = 1 / (samples pdf) the sample's
    share of the sphere, pdf = D(NoH) NoH / (4 VoH) = D / 4 as NoH = VoH; the shader adds
    -1.5 log2(max |L|), the texel solid angle's variation over a face.
    """
    a = float(roughness) ** 2
    xi = hammersley(np.arange(samples), samples)
    # sampling.glsl importanceSampleGGX, in float64: cos and sin of theta_h, azimuth phi
    phi = 2.0 * np.pi * xi[:, 0]
    a2y = a * a * xi[:, 1]
    denom = np.maximum((1.0 - xi[:, 1]) + a2y, 1e-30)
    cos_h = np.sqrt((1.0 - xi[:, 1]) / denom)
    sin_h = np.sqrt(a2y / denom)
    # L = 2 (N.H) H - N
    nol = 2.0 * cos_h * cos_h - 1.0
    keep = nol > 0.0
    lx = 2.0 * cos_h * sin_h * np.cos(phi)
    ly = 2.0 * cos_h * sin_h * np.sin(phi)
    # GGX D (Karis 2013, eq 3), a = roughness^2
    a2 = a * a
    d = a2 / (np.pi * (cos_h * cos_h * (a2 - 1.0) + 1.0) ** 2)
    omega_s = 1.0 / (samples * 0.25 * np.maximum(d, 1e-300))
    omega_p = 4.0 / float(source_size) ** 2
    lod0 = 0.5 * np.log2(omega_s / omega_p) + lod_bias
    rows = np.stack([lx, ly, nol, lod0], axis=-1)[keep].astype(np.float32)
    return rows, float(nol[keep].sum())


class Baker:
    """Owns the bake programs for one moderngl context, which the caller provides (contexts
    are created in matedit.render or the application, never in this layer)."""

    def __init__(self, ctx: moderngl.Context) -> None:
        if ctx is None:
            raise ValueError("baking needs a moderngl context (matedit.render.headless_context)")
        self.ctx = ctx
        self._programs: dict[tuple[str, str], moderngl.Program] = {}
        self._vaos: dict[tuple[str, str], moderngl.VertexArray] = {}
        self._default_fbo: moderngl.Framebuffer | None = None
        self._table: moderngl.Buffer | None = None

    def close(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        for prog in self._programs.values():
            prog.release()
        self._vaos.clear()
        self._programs.clear()
        if self._table is not None:
            self._table.release()
            self._table = None

    def __enter__(self) -> Baker:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- plumbing -------------------------------------------------------------------------

    def _vao(self, frag: str, defines: str = "") -> tuple[moderngl.Program, moderngl.VertexArray]:
        key = (frag, defines)
        if key not in self._programs:
            root = shaders_dir()
            vert = assemble(
                (root / "bake" / "fullscreen.vert").read_text(), name="bake/fullscreen.vert"
            )
            frag_asm = assemble(
                (root / "bake" / frag).read_text(), name=f"bake/{frag}", prelude=defines
            )
            try:
                prog = self.ctx.program(vertex_shader=vert.text, fragment_shader=frag_asm.text)
            except moderngl.Error as exc:
                raise BakeShaderError(f"bake/{frag}: {frag_asm.map_log(str(exc))}") from exc
            self._programs[key] = prog
            self._vaos[key] = self.ctx.vertex_array(prog, [])
        return self._programs[key], self._vaos[key]

    def _draw(self, vao: moderngl.VertexArray, width: int, height: int) -> np.ndarray:
        """Run `vao` over a width x height float target; (height, width, 4), row 0 = y 0."""
        # Rebind what was bound before releasing our target: moderngl would otherwise
        # restore the deleted framebuffer when it next creates one (GL_INVALID_OPERATION).
        previous = self.ctx.fbo
        if previous is None:
            if self._default_fbo is None:
                self._default_fbo = self.ctx.detect_framebuffer(0)
            previous = self._default_fbo
        viewport = self.ctx.viewport
        tex = self.ctx.texture((width, height), 4, dtype="f4")
        fbo = self.ctx.framebuffer(color_attachments=[tex])
        try:
            fbo.use()
            self.ctx.viewport = (0, 0, width, height)
            self.ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST | moderngl.CULL_FACE)
            vao.render(moderngl.TRIANGLES, vertices=3)
            data = fbo.read(components=4, dtype="f4")
        finally:
            previous.use()
            if viewport is not None:
                self.ctx.viewport = viewport
            fbo.release()
            tex.release()
        return np.frombuffer(data, dtype=np.float32).reshape(height, width, 4).copy()

    def _draw_faces(self, prog: moderngl.Program, vao: moderngl.VertexArray,
                    size: int) -> np.ndarray:
        """Run `vao` for the six faces of a size x size cube, as many side by side in one
        target as the driver allows (uniforms uFaceBase and uSize); (6, size, size, 3)."""
        info = self.ctx.info
        widest = min(int(info["GL_MAX_TEXTURE_SIZE"]), int(info["GL_MAX_VIEWPORT_DIMS"][0]))
        per_draw = max(1, min(6, widest // size))
        out = np.empty((6, size, size, 3), dtype=np.float32)
        self._set(prog, "uSize", size)
        for base in range(0, 6, per_draw):
            count = min(per_draw, 6 - base)
            self._set(prog, "uFaceBase", base)
            strip = self._draw(vao, count * size, size)[..., :3]
            out[base:base + count] = strip.reshape(size, count, size, 3).transpose(1, 0, 2, 3)
        return out

    @staticmethod
    def _set(prog: moderngl.Program, name: str, value) -> None:
        if name in prog:  # the driver may drop uniforms a variant does not use
            prog[name].value = value

    # -- environment -> cube ------------------------------------------------------------------

    def equirect_to_cube(self, image: np.ndarray, size: int) -> np.ndarray:
        """Resample an equirect image (h, w, 3) to cube faces (6, size, size, 3), box-filtered."""
        h, w = image.shape[:2]
        rgb = np.ascontiguousarray(image[..., :3], dtype=np.float32)
        tex = self.ctx.texture((w, h), 3, data=rgb.tobytes(), dtype="f4")
        tex.repeat_x, tex.repeat_y = True, False
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        # Source texels per output texel (equator vs. face centre), rounded up.
        ratio = w / (math.pi * size)
        try:
            return self._to_cube(tex, "", size, max(1, min(8, math.ceil(ratio))))
        finally:
            tex.release()

    def resample_cube(self, faces: np.ndarray, size: int) -> np.ndarray:
        """Resample cube faces (6, n, n, 3) to another face size."""
        n = faces.shape[1]
        if n == size:
            return np.ascontiguousarray(faces[..., :3], dtype=np.float32)
        tex = self.cube_texture(faces, mipmaps=False)
        try:
            return self._to_cube(
                tex, "#define SOURCE_CUBE\n", size, max(1, min(8, math.ceil(n / size)))
            )
        finally:
            tex.release()

    def _to_cube(self, tex, defines: str, size: int, supersample: int) -> np.ndarray:
        prog, vao = self._vao("to_cube.frag", defines)
        self.ctx.enable_direct(GL_TEXTURE_CUBE_MAP_SEAMLESS)
        tex.use(location=0)
        self._set(prog, "uSource", 0)
        self._set(prog, "uSuper", supersample)
        return self._draw_faces(prog, vao, size)

    def cube_texture(self, faces: np.ndarray, mipmaps: bool = True) -> moderngl.TextureCube:
        """Upload faces (6, n, n, 3) as an RGB32F cube map, optionally with a full mip chain."""
        n = faces.shape[1]
        tex = self.ctx.texture_cube((n, n), 3, dtype="f4")
        for face in range(6):
            tex.write(face, np.ascontiguousarray(faces[face, ..., :3], dtype=np.float32).tobytes())
        if mipmaps:
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        else:
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        return tex

    # -- GGX prefiltering ---------------------------------------------------------------------

    def prefilter(
        self,
        faces: np.ndarray,
        levels: int,
        samples: int,
        lod_bias: float = DEFAULT_LOD_BIAS,
        progress: Progress | None = None,
        growth: int = 4,
        max_growth: int = 16,
        grow_after: int = 1,
    ) -> list[np.ndarray]:
        """Mips 0..levels-1 of the prefiltered environment; mip m is for roughness m/(levels-1).

        Mip 0 (roughness 0, a mirror) is the source itself, copied exactly. Mip 1 takes
        `samples` GGX samples a texel, and so do mips up to `grow_after`; each rougher mip,
        with a quarter of the texels, takes `growth` times more, up to `max_growth` times
        `samples`. The
        samples of a mip are one table for all texels (`ggx_sample_table`), and a mip is
        one draw over its six faces (more when the sample set exceeds TABLE_ROWS).
        """
        n = faces.shape[1]
        mips = [np.ascontiguousarray(faces[..., :3], dtype=np.float32)]
        if levels <= 1:
            return mips
        src = self.cube_texture(faces)
        prog, vao = self._vao("prefilter_ggx.frag")
        if self._table is None:
            self._table = self.ctx.buffer(reserve=TABLE_ROWS * 16)
        self._table.bind_to_uniform_block(0)
        prog["SampleTable"].binding = 0
        self.ctx.enable_direct(GL_TEXTURE_CUBE_MAP_SEAMLESS)
        # Work per mip is proportional to its texel count times its samples.
        counts = [samples_for_mip(samples, m, growth, max_growth, grow_after)
                  for m in range(1, levels)]
        work = [6 * max(1, n >> m) ** 2 * counts[m - 1] for m in range(1, levels)]
        done = 0
        try:
            src.use(location=0)
            self._set(prog, "uSource", 0)
            self._set(prog, "uMaxSourceLod", float(int(math.log2(n))))
            for m in range(1, levels):
                size = max(1, n >> m)
                roughness = m / (levels - 1)
                rows, nol_sum = ggx_sample_table(counts[m - 1], roughness, n, lod_bias)
                nearest = roughness <= NEAREST_MIP_ROUGHNESS
                src.filter = (moderngl.LINEAR_MIPMAP_NEAREST if nearest
                              else moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
                self._set(prog, "uScale", 1.0 / max(nol_sum, 1e-30))
                mip = np.zeros((6, size, size, 3), dtype=np.float32)
                # Partial sums of TABLE_ROWS samples each, already scaled, add up.
                for start in range(0, len(rows), TABLE_ROWS):
                    chunk = rows[start:start + TABLE_ROWS]
                    self._table.write(np.ascontiguousarray(chunk).tobytes())
                    self._set(prog, "uCount", len(chunk))
                    mip += self._draw_faces(prog, vao, size)
                mips.append(mip)
                done += work[m - 1]
                if progress:
                    progress(done / sum(work), f"prefilter mip {m}/{levels - 1}")
        finally:
            src.release()
        return mips

    # -- environment BRDF LUT -------------------------------------------------------------------

    def brdf_lut(self, size: int, samples: int, method: str = "quadrature") -> np.ndarray:
        """The (size, size, 3) LUT: [k, i] = (A, B, E_sheen) at roughness (k+.5)/size, NoV
        (i+.5)/size; E_sheen is the Charlie sheen's directional albedo (brdf_lut.frag).

        `samples` is the number of integrand evaluations per texel: with the default
        "quadrature" method it sets the number of panels (samples / 32); "hammersley" is
        the notes' Monte Carlo estimator with that many points, kept for comparison.
        """
        defines = f"#define S_NODES {LUT_S_NODES}\n#define PHI_NODES {LUT_PHI_NODES}\n"
        if method == "hammersley":
            prog, vao = self._vao("brdf_lut.frag", defines + "#define LUT_HAMMERSLEY\n")
            self._set(prog, "uSamples", int(samples))
        elif method == "quadrature":
            prog, vao = self._vao("brdf_lut.frag", defines)
            panels = max(2, round(samples / (LUT_S_NODES * LUT_PHI_NODES)))
            self._set(prog, "uPanels", panels)
        else:
            raise ValueError(f"unknown LUT method {method!r}")
        # The Gauss-Legendre rules of the quadrature; the sheen channel uses them either way.
        xs, ws = _gauss_legendre01(LUT_S_NODES)
        xp, wp = _gauss_legendre01(LUT_PHI_NODES)
        for name, values in (("uNodeS", xs), ("uWeightS", ws), ("uNodePhi", xp),
                             ("uWeightPhi", wp)):
            if name in prog:
                prog[name].write(values.tobytes())
        self._set(prog, "uSize", int(size))
        return self._draw(vao, size, size)[..., :3].copy()
