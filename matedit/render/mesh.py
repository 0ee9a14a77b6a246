"""Preview meshes: generated shapes with tangents, and the user's OBJ files.

`MeshData` is plain numpy (positions, normals, tangents with handedness in w,
UVs, triangle indices); `GpuMesh` uploads it to a moderngl context.
"""

from __future__ import annotations

import io
import itertools
import math
import os
import re
from array import array
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from matedit.io.atomic import UnsafeFileError, read_bounded

MAX_OBJ_BYTES = 256 * 1024 * 1024
# A preview mesh has at most 2 million vertices (each of v, vt and vn, and the distinct
# corners the GPU draws) and 2 million triangles after fanning. A scanned asset at preview
# density fits; such a file parses in about 10 s within 1 GB, and llvmpipe draws it in well
# under a second a frame. Counted while parsing, so no file within MAX_OBJ_BYTES (which
# could otherwise list ~100 million corners) grows past it.
MAX_OBJ_VERTICES = 2_000_000
MAX_OBJ_TRIANGLES = 2_000_000

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

    def is_closed(self) -> bool:
        """Whether the triangles bound a solid, wound counter-clockwise seen from outside:
        with vertices welded by position (UV seams split them), every directed edge is used
        exactly once and its reverse once (a closed, consistently oriented 2-manifold), and
        the enclosed signed volume is positive. Then, seen from outside, every back-facing
        point lies behind a front-facing one, and an opaque pass may cull back faces."""
        return _is_closed(self.positions, self.indices)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The axis-aligned bounding box (min, max corners) of the positions."""
        if not len(self.positions):
            return np.zeros(3), np.zeros(3)
        p = np.asarray(self.positions, dtype=np.float64)
        return p.min(axis=0), p.max(axis=0)


def _is_closed(positions: np.ndarray, indices: np.ndarray) -> bool:
    """MeshData.is_closed (vectorised; positions welded on a grid of 1e-6 of the mesh's size,
    so that seams whose copies differ by rounding weld; degenerate triangles, such as a UV
    sphere's at its poles, are left out)."""
    p = np.asarray(positions, dtype=np.float64)
    tri = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    if not len(p) or not len(tri):
        return False
    extent = float(np.max(p.max(axis=0) - p.min(axis=0)))
    if not np.isfinite(extent) or extent <= 0.0:
        return False
    cells = np.round(p / (extent * 1e-6)).astype(np.int64)
    _, weld = np.unique(cells, axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    t = weld[tri]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    if not len(t):
        return False
    n = int(weld.max()) + 1
    a = np.concatenate([t[:, 0], t[:, 1], t[:, 2]])
    b = np.concatenate([t[:, 1], t[:, 2], t[:, 0]])
    edges = np.sort(a * n + b)
    if np.any(edges[1:] == edges[:-1]):  # a directed edge used twice: not a 2-manifold
        return False
    reverse = b * n + a
    pos = np.searchsorted(edges, reverse)
    if np.any(pos >= len(edges)) or np.any(edges[np.minimum(pos, len(edges) - 1)] != reverse):
        return False  # an edge without its opposite: a border, or inconsistent winding
    v0, v1, v2 = (p[tri[:, k]] for k in range(3))
    volume = float(np.einsum("ij,ij->i", v0, np.cross(v1, v2)).sum()) / 6.0
    return volume > 0.0


def _normalize(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 1e-12, n, 1.0)


def compute_tangents(p: np.ndarray, n: np.ndarray, uv: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Per-vertex tangents from UV gradients (Lengyel's method), Gram-Schmidt against N.

    Where the UVs give no direction (coincident or collinear UVs, zero-area triangles) the
    tangent is any unit vector orthogonal to N, so every tangent is finite and unit. The
    triangles are taken a million at a time, which bounds the temporary arrays."""
    t = np.zeros_like(p)
    b = np.zeros_like(p)
    step = 1 << 20
    for lo in range(0, len(idx), step):
        tri = idx[lo:lo + step]
        p0, w0 = p[tri[:, 0]], uv[tri[:, 0]]
        e1, e2 = p[tri[:, 1]] - p0, p[tri[:, 2]] - p0
        d1, d2 = uv[tri[:, 1]] - w0, uv[tri[:, 2]] - w0
        det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
        r = np.zeros_like(det)
        usable = np.abs(det) > 1e-12
        r[usable] = 1.0 / det[usable]
        sdir = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r[:, None]
        tdir = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r[:, None]
        for k in range(3):
            np.add.at(t, tri[:, k], sdir)
            np.add.at(b, tri[:, k], tdir)
    t = t - n * np.sum(n * t, axis=1, keepdims=True)
    fallback = np.cross(n, np.where(np.abs(n[:, 1:2]) < 0.99, [0, 1, 0], [1, 0, 0]))
    bad = ~(np.linalg.norm(t, axis=1) >= 1e-8)  # NaN counts as bad
    t[bad] = fallback[bad]
    t = _normalize(t)
    w = np.where(np.sum(np.cross(n, t) * b, axis=1) < 0.0, -1.0, 1.0)
    return np.hstack([t, w[:, None]])


def _finish(p, n, uv, idx, tangents=None) -> MeshData:
    p = np.asarray(p, np.float32)
    n = _normalize(np.asarray(n, np.float64))
    n[~(np.linalg.norm(n, axis=1) > 0.5)] = (0.0, 1.0, 0.0)  # no direction: face up (+Y)
    n = n.astype(np.float32)
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
    fanned. Missing normals are computed (smooth), missing UVs are zero. The counts are
    bounded while parsing (MAX_OBJ_VERTICES, MAX_OBJ_TRIANGLES), so a file within the read
    limit cannot expand past what a preview draws in seconds.
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
    obj = _ObjParser(path)
    obj.parse(text)
    del text
    obj.release_text()
    corner_of, unique = _distinct_corners(obj.corners())
    if len(unique) > MAX_OBJ_VERTICES:
        raise MeshError(f"{path}: more than {MAX_OBJ_VERTICES:,} distinct vertices (position, "
                        "texture coordinate and normal combinations)")
    idx = corner_of[_fan(obj.faces())]
    vs, vts, vns, has_n = obj.vs, obj.vts, obj.vns, obj.has_normals()
    p = np.frombuffer(vs, np.float64).reshape(-1, 3)[unique[:, 0]]
    uv = np.zeros((len(unique), 2))
    has_uv = unique[:, 1] >= 0
    uv[has_uv] = np.frombuffer(vts, np.float64).reshape(-1, 2)[unique[has_uv, 1]]
    n = np.frombuffer(vns, np.float64).reshape(-1, 3)[unique[:, 2]] if has_n else \
        np.zeros_like(p)
    for values, what in ((p, "vertex positions"), (uv, "texture coordinates (vt)"),
                         (n, "normals (vn)")):
        if not np.all(np.isfinite(values)):
            raise MeshError(f"{path}: {what} are not finite")
        if float(np.max(np.abs(values))) > 1e30:
            raise MeshError(f"{path}: {what} are too large (beyond 1e30)")
    if not has_n:
        fn = np.cross(p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]])
        for k in range(3):
            np.add.at(n, idx[:, k], fn)
    # centre and scale to a unit-ish bounding sphere like the built-in shapes
    centre = (p.min(axis=0) + p.max(axis=0)) / 2
    p = p - centre
    scale = np.max(np.linalg.norm(p, axis=1))
    p = p / (scale if scale > 0 else 1.0)
    return _finish(p, n, uv, idx)


def _limit(path: Path, lineno: int, what: str) -> MeshError:
    return MeshError(f"{path}:{lineno}: {what}: the limit for a preview mesh")


_INT = r"[-+]?[0-9]{1,18}"
# Faces whose corners all share one of the four layouts keep their text, read at the end by
# numpy in one pass; anything else (mixed layouts, odd spellings, huge numbers) is read
# corner by corner. Layout -> (group, fields per corner, the v/vt/vn columns they fill).
_FACE_LAYOUTS = {
    (0, False): (re.compile(rf"{_INT}(?: {_INT})*"), 0),
    (1, False): (re.compile(rf"{_INT}/{_INT}(?: {_INT}/{_INT})*"), 1),
    (2, True): (re.compile(rf"{_INT}//{_INT}(?: {_INT}//{_INT})*"), 2),
    (2, False): (re.compile(rf"{_INT}/{_INT}/{_INT}(?: {_INT}/{_INT}/{_INT})*"), 3),
}
_GROUP_COLUMNS = ([0], [0, 1], [0, 2], [0, 1, 2], [0, 1, 2])
_SLOW = 4
_WHAT = ("vertex", "texture coordinate", "normal")
_HUGE = 1 << 62  # beyond any count the limits allow; kept out of the 64-bit arrays


class _ObjParser:
    """The records of an OBJ as flat arrays, counted against the limits line by line.

    Corners keep the file's index (0: absent) with the record counts of their face, so
    relative indices are resolved, and every index checked, at the end with numpy."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.vs, self.vts, self.vns = array("d"), array("d"), array("d")
        self.texts: tuple[list[str], ...] = ([], [], [], [])  # face corners, by layout
        self.slow = array("q")  # v, vt, vn (0: absent) of the corners read one by one
        self.face_info = array("q")  # per face: corners, group, #v, #vt, #vn, line
        self.triangles = 0
        self.text = ""
        self._raw: np.ndarray | None = None
        self._resolved_cache: tuple | None = None

    def parse(self, text: str) -> None:
        self.text = text
        vs, vts, vns = self.vs, self.vts, self.vns
        info, texts = self.face_info, self.texts
        nv = nt = nn = 0
        split_max = MAX_OBJ_TRIANGLES + 3
        lineno = 0
        for lineno, line in enumerate(io.StringIO(text, newline=None), 1):
            if "#" in line:
                line = line.split("#", 1)[0]
            # At most the corners one more face may have are split out: a longer face is
            # refused below without its corners ever being listed.
            parts = line.split(None, split_max)
            if not parts:
                continue
            tag = parts[0]
            try:
                if tag == "f":
                    n = len(parts) - 1
                    if n < 3:
                        raise ValueError("a face needs at least 3 corners")
                    self.triangles += n - 2
                    if self.triangles > MAX_OBJ_TRIANGLES:
                        raise _limit(self.path, lineno, f"more than {MAX_OBJ_TRIANGLES:,} "
                                     "triangles after the polygons are fanned")
                    split_max = max(MAX_OBJ_TRIANGLES - self.triangles + 3, 8)
                    first = parts[1]
                    layout = _FACE_LAYOUTS.get((first.count("/"), "//" in first))
                    joined = " ".join(parts[1:]) if layout else ""
                    if layout and layout[0].fullmatch(joined):
                        group = layout[1]
                        texts[group].append(joined)
                    else:
                        group = _SLOW
                        self._slow_corners(parts[1:])
                    info.extend((n, group, nv, nt, nn, lineno))
                elif tag == "v":
                    if len(parts) < 4:
                        raise ValueError("a vertex needs 3 coordinates")
                    vs.extend((float(parts[1]), float(parts[2]), float(parts[3])))
                    nv += 1
                    if nv > MAX_OBJ_VERTICES:
                        raise _limit(self.path, lineno,
                                     f"more than {MAX_OBJ_VERTICES:,} vertices")
                elif tag == "vt":
                    if len(parts) < 2:
                        raise ValueError("a texture coordinate needs a value")
                    vts.extend((float(parts[1]), float(parts[2]) if len(parts) > 2 else 0.0))
                    nt += 1
                    if nt > MAX_OBJ_VERTICES:
                        raise _limit(self.path, lineno,
                                     f"more than {MAX_OBJ_VERTICES:,} texture coordinates")
                elif tag == "vn":
                    if len(parts) < 4:
                        raise ValueError("a normal needs 3 components")
                    vns.extend((float(parts[1]), float(parts[2]), float(parts[3])))
                    nn += 1
                    if nn > MAX_OBJ_VERTICES:
                        raise _limit(self.path, lineno,
                                     f"more than {MAX_OBJ_VERTICES:,} normals")
            except (ValueError, OverflowError) as exc:
                if isinstance(exc, MeshError):
                    raise
                self._check_indices()  # an earlier bad index is the first error
                raise MeshError(f"{self.path}:{lineno}: {exc}: "
                                f"{line.strip()[:60]!r}") from None
        self._check_indices()

    def _slow_corners(self, corners: list[str]) -> None:
        fields = [(corner.split("/") + ["", ""])[:3] for corner in corners]
        values = [[int(x) if x else 0 for x in f] for f in fields]
        if any(not f[0] for f in fields):
            raise ValueError("a face corner needs a vertex index")
        for corner in values:
            for f, value in enumerate(corner):
                if abs(value) > _HUGE:
                    raise ValueError(f"{_WHAT[f]} index {value} out of range")
        for corner in values:
            self.slow.extend(corner)

    def corner_count(self) -> int:
        return int(np.frombuffer(self.face_info, np.int64).reshape(-1, 6)[:, 0].sum())

    def raw(self) -> np.ndarray:
        """(corners, 3): each corner's v, vt, vn index as written (0: absent), file order."""
        if self._raw is not None and len(self._raw) == self.corner_count():
            return self._raw
        info = np.frombuffer(self.face_info, np.int64).reshape(-1, 6)
        count = info[:, 0]
        start = np.cumsum(count) - count
        raw = np.zeros((int(count.sum()), 3), np.int64)
        for group, columns in enumerate(_GROUP_COLUMNS):
            faces = np.nonzero(info[:, 1] == group)[0]
            if not len(faces):
                continue
            if group == _SLOW:
                values = np.frombuffer(self.slow, np.int64)
            else:
                values = np.fromstring(" ".join(self.texts[group]).replace("/", " "),
                                       dtype=np.int64, sep=" ")
            n = count[faces]
            ids = np.repeat(start[faces] - (np.cumsum(n) - n), n) + np.arange(int(n.sum()))
            raw[np.ix_(ids, columns)] = values.reshape(-1, len(columns))
        self._raw = raw
        return raw

    def release_text(self) -> None:
        """Drop the file's text and the faces' text once the corners are arrays."""
        self.raw()
        self.text = ""
        self.texts = ([], [], [], [])
        self.slow = array("q")

    def _resolved(self):
        """Per corner: its face, each field's 0-based index (-1: absent or invalid), and a
        mask of the indices that are out of range, per field."""
        if self._resolved_cache is not None and self._resolved_cache[0] == len(self.face_info):
            return self._resolved_cache[1]
        info = np.frombuffer(self.face_info, np.int64).reshape(-1, 6)
        face = np.repeat(np.arange(len(info)), info[:, 0])
        raw = self.raw()
        out, bad = [], []
        for f in range(3):
            r = raw[:, f]
            have = info[face, 2 + f]
            j = np.where(r > 0, r - 1, have + r)
            wrong = (j < 0) | (j >= have)
            if f:
                wrong &= r != 0
            out.append(np.where(wrong | (r == 0), -1, j))
            bad.append(wrong)
        self._resolved_cache = (len(self.face_info), (info, face, out, bad))
        return info, face, out, bad

    def _check_indices(self) -> None:
        """Raise the first out-of-range index in file order, naming the corner's line."""
        if not len(self.face_info):
            return
        info, face, _, bad = self._resolved()
        any_bad = bad[0] | bad[1] | bad[2]
        if not any_bad.any():
            return
        c = int(np.argmax(any_bad))
        f = next(k for k in range(3) if bad[k][c])
        value = int(self.raw()[c, f])
        have = int(info[face[c], 2 + f])
        lineno = int(info[face[c], 5])
        line = next(itertools.islice(io.StringIO(self.text, newline=None), lineno - 1, None))
        raise MeshError(f"{self.path}:{lineno}: {_WHAT[f]} index {value} out of range "
                        f"(have {have}): {line.split('#', 1)[0].strip()[:60]!r}")

    def corners(self) -> np.ndarray:
        if not self.triangles:
            raise MeshError(f"{self.path}: no faces found (is it an OBJ file?)")
        _, _, out, _ = self._resolved()
        return np.stack(out, axis=1)

    def faces(self) -> np.ndarray:
        """(faces, 2): each face's first corner and its corner count."""
        count = np.frombuffer(self.face_info, np.int64).reshape(-1, 6)[:, 0]
        return np.stack([np.cumsum(count) - count, count], axis=1)

    def has_normals(self) -> bool:
        return bool(np.all(self.raw()[:, 2] != 0))


def _distinct_corners(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(output vertex of each corner, the distinct (v, vt, vn) rows), numbered in order of
    first appearance, as the file lists them."""
    c = corners.astype(np.int64)
    span = c.max(axis=0) + 2  # -1 (absent) .. max
    if float(span[0]) * float(span[1]) * float(span[2]) < 2.0 ** 62:
        key = ((c[:, 0] + 1) * span[1] + (c[:, 1] + 1)) * span[2] + (c[:, 2] + 1)
        _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    else:
        _, first, inverse = np.unique(c, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return rank[inverse.reshape(-1)], c[first[order]]


def _fan(faces: np.ndarray) -> np.ndarray:
    """Triangles (first, k, k + 1) of each face's corners, as corner numbers."""
    start, count = faces[:, 0].astype(np.int64), faces[:, 1].astype(np.int64)
    per = count - 2
    face = np.repeat(np.arange(len(faces)), per)
    k = np.arange(int(per.sum())) - np.repeat(np.cumsum(per) - per, per) + 1
    base = start[face]
    return np.stack([base, base + k, base + k + 1], axis=1)


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
        self._closed: bool | None = None
        self._bounds: tuple[np.ndarray, np.ndarray] | None = None
        self._sphere: tuple[np.ndarray, float] | None = None

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

    @property
    def closed(self) -> bool:
        """MeshData.is_closed, computed once (at the first frame that asks)."""
        if self._closed is None:
            self._closed = self.data.is_closed()
        return self._closed

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """MeshData.bounds, computed once."""
        if self._bounds is None:
            self._bounds = self.data.bounds()
        return self._bounds

    def seen_from_outside(self, camera, aspect: float) -> bool:
        """Whether no point of the mesh's bounding box lies within the near plane's reach of
        `camera` (an OrbitCamera: eye, fov, near) at this aspect: then the eye is outside
        the mesh and nothing of it is clipped open by the near plane."""
        lo, hi = self.bounds
        eye = np.asarray(camera.eye, dtype=np.float64)
        gap = float(np.linalg.norm(np.maximum(np.maximum(lo - eye, eye - hi), 0.0)))
        tan = math.tan(math.radians(camera.fov) / 2.0)
        # the farthest a point of the near plane's rectangle lies from the eye
        reach = camera.near * math.sqrt(1.0 + tan * tan * (1.0 + aspect * aspect))
        return gap > 2.0 * reach

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """(centre, radius) of a sphere holding every vertex (so every triangle): the centre
        of the bounding box and the farthest vertex from it, computed once."""
        if self._sphere is None:
            lo, hi = self.bounds
            centre = (lo + hi) / 2.0
            p = np.asarray(self.data.positions, dtype=np.float64).reshape(-1, 3)
            radius = float(np.sqrt(((p - centre) ** 2).sum(axis=1).max())) if len(p) else 0.0
            self._sphere = (centre, radius * (1.0 + 1e-6))
        return self._sphere

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
