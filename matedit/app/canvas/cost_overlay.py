"""The canvas's cost overlay (View ▸ Cost Overlay): each node tinted by its share of the
material's instructions, the figures in its tooltip. The figures are `matedit stats`'s for
glsl450 (`matedit.commands.stats.material_stats`: glslang and spirv-opt, a second or two),
computed on a worker thread from a copy of the document, one at a time; a request made while
one runs waits for it and supersedes it (the older answer is dropped).

The worker thread holds no Qt object and calls no Qt: it runs the class's `compute` (a static
function of the document copy) and leaves its answer in a list the overlay's timer polls on the
UI thread. A thread that held the overlay could drop the last reference to a closed window and
destroy its widgets off the UI thread."""

from __future__ import annotations

import copy
import dataclasses
import threading

from PySide6.QtCore import QObject, QTimer, Signal

TARGET = "glsl450"


def document_copy(doc):
    """The document for another thread: its own graph (no listeners), preview and metadata."""
    return dataclasses.replace(doc, graph=doc.graph.copy(), preview=copy.deepcopy(doc.preview),
                               extra=copy.deepcopy(doc.extra))


def node_costs(report: dict) -> dict[str, tuple[float, str]]:
    """node id -> (tint, tooltip text) from one target's figures: the tint is the node's
    instructions over the costliest node's, the text its figures and its share of the whole."""
    total = report["instructions"] or 1
    top = max((r["instructions"] for r in report["nodes"]), default=0.0) or 1.0
    out = {}
    for r in report["nodes"]:
        out[r["id"]] = (r["instructions"] / top,
                        f"Cost ({TARGET}, spirv-opt -O): {r['instructions']:.1f} instructions, "
                        f"{100.0 * r['instructions'] / total:.1f} % of {report['instructions']}"
                        f"\n{r['samples']:.1f} texture samples")
    return out


def _work(compute, doc, answer: list) -> None:
    """The worker thread: `compute(doc)` or the exception it raised, appended to `answer`."""
    try:
        result: object = compute(doc)
    except Exception as exc:  # a graph that does not compile, a missing tool
        result = exc
    answer.append(result)


class CostOverlay(QObject):
    """Computes the figures for a canvas's document off the UI thread; `ready` carries them
    (node id -> (tint, text)), `failed` a one-line reason."""

    ready = Signal(dict)
    computed = Signal(object)  # the report itself (one target's figures), after `ready`
    failed = Signal(str)
    POLL_MS = 50  # how often the UI thread looks for the worker's answer while one runs

    def __init__(self, parent: QObject, document) -> None:
        super().__init__(parent)
        self._document = document  # () -> the canvas's current MaterialDocument
        self.active = False
        self.report: dict | None = None  # the last figures shown
        self._generation = 0
        self._busy = False  # a worker is running: a new request waits for it
        self._pending = False
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(400)  # edits in a burst: one computation after them
        self._timer.timeout.connect(self.request)
        self._answer: list = []  # the running worker's answer, once it has one
        self._answer_gen = 0
        self._poll = QTimer(self)
        self._poll.setInterval(self.POLL_MS)
        self._poll.timeout.connect(self._collect)

    def set_active(self, on: bool) -> None:
        self.active = on
        self._generation += 1  # whatever is under way is no longer wanted
        if on:
            self.request()
        else:
            self._timer.stop()
            self.report = None
            self.ready.emit({})

    def document_changed(self) -> None:
        if self.active:
            self._timer.start()

    def request(self) -> None:
        if not self.active:
            return
        if self._busy:  # one worker at a time: edits in a row never pile up computations
            self._pending = True
            return
        doc = self._document()
        self._generation += 1
        gen = self._generation
        if doc.is_function:
            self.failed.emit("cost overlay: figures are for materials; open one that calls "
                             "this function")
            return
        work = document_copy(doc)
        self._busy = True
        self._answer, self._answer_gen = [], gen
        threading.Thread(target=_work, args=(type(self).compute, work, self._answer),
                         daemon=True, name="matedit-cost-overlay").start()
        self._poll.start()

    @staticmethod
    def compute(doc) -> dict:
        """The report, on the worker thread: glsl450's figures (`StatsService` adds more)."""
        from matedit.interop.stats import material_stats
        from matedit.io.document import FileResolver

        return material_stats(doc, FileResolver(), [TARGET])[TARGET]

    def _collect(self) -> None:
        if not self._answer:
            return
        self._poll.stop()
        self._finished(self._answer_gen, self._answer[0])

    def _finished(self, gen: int, result: object) -> None:
        self._busy = False
        if self._pending:
            self._pending = False
            self.request()
            return
        if gen != self._generation or not self.active:
            return
        if isinstance(result, BaseException):
            self.failed.emit(f"cost overlay: {' '.join(str(result).split())[:160]}")
            return
        assert isinstance(result, dict)
        self.report = result
        self.ready.emit(node_costs(result))
        self.computed.emit(result)
