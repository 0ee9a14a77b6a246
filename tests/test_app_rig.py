"""The Lights panel saves and loads light rigs (matedit.io.rig)."""

from __future__ import annotations

import json

import pytest

from matedit.shading.lights import Light

pytestmark = pytest.mark.gui


def test_panel_saves_and_loads_a_rig(qtbot, tmp_path):
    from matedit.app.lights_panel import LightsPanel
    from matedit.app.rig_actions import load_rig_into, save_rig_from

    panel = LightsPanel([Light("sphere", position=(1.0, 2.0, 3.0), source_radius=0.2,
                               intensity=7.0)])
    qtbot.addWidget(panel)
    assert panel.findChild(object, "rig_open") is not None
    assert panel.findChild(object, "rig_save") is not None
    path = tmp_path / "rig.json"
    assert save_rig_from(panel, str(path)) is None
    raw = json.loads(path.read_text())
    assert raw["format"] == "matedit.lightrig" and raw["lights"][0]["radius"] == 0.2
    panel.set_lights([])
    with qtbot.waitSignal(panel.lightsChanged):
        assert load_rig_into(panel, str(path)) is None
    (light,) = panel.lights
    assert light.kind == "sphere" and light.position == (1.0, 2.0, 3.0)
    assert light.intensity == 7.0 and light.source_radius == pytest.approx(0.2)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"format": "matedit.lightrig", "version": 1,
                               "lights": [{"type": "tube", "length": "long"}]}))
    msg = load_rig_into(panel, str(bad))
    assert msg.startswith(f"{bad}: light 0, field length")
    assert len(panel.lights) == 1  # unchanged
