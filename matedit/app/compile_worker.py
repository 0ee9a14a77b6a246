"""Compiles materials off the UI thread.

A structural edit hands a snapshot of the document (a deep copy taken on the UI thread, so
later edits cannot change what is being compiled) to one worker thread, which lowers it to IR,
optimises it and writes the GLSL of the viewport's entry variants (FORWARD, and GBUFFER for the
deferred preview). The result comes back to the UI thread as a queued Qt signal; the viewport
then links the small GBUFFER program there (GL stays on its own thread) and swaps it in, drawing
the last good program until then. Each request has a generation number: a newer request
supersedes an older one (a queued one is cancelled, a running one's result is dropped).
"""

from __future__ import annotations

import copy
import dataclasses
import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field

from PySide6.QtCore import QObject, Signal


@dataclass
class CompileResult:
    generation: int
    compiled: object | None = None  # CompiledMaterial
    diagnostics: list = field(default_factory=list)
    error: BaseException | None = None  # a compiler bug, reported as a diagnostic
    ms: float = 0.0


def compile_snapshot(doc, resolver, target: str, compile_fn=None):
    """Compile `doc` for `target` and warm its deferred variant: the work of the worker."""
    from matedit.compiler import compile_document
    from matedit.compiler.emit import Entry

    cm = (compile_fn or compile_document)(doc, resolver, target)
    cm.variant(Entry.GBUFFER)  # the program the deferred viewport links
    return cm


def snapshot_document(doc):
    """A copy of `doc` the worker can read while the UI edits the original: the graph through
    MaterialGraph.copy (no listeners), the rest copied shallowly or deeply as it is mutable."""
    return dataclasses.replace(doc, graph=doc.graph.copy(), preview=copy.deepcopy(doc.preview),
                               extra=copy.deepcopy(doc.extra), link_extra=dict(doc.link_extra))


class CompileWorker(QObject):
    """One background thread; `finished(CompileResult)` arrives on the UI thread."""

    finished = Signal(object)
    _done = Signal(object)  # emitted on the worker thread, delivered queued

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="matedit-compile")
        self.generation = 0
        self._future: Future | None = None
        self._delivered = 0
        self.compile_fn = None  # None: matedit.compiler.compile_document (tests slow it down)
        self._done.connect(self._deliver)

    @property
    def pending(self) -> bool:
        return self._delivered < self.generation

    def submit(self, doc, resolver, target: str) -> int:
        """Queue a compile of a snapshot of `doc`; returns its generation."""
        self.generation += 1
        gen = self.generation
        if self._future is not None:
            self._future.cancel()  # not started yet: never will be
        snapshot = snapshot_document(doc)
        fn = self.compile_fn
        future = self._pool.submit(self._run, gen, snapshot, resolver, target, fn)
        future.add_done_callback(lambda f: None if f.cancelled() else self._done.emit(f.result()))
        self._future = future
        return gen

    @staticmethod
    def _run(gen: int, doc, resolver, target: str, fn) -> CompileResult:
        from matedit.compiler import CompileError

        t0 = time.perf_counter()
        try:
            cm = compile_snapshot(doc, resolver, target, fn)
            return CompileResult(gen, cm, ms=(time.perf_counter() - t0) * 1e3)
        except CompileError as exc:
            return CompileResult(gen, None, list(exc.diagnostics),
                                 ms=(time.perf_counter() - t0) * 1e3)
        except Exception as exc:  # a compiler bug must not take the editor down
            return CompileResult(gen, None, [], exc, ms=(time.perf_counter() - t0) * 1e3)

    def wait(self) -> CompileResult | None:
        """Block until the newest request is done and deliver it now (tests, export, save)."""
        future = self._future
        if future is None or not self.pending:
            return None
        result = future.result()
        self._deliver(result)
        return result

    def supersede(self) -> None:
        """Drop whatever is pending (a synchronous compile took its place)."""
        self.generation += 1
        self._delivered = self.generation
        if self._future is not None:
            self._future.cancel()

    def _deliver(self, result: CompileResult) -> None:
        if result.generation != self.generation or result.generation <= self._delivered:
            return  # superseded by a newer request, or already delivered by wait()
        self._delivered = result.generation
        self.finished.emit(result)

    def shutdown(self) -> None:
        self.supersede()
        self._pool.shutdown(wait=False, cancel_futures=True)
