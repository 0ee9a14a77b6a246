"""View ▸ Cost Overlay (issue 28): the canvas tints each node by its share of the material's
instructions and puts the figures in its tooltip, computed off the UI thread. The figures read
back from the tooltips are checked against `matedit stats`' own for the same file."""

from __future__ import annotations

import re
import shutil

import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window  # noqa: F401 - fixture

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env"),
              pytest.mark.skipif(not all(shutil.which(t) for t in
                                         ("glslangValidator", "spirv-opt", "spirv-dis")),
                                 reason="glslang-tools and spirv-tools are not installed")]

_FIGURES = re.compile(r"Cost \(glsl450, spirv-opt -O\): ([0-9.]+) instructions, ([0-9.]+) % "
                      r"of (\d+)<br>([0-9.]+) texture samples")


def test_cost_overlay_tints_nodes_and_tooltips_carry_the_figures(qtbot):
    from matedit.commands.stats import material_stats
    from matedit.io.document import FileResolver, load

    expected = material_stats(load(EDITOR_SAMPLE), FileResolver(), ["glsl450"])["glsl450"]
    rows = {r["id"]: r for r in expected["nodes"]}
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    table = w.tabs.canvas_actions
    action = table["cost_overlay"]
    view_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&View")
    assert action in view_menu.actions() and action.isCheckable()
    item = canvas.scene().node_items["mask_noise"]
    plain = item.toolTip()
    assert "Cost (" not in plain

    action.trigger()
    table.refresh(canvas)
    assert action.isChecked()
    # the UI thread is free while the figures are computed: events keep being processed
    qtbot.waitUntil(lambda: bool(canvas.scene().costs), timeout=120_000)
    tip = item.toolTip()
    assert tip.startswith(plain)
    m = _FIGURES.search(tip)
    assert m, tip
    instr, share, total, samples = float(m[1]), float(m[2]), int(m[3]), float(m[4])
    assert total == expected["instructions"]
    assert instr == pytest.approx(rows["mask_noise"]["instructions"], abs=0.05)
    assert share == pytest.approx(100 * instr / total, abs=0.05)
    assert samples == pytest.approx(rows["mask_noise"]["samples"], abs=0.05)
    # the tint is the node's instructions over the costliest node's
    top = max(r["instructions"] for r in expected["nodes"])
    assert item.cost[0] == pytest.approx(rows["mask_noise"]["instructions"] / top)
    assert max(i.cost[0] for i in canvas.scene().node_items.values() if i.cost) == 1.0

    # an edit while the overlay is on: the figures follow it (the noise's node gone, what it
    # fed keeps its own cost, and the material's total drops by about the noise's share)
    from matedit.graph.commands import RemoveNode

    before = canvas.cost_overlay.report
    assert canvas.controller.push(RemoveNode("mask_noise"))
    qtbot.waitUntil(lambda: canvas.cost_overlay.report is not before, timeout=120_000)
    after = canvas.cost_overlay.report
    assert "mask_noise" not in {r["id"] for r in after["nodes"]}
    assert "mask_noise" not in canvas.scene().costs
    assert after["instructions"] < before["instructions"]
    assert before["instructions"] - after["instructions"] == pytest.approx(
        rows["mask_noise"]["instructions"], rel=0.25)

    action.trigger()
    table.refresh(canvas)
    assert not action.isChecked()
    qtbot.waitUntil(lambda: not canvas.scene().costs, timeout=5_000)
    assert all(i.cost is None for i in canvas.scene().node_items.values())


def test_the_worker_thread_holds_no_qt_object_and_the_answer_arrives_on_the_ui_thread(
        qtbot, monkeypatch):
    """The worker runs a static function of a document copy and leaves its answer for the
    overlay's timer: a thread holding the overlay could drop the last reference to a closed
    window and destroy its widgets off the UI thread (a crash in the next test's Qt calls)."""
    import threading

    from PySide6.QtCore import QObject

    from matedit.app.canvas import cost_overlay
    from matedit.io.document import load

    started = threading.Event()
    release = threading.Event()
    seen_threads = []

    def slow_compute(doc):
        seen_threads.append(threading.current_thread())
        started.set()
        release.wait(30)
        return {"instructions": 10, "nodes": [{"id": "n", "instructions": 10.0,
                                               "samples": 0.0}]}

    monkeypatch.setattr(cost_overlay.CostOverlay, "compute", staticmethod(slow_compute))
    owner = QObject()
    doc = load(EDITOR_SAMPLE)
    overlay = cost_overlay.CostOverlay(owner, lambda: doc)
    got = []
    overlay.ready.connect(lambda costs: got.append((threading.current_thread(), costs)))
    overlay.set_active(True)
    assert started.wait(30)
    worker, = [t for t in threading.enumerate() if t.name == "matedit-cost-overlay"]
    held = [worker._target, *worker._args]  # what the thread keeps alive
    assert not any(isinstance(x, QObject) for x in held)
    assert getattr(worker._target, "__self__", None) is None
    release.set()
    qtbot.waitUntil(lambda: bool(got), timeout=10_000)
    assert got[0][0] is threading.main_thread() and set(got[0][1]) == {"n"}
    assert seen_threads[0] is not threading.main_thread()
    owner.deleteLater()
