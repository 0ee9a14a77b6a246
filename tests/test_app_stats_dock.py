"""The Stats dock, the Layers panel's cost column and the cost budget in Diagnostics (issue
28). The figures shown are read back and compared with `matedit stats`' own for the same file,
computed here independently of the window."""

from __future__ import annotations

import shutil

import pytest
from test_app_support import app_env, make_window  # noqa: F401 - fixture

from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env"),
              pytest.mark.skipif(not all(shutil.which(t) for t in
                                         ("glslangValidator", "spirv-opt", "spirv-dis")),
                                 reason="glslang-tools and spirv-tools are not installed")]

SAMPLE = graphs_dir() / "materials" / "worn_painted_steel.json"  # a layer stack, a switch


@pytest.fixture(scope="module")
def expected():
    from matedit.interop.stats import ALL_TARGETS, material_stats, permutations
    from matedit.io.document import FileResolver, load

    doc = load(SAMPLE)
    return material_stats(doc, FileResolver(), list(ALL_TARGETS)), \
        permutations(doc, FileResolver())


def _open_stats(qtbot, w):
    dock = w.stats.dock
    view_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&View")
    assert dock.toggleViewAction() in view_menu.actions()
    assert not w.stats.service.active  # tabbed behind History, not shown: nothing computed
    dock.show()
    dock.raise_()
    qtbot.waitUntil(lambda: w.stats.panel.report is not None, timeout=180_000)
    return w.stats.panel


def test_stats_dock_shows_every_target_and_the_permutations(qtbot, expected):
    per_target, perms = expected
    w = make_window(qtbot, SAMPLE, show=True)
    panel = _open_stats(qtbot, w)
    rows = {panel.totals.topLevelItem(i).text(0): panel.totals.topLevelItem(i)
            for i in range(panel.totals.topLevelItemCount())}
    assert set(rows) == set(per_target)
    cols = {name: k for k, name in enumerate(panel.totals.headerItem().text(c)
                                             for c in range(panel.totals.columnCount()))}
    for t, f in per_target.items():
        it = rows[t]
        assert int(it.text(cols["instructions"])) == f["instructions"], t
        assert int(it.text(cols["static"])) == f["static"]["instructions"], t
        for col, key in (("ALU", "alu"), ("texture", "texture"), ("memory", "memory"),
                         ("control", "control"), ("samples", "samples"),
                         ("samplers", "samplers"), ("uniform bytes", "uniform_bytes"),
                         ("varyings", "varyings")):
            assert int(it.text(cols[col])) == f[key], (t, col)
    assert panel.perms.topLevelItemCount() == len(perms["variants"]) == 2
    got = sorted(int(panel.perms.topLevelItem(i).text(1)) for i in range(2))
    assert got == sorted(v["instructions"] for v in perms["variants"])

    # the Layers panel's cost column: each row's figure is its layer's, with its share
    g = per_target["glsl450"]
    layers = {lay["id"]: lay for lay in g["layers"]}
    lp = w.layers
    assert lp.list.count() == len(layers) >= 2
    for i in range(lp.list.count()):
        row = lp.list.itemWidget(lp.list.item(i))
        lay = layers[row.layer_id]
        share = float(row.cost.text().rstrip(" %"))
        assert share == pytest.approx(100 * lay["instructions"] / g["instructions"], abs=0.5)
        tip = row.cost.toolTip()
        instr, pct = float(tip.split(" instructions")[0]), tip.split(": ")[1].split(" %")[0]
        assert instr == pytest.approx(lay["instructions"], abs=0.05), tip
        assert float(pct) == pytest.approx(100 * lay["instructions"] / g["instructions"],
                                           abs=0.05)

    # a structural edit: the dock and the column follow it, off the UI thread
    before = panel.report
    top = lp.layer_ids_top_first()[0]
    assert lp.remove_layer(top)
    qtbot.waitUntil(lambda: panel.report is not before, timeout=180_000)
    assert top not in {lay["id"] for lay in panel.report["layers"]}
    assert panel.report["instructions"] < before["instructions"]
    assert all(lp.list.itemWidget(lp.list.item(i)).cost.text()
               for i in range(lp.list.count()))


def test_budget_warning_in_diagnostics(qtbot, expected):
    from PySide6.QtCore import QSettings

    from matedit.app.stats_dock import SAMPLERS_KEY

    per_target, _ = expected
    n = per_target["essl300"]["samplers"]
    assert n >= 2
    QSettings().setValue(SAMPLERS_KEY, n - 1)  # one under what the material reads
    w = make_window(qtbot, SAMPLE, show=True)
    _open_stats(qtbot, w)
    qtbot.waitUntil(lambda: any("cost budget" in p.message for p in w.diagnostics.problems),
                    timeout=30_000)
    (p,) = [p for p in w.diagnostics.problems if "cost budget" in p.message]
    assert p.severity == "warning"
    assert f"{n} texture samplers on essl300" in p.message and f"budget of {n - 1}" in p.message
    # raised in the dock: the warning goes with the next figures
    w.stats.panel.budget_samplers.setValue(n)
    assert int(QSettings().value(SAMPLERS_KEY)) == n
    w.layers.set_visible(w.layers.layer_ids_top_first()[0], False)  # an edit: new figures
    qtbot.waitUntil(lambda: not any("cost budget" in p.message
                                    for p in w.diagnostics.problems), timeout=180_000)
