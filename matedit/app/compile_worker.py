"""Compiles materials off the UI thread.

A structural edit hands a snapshot of the document (a deep copy taken on the UI thread, so
later edits cannot change what is being compiled) to one worker thread, which lowers it to IR,
optimises it and writes the GLSL of the viewport's entry variants (FORWARD, and GBUFFER for the
deferred preview). With `warm_up` on and the viewport's state
(matedit.render.warmup.ViewportState) the worker then has that program linked and drawn once in
a headless context of a helper process (matedit.render.warmup), so that the driver's compiled
shaders are in Mesa's shader cache before the viewport's render process asks for them. It is
off by default: the render process keeps the link and the JIT off the UI thread either way, and
on a quiet machine the warm-up made the edit no sooner (benchmarks/bench_ui_block.py measures
both; 2026-12-05: edit to pixels 325 ms without, 360 ms with) for a process more.
The result comes back to the UI thread as a queued Qt signal; the viewport sends the program
to its render process (matedit.render.server), which links it and swaps it in, drawing the
last good program until then. Each request has a generation number: a newer request supersedes
an older one (a queued one is cancelled, a running one's result is dropped, and a superseded
result is not warmed).
"""

from __future__ import annotations

import copy
import dataclasses
import threading
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


def compile_snapshot(doc, resolver, target: str, compile_fn=None, analysis=None):
    """Compile `doc` for `target` and warm its deferred variant: the work of the worker.
    `analysis`: the editor's analysis of the document the snapshot was taken of, made since
    its last change (DocumentController.current_analysis): the graph is not validated again."""
    from matedit.compiler import compile_document
    from matedit.compiler.emit import PREVIEW_DEFINES, Entry

    if compile_fn is not None:
        cm = compile_fn(doc, resolver, target)
    else:
        cm = compile_document(doc, resolver, target, analysis=analysis)
    cm.variant(Entry.GBUFFER, PREVIEW_DEFINES)  # the program the deferred viewport links
    return cm


def snapshot_document(doc):
    """A copy of `doc` the worker can read while the UI edits the original: the graph through
    MaterialGraph.copy (no listeners), the rest copied shallowly or deeply as it is mutable."""
    return dataclasses.replace(doc, graph=doc.graph.copy(), preview=copy.deepcopy(doc.preview),
                               extra=copy.deepcopy(doc.extra), link_extra=dict(doc.link_extra))


def viewport_textures(cm, doc) -> dict:
    """The texture files the viewport will load for `cm` (what its value push names)."""
    from matedit.app.paths import texture_paths

    return {k: (str(v) if v else None) for k, v in texture_paths(cm, doc).items()}


class CompileWorker(QObject):
    """One background thread; `finished(CompileResult)` arrives on the UI thread.

    `warm_up` (default off; nothing is warmed while MESA_SHADER_CACHE_DISABLE is set) has
    the viewport's programs warmed after each compile when `submit` is given the viewport's
    state (asked from that thread, done in matedit.render.warmup's child process); `warmed`
    lists (generation, asking thread, WarmReply), for tests."""

    finished = Signal(object)
    _done = Signal(object)  # emitted on the worker thread, delivered queued
    warm_up = False  # per instance too (tests, benchmarks/bench_ui_block.py)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="matedit-compile")
        self.generation = 0
        self._future: Future | None = None
        self._delivered = 0
        self.compile_fn = None  # None: matedit.compiler.compile_document (tests slow it down)
        self.warm_fn = None  # None: WarmupClient.warm (tests wrap it)
        self.warmed: list[tuple[int, threading.Thread, object]] = []
        self._warmer = None  # a WarmupClient, used from the worker thread only
        self._done.connect(self._deliver)

    @property
    def pending(self) -> bool:
        return self._delivered < self.generation

    def submit(self, doc, resolver, target: str, viewport=None, analysis=None) -> int:
        """Queue a compile of a snapshot of `doc`; returns its generation. `viewport` (a
        matedit.render.warmup.ViewportState, taken now on the UI thread) asks for a warm-up;
        `analysis` is `doc`'s current one (compile_snapshot)."""
        self.generation += 1
        gen = self.generation
        if self._future is not None:
            self._future.cancel()  # not started yet: never will be
        snapshot = snapshot_document(doc)
        fn = self.compile_fn
        viewport = viewport if self.warming else None
        future = self._pool.submit(self._run, gen, snapshot, resolver, target, fn, viewport,
                                   analysis)
        future.add_done_callback(lambda f: None if f.cancelled() else self._done.emit(f.result()))
        self._future = future
        return gen

    def _run(self, gen: int, doc, resolver, target: str, fn, viewport=None,
             analysis=None) -> CompileResult:
        from matedit.compiler import CompileError

        t0 = time.perf_counter()
        try:
            cm = compile_snapshot(doc, resolver, target, fn, analysis)
        except CompileError as exc:
            return CompileResult(gen, None, list(exc.diagnostics),
                                 ms=(time.perf_counter() - t0) * 1e3)
        except Exception as exc:  # a compiler bug must not take the editor down
            return CompileResult(gen, None, [], exc, ms=(time.perf_counter() - t0) * 1e3)
        result = CompileResult(gen, cm, ms=(time.perf_counter() - t0) * 1e3)
        if viewport is not None and gen == self.generation:  # superseded: not worth warming
            self._warm(gen, cm, doc, viewport)
        return result

    def prepare_warm_up(self) -> None:
        """Starts the warm-up's child process now (it takes seconds to be ready; edits until
        then are not warmed and not held back)."""
        from matedit.render.warmup import WarmupClient

        if self.warming:
            if self._warmer is None:
                self._warmer = WarmupClient()
            self._warmer.start()

    @property
    def warming(self) -> bool:
        """`warm_up`, and Mesa's shader cache on (without it a warm-up only delays)."""
        from matedit.render.warmup import shader_cache_enabled

        return bool(self.warm_up) and shader_cache_enabled()

    @property
    def warm_up_started(self) -> bool:
        return self._warmer is not None

    def warm_up_ready(self, timeout: float = 0.0) -> bool:
        """Whether the warm-up's child is ready (tests; it may wait for a running warm-up)."""
        return self._warmer is not None and self._warmer.wait_ready(timeout)

    def _warm(self, gen: int, cm, doc, viewport) -> None:
        """On the worker thread. Any failure here only loses the warm-up: the UI thread links
        as it would without one (and reports link errors itself)."""
        import dataclasses as dc

        from matedit.render.warmup import WarmupClient

        try:
            state = dc.replace(viewport, textures=viewport_textures(cm, doc))
            if self._warmer is None:
                self._warmer = WarmupClient()
            reply = (self.warm_fn or WarmupClient.warm)(self._warmer, cm, state)
            if reply.starting:
                return  # no warm-up this time: the UI thread links as it did before
            self.warmed.append((gen, threading.current_thread(), reply))
        except Exception:  # noqa: BLE001 - a bad file, a pickling problem: no warm-up
            pass

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
        if self._warmer is not None:  # after a running warm-up, on the worker thread
            try:
                self._pool.submit(self._warmer.close)
            except RuntimeError:  # shut down before
                pass
        self._pool.shutdown(wait=False)  # the pending compile, if any, was cancelled above
