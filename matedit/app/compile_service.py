"""Compiles the open material after each structural edit, and reads uniform values.

One place turns `structureChanged` into a `CompiledMaterial` (glsl330 for the
viewport; other targets on demand for the code view and export) or into
diagnostics. Value edits never come here: `uniform_values` reads the current
numbers for a compiled material's uniforms straight from the document, under
the compiler's names (`p_<parameter>`, `u_<node>_<port>`).
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from typing import Any

from PySide6.QtCore import QObject, QTimer, Signal

from matedit.app.controller import DocumentController
from matedit.app.node_preview import PreviewTarget, preview_document
from matedit.compiler import CompiledMaterial, CompileError, compile_document
from matedit.graph.model import MaterialDocument
from matedit.graph.types import PortType, coerce_value
from matedit.graph.validate import Diagnostic, Severity

VIEWPORT_TARGET = "glsl330"


def uniform_values(compiled: CompiledMaterial, doc: MaterialDocument,
                   uniforms: Iterable[Any] | None = None) -> dict[str, Any]:
    """Current values of the compiled material's uniforms (or of `uniforms`, some of them),
    from the document."""
    out: dict[str, Any] = {}
    for u in compiled.ir.uniforms if uniforms is None else uniforms:
        node = doc.graph.nodes.get(u.node)
        value = node.values.get(u.port, u.default) if node is not None else u.default
        try:
            out[u.name] = coerce_value(PortType(u.type.value), value)
        except (ValueError, TypeError):
            out[u.name] = u.default
    return out


def uniforms_by_port(compiled: CompiledMaterial) -> dict[tuple[str, str], list[Any]]:
    """The compiled material's uniforms by the (node, port) whose value each reads: a value
    edit sets those and no other."""
    out: dict[tuple[str, str], list[Any]] = {}
    for u in compiled.ir.uniforms:
        out.setdefault((u.node, u.port), []).append(u)
    return out


class MaterialCompiler(QObject):
    """Recompiles on `structureChanged`; emits `compiled` or `failed(diagnostics)`.

    With `asynchronous` (the editor sets it; matedit.app.app.run) a structural edit compiles on
    a worker thread (matedit.app.compile_worker) and the signals come when it is done; reading
    `current`, `last_good`, `diagnostics` or `last_compile_ms` first waits for a pending result
    (`latest` does not). `recompile()` called directly is always synchronous.

    The last good material belongs to the document: opening or creating another one forgets
    it (`documentChanged`), so a document that never compiled has none to stand in for it."""

    compiled = Signal(object)  # CompiledMaterial
    failed = Signal(list)  # list[Diagnostic]
    documentChanged = Signal()  # another document: nothing compiled for it yet
    previewChanged = Signal(object)  # PreviewTarget | None: the viewport shows that socket
    asynchronous = False
    # the viewport's state for the worker's warm-up (ViewportPanel sets it): a callable giving a
    # matedit.render.warmup.ViewportState, or None while the viewport has no renderer
    viewport_state = None

    def __init__(self, controller: DocumentController, parent=None) -> None:
        super().__init__(parent)
        self.controller = controller
        self._current: CompiledMaterial | None = None
        self._last_good: CompiledMaterial | None = None
        self._diagnostics: list[Diagnostic] = []
        self._last_compile_ms = 0.0
        self._cache: dict[str, CompiledMaterial] = {}
        self.preview: PreviewTarget | None = None
        self.worker = None
        # Another document's first compile starts on this timer, after the event that opened
        # or showed it (the canvas built, the tab shown, its first paint): the worker thread's
        # Python would otherwise take turns with that event's for the interpreter lock and
        # stretch it (asynchronous only; `_settled` starts it at once when asked)
        self._first = QTimer(self)
        self._first.setSingleShot(True)
        self._first.setInterval(1)
        self._first.timeout.connect(self._submit)
        self._defer_next = False
        controller.structureChanged.connect(self._structure_changed)
        controller.documentReplaced.connect(self._document_replaced)

    def _document_replaced(self) -> None:
        """Another document: what was compiled for the previous one is not its own (a pending
        compile of it is dropped); the compile that follows starts afresh."""
        if self.worker is not None:
            self.worker.supersede()
        self._current = self._last_good = None
        self._diagnostics = []
        self._cache.clear()
        self._defer_next = True
        self.set_preview(None, recompile=False)
        self.documentChanged.emit()

    # what a pending compile will replace: wait for it first
    def _settled(self, name: str):
        if self._first.isActive():  # asked before the deferred first compile started
            self._first.stop()
            self._submit()
        if self.worker is not None and self.worker.pending:
            self.worker.wait()
        return getattr(self, name)

    current = property(lambda self: self._settled("_current"),
                       lambda self, v: setattr(self, "_current", v))
    last_good = property(lambda self: self._settled("_last_good"),
                         lambda self, v: setattr(self, "_last_good", v))
    diagnostics = property(lambda self: self._settled("_diagnostics"),
                           lambda self, v: setattr(self, "_diagnostics", v))
    last_compile_ms = property(lambda self: self._settled("_last_compile_ms"),
                               lambda self, v: setattr(self, "_last_compile_ms", v))

    @property
    def latest(self) -> CompiledMaterial | None:
        """The newest compiled material delivered so far (never waits)."""
        return self._current or self._last_good

    def _structure_changed(self) -> None:
        defer, self._defer_next = self._defer_next, False
        if not self.asynchronous:
            self.recompile()
            return
        if defer:
            self._first.start()
            return
        self._submit()

    def _submit(self) -> None:
        """The viewport's document to the compile worker (asynchronous)."""
        self._first.stop()
        doc = self._viewport_document()
        if doc.is_function:
            self.recompile()
            return
        if self.worker is None:
            from matedit.app.compile_worker import CompileWorker

            self.worker = CompileWorker(self)
            self.worker.finished.connect(self._finished)
        state = self.viewport_state() if self.viewport_state is not None else None
        if state is not None and self.worker.warming and not self.worker.warm_up_started:
            self.worker.prepare_warm_up()  # ready for the next edits
        # the controller's analysis, when it is of this very document as it is now: the
        # worker does not validate the graph again
        analysis = self.controller.current_analysis if doc is self.controller.document else None
        self.worker.submit(doc, self.controller.resolver, VIEWPORT_TARGET, state, analysis)

    def _finished(self, result) -> None:
        """A worker's result, on the UI thread: the same outcome as a synchronous compile."""
        self._cache.clear()
        self._last_compile_ms = result.ms
        if result.compiled is None:
            self._current = None
            if result.error is not None:
                exc = result.error
                self._diagnostics = [Diagnostic(Severity.ERROR, f"internal compiler error: "
                                                f"{type(exc).__name__}: {exc}")]
            else:
                self._diagnostics = list(result.diagnostics)
            self.failed.emit(self._diagnostics)
            return
        self._diagnostics = []
        self._current = self._last_good = result.compiled
        self._cache[VIEWPORT_TARGET] = result.compiled
        self.compiled.emit(result.compiled)

    # --- preview any node ------------------------------------------------------------------
    def set_preview(self, target: PreviewTarget | None, recompile: bool = True) -> bool:
        """Show `target` in the viewport instead of the material (None: the material again).
        A structural change for the viewport; the document is not touched."""
        if target is not None and self._preview_type(target) is None:
            return False
        if target == self.preview:
            return True
        self.preview = target
        self.previewChanged.emit(target)
        if recompile:
            self.recompile()
        return True

    def _preview_type(self, target: PreviewTarget) -> PortType | None:
        a = self.controller.analysis
        t = a.out_types.get(target.node_id, {}).get(target.port) if a is not None else None
        if t is None or not (t.is_numeric or t == PortType.MATERIAL):
            return None
        return t

    def _viewport_document(self) -> MaterialDocument:
        """The document the viewport compiles: the material, or a copy showing the preview."""
        doc = self.controller.document
        if self.preview is None:
            return doc
        t = self._preview_type(self.preview)
        if t is None:  # the node went away or changed type: back to the material
            self.preview = None
            self.previewChanged.emit(None)
            return doc
        return preview_document(doc, self.preview, t)

    def recompile(self) -> CompiledMaterial | None:
        if self.worker is not None:
            self.worker.supersede()  # this compile is newer than any pending one
        doc = self.controller.document
        self._cache.clear()
        self.current = None
        if doc.is_function:
            self.diagnostics = []
            return None
        t0 = time.perf_counter()
        shown = self._viewport_document()
        try:
            analysis = self.controller.current_analysis \
                if shown is self.controller.document else None
            cm = compile_document(shown, self.controller.resolver, VIEWPORT_TARGET,
                                  analysis=analysis)
        except CompileError as exc:
            self.diagnostics = list(exc.diagnostics)
            self.last_compile_ms = (time.perf_counter() - t0) * 1e3
            self.failed.emit(self.diagnostics)
            return None
        except Exception as exc:  # a compiler bug must not take the editor down
            self.diagnostics = [Diagnostic(Severity.ERROR, f"internal compiler error: "
                                           f"{type(exc).__name__}: {exc}")]
            self.failed.emit(self.diagnostics)
            return None
        self.last_compile_ms = (time.perf_counter() - t0) * 1e3
        self.diagnostics = []
        self.current = self.last_good = cm
        if shown is doc:  # exports and the code view want the material, never a preview
            self._cache[VIEWPORT_TARGET] = cm
        self.compiled.emit(cm)
        return cm

    def for_target(self, target: str) -> CompiledMaterial:
        """The current document compiled for `target` (raises CompileError)."""
        hit = self._cache.get(target)
        if hit is None:
            hit = compile_document(self.controller.document, self.controller.resolver, target)
            self._cache[target] = hit
        return hit

    def uniforms(self) -> dict[str, Any]:
        cm = self.current or self.last_good
        return uniform_values(cm, self.controller.document) if cm else {}
