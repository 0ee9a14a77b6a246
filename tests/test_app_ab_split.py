"""View › A/B Split: the material before the last structural edit left of the divider, the
material now right of it, in the real window's viewport under Xvfb."""

from __future__ import annotations

import numpy as np
import pytest
from test_app_support import app_env, settle  # noqa: F401
from test_app_viewport import frame, window  # noqa: F401, F811 - the shown sample

from matedit.graph.commands import SetValue

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def _edited(qtbot, w, edit):
    """Applies a structural edit and waits for its material in the view."""
    before = w.compiler.current
    edit()
    settle(qtbot, w)
    qtbot.waitUntil(lambda: w.compiler.latest is not None and w.compiler.latest is not before,
                    timeout=20000)
    settle(qtbot, w, 50)


def test_split_shows_the_material_before_the_last_edit_on_the_left(window, qtbot):  # noqa: F811
    w = window
    vp = w.viewport
    assert "view.ab_split" in [a.objectName() for a in w.menus.view.actions()]
    original = frame(qtbot, vp.view)
    canvas = w.tabs.material.canvas
    canvas.select_nodes(["mask"])
    _edited(qtbot, w, canvas.toggle_bypass)  # the rust mask bypassed: a structural edit
    edited = frame(qtbot, vp.view)
    h, wd, _ = edited.shape
    assert np.abs(edited - original).mean() > 0.005  # the edit shows on the sphere

    vp.ab_button.click()
    assert vp.comparing and vp.divider.isVisibleTo(vp)
    assert vp.a_label.text() == "A · before the last edit" and vp.b_label.text() == "B · now"
    split = frame(qtbot, vp.view)
    cut = int(round(vp.view.split * wd))
    margin = 2  # the divider's columns aside (8-bit frames: 1/255 tolerance)
    np.testing.assert_allclose(split[:, :cut - margin], original[:, :cut - margin],
                               atol=1.5 / 255)
    np.testing.assert_allclose(split[:, cut + margin:], edited[:, cut + margin:],
                               atol=1.5 / 255)

    # dragging the divider moves where A ends
    g = vp.view.geometry()
    vp.divider.moved.emit(g.x() + int(0.25 * g.width()))
    assert vp.view.split == pytest.approx(0.25, abs=0.01)
    assert abs(vp.divider.geometry().center().x() - (g.x() + 0.25 * g.width())) <= 3
    split = frame(qtbot, vp.view)
    cut = int(round(vp.view.split * wd))
    np.testing.assert_allclose(split[:, cut + margin:], edited[:, cut + margin:],
                               atol=1.5 / 255)
    assert np.abs(split[:, cut // 2] - original[:, cut // 2]).max() <= 1.5 / 255

    # a value edit changes B only: A is the past
    vp.view.set_split(0.5)
    w.controller.push(SetValue("stack", "paint_color", [0.6, 0.05, 0.02]))
    settle(qtbot, w, 50)
    repainted = frame(qtbot, vp.view)
    cut = int(round(0.5 * wd))
    np.testing.assert_allclose(repainted[:, :cut - margin], original[:, :cut - margin],
                               atol=1.5 / 255)
    assert np.abs(repainted[:, cut + margin:] - edited[:, cut + margin:]).mean() > 0.005

    vp.set_comparing(False)
    assert not vp.divider.isVisibleTo(vp)
    off = frame(qtbot, vp.view)
    assert np.abs(off[:, :cut - margin] - original[:, :cut - margin]).mean() > 0.005
    assert w.controller.document.graph.nodes["mask"].muted  # the split never edits


@pytest.fixture
def beside_instance(qtbot, request, tmp_path):
    """The editor's sample copied with its library, and an instance of it beside it (red
    paint over the material's blue; every other parameter inherited)."""
    import shutil

    from test_app_support import make_window, wait_for_renderer

    from matedit.io.instance import new_instance, save_instance
    from tests.graphs_util import EDITOR_GRAPHS

    request.getfixturevalue("app_env")
    root = tmp_path / "lib"
    shutil.copytree(EDITOR_GRAPHS, root)
    material = root / "materials" / "rusty_painted_metal.json"
    inst = new_instance(material, root / "materials" / "red_paint.json", name="Red paint")
    inst.parameters["paint_color"] = [0.6, 0.05, 0.02]
    save_instance(inst)
    w = make_window(qtbot, material, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    return w, root / "materials" / "red_paint.json"


def test_split_against_an_instance_of_the_material(beside_instance, qtbot):
    """A: the instance's effective material (its overrides on the open material), equal to
    the instance as the command line reads it; B: the material. A material edit of a value
    the instance does not override reaches A; B keeps being the material."""
    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver
    from matedit.io.instance import load_effective

    w, inst_path = beside_instance
    vp = w.viewport
    assert vp.instances_of() == [("Red paint", inst_path.resolve())]
    vp.ab_menu.aboutToShow.emit()
    texts = [a.text() for a in vp.ab_menu.actions()]
    assert texts == ["Before the Last Edit", "Against Instance \u2018Red paint\u2019"]
    material = frame(qtbot, vp.view)
    said: list[str] = []
    vp.statusMessage.connect(said.append)
    vp.ab_menu.actions()[1].trigger()
    settle(qtbot, w, 50)
    assert not [s for s in said if s.startswith("A/B")], said
    assert vp.comparing and vp.a_label.text() == "A \u00b7 instance Red paint"
    assert vp.b_label.text() == "B \u00b7 the material now"
    split = frame(qtbot, vp.view)
    h, wd, _ = split.shape
    cut, margin = int(round(vp.view.split * wd)), 2

    doc, _ = load_effective(inst_path)  # the reference: the instance file as CLI reads it
    ref_cm = compile_document(doc, FileResolver(), "glsl330")
    vp.view.set_compare(None)
    vp.view.set_material(ref_cm)
    reference = frame(qtbot, vp.view)
    np.testing.assert_allclose(split[:, :cut - margin], reference[:, :cut - margin],
                               atol=1.5 / 255)  # 8-bit frames
    np.testing.assert_allclose(split[:, cut + margin:], material[:, cut + margin:],
                               atol=1.5 / 255)
    assert np.abs(reference - material).mean() > 0.005  # red against blue paint shows

    # back to the window's own state, then a value the instance inherits changes both sides
    vp.view.set_material(w.compiler.latest)
    vp.push_values()
    vp.compare_with(("Red paint", inst_path))
    settle(qtbot, w, 50)
    amount = next(n for n, node in w.controller.document.graph.nodes.items()
                  if node.settings.get("name") == "rust_amount")
    w.controller.push(SetValue(amount, "value", 1.0))
    qtbot.wait(400)  # the split's refresh of A waits 250 ms for edits to settle
    settle(qtbot, w, 50)
    edited = frame(qtbot, vp.view)
    assert np.abs(edited[:, :cut - margin] - reference[:, :cut - margin]).mean() > 0.002
    assert np.abs(edited[:, cut + margin:] - material[:, cut + margin:]).mean() > 0.002

    vp.ab_menu.aboutToShow.emit()
    vp.ab_menu.actions()[0].trigger()  # back to before the last edit
    settle(qtbot, w, 50)
    assert vp.a_label.text().startswith("A \u00b7 ") and "instance" not in vp.a_label.text()
