"""The viewport's energy-compensation toggle: it changes a rough metal's image, the panel and
the render settings agree, and it is remembered across restarts (real GL under Xvfb)."""

from __future__ import annotations

import pytest
from graphs_util import link, material, node
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401
from test_app_viewport import frame

from matedit.io.document import save

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def rough_metal(path):
    """A white-ish metal at roughness 0.9: single-scattering GGX loses the most energy there
    (about a third at alpha ~0.8, Kulla & Conty 2017), so compensation brightens it visibly."""
    d = material(path)
    node(d, "make", "make_attributes",
         values={"baseColor": [0.95, 0.93, 0.88], "metallic": 1.0, "roughness": 0.9})
    node(d, "out", "material_output", pos=(300.0, 0.0))
    link(d, "make", "attributes", "out", "attributes")
    save(d, path)
    return path


def test_energy_compensation_brightens_a_rough_metal_and_is_remembered(qtbot, tmp_path):
    path = rough_metal(tmp_path / "rough_metal.json")
    w = make_window(qtbot, path, show=True)
    r = wait_for_renderer(qtbot, w)
    settle(qtbot, w, 50)
    view = w.viewport.view
    view.change_settings(show_background=False)  # the mesh alone, on black
    off = frame(qtbot, view)
    off_linear = view.read_hdr()
    assert not view.settings.energy_compensation and not r.energy_compensation

    box = w.environment.energy
    assert not box.isChecked()
    box.setChecked(True)
    assert view.settings.energy_compensation and r.energy_compensation
    on = frame(qtbot, view)
    on_linear = view.read_hdr()
    mesh = off.max(axis=2) > 0.02  # the sphere's pixels
    assert mesh.mean() > 0.05, "no mesh in view"
    # Compensation only adds energy: the metal gets brighter, never darker, by more than
    # 8-bit noise on average (the lobe's loss at roughness 0.9 is tens of percent at grazing
    # angles and several percent head-on).
    gain = (on_linear - off_linear)[mesh].mean()
    assert gain > 0.01, gain
    assert (on - off)[mesh].mean() > 0.005
    assert (on[mesh] - off[mesh]).min() > -2.5 / 255  # no pixel darker beyond rounding

    w.save_layout()
    w2 = make_window(qtbot, path, show=True)
    wait_for_renderer(qtbot, w2)
    w2.restore_layout()
    settle(qtbot, w2, 50)
    qtbot.waitUntil(lambda: w2.viewport.view.settings.energy_compensation, timeout=5000)
    assert w2.environment.energy.isChecked()
    assert w2.viewport.view.renderer.energy_compensation
    assert w2.viewport.view_state()["energy_compensation"] is True
