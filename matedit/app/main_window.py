"""The main window: canvas tabs in the centre, dockable panels around it, menus, status bar.

Panels are wired to the active tab's controller (inspector, history, diagnostics)
or to the material's (viewport, layers, code). Dock layout and window geometry
are kept in QSettings and restored at the next start.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import shiboken6
from PySide6.QtCore import QByteArray, QEvent, QSettings, Qt, QTimer
from PySide6.QtGui import QAction, QCloseEvent, QCursor, QKeySequence, QUndoGroup
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QLabel,
    QMainWindow,
    QMenu,
    QScrollArea,
    QUndoView,
    QVBoxLayout,
    QWidget,
)

from matedit.app.canvas import NodeCanvasView
from matedit.app.canvas_tabs import CanvasTab, CanvasTabs
from matedit.app.code_view import CodeView
from matedit.app.compile_service import MaterialCompiler
from matedit.app.controller import DocumentController
from matedit.app.diagnostics import DiagnosticsPanel
from matedit.app.document_actions import DocumentActions, document_title, new_material
from matedit.app.export_dialog import ExportDialog
from matedit.app.help import NodeDocs, ShortcutReference, show_about
from matedit.app.inspector import InspectorPanel
from matedit.app.instance_editor import install as install_instances
from matedit.app.layers_panel import LayersPanel
from matedit.app.library import LibraryPanel
from matedit.app.lights_panel import LightsPanel
from matedit.app.node_preview import PreviewTarget
from matedit.app.problems import ProblemsModel
from matedit.app.theme import icon
from matedit.app.viewport import EnvironmentPanel, ViewportPanel
from matedit.graph.nodes import Role, kind_for
from matedit.resources import graphs_dir
from matedit.shading.lights import Light

SAMPLE = "materials/rusty_painted_metal.json"
GEOMETRY_KEY, STATE_KEY = "window/geometry", "window/state"
VIEW_KEY, LIGHTS_KEY, SNAP_KEY = "viewport/state", "viewport/lights", "canvas/snap"
STATE_VERSION = 1


def sample_path() -> Path:
    return graphs_dir() / SAMPLE


class MainWindow(QMainWindow):
    def __init__(self, path: str | Path | None = None, *, sample: bool = True,
                 restore_layout: bool = True, start: bool = True) -> None:
        super().__init__()
        self.setObjectName("MainWindow")
        self.resize(1480, 900)
        self.setDockNestingEnabled(True)
        self.controller = DocumentController(new_material(), self)
        self.actions = DocumentActions(self, self.controller)
        self.compiler = MaterialCompiler(self.controller, self)
        self.undo_group = QUndoGroup(self)

        self.tabs = CanvasTabs(self.controller, self.actions, self.undo_group, self)
        self.setCentralWidget(self.tabs)
        self._build_docks()
        self.problems = ProblemsModel(self.compiler, self.viewport, self)
        self._build_actions()
        self._build_menus()
        self._build_status()
        self._connect()
        install_instances(self)  # File › New Instance, Library instances (instance_editor)
        self._default_state = self.saveState(STATE_VERSION)
        if restore_layout:
            self.restore_layout()
        self.undo_group.setActiveStack(self.controller.undo_stack)
        self._on_active(self.tabs.active)
        self._retitle()
        self.extra_windows: list[MainWindow] = []  # recovered materials opened at start-up
        self._shortcuts: ShortcutReference | None = None
        self._docs: NodeDocs | None = None
        QApplication.instance().installEventFilter(self)
        self.actions.open_recovered_function = lambda e, doc: self.tabs.open_function(
            e.document, self.tabs.material, recovered=doc)
        self.actions.open_recovered_material = self._open_recovered_material
        self.actions.open_function = lambda p: self.tabs.open_function(p, self.tabs.material)
        self.actions.preview_settings = self.viewport.document_preview
        if start:
            self.actions.start(path, sample_path() if sample else None)
            self.compiler.recompile()

    # --- construction ----------------------------------------------------------------------
    def _dock(self, title: str, name: str, widget, area, icon_name: str = "") -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(name)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                         | QDockWidget.DockWidgetFeature.DockWidgetClosable)
        self.addDockWidget(area, dock)
        # No icon on the View menu's entry: styles draw an icon instead of the check mark.
        dock.toggleViewAction().setCheckable(True)
        dock.setProperty("iconName", icon_name)
        return dock

    def _build_docks(self) -> None:
        L, R, B = (Qt.DockWidgetArea.LeftDockWidgetArea, Qt.DockWidgetArea.RightDockWidgetArea,
                   Qt.DockWidgetArea.BottomDockWidgetArea)
        self.viewport = ViewportPanel(self.compiler)
        self.inspector = InspectorPanel(self.controller)
        self.layers = LayersPanel(self.controller)
        self.library = LibraryPanel()
        self.lights = LightsPanel()
        self.code = CodeView(self.compiler)
        self.diagnostics = DiagnosticsPanel()
        self.history = QUndoView(self.undo_group)
        self.history.setEmptyLabel("<opened>")

        self.library_dock = self._dock("Library", "libraryDock", self.library, L, "folder-add")
        self.layers_dock = self._dock("Layers", "layersDock", self.layers, L, "layer")
        self.viewport_dock = self._dock("Viewport", "viewportDock", self.viewport, R,
                                        "material")
        self.inspector_dock = self._dock("Inspector", "inspectorDock", self.inspector, R)
        self.environment = EnvironmentPanel(self.viewport)
        lights_host = QWidget()
        lh = QVBoxLayout(lights_host)
        lh.setContentsMargins(0, 0, 0, 0)
        lh.setSpacing(0)
        lh.addWidget(self.environment)
        lh.addWidget(self.lights, 1)
        lights_scroll = QScrollArea()  # its height must not squeeze the viewport above
        lights_scroll.setWidgetResizable(True)
        lights_scroll.setFrameShape(QScrollArea.Shape.NoFrame)
        lights_scroll.setWidget(lights_host)
        self.lights_dock = self._dock("Lights & Environment", "lightsDock", lights_scroll, R,
                                      "light")
        for sig in (self.lights_dock.topLevelChanged, self.lights_dock.dockLocationChanged,
                    self.lights_dock.visibilityChanged):
            sig.connect(lambda *_: shiboken6.isValid(self)  # also fires while closing down
                        and QTimer.singleShot(0, self, self._retitle_lights))
        self.diagnostics_dock = self._dock("Diagnostics", "diagnosticsDock", self.diagnostics,
                                           B, "warning")
        self.code_dock = self._dock("GLSL", "codeDock", self.code, B)
        self.history_dock = self._dock("History", "historyDock", self.history, B, "undo")
        self.splitDockWidget(self.library_dock, self.layers_dock, Qt.Orientation.Vertical)
        self.splitDockWidget(self.viewport_dock, self.inspector_dock, Qt.Orientation.Vertical)
        self.tabifyDockWidget(self.inspector_dock, self.lights_dock)
        self.inspector_dock.raise_()
        self.tabifyDockWidget(self.diagnostics_dock, self.code_dock)
        self.tabifyDockWidget(self.code_dock, self.history_dock)
        self.diagnostics_dock.raise_()
        self._retitle_lights()
        self.resizeDocks([self.library_dock, self.viewport_dock], [270, 430],
                         Qt.Orientation.Horizontal)
        self.resizeDocks([self.viewport_dock, self.inspector_dock], [400, 420],
                         Qt.Orientation.Vertical)
        self.resizeDocks([self.library_dock, self.layers_dock], [330, 420],
                         Qt.Orientation.Vertical)
        self.resizeDocks([self.diagnostics_dock], [170], Qt.Orientation.Vertical)

    def _retitle_lights(self) -> None:
        """'&' shown as itself everywhere: a dock's title bar draws its title as it is, but
        the tab of tabified docks and the View menu read '&' as a mnemonic marker."""
        d = self.lights_dock
        tabbed = not d.isFloating() and bool(self.tabifiedDockWidgets(d))
        d.setWindowTitle("Lights && Environment" if tabbed else "Lights & Environment")
        d.toggleViewAction().setText("Lights && Environment")

    def _action(self, text: str, slot, shortcut=None, icon_name: str = "",
                tip: str = "") -> QAction:
        a = QAction(icon(icon_name) if icon_name else icon("none"), text, self)
        if shortcut is not None:
            a.setShortcut(shortcut)
        if tip:
            a.setStatusTip(tip)
            a.setToolTip(tip)
        a.triggered.connect(slot)
        return a

    def _build_actions(self) -> None:
        K = QKeySequence.StandardKey
        self.act_new = self._action("&New", self.actions.new, K.New, "new", "New material")
        self.act_open = self._action("&Open…", self.actions.open_dialog, K.Open, "open",
                                     "Open a material")
        self.act_save = self._action("&Save", self.save_active, K.Save, "save",
                                     "Save the document in the active tab")
        self.act_save_as = self._action("Save &As…", self.save_active_as, K.SaveAs, "save-as")
        self.act_export = self._action("&Export Shaders…", self.export_shaders, "Ctrl+E",
                                       "export", "Write GLSL for chosen targets to a folder")
        self.act_save_image = self._action("Save &Viewport Image…",
                                           lambda: self.viewport.save_image_dialog(), None,
                                           "save", "The viewport's frame as PNG or linear EXR")
        self.act_quit = self._action("&Quit", self.close, K.Quit)
        self.act_undo = self.undo_group.createUndoAction(self, "&Undo")
        self.act_undo.setShortcut(K.Undo)
        self.act_undo.setIcon(icon("undo"))
        self.act_redo = self.undo_group.createRedoAction(self, "&Redo")
        self.act_redo.setShortcut(K.Redo)
        self.act_redo.setIcon(icon("redo"))
        # The canvas owns its keys (Tab, F, Home, Delete, Ctrl+C/X/V/D): menus only show them.
        self.act_add_node = self._action("Add &Node…\tTab", self.open_palette, None, "add",
                                         "Add a node (palette)")
        self.act_frame_all = self._action("Frame &All\tHome", lambda: self.canvas.frame_all(),
                                          None, "frame", "Frame the whole graph")
        self.act_frame_sel = self._action("Frame &Selection\tF",
                                          lambda: self.canvas.frame_selection())
        self.canvas_actions = []
        V = NodeCanvasView
        for text, method in (("&Delete\tDel", V.delete_selection),
                             ("Cu&t\tCtrl+X", V.cut_selection),
                             ("&Copy\tCtrl+C", V.copy_selection),
                             ("&Paste\tCtrl+V", V.paste),
                             ("D&uplicate\tCtrl+D", V.duplicate_selection),
                             ("Co&mment Selection\tC", V.comment_selection)):
            self.canvas_actions.append(self._action(text, lambda _=False, m=method:
                                                    m(self.canvas)))
        self.act_reset_layout = self._action("Reset &Layout", self.reset_layout)
        self.act_snap = self._action("&Snap to Grid", self.tabs.set_snap_to_grid, None,
                                     tip="Moved nodes land on the canvas grid")
        self.act_snap.setCheckable(True)
        self.act_shortcuts = self._action("&Keyboard Reference…", self.show_shortcuts,
                                          "Ctrl+/", tip="Every shortcut, searchable")
        self.act_node_docs = self._action("&Node Reference", self.show_selected_docs, None,
                                          tip="Documentation of the selected node kind (F1)")
        self.act_about = self._action("&About matedit", self.show_about)

    def _build_menus(self) -> None:
        mb = self.menuBar()
        f = mb.addMenu("&File")
        for a in (self.act_new, self.act_open):
            f.addAction(a)
        self.recent_menu = QMenu("Open &Recent", self)
        self.recent_menu.aboutToShow.connect(self._fill_recent)
        f.addMenu(self.recent_menu)
        f.addSeparator()
        for a in (self.act_save, self.act_save_as):
            f.addAction(a)
        f.addSeparator()
        f.addAction(self.act_export)
        f.addAction(self.act_save_image)
        from matedit.app.interop_actions import install as install_interop
        self.interop = install_interop(self, f, self.act_export)
        f.addSeparator()
        f.addAction(self.act_quit)
        e = mb.addMenu("&Edit")
        e.addAction(self.act_undo)
        e.addAction(self.act_redo)
        e.addSeparator()
        for a in self.canvas_actions:
            e.addAction(a)
        e.addSeparator()
        e.addAction(self.act_add_node)
        v = mb.addMenu("&View")
        v.addAction(self.act_frame_all)
        v.addAction(self.act_frame_sel)
        v.addSeparator()
        for dock in (self.viewport_dock, self.inspector_dock, self.layers_dock,
                     self.library_dock, self.lights_dock, self.code_dock,
                     self.diagnostics_dock, self.history_dock):
            v.addAction(dock.toggleViewAction())
        v.addAction(self.act_snap)
        v.addSeparator()
        v.addAction(self.act_reset_layout)
        h = mb.addMenu("&Help")
        for a in (self.act_shortcuts, self.act_node_docs, None, self.act_about):
            if a is None:
                h.addSeparator()
            else:
                h.addAction(a)
        tb = self.addToolBar("Main")
        tb.setObjectName("mainToolBar")
        tb.setMovable(False)
        tb.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonIconOnly)
        for a in (self.act_new, self.act_open, self.act_save, None, self.act_undo,
                  self.act_redo, None, self.act_add_node, self.act_frame_all, None,
                  self.act_export):
            if a is None:
                tb.addSeparator()
            else:
                tb.addAction(a)

    def _build_status(self) -> None:
        sb = self.statusBar()
        self.compile_label = QLabel("")
        self.count_label = QLabel("")
        sb.addPermanentWidget(self.count_label)
        sb.addPermanentWidget(self.compile_label)

    def _connect(self) -> None:
        c = self.controller
        c.undo_stack.cleanChanged.connect(self._clean_changed)
        c.documentReplaced.connect(self._document_replaced)
        c.analysed.connect(lambda _a: self._refresh_problems())
        self.actions.opened.connect(lambda _p: self._retitle())
        self.actions.saved.connect(lambda p: self.status(f"saved {p}"))
        self.actions.message.connect(self.status)
        self.problems.changed.connect(self._refresh_problems)
        self.viewport.statusMessage.connect(self.status)
        self.viewport.environmentChanged.connect(lambda s: self.status(f"environment: {s}"))
        self.tabs.materialOpenRequested.connect(self.open_material)
        self.tabs.docsRequested.connect(self.show_docs)
        self.inspector.docsRequested.connect(self.show_docs)
        self.tabs.previewRequested.connect(
            lambda nid, port: self.compiler.set_preview(PreviewTarget(nid, port)))
        self.tabs.activeChanged.connect(self._on_active)
        self.tabs.selectionChanged.connect(self.inspector.set_selection)
        self.tabs.message.connect(self.status)
        self.tabs.functionSaved.connect(lambda _p: self.controller.reanalyse())
        self.inspector.message.connect(self.status)
        self.inspector.functionOpenRequested.connect(
            lambda p: self.tabs.open_function(p, self.tabs.active))
        self.layers.message.connect(self.status)
        self.layers.layerSelected.connect(self._layer_selected)
        self.library.materialOpenRequested.connect(self.open_material)
        self.library.functionOpenRequested.connect(
            lambda p: self.tabs.open_function(p, self.tabs.material))
        self.library.layerAddRequested.connect(
            lambda p: self.layers.add_layer_file(Path(p)))
        self.diagnostics.nodeActivated.connect(self.select_node)
        self.lights.lightsChanged.connect(self.viewport.set_lights)
        QTimer.singleShot(0, self, self._sync_lights)

    def _sync_lights(self) -> None:
        """The lights panel starts with the renderer's default lights once GL is up."""
        lights = self.viewport.renderer_lights()
        if lights is None:
            QTimer.singleShot(200, self, self._sync_lights)
        elif lights and not self.lights.lights:
            self.lights.set_lights(lights)

    # --- documents -------------------------------------------------------------------------
    def open_material(self, path: str | Path) -> bool:
        if not self.tabs.close_functions():
            return False
        return self.actions.open(path)

    # --- help ------------------------------------------------------------------------------
    def show_shortcuts(self) -> ShortcutReference:
        if self._shortcuts is None:
            self._shortcuts = ShortcutReference(self)
        self._shortcuts.show()
        self._shortcuts.raise_()
        return self._shortcuts

    def show_docs(self, kind: str) -> NodeDocs:
        if self._docs is None:
            self._docs = NodeDocs(kind, self)
        self._docs.show_kind(kind)
        self._docs.show()
        self._docs.raise_()
        return self._docs

    def show_selected_docs(self) -> None:
        ids = self.tabs.active.canvas.selected_ids()
        node = self.tabs.active.controller.document.graph.nodes.get(ids[0]) if ids else None
        self.show_docs(node.kind if node is not None else kind_for(Role.MATERIAL_OUTPUT))

    def show_about(self) -> None:
        show_about(self, self.viewport.gl_renderer())

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        """Tab opens the palette whenever the pointer is over the active canvas, wherever
        the keyboard focus is in this window."""
        if event.type() == QEvent.Type.KeyPress and event.key() == Qt.Key.Key_Tab and \
                event.modifiers() == Qt.KeyboardModifier.NoModifier and \
                isinstance(obj, QWidget) and obj.window() is self:
            canvas = self.tabs.active.canvas
            vp = canvas.viewport()
            inside = vp.rect().contains(vp.mapFromGlobal(QCursor.pos()))
            if inside and canvas.isVisible() and not canvas.node_palette.isAncestorOf(obj) \
                    and obj is not canvas.node_palette:
                canvas.open_palette()
                return True
        return super().eventFilter(obj, event)

    def _open_recovered_material(self, entry, doc) -> None:
        """A second recovered material gets a window of its own."""
        w = MainWindow(restore_layout=False, start=False)
        w.actions.ask_save_changes = self.actions.ask_save_changes
        w.actions.ask_recover = self.actions.ask_recover
        w.actions.show_error = self.actions.show_error
        w.actions._adopt(entry, doc)
        w.compiler.recompile()
        w.show()
        self.extra_windows.append(w)

    def save_active(self) -> bool:
        return self.tabs.active.actions.save()

    def save_active_as(self) -> bool:
        return self.tabs.active.actions.save_as()

    def export_shaders(self) -> None:
        if self.compiler.current is None:
            self.status("the material does not compile: see Diagnostics")
        dlg = ExportDialog(self.controller.document, self.controller.resolver, self)
        if dlg.exec() and dlg.written:
            self.status(f"exported {len(dlg.written)} files to {dlg.written[0].parent}")

    def _document_replaced(self) -> None:
        self._retitle()
        self.viewport.set_preview(self.controller.document.preview,
                                  self.controller.document.path)
        self.inspector.show_node(None)

    def _clean_changed(self, _clean: bool) -> None:
        self._retitle()

    def _retitle(self) -> None:
        doc = self.controller.document
        name = document_title(doc)
        self.setWindowTitle(f"{name}[*] — matedit")
        self.setWindowModified(self.controller.dirty)
        g = doc.graph
        self.count_label.setText(f"{len(g.nodes)} nodes · {len(g.links)} links")

    def _fill_recent(self) -> None:
        self.recent_menu.clear()
        files = self.actions.recent_files()
        for f in files:
            a = self.recent_menu.addAction(Path(f).name)
            a.setToolTip(f)
            a.setStatusTip(f)
            a.triggered.connect(lambda _=False, p=f: self.open_material(p))
        if not files:
            self.recent_menu.addAction("(none)").setEnabled(False)
        else:
            self.recent_menu.addSeparator()
            self.recent_menu.addAction("Clear", self.actions.clear_recent)

    # --- active tab ------------------------------------------------------------------------
    def _on_active(self, tab: CanvasTab) -> None:
        self.inspector.set_controller(tab.controller)
        self._refresh_problems()

    def select_node(self, node_id: str) -> None:
        canvas = self.tabs.active.canvas
        canvas.select_nodes([node_id])
        canvas.frame_selection()
        self.inspector.show_node(node_id)
        self.inspector_dock.show()
        self.inspector_dock.raise_()

    def _layer_selected(self, stack_id: str) -> None:
        if self.tabs.active is not self.tabs.material:
            return
        self.tabs.material.canvas.select_nodes([stack_id])
        self.inspector.show_node(stack_id)

    @property
    def canvas(self) -> NodeCanvasView:
        """The active tab's canvas."""
        return self.tabs.active.canvas

    def open_palette(self) -> None:
        self.canvas.open_palette()

    # --- problems --------------------------------------------------------------------------
    def _refresh_problems(self) -> None:
        tab = self.tabs.active
        m = self.tabs.material
        self.compile_label.setText(self.problems.status)
        self.diagnostics.set_problems(self.problems.for_tab(tab.controller.analysis,
                                                            tab is m))
        tab.canvas.set_node_errors(self.diagnostics.errors_by_node())
        if tab is not m:
            m.canvas.set_node_errors(self.problems.material_errors())
        n = sum(1 for p in self.diagnostics.problems if p.severity == "error")  # the rows
        self.diagnostics_dock.setWindowTitle("Diagnostics" + (f" ({n})" if n else ""))
        self._retitle()

    def status(self, text: str) -> None:
        self.statusBar().showMessage(text, 6000)

    # --- layout ----------------------------------------------------------------------------
    def restore_layout(self) -> None:
        """Window geometry, docks, the viewport's view, the light rig and grid snapping."""
        s = QSettings()
        self.act_snap.setChecked(s.value(SNAP_KEY, False, type=bool))
        try:
            view = json.loads(str(s.value(VIEW_KEY, "") or "{}"))
            rig = json.loads(str(s.value(LIGHTS_KEY, "") or "null"))
        except ValueError:
            view, rig = {}, None
        if isinstance(view, dict) and view:
            QTimer.singleShot(0, self, lambda: self.viewport.restore_view_state(view))
        if isinstance(rig, list):
            try:
                lights = [Light(**{k: tuple(v) if isinstance(v, list) else v
                                   for k, v in d.items()}) for d in rig]
            except TypeError:
                lights = None
            if lights is not None:
                self.lights.set_lights(lights, emit=True)
        geo = s.value(GEOMETRY_KEY)
        state = s.value(STATE_KEY)
        if isinstance(geo, QByteArray) and not geo.isEmpty():
            self.restoreGeometry(geo)
        if isinstance(state, QByteArray) and not state.isEmpty():
            self.restoreState(state, STATE_VERSION)

    def save_layout(self) -> None:
        s = QSettings()
        s.setValue(SNAP_KEY, self.act_snap.isChecked())
        s.setValue(VIEW_KEY, json.dumps(self.viewport.view_state()))
        if self.lights.lights:
            s.setValue(LIGHTS_KEY, json.dumps([asdict(light) for light in self.lights.lights]))
        s.setValue(GEOMETRY_KEY, self.saveGeometry())
        s.setValue(STATE_KEY, self.saveState(STATE_VERSION))

    def reset_layout(self) -> None:
        self.restoreState(self._default_state, STATE_VERSION)
        for dock in self.findChildren(QDockWidget):
            if not dock.isFloating():
                dock.show()

    # --- closing ---------------------------------------------------------------------------
    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        if not self.tabs.close_functions() or not self.actions.close():
            event.ignore()
            return
        self.save_layout()
        if self.compiler.worker is not None:  # its thread, and the warm-up's child process
            self.compiler.worker.shutdown()
        event.accept()
