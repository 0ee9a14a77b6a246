"""The viewport inside the editor: it draws, follows value edits without relinking, and keeps
the last good image when an edit breaks the material (real GL under Xvfb)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from broken_material import BrokenMaterial
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401

from matedit.graph.commands import Connect, SetValue
from matedit.graph.model import Link

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

SAMPLE = EDITOR_SAMPLE


def frame(qtbot, view) -> np.ndarray:
    """The viewport's own framebuffer after one more frame, as (H, W, 3) floats in [0, 1]."""
    from PySide6.QtGui import QImage

    serial = view.request_frame()  # a picture drawn after every change sent so far
    qtbot.waitUntil(lambda: view.shown_serial >= serial > 0, timeout=30000)
    img = view.current_image().convertToFormat(QImage.Format.Format_RGB888)
    h, w, bpl = img.height(), img.width(), img.bytesPerLine()
    arr = np.frombuffer(img.constBits(), np.uint8, count=h * bpl).reshape(h, bpl)
    return arr[:, : w * 3].reshape(h, w, 3).astype(np.float32) / 255.0


@pytest.fixture
def window(qtbot, request):
    request.getfixturevalue("app_env")
    w = make_window(qtbot, SAMPLE, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    return w


def test_viewport_draws_and_a_parameter_edit_changes_it_without_relinking(window, qtbot):
    view = window.viewport.view
    before = frame(qtbot, view)
    assert before.std() > 0.05, "the viewport is blank"
    h, w, _ = before.shape
    centre = before[h // 2 - 5: h // 2 + 5, w // 2 - 5: w // 2 + 5].mean(axis=(0, 1))
    assert centre.max() > 0.1  # the sphere is lit
    links = view.renderer.link_count
    recompiles = []
    window.controller.structureChanged.connect(lambda: recompiles.append(1))
    assert window.controller.push(SetValue("stack", "paint_color", [0.9, 0.02, 0.02]))
    after = frame(qtbot, view)
    settle(qtbot, window)
    assert np.abs(after - before).mean() > 0.01, "a colour edit did not show"
    redness = after[..., 0].mean() - after[..., 2].mean()
    assert redness > before[..., 0].mean() - before[..., 2].mean()
    assert view.renderer.link_count == links and recompiles == []


def test_an_idle_viewport_draws_forward_and_a_structural_edit_goes_back(qtbot, request,
                                                                         monkeypatch):
    """The render process draws the material forward once idle (FORWARD_WHEN_IDLE_S): the
    picture stays the same to the eye; the next structural edit is drawn deferred."""
    import time

    from matedit.app.viewport import ViewportWidget
    from matedit.render.server import FORWARD_WHEN_IDLE_S

    monkeypatch.setattr(ViewportWidget, "forward_when_idle", True)
    request.getfixturevalue("app_env")
    w = make_window(qtbot, SAMPLE, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    view = w.viewport.view
    before = frame(qtbot, view)
    assert not view.renderer.is_forward
    promoted = False
    end = time.monotonic() + 60
    while not promoted and time.monotonic() < end:
        qtbot.wait(int((FORWARD_WHEN_IDLE_S + 0.5) * 1000))  # asking is a message: wait first
        promoted = view.renderer.promoted
    assert promoted and view.renderer.is_forward
    after = frame(qtbot, view)
    assert np.abs(after - before).max() <= 3 / 255  # the forward path's picture: the same
    d = w.controller.document
    node = next(n for n in d.graph.nodes.values() if n.kind == "scalar_parameter")
    assert w.controller.push(SetValue(node.id, "value", 0.77))  # a value: still forward
    frame(qtbot, view)
    assert view.renderer.is_forward
    w.controller.push(Connect(Link(node.id, "value", *_free_float_input(d))))
    settle(qtbot, w)
    qtbot.waitUntil(lambda: not view.renderer.promoted, timeout=60000)
    assert not view.renderer.is_forward


def _free_float_input(d) -> tuple[str, str]:
    """(node id, input) of an unconnected float input of a maths node in `d`."""
    linked = {(lk.dst, lk.dst_port) for lk in d.graph.links}
    for nid, n in d.graph.nodes.items():
        if n.kind in ("add", "multiply", "subtract") and (nid, "b") not in linked:
            return nid, "b"
    raise AssertionError("no free maths input in the sample")


def test_a_broken_edit_keeps_the_last_good_image(window, qtbot):
    view = window.viewport.view
    good = frame(qtbot, view)
    # A wire from an output that does not exist: the graph no longer compiles.
    assert window.controller.push(Connect(Link("mask_noise", "nope", "mask", "value")))
    settle(qtbot, window)
    assert window.compiler.current is None
    assert any(p.severity == "error" for p in window.diagnostics.problems)
    still = frame(qtbot, view)
    assert np.abs(still - good).max() < 2.5 / 255

    # A program that fails in the GL compiler: errors reported, the old program stays.
    window.controller.undo_stack.undo()
    settle(qtbot, window)
    good = frame(qtbot, view)
    cm = copy.copy(window.compiler.current)
    cm.__class__ = BrokenMaterial  # sent to the render process as it is
    cm.__dict__.pop("_variants", None)
    cm.structure_hash = "broken"
    errors = []
    view.glErrors.connect(errors.append)
    window.viewport.on_compiled(cm)
    qtbot.waitUntil(lambda: bool(errors), timeout=30000)  # the link is in the render process
    assert errors[0]
    assert any(p.source == "GL" for p in window.diagnostics.problems)
    still = frame(qtbot, view)
    assert np.abs(still - good).max() < 2.5 / 255


def test_reference_mode_keeps_drawing_until_converged(window, qtbot):
    view = window.viewport.view
    view.renderer.reference_frames = 4
    window.viewport.mode_combo.setCurrentText("Difference")
    n = view.frames
    qtbot.waitUntil(lambda: view.frames >= n + 4, timeout=30000)
    qtbot.waitUntil(lambda: not view.renderer.needs_redraw, timeout=30000)
    # the converged picture follows the renderer's state from the render process
    qtbot.waitUntil(lambda: view.frame_info is not None and view.frame_info.converged,
                    timeout=30000)
    assert "mean" in window.viewport.diff_label.text()
    window.viewport.mode_combo.setCurrentText("Split-sum")


def test_lights_panel_drives_the_renderer(window, qtbot):
    view = window.viewport.view
    qtbot.waitUntil(lambda: bool(window.lights.lights), timeout=5000)
    n = len(view.renderer.lights)
    window.lights.add_light("tube")
    assert len(view.renderer.lights) == n + 1
    assert view.renderer.lights[-1].kind == "tube"
    window.lights.list.setCurrentRow(n)
    window.lights.remove_selected()
    assert len(view.renderer.lights) == n


def test_a_bad_environment_file_is_reported_and_the_old_one_kept(window, qtbot, tmp_path,
                                                                  monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    bad = tmp_path / "broken.hdr"
    bad.write_bytes(b"not an image")
    shown = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: shown.append(a[2]))
    assert not window.viewport.choose_environment(str(bad))
    assert shown and "broken.hdr" in shown[0]
    assert window.viewport.env_combo.currentText() == "Studio"


def test_render_settings_are_a_typed_record_applied_to_the_renderer(window, qtbot):
    from matedit.app.viewport import RenderSettings

    view = window.viewport.view
    before = frame(qtbot, view)
    view.change_settings(show_background=False, environment_intensity=0.5)
    assert view.settings == RenderSettings(0.5, False, 0.0)
    r = view.renderer
    assert (r.show_background, r.environment_intensity) == (False, 0.5)
    after = frame(qtbot, view)
    assert np.abs(after - before).mean() > 0.01  # the background went, the light halved
    box = window.environment.background  # the panel goes through the same record
    box.setChecked(False)
    box.setChecked(True)
    assert view.settings.show_background and r.show_background
    assert view.settings.environment_intensity == 0.5  # the other fields kept


# --- the last good shader belongs to the document (issue 22) ---------------------------------

def _never_compiles(path):
    """A material that loads but does not compile: a number wired into the output."""
    from matedit.app.document_actions import new_material
    from matedit.graph.model import Node
    from matedit.io.document import save

    doc = new_material()
    doc.name = "Broken wiring"
    doc.graph.nodes["c"] = Node("c", "constant", (0.0, 0.0), {}, {"value": 0.5})
    doc.graph.links.add(Link("c", "value", "out", "attributes"))
    save(doc, path)
    return path


def _centre(img: np.ndarray) -> np.ndarray:
    h, w, _ = img.shape
    return img[h // 2 - 5: h // 2 + 5, w // 2 - 5: w // 2 + 5].mean(axis=(0, 1))


def test_a_material_that_never_compiled_shows_no_other_documents_shader(window, qtbot,
                                                                        tmp_path):
    view = window.viewport.view
    good = frame(qtbot, view)
    assert _centre(good).max() > 0.1 and window.viewport.shows_material()
    assert window.compiler.last_good is not None

    broken = _never_compiles(tmp_path / "broken.json")
    assert window.actions.open(broken)
    settle(qtbot, window)
    assert window.controller.document.path == broken  # the file asked for is open
    assert window.compiler.current is None and window.compiler.last_good is None
    # What is drawn: no material program at all, and a notice saying why.
    assert not view.renderer.has_material and not window.viewport.shows_material()
    shown = frame(qtbot, view)
    assert np.abs(_centre(shown) - _centre(good)).max() > 0.05, "the old sphere is still drawn"
    notice = window.viewport.failure_message
    assert notice.startswith("This material does not compile")
    assert "cannot connect float to MaterialAttributes" in notice
    assert window.viewport.failure.isVisible()
    # The GLSL panel shows no other document's code, and says so; Diagnostics list the error.
    window.code.ensure_current()  # what the panel shows when it is opened
    code = window.code.text.toPlainText()
    assert "does not compile" in window.code.info.text()
    assert "void main" not in code and "cannot connect float" in code
    assert any(p.severity == "error" and p.node_id == "out" for p in window.diagnostics.problems)
    assert "nothing to show" in window.compile_label.text()

    # Fixing it in place draws it, and the notice goes.
    from matedit.graph.commands import Disconnect

    assert window.controller.push(Disconnect(Link("c", "value", "out", "attributes")))
    settle(qtbot, window)
    assert window.compiler.current is not None
    assert view.renderer.has_material and window.viewport.shows_material()
    assert window.viewport.failure_message == ""


def test_a_new_document_whose_glsl_fails_to_link_draws_nothing_of_the_last(window, qtbot):
    view = window.viewport.view
    frame(qtbot, view)
    cm = copy.copy(window.compiler.current)
    cm.__class__ = BrokenMaterial  # sent to the render process as it is
    cm.__dict__.pop("_variants", None)
    cm.structure_hash = "broken-new-document"
    window.actions.ask_save_changes = lambda _n: "discard"
    # The new document's first program is the broken one: the panel sees no other compile.
    window.compiler.compiled.disconnect(window.viewport.on_compiled)
    try:
        assert window.actions.new()
        settle(qtbot, window)
        window.viewport.on_compiled(cm)  # and it fails in the driver
    finally:
        window.compiler.compiled.connect(window.viewport.on_compiled)
    # the link fails in the render process: its reply comes back to the panel
    qtbot.waitUntil(lambda: window.viewport.failure_message != "", timeout=30000)
    assert not view.renderer.has_material and not window.viewport.shows_material()
    assert window.viewport.failure_message.startswith("This material's GLSL does not build")
    assert any(p.source == "GL" for p in window.diagnostics.problems)


def test_a_value_edit_sets_the_uniforms_of_that_port_and_no_other(window, qtbot, monkeypatch):
    """valuesChanged names the node and port: the viewport sets the uniforms that read it
    (from the compiled material's table) and redraws; a macro of edits sets them all."""
    from matedit.app.controller import MANY_VALUES, ValueChange
    from matedit.graph.commands import Macro

    cm = window.compiler.latest
    reading = sorted(u.name for u in cm.ir.uniforms if (u.node, u.port) == ("stack",
                                                                             "paint_color"))
    assert reading and len(cm.ir.uniforms) > len(reading)  # others are left alone
    changes, sets = [], []
    window.controller.valuesChanged.connect(changes.append)
    real = window.viewport.view.set_values
    monkeypatch.setattr(window.viewport.view, "set_values",
                        lambda u, t: (sets.append((sorted(u), dict(t))), real(u, t)))
    assert window.controller.push(SetValue("stack", "paint_color", [0.9, 0.02, 0.02]))
    assert changes == [ValueChange("stack", "paint_color")]
    assert sets == [(reading, {})]
    values = window.viewport.view.renderer.material.values  # what the buffer was packed from
    assert all(np.allclose(values[n], [0.9, 0.02, 0.02], atol=1e-6) for n in reading)

    changes.clear()
    sets.clear()
    macro = Macro([SetValue("stack", "paint_color", [0.1, 0.2, 0.3]),
                   SetValue("stack", "paint_color", [0.2, 0.3, 0.4])], text="two")
    assert window.controller.push(macro)
    assert changes == [MANY_VALUES]  # one announcement for the whole macro
    assert len(sets) == 1 and sets[0][0] == sorted(u.name for u in cm.ir.uniforms)
    window.controller.undo_stack.undo()
    assert changes == [MANY_VALUES, MANY_VALUES]


def test_a_render_process_that_dies_is_started_again_with_what_it_drew(window, qtbot):
    """A driver crash takes the render process, not the editor: the viewport starts another
    and sends it the material, its values and the environment; the picture comes back."""
    import os
    import signal

    view = window.viewport.view
    before = frame(qtbot, view)
    said: list[str] = []
    view.statusMessage.connect(said.append)
    pid = view._proc._proc.pid
    os.kill(pid, signal.SIGKILL)
    qtbot.waitUntil(lambda: view.running and view._proc._proc.pid != pid, timeout=60000)
    qtbot.waitUntil(lambda: view.environment_ready, timeout=60000)
    after = frame(qtbot, view)
    assert not view.problem and view.renderer.has_material
    assert any("restarted" in m for m in said)
    assert not any(p.source == "GL" for p in window.diagnostics.problems)
    assert np.abs(after - before).mean() < 0.01  # the same material, values and lighting
