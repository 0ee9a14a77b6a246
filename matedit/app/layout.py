"""What the main window keeps across restarts in QSettings: its geometry and docks, the
viewport's view, the light rig and grid snapping."""

from __future__ import annotations

import json
from dataclasses import asdict

from PySide6.QtCore import QByteArray, QSettings, QTimer
from PySide6.QtWidgets import QDockWidget, QMainWindow

from matedit.shading.lights import Light

GEOMETRY_KEY, STATE_KEY = "window/geometry", "window/state"
VIEW_KEY, LIGHTS_KEY, SNAP_KEY = "viewport/state", "viewport/lights", "canvas/snap"
STATE_VERSION = 1


def lights_from_json(text: str) -> list[Light] | None:
    """A saved rig, or None if there is none or it does not read as lights."""
    try:
        rig = json.loads(text or "null")
    except ValueError:
        return None
    if not isinstance(rig, list):
        return None
    try:
        return [Light(**{k: tuple(v) if isinstance(v, list) else v for k, v in d.items()})
                for d in rig]
    except (TypeError, AttributeError):
        return None


class WindowLayout:
    """Saves and restores `window`'s layout; `reset()` goes back to the layout it had when
    this was made (build it once the docks are in place)."""

    def __init__(self, window: QMainWindow, viewport, lights, snap_action) -> None:
        self.window = window
        self.viewport = viewport
        self.lights = lights
        self.snap = snap_action
        self.default_state = window.saveState(STATE_VERSION)

    def restore(self) -> None:
        w, s = self.window, QSettings()
        self.snap.setChecked(s.value(SNAP_KEY, False, type=bool))
        try:
            view = json.loads(str(s.value(VIEW_KEY, "") or "{}"))
        except ValueError:
            view = {}
        if isinstance(view, dict) and view:
            QTimer.singleShot(0, w, lambda: self.viewport.restore_view_state(view))
        lights = lights_from_json(str(s.value(LIGHTS_KEY, "") or ""))
        if lights is not None:
            self.lights.set_lights(lights, emit=True)
        geo, state = s.value(GEOMETRY_KEY), s.value(STATE_KEY)
        if isinstance(geo, QByteArray) and not geo.isEmpty():
            w.restoreGeometry(geo)
        if isinstance(state, QByteArray) and not state.isEmpty():
            w.restoreState(state, STATE_VERSION)

    def save(self) -> None:
        w, s = self.window, QSettings()
        s.setValue(SNAP_KEY, self.snap.isChecked())
        s.setValue(VIEW_KEY, json.dumps(self.viewport.view_state()))
        if self.lights.lights:
            s.setValue(LIGHTS_KEY, json.dumps([asdict(light) for light in self.lights.lights]))
        s.setValue(GEOMETRY_KEY, w.saveGeometry())
        s.setValue(STATE_KEY, w.saveState(STATE_VERSION))

    def reset(self) -> None:
        self.window.restoreState(self.default_state, STATE_VERSION)
        for dock in self.window.findChildren(QDockWidget):
            if not dock.isFloating():
                dock.show()
