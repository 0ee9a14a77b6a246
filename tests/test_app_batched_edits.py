"""A macro of many edits (delete everything, duplicate everything, undo either) costs the UI
thread one rebuild of each panel, not one per node: the parameters panel and the selection's
inspector wait for the controller's `batchEnded`. And the free space a pasted group is moved
into is the same shift a plain search finds. Real widgets under Xvfb; counted, never timed
(benchmarks/bench_ui_block.py times these actions)."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import random  # noqa: E402

import pytest  # noqa: E402
from PySide6.QtCore import QPointF, QRectF  # noqa: E402

from matedit.app.canvas import placement  # noqa: E402

pytestmark = pytest.mark.gui


def _plain_offset(rects: list[QRectF], taken: list[QRectF]) -> QPointF:
    """The search written out: every ring's grid shifts nearest first (below, then right, at
    equal distance), each rect grown by GAP against every taken one."""
    def clear(dx: float, dy: float) -> bool:
        return not any(r.translated(dx, dy).adjusted(-placement.GAP, -placement.GAP,
                                                      placement.GAP, placement.GAP).intersects(t)
                       for r in rects for t in taken)

    if not rects or clear(0.0, 0.0):
        return QPointF(0.0, 0.0)
    for ring in range(1, placement.MAX_RINGS + 1):
        spots = {(x, y) for x in range(-ring, ring + 1) for y in (-ring, ring)} | \
            {(x, y) for x in (-ring, ring) for y in range(-ring, ring + 1)}
        for x, y in sorted(spots, key=lambda p: (p[0] ** 2 + p[1] ** 2, -p[1], -p[0])):
            if clear(x * placement.STEP, y * placement.STEP):
                return QPointF(x * placement.STEP, y * placement.STEP)
    return QPointF(0.0, 0.0)


def test_free_offset_finds_the_plain_searchs_shift():
    rng = random.Random(7)
    for case in range(60):
        def rect() -> QRectF:
            return QRectF(rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(80, 260),
                          rng.uniform(40, 200))

        taken = [rect() for _ in range(rng.randint(0, 25))]
        if case % 3 == 0:  # a pasted copy of the taken nodes themselves, as Ctrl+D of all
            rects = [QRectF(t) for t in taken[: rng.randint(1, max(1, len(taken)))]] or [rect()]
        else:
            rects = [rect() for _ in range(rng.randint(1, 6))]
        if case % 7 == 0 and taken:  # touching edges: no overlap of non-zero area
            t = taken[0]
            rects = [QRectF(t.right() + placement.GAP, t.top(), 50, 50)]
        got = placement.free_offset(rects, taken)
        want = _plain_offset(rects, taken)
        assert (got.x(), got.y()) == (want.x(), want.y()), case


@pytest.fixture
def window(qtbot, tmp_path, monkeypatch):
    from graphs_util import EDITOR_SAMPLE

    from matedit.app.main_window import MainWindow

    monkeypatch.setenv("HOME", str(tmp_path))
    w = MainWindow(EDITOR_SAMPLE, restore_layout=False)
    qtbot.addWidget(w)
    w.actions.ask_save_changes = lambda name: "discard"
    return w


def test_deleting_and_duplicating_everything_rebuilds_each_panel_once(window, monkeypatch,
                                                                      qtbot):
    from matedit.app.inspector import InspectorPanel as Inspector
    from matedit.app.parameter_panel import ParameterPanel

    w = window
    canvas = w.canvas
    builds = {"parameters": 0, "inspector": 0}
    real_set, real_rebuild = ParameterPanel.set_parameters, Inspector.rebuild

    def counted_set(self, *a, **k):
        builds["parameters"] += 1
        return real_set(self, *a, **k)

    def counted_rebuild(self, *a, **k):
        builds["inspector"] += 1
        return real_rebuild(self, *a, **k)

    monkeypatch.setattr(ParameterPanel, "set_parameters", counted_set)
    monkeypatch.setattr(Inspector, "rebuild", counted_rebuild)
    graph = w.controller.document.graph
    everything = sorted(graph.nodes)
    panel = w.instances.parameters_panel
    qtbot.waitUntil(lambda: panel.settled)
    params_before = set(panel.rows)
    assert params_before
    assert len(everything) > 5

    canvas.select_nodes(everything)
    builds.update(parameters=0, inspector=0)
    assert canvas.delete_selection()
    assert not graph.nodes
    qtbot.wait(20)  # the Parameters dock's rows are built in an event after the macro's
    # one rebuild each where there used to be one per deleted node
    assert builds["parameters"] <= 1 and builds["inspector"] <= 1, builds
    w.controller.undo_stack.undo()
    assert sorted(graph.nodes) == everything
    qtbot.wait(20)
    assert builds["parameters"] <= 2 and builds["inspector"] <= 2, builds

    canvas.select_nodes(everything)
    builds.update(parameters=0, inspector=0)
    copies = canvas.duplicate_selection()
    assert len(copies) == len(everything)
    qtbot.wait(20)
    assert builds["parameters"] <= 1 and builds["inspector"] <= 1, builds
    # the panels show the document as it is after the macro
    assert set(canvas.selected_ids()) == set(copies)
    # the copies' parameters, under free names
    qtbot.waitUntil(lambda: panel.settled and params_before < set(panel.rows))
    w.controller.undo_stack.undo()
    qtbot.waitUntil(lambda: panel.settled and set(panel.rows) == params_before)


def test_another_documents_layer_rows_come_one_a_turn(window, monkeypatch, qtbot):
    """Opening a layered material: the Layers panel builds its rows one a turn of the event
    loop (a row is ~10 ms of the UI thread), with a timer's events between turns, top layer
    first, selection kept; and the Parameters dock builds its first rows in a turn after
    its own rebuild's."""
    import time

    from PySide6.QtCore import QTimer

    import matedit.app.layers_panel as lp
    from matedit.app.parameter_panel import ParameterPanel
    from matedit.resources import graphs_dir

    w = window
    layers = w.layers
    turns: list[float] = []
    real = lp.LayersPanel._build_rows
    monkeypatch.setattr(lp.LayersPanel, "_build_rows",
                        lambda self, count=0: (turns.append(time.perf_counter()),
                                               real(self, count)))
    built: list[float] = []
    refreshed: list[float] = []
    real_built = ParameterPanel._build_queued
    monkeypatch.setattr(ParameterPanel, "_build_queued",
                        lambda self, count=0: (built.append(time.perf_counter()),
                                               real_built(self, count)))
    panel = w.instances.parameters_panel
    real_refresh = type(panel).refresh
    monkeypatch.setattr(type(panel), "refresh",
                        lambda self, first_now=True: (refreshed.append(time.perf_counter()),
                                                      real_refresh(self, first_now)))
    qtbot.waitUntil(lambda: layers.settled and panel.settled, timeout=20000)
    qtbot.wait(50)
    for stamps in (turns, built, refreshed):
        stamps.clear()
    ticks: list[float] = []
    timer = QTimer()
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start(0)
    assert w.open_material(graphs_dir() / "materials" / "worn_painted_steel.json")
    qtbot.waitUntil(lambda: layers.settled and panel.settled, timeout=20000)
    timer.stop()
    stack = layers.stack
    assert stack is not None and len(stack.layers) == 3
    assert len(turns) >= 3  # one row each
    ids = [layers.list.item(i).data(0x0100) for i in range(layers.list.count())]
    assert ids == layers.layer_ids_top_first()
    for a, b in zip(turns, turns[1:]):
        assert any(a < t < b for t in ticks), (a, b)
    # the dock's one rebuild, then its first rows in a later turn
    assert len(refreshed) == 1 and built and built[0] > refreshed[0]
    assert any(refreshed[0] < t < built[0] for t in ticks)
