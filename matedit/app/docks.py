"""The main window's dockable panels: which panel goes where, their default sizes, and the
Lights dock's title (an '&' drawn as itself).

`build_docks(window)` makes the panels and docks and sets them on the window as
attributes (``viewport``, ``inspector``, …, ``viewport_dock``, ``inspector_dock``, …).
"""

from __future__ import annotations

import shiboken6
from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QDockWidget, QMainWindow, QScrollArea, QUndoView, QVBoxLayout, QWidget

from matedit.app.code_view import CodeView
from matedit.app.diagnostics import DiagnosticsPanel
from matedit.app.inspector import InspectorPanel
from matedit.app.layers_panel import LayersPanel
from matedit.app.library import LibraryPanel
from matedit.app.lights_panel import LightsPanel
from matedit.app.viewport import EnvironmentPanel, ViewportPanel

LIGHTS_TITLE = "Lights & Environment"
# Default sizes at the default window size (1480x900): the viewport keeps a useful square,
# the inspector's first fields and the Lights panel's light properties show unscrolled.
SIDE_WIDTHS = (270, 430)  # left column (library, layers), right column (viewport, inspector)
RIGHT_HEIGHTS = (300, 520)  # viewport, inspector/lights
LEFT_HEIGHTS = (330, 420)  # library, layers
BOTTOM_HEIGHT = 170  # diagnostics, code, history


def add_dock(window: QMainWindow, title: str, name: str, widget: QWidget,
             area: Qt.DockWidgetArea, icon_name: str = "") -> QDockWidget:
    dock = QDockWidget(title, window)
    dock.setObjectName(name)
    dock.setWidget(widget)
    dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                     | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                     | QDockWidget.DockWidgetFeature.DockWidgetClosable)
    window.addDockWidget(area, dock)
    # No icon on the View menu's entry: styles draw an icon instead of the check mark.
    dock.toggleViewAction().setCheckable(True)
    dock.setProperty("iconName", icon_name)
    return dock


def _lights_host(w) -> QScrollArea:
    host = QWidget()
    lay = QVBoxLayout(host)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.setSpacing(0)
    lay.addWidget(w.environment)
    lay.addWidget(w.lights, 1)
    scroll = QScrollArea()  # its height must not squeeze the viewport above
    scroll.setObjectName("lightsScroll")
    scroll.setWidgetResizable(True)
    scroll.setFrameShape(QScrollArea.Shape.NoFrame)
    scroll.setWidget(host)
    return scroll


def build_docks(w) -> None:
    """The panels and their docks on the main window `w` (needs ``w.compiler``,
    ``w.controller`` and ``w.undo_group``)."""
    L, R, B = (Qt.DockWidgetArea.LeftDockWidgetArea, Qt.DockWidgetArea.RightDockWidgetArea,
               Qt.DockWidgetArea.BottomDockWidgetArea)
    # The side columns run the window's full height; the bottom docks sit under the canvas
    # alone, so the inspector and the lights get that height.
    w.setCorner(Qt.Corner.BottomLeftCorner, L)
    w.setCorner(Qt.Corner.BottomRightCorner, R)
    w.viewport = ViewportPanel(w.compiler)
    w.inspector = InspectorPanel(w.controller)
    w.layers = LayersPanel(w.controller)
    w.library = LibraryPanel()
    w.lights = LightsPanel()
    w.code = CodeView(w.compiler)
    w.diagnostics = DiagnosticsPanel()
    w.history = QUndoView(w.undo_group)
    w.history.setEmptyLabel("<opened>")
    w.environment = EnvironmentPanel(w.viewport)

    w.library_dock = add_dock(w, "Library", "libraryDock", w.library, L, "folder-add")
    w.layers_dock = add_dock(w, "Layers", "layersDock", w.layers, L, "layer")
    w.viewport_dock = add_dock(w, "Viewport", "viewportDock", w.viewport, R, "material")
    w.inspector_dock = add_dock(w, "Inspector", "inspectorDock", w.inspector, R)
    w.lights_dock = add_dock(w, LIGHTS_TITLE, "lightsDock", _lights_host(w), R, "light")
    for sig in (w.lights_dock.topLevelChanged, w.lights_dock.dockLocationChanged,
                w.lights_dock.visibilityChanged):
        sig.connect(lambda *_: shiboken6.isValid(w)  # also fires while closing down
                    and QTimer.singleShot(0, w, lambda: retitle_lights(w)))
    w.diagnostics_dock = add_dock(w, "Diagnostics", "diagnosticsDock", w.diagnostics, B,
                                  "warning")
    w.code_dock = add_dock(w, "GLSL", "codeDock", w.code, B)
    w.history_dock = add_dock(w, "History", "historyDock", w.history, B, "undo")
    w.splitDockWidget(w.library_dock, w.layers_dock, Qt.Orientation.Vertical)
    w.splitDockWidget(w.viewport_dock, w.inspector_dock, Qt.Orientation.Vertical)
    w.tabifyDockWidget(w.inspector_dock, w.lights_dock)
    w.inspector_dock.raise_()
    w.tabifyDockWidget(w.diagnostics_dock, w.code_dock)
    w.tabifyDockWidget(w.code_dock, w.history_dock)
    w.diagnostics_dock.raise_()
    retitle_lights(w)
    w.resizeDocks([w.library_dock, w.viewport_dock], list(SIDE_WIDTHS),
                  Qt.Orientation.Horizontal)
    w.resizeDocks([w.viewport_dock, w.inspector_dock], list(RIGHT_HEIGHTS),
                  Qt.Orientation.Vertical)
    w.resizeDocks([w.library_dock, w.layers_dock], list(LEFT_HEIGHTS),
                  Qt.Orientation.Vertical)
    w.resizeDocks([w.diagnostics_dock], [BOTTOM_HEIGHT], Qt.Orientation.Vertical)


def panel_docks(w) -> list[QDockWidget]:
    """The docks in the order the View menu lists them."""
    return [w.viewport_dock, w.inspector_dock, w.layers_dock, w.library_dock, w.lights_dock,
            w.code_dock, w.diagnostics_dock, w.history_dock]


def retitle_lights(w) -> None:
    """'&' shown as itself everywhere: a dock's title bar draws its title as it is, but
    the tab of tabified docks and the View menu read '&' as a mnemonic marker."""
    d = w.lights_dock
    tabbed = not d.isFloating() and bool(w.tabifiedDockWidgets(d))
    d.setWindowTitle(LIGHTS_TITLE.replace("&", "&&") if tabbed else LIGHTS_TITLE)
    d.toggleViewAction().setText(LIGHTS_TITLE.replace("&", "&&"))
