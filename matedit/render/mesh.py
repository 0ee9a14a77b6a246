"""Preview meshes: generated shapes with tangents, and the user's OBJ files.

`MeshData` is plain numpy (positions, normals, tangents with handedness in w,
UVs, triangle indices); `GpuMesh` uploads it to a moderngl context.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from matedit.io.atomic import UnsafeFileError, read_bounded

MAX_OBJ_BYTES = 256 * 1024 * 1024

BUILTIN_MESHES = ("sphere", "cube", "plane", "cylinder")


class MeshError(ValueError):
    """A mesh that cannot be loaded, naming the file and line."""


@dataclass
class MeshData:
    positions: np.ndarray  # (n, 3) float32
    normals: np.ndarray  # (n, 3)
    tangents: np.ndarray  # (n, 4): xyz tangent along +u, w handedness
    uvs: np.ndarray  # (n, 2)
    indices: np.ndarray  # (m, 3) uint32

    def interleaved(self) -> np.ndarray:
        return np.hstack([self.positions, self.normals, self.tangents, self.uvs]).astype("f4")

    @property
    def radius(self) -> float:
        return float(np.max(np.linalg.norm(self.positions, axis=1))) if len(self.positions) else 1.0


def _normalize(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 1e-12, n, 1.0)


def compute_tangents(p: np.ndarray, n: np.ndarray, uv: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Per-vertex tangents from UV gradients (Lengyel's method), Gram-Schmidt against N."""
    t = np.zeros_like(p)
    b = np.zeros_like(p)
    p0, p1, p2 = p[idx[:, 0]], p[idx[:, 1]], p[idx[:, 2]]
    w0, w1, w2 = uv[idx[:, 0]], uv[idx[:, 1]], uv[idx[:, 2]]
    e1, e2 = p1 - p0, p2 - p0
    d1, d2 = w1 - w0, w2 - w0
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    r = np.where(np.abs(det) > 1e-12, 1.0 / np.where(det == 0, 1, det), 0.0)[:, None]
    sdir = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r
    tdir = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r
    for k in range(3):
        np.add.at(t, idx[:, k], sdir)
        np.add.at(b, idx[:, k], tdir)
    t = t - n * np.sum(n * t, axis=1, keepdims=True)
    fallback = np.cross(n, np.where(np.abs(n[:, 1:2]) < 0.99, [0, 1, 0], [1, 0, 0]))
    bad = np.linalg.norm(t, axis=1) < 1e-8
    t[bad] = fallback[bad]
    t = _normalize(t)
    w = np.where(np.sum(np.cross(n, t) * b, axis=1) < 0.0, -1.0, 1.0)
    return np.hstack([t, w[:, None]])


def _finish(p, n, uv, idx, tangents=None) -> MeshData:
    p = np.asarray(p, np.float32)
    n = _normalize(np.asarray(n, np.float64)).astype(np.float32)
    uv = np.asarray(uv, np.float32)
    idx = np.asarray(idx, np.uint32).reshape(-1, 3)
    tan = tangents if tangents is not None else compute_tangents(
        p.astype(np.float64), n.astype(np.float64), uv.astype(np.float64), idx)
    return MeshData(p, n, np.asarray(tan, np.float32), uv, idx)


def uv_sphere(radius: float = 1.0, segments: int = 64, rings: int = 32) -> MeshData:
    """Y-up sphere; analytic tangents along +u (east), so normal maps read the same everywhere."""
    u = np.linspace(0.0, 1.0, segments + 1)
    v = np.linspace(0.0, 1.0, rings + 1)
    uu, vv = np.meshgrid(u, v)
    phi = uu * 2 * math.pi
    theta = vv * math.pi
    n = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta), -np.sin(theta) * np.sin(phi)], -1)
    tan = np.stack([-np.sin(phi), np.zeros_like(phi), -np.cos(phi)], -1)
    tan4 = np.concatenate([tan, np.ones(tan.shape[:-1] + (1,))], -1)
    idx = []
    w = segments + 1
    for j in range(rings):
        for i in range(segments):
            a, b, c, d = j * w + i, j * w + i + 1, (j + 1) * w + i, (j + 1) * w + i + 1
            idx += [(a, c, b), (b, c, d)]
    uv = np.stack([uu, 1.0 - vv], -1)
    return _finish((n * radius).reshape(-1, 3), n.reshape(-1, 3), uv.reshape(-1, 2), idx,
                   tan4.reshape(-1, 4))


def plane(size: float = 2.0, divisions: int = 1) -> MeshData:
    """A square in XZ facing +Y."""
    s = np.linspace(-size / 2, size / 2, divisions + 1)
    xx, zz = np.meshgrid(s, s)
    p = np.stack([xx, np.zeros_like(xx), zz], -1).reshape(-1, 3)
    uv = np.stack([(xx / size + 0.5), 1.0 - (zz / size + 0.5)], -1).reshape(-1, 2)
    n = np.tile([0.0, 1.0, 0.0], (len(p), 1))
    w = divisions + 1
    idx = []
    for j in range(divisions):
        for i in range(divisions):
            a, b, c, d = j * w + i, j * w + i + 1, (j + 1) * w + i, (j + 1) * w + i + 1
            idx += [(a, c, b), (b, c, d)]
    return _finish(p, n, uv, idx)


def rounded_cube(size: float = 1.6, radius: float = 0.2, divisions: int = 12) -> MeshData:
    """A cube with rounded edges: each face a grid pushed onto a rounded box."""
    half = size / 2
    inner = half - radius
    ps, ns, uvs, idx = [], [], [], []
    axes = [(0, 1, 2, 1), (0, 1, 2, -1), (1, 2, 0, 1), (1, 2, 0, -1), (2, 0, 1, 1), (2, 0, 1, -1)]
    g = np.linspace(-1.0, 1.0, divisions + 1)
    for a, b, c, sign in axes:
        uu, vv = np.meshgrid(g, g)
        cube = np.zeros(uu.shape + (3,))
        cube[..., a] = sign
        cube[..., b] = uu * sign
        cube[..., c] = vv
        pt = cube * half
        core = np.clip(pt, -inner, inner)
        n = _normalize(pt - core)
        p = core + n * radius
        base = len(ps) and sum(len(x) for x in ps)
        ps.append(p.reshape(-1, 3))
        ns.append(n.reshape(-1, 3))
        uvs.append(np.stack([(uu + 1) / 2, (vv + 1) / 2], -1).reshape(-1, 2))
        w = divisions + 1
        for j in range(divisions):
            for i in range(divisions):
                q0, q1 = base + j * w + i, base + j * w + i + 1
                q2, q3 = base + (j + 1) * w + i, base + (j + 1) * w + i + 1
                idx += [(q0, q1, q2), (q1, q3, q2)]
    p = np.concatenate(ps)
    n = np.concatenate(ns)
    idx = np.asarray(idx)
    # make every triangle face outwards
    tri = p[idx]
    face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = np.sum(face_n * n[idx[:, 0]], axis=1) < 0
    idx[flip] = idx[flip][:, [0, 2, 1]]
    return _finish(p, n, np.concatenate(uvs), idx)


def cylinder(radius: float = 0.8, height: float = 1.8, segments: int = 64) -> MeshData:
    """Capped Y-up cylinder."""
    ps, ns, uvs, idx = [], [], [], []
    u = np.linspace(0, 1, segments + 1)
    phi = u * 2 * math.pi
    for k, y in enumerate((-height / 2, height / 2)):
        for i in range(segments + 1):
            ps.append((radius * math.cos(phi[i]), y, -radius * math.sin(phi[i])))
            ns.append((math.cos(phi[i]), 0.0, -math.sin(phi[i])))
            uvs.append((u[i], k))
    w = segments + 1
    for i in range(segments):
        idx += [(i, i + 1, w + i), (i + 1, w + i + 1, w + i)]
    for y, ny in ((-height / 2, -1.0), (height / 2, 1.0)):
        c = len(ps)
        ps.append((0.0, y, 0.0))
        ns.append((0.0, ny, 0.0))
        uvs.append((0.5, 0.5))
        for i in range(segments + 1):
            ps.append((radius * math.cos(phi[i]), y, -radius * math.sin(phi[i])))
            ns.append((0.0, ny, 0.0))
            uvs.append((0.5 + 0.5 * math.cos(phi[i]), 0.5 + 0.5 * math.sin(phi[i])))
        for i in range(segments):
            a, b = c + 1 + i, c + 2 + i
            idx.append((c, a, b) if ny > 0 else (c, b, a))
    return _finish(ps, ns, uvs, idx)


def load_obj(path: str | Path) -> MeshData:
    """Triangulated positions, normals and UVs from a Wavefront OBJ (no code is executed).

    Faces may use v, v/vt, v//vn or v/vt/vn with negative (relative) indices; polygons are
    fanned. Missing normals are computed (smooth), missing UVs are zero.
    """
    path = Path(path)
    try:
        text = read_bounded(path, MAX_OBJ_BYTES).decode("utf-8", errors="strict")
    except FileNotFoundError:
        raise MeshError(f"{path}: file not found") from None
    except UnsafeFileError as exc:
        raise MeshError(str(exc)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MeshError(f"{path}: cannot read as an OBJ text file "
                        f"({getattr(exc, 'strerror', None) or exc})") from None
    vs, vts, vns = [], [], []
    corners: dict[tuple[int, int, int], int] = {}
    out_p, out_uv, out_n, tris = [], [], [], []
    has_n = True
    for lineno, raw in enumerate(text.splitlines(), 1):
        parts = raw.split("#", 1)[0].split()
        if not parts:
            continue
        tag, args = parts[0], parts[1:]
        try:
            if tag == "v":
                vs.append([float(x) for x in args[:3]])
                if len(vs[-1]) != 3:
                    raise ValueError("a vertex needs 3 coordinates")
            elif tag == "vt":
                vts.append([float(x) for x in (args + ["0"])[:2]])
            elif tag == "vn":
                vns.append([float(x) for x in args[:3]])
                if len(vns[-1]) != 3:
                    raise ValueError("a normal needs 3 components")
            elif tag == "f":
                if len(args) < 3:
                    raise ValueError("a face needs at least 3 corners")
                ids = []
                for corner in args:
                    fields = (corner.split("/") + ["", ""])[:3]
                    vi = _obj_index(fields[0], len(vs), "vertex")
                    ti = _obj_index(fields[1], len(vts), "texture coordinate") if fields[1] \
                        else -1
                    ni = _obj_index(fields[2], len(vns), "normal") if fields[2] else -1
                    has_n &= ni >= 0
                    key = (vi, ti, ni)
                    if key not in corners:
                        corners[key] = len(out_p)
                        out_p.append(vs[vi])
                        out_uv.append(vts[ti] if ti >= 0 else [0.0, 0.0])
                        out_n.append(vns[ni] if ni >= 0 else [0.0, 0.0, 0.0])
                    ids.append(corners[key])
                for k in range(1, len(ids) - 1):
                    tris.append((ids[0], ids[k], ids[k + 1]))
        except (ValueError, IndexError) as exc:
            raise MeshError(f"{path}:{lineno}: {exc}: {raw.strip()[:60]!r}") from None
    if not tris:
        raise MeshError(f"{path}: no faces found (is it an OBJ file?)")
    p = np.asarray(out_p, np.float64)
    if not np.all(np.isfinite(p)):
        raise MeshError(f"{path}: vertex positions are not finite")
    idx = np.asarray(tris, np.uint32)
    n = np.asarray(out_n, np.float64)
    uv = np.asarray(out_uv, np.float64)
    if not np.all(np.isfinite(uv)):
        raise MeshError(f"{path}: texture coordinates (vt) are not finite")
    if not np.all(np.isfinite(n)):
        raise MeshError(f"{path}: normals (vn) are not finite")
    if float(np.max(np.abs(p))) > 1e30:
        raise MeshError(f"{path}: vertex positions are too large (beyond 1e30)")
    if not has_n:
        n = np.zeros_like(p)
        fn = np.cross(p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]])
        for k in range(3):
            np.add.at(n, idx[:, k], fn)
    # centre and scale to a unit-ish bounding sphere like the built-in shapes
    centre = (p.min(axis=0) + p.max(axis=0)) / 2
    p = p - centre
    scale = np.max(np.linalg.norm(p, axis=1))
    p = p / (scale if scale > 0 else 1.0)
    return _finish(p, n, uv, idx)


def _obj_index(field: str, count: int, what: str) -> int:
    i = int(field)
    j = i - 1 if i > 0 else count + i
    if not 0 <= j < count:
        raise ValueError(f"{what} index {i} out of range (have {count})")
    return j


def builtin_mesh(name: str) -> MeshData:
    makers = {"sphere": uv_sphere, "cube": rounded_cube, "plane": plane, "cylinder": cylinder}
    if name not in makers:
        raise MeshError(f"unknown mesh {name!r} (expected {', '.join(BUILTIN_MESHES)} or an "
                        ".obj file)")
    return makers[name]()


def mesh_from_spec(spec: str | Path) -> MeshData:
    """`builtin:NAME` or a bare built-in name (text only), else an OBJ file
    (`matedit.io.inputs.builtin_name`: `./sphere` is a file)."""
    from matedit.io.inputs import BuiltinNameError, builtin_name, spellings

    try:
        name = builtin_name(spec, "mesh")
    except BuiltinNameError as exc:
        raise MeshError(str(exc)) from None
    if name is not None:
        return builtin_mesh(name)
    if not os.path.lexists(spec):  # False for a name no file can have
        raise MeshError(f"{spec}: no such file (a mesh is {spellings('mesh')})")
    return load_obj(spec)


class GpuMesh:
    """A mesh's buffers on one moderngl context; vertex arrays cached per program."""

    def __init__(self, ctx, data: MeshData) -> None:
        self.ctx = ctx
        self.data = data
        self.vbo = ctx.buffer(data.interleaved().tobytes())
        self.ibo = ctx.buffer(data.indices.astype("u4").tobytes())
        self._vaos: dict[int, object] = {}

    def vao(self, program):
        key = program.glo
        if key not in self._vaos:
            names = ["a_position", "a_normal", "a_tangent", "a_uv"]
            fmt = []
            used = []
            for name, n in zip(names, (3, 3, 4, 2)):
                if name in program:
                    fmt.append(f"{n}f")
                    used.append(name)
                else:
                    fmt.append(f"{n * 4}x")
            self._vaos[key] = self.ctx.vertex_array(
                program, [(self.vbo, " ".join(fmt), *used)], self.ibo)
        return self._vaos[key]

    def forget(self, program) -> None:
        vao = self._vaos.pop(program.glo, None)
        if vao is not None:
            vao.release()

    def render(self, program) -> None:
        self.vao(program).render()

    def release(self) -> None:
        for v in self._vaos.values():
            v.release()
        self._vaos.clear()
        self.vbo.release()
        self.ibo.release()
