"""Live preview thumbnails on canvas nodes, from the CPU evaluator.

After each edit settles, the material is lowered (not optimised, so every socket
exists) and evaluated with numpy on a small preview sphere, so that masks built
from normals and positions read as well as those built from UVs; each shown
node's first float, vector or MaterialAttributes output becomes a thumbnail:
floats as grey, vectors as colour, MaterialAttributes shaded by the numpy twin of
the shading under a small fixed rig (matedit.shading.thumbnail), all display-encoded
(sRGB). Thumbnails show on pattern nodes (noise, checker, gradient, textures, function
calls, layer stacks: NodeDef.thumbnail) and on the selected nodes, so they do not crowd
the graph; large graphs skip them: previews never slow editing.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, Qt, QTimer, Signal
from PySide6.QtGui import QImage

from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.cpu_nodes import SurfaceArrays
from matedit.compiler.lower import CompileError, lower_document
from matedit.graph import nodes
from matedit.graph.nodes import Role, Thumbnail
from matedit.graph.types import PortType
from matedit.nodes.twin import sphere_surface
from matedit.shading import thumbnail

SIZE = 48
MAX_NODES = 400
BACKGROUND = np.array([0.035, 0.04, 0.05])  # linear; matches the node body once encoded


def preview_sphere(size: int = SIZE) -> tuple[SurfaceArrays, np.ndarray]:
    """The preview sphere (matedit.nodes.twin.sphere_surface) at the thumbnails' size."""
    return sphere_surface(size)


def shaded(attrs: dict, size: int = SIZE) -> np.ndarray:
    """A MaterialAttributes on the preview sphere, shaded by the numpy twin of the shading
    (every lobe) under the thumbnail rig (matedit.shading.thumbnail)."""
    surface, _ = preview_sphere(size)
    N = surface.normal
    T, B = thumbnail.preview_frame(N)
    with np.errstate(all="ignore"):
        return thumbnail.shade_attributes(attrs, N, T, B, surface.view)


def to_image(value, inside: np.ndarray | None = None, size: int = SIZE) -> QImage | None:
    if isinstance(value, dict):
        value = shaded(value, size) if "baseColor" in value else None
    if value is None:
        return None
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 1:
        rgb = np.repeat(a[:, None], 3, axis=1)
    elif a.shape[1] == 2:
        rgb = np.concatenate([a, np.zeros((len(a), 1))], axis=1)
    else:
        rgb = a[:, :3]
    rgb = np.clip(np.nan_to_num(rgb), 0.0, 1.0)
    if inside is not None:
        rgb = np.where(inside[:, None], rgb, BACKGROUND)
    srgb = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)
    pixels = np.ascontiguousarray((srgb * 255 + 0.5).astype(np.uint8).reshape(size, size, 3))
    img = QImage(pixels.data, size, size, 3 * size, QImage.Format.Format_RGB888)
    return img.copy()  # own the pixels


def kind_thumbnail(kind: str, size: int = SIZE) -> QImage | None:
    """A node kind alone, at its defaults: its first float, vector or MaterialAttributes
    output on the preview sphere, as the canvas shows it (the Node Reference's picture).
    None for kinds that need a wire, a function or a texture to make a value."""
    from matedit.graph.model import DocumentKind, MaterialDocument, Node
    from matedit.io.document import FileResolver

    d = nodes.get(kind)
    if d is None or d.role == Role.MATERIAL_OUTPUT:
        return None
    doc = MaterialDocument(kind=DocumentKind.MATERIAL, name="reference")
    doc.graph.nodes["n"] = Node("n", kind, (0.0, 0.0), {s.name: s.default for s in d.settings})
    doc.graph.nodes["out"] = Node("out", nodes.kind_for(Role.MATERIAL_OUTPUT))
    surface, inside = preview_sphere(size)
    probe: dict = {}
    try:
        ir = lower_document(doc, FileResolver())
        with np.errstate(all="ignore"):
            evaluate(ir, surface, textures={}, probe=probe)
    except (CompileError, LookupError, ValueError, KeyError, TypeError, FloatingPointError):
        return None
    n = size * size
    for o in d.outputs:
        value = probe.get(f"n.{o.name}")
        if value is None:
            continue
        if not isinstance(value, dict):
            a = np.asarray(value, dtype=np.float64)
            if a.ndim == 0 or (a.ndim == 1 and len(a) in (2, 3, 4)):  # a constant
                a = np.broadcast_to(a, (n,) + a.shape)
            if a.shape[0] != n or a.ndim > 2 or (a.ndim == 2 and a.shape[1] > 4):
                return None  # not a picture (a matrix, a struct of arrays)
            value = a
        with np.errstate(all="ignore"):
            return to_image(value, inside, size)
    return None


class TextureCache:
    """Texture images for the CPU evaluator, as the viewport samples them: float RGBA, row 0
    at v = 0; 8-bit colour files flagged sRGB decoded to linear. Kept small (thumbnails need
    no detail) and keyed by path and modification time, so an edit re-reads nothing."""

    MAX_SIZE = 128

    def __init__(self) -> None:
        self._cache: dict[tuple, np.ndarray | None] = {}

    def get(self, path: str, srgb: bool) -> np.ndarray | None:
        """The image at `path`, or None (a missing or bad file: the evaluator's checker)."""
        if not path:
            return None
        p = Path(path)
        try:
            key = (str(p), p.stat().st_mtime_ns, bool(srgb))
        except OSError:
            return None
        if key not in self._cache:
            self._cache[key] = self._load(p, srgb)
        return self._cache[key]

    def _load(self, path: Path, srgb: bool) -> np.ndarray | None:
        from matedit.io.images import read_image

        try:
            data = read_image(path)
        except (ValueError, OSError):
            return None
        px = data.pixels
        step = max(1, max(px.shape[:2]) // self.MAX_SIZE)
        px = px[::step, ::step].astype(np.float64)
        if px.shape[2] == 1:
            px = np.repeat(px, 3, axis=2)
        elif px.shape[2] == 2:  # grey and alpha
            px = np.concatenate([np.repeat(px[:, :, :1], 3, axis=2), px[:, :, 1:]], axis=2)
        if px.shape[2] == 3:
            px = np.concatenate([px, np.ones(px.shape[:2] + (1,))], axis=2)
        px = px[:, :, :4]
        if srgb and data.is_ldr:
            c = px[:, :, :3]
            px[:, :, :3] = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
        return np.ascontiguousarray(px[::-1])  # row 0 = v = 0, as the renderer uploads it


class _Delivery(QObject):
    """Carries a worker's thumbnails to the UI thread (queued)."""

    done = Signal(int, object)  # generation, {node id: QImage}


@dataclass(frozen=True)
class _Inputs:
    """What one evaluation reads, taken on the UI thread: the worker never sees the live
    document, which the UI goes on editing."""

    doc: Any
    resolver: Any
    out_types: dict
    selection: frozenset
    analysis: Any = None  # the editor's, when current (not validated again)


def _evaluate(textures: TextureCache, inputs: _Inputs) -> dict[str, QImage]:
    """The thumbnails of `inputs`, on the worker thread. A module function of plain data:
    the work item holds no QObject, so a canvas closed meanwhile is never released (and
    deleted) on the worker thread."""
    doc = inputs.doc
    if doc.is_function or len(doc.graph.nodes) > MAX_NODES:
        return {}
    try:
        ir = lower_document(doc, inputs.resolver, inputs.analysis)
        probe: dict = {}
        surface, inside = preview_sphere()
        images = {t.name: textures.get(t.path, t.srgb) for t in ir.textures}
        evaluate(ir, surface, textures={k: v for k, v in images.items() if v is not None},
                 probe=probe)
    except (CompileError, LookupError, ValueError, KeyError, TypeError,
            FloatingPointError):
        return {}
    out: dict[str, QImage] = {}
    for nid, node in doc.graph.nodes.items():
        d = nodes.get(node.kind)
        shown = d.thumbnail if d is not None else Thumbnail.NEVER  # NodeDef.thumbnail
        if shown == Thumbnail.NEVER or (shown == Thumbnail.SELECTED
                                         and nid not in inputs.selection):
            continue
        for port, t in inputs.out_types.get(nid, {}).items():
            if t.is_numeric or t == PortType.MATERIAL:
                value = probe.get(f"{nid}.{port}")
                if value is not None:
                    img = to_image(value, inside)
                    if img is not None:
                        out[nid] = img
                break
    return out


class NodePreviews(QObject):
    """Keeps the thumbnails of one material canvas up to date. The evaluation runs on a
    worker thread (one at a time; a result older than the last edit is dropped), so that an
    edit never waits for it: on the sample layered material it is 150-250 ms of numpy."""

    def __init__(self, controller, canvas, parent=None) -> None:
        super().__init__(parent)
        self.controller = controller
        self.canvas = canvas
        self.enabled = True
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(120)
        self._timer.timeout.connect(self.refresh)
        controller.structureChanged.connect(self._timer.start)
        controller.valuesChanged.connect(self._values_changed)
        controller.documentReplaced.connect(self._timer.start)
        canvas.selectionChangedIds.connect(self._selected)
        self._selection: set[str] = set()
        self._shown: set[str] = set()
        self.textures = TextureCache()
        self._generation = 0
        self._busy = False  # an evaluation is under way on the worker
        self._delivery = _Delivery(self)
        self._delivery.done.connect(self._apply, Qt.ConnectionType.QueuedConnection)
        self.applied = 0  # results shown (tests)
        self._timer.start()

    def _values_changed(self, _change) -> None:
        """Any value can reach every thumbnail downstream of it: all are evaluated again."""
        self._timer.start()

    def _inputs(self) -> _Inputs:
        from matedit.app.compile_worker import snapshot_document

        a = self.controller.analysis
        out_types = {nid: dict(t) for nid, t in a.out_types.items()} if a is not None else {}
        return _Inputs(snapshot_document(self.controller.document), self.controller.resolver,
                       out_types, frozenset(self._selection),
                       getattr(self.controller, "current_analysis", None))

    def images(self) -> dict[str, QImage]:
        """The thumbnails of the document as it is now, evaluated on this thread."""
        return _evaluate(self.textures, self._inputs())

    def _selected(self, ids: list) -> None:
        self._selection = set(ids)
        self._timer.start()

    def refresh(self) -> None:
        """Evaluates the thumbnails again on the worker; they are shown when it is done
        (`applied` counts the results shown)."""
        self._generation += 1
        if not self.enabled:
            self._apply(self._generation, {})
            return
        if self._busy:  # one evaluation at a time: the newest edit follows this one
            return
        self._busy = True
        gen, inputs = self._generation, self._inputs()
        future = _pool().submit(_evaluate, self.textures, inputs)
        delivery = self._delivery

        def done(f) -> None:
            try:
                images = f.result()
            except Exception:  # noqa: BLE001 - thumbnails are an aid: none this time
                images = {}
            try:
                delivery.done.emit(gen, images)
            except RuntimeError:  # the canvas has gone meanwhile
                pass

        future.add_done_callback(done)

    @property
    def idle(self) -> bool:
        """No evaluation under way or waiting for its timer."""
        return not self._busy and not self._timer.isActive()

    def flush(self) -> None:
        """Starts the evaluation an edit has scheduled now (tests, like the controller's)."""
        if self._timer.isActive():
            self._timer.stop()
            self.refresh()

    def _apply(self, gen: int, images: dict) -> None:
        self._busy = False
        if gen != self._generation:  # an edit came meanwhile: evaluate that instead
            self.refresh()
            return
        for nid in self._shown - set(images):
            self.canvas.set_node_preview(nid, None)
        for nid, img in images.items():
            self.canvas.set_node_preview(nid, img)
        self._shown = set(images)
        self.applied += 1


_POOL: ThreadPoolExecutor | None = None


def _pool() -> ThreadPoolExecutor:
    """The thumbnails' worker thread, one for every canvas (evaluations are short and
    rare; two at once would only share the same cores)."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=1, thread_name_prefix="matedit-previews")
    return _POOL
