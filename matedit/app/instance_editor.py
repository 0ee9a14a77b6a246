"""The instance editor: a parameter-only view of a material instance with a live preview.

Opening an instance shows its parent chain, the parent's parameters grouped and ordered
(`ParameterPanel`), and a viewport previewing the instance. Editing a scalar, vector, colour
or texture parameter is a uniform or texture update: no compile, no link. Toggling a static
switch compiles the instance's permutation; the renderer keeps programs by structure hash,
so switching back links nothing. Saving writes the instance file (atomically) with the
parent's parameter list, so orphaned overrides stay recognisable.

`Instances(window, host, file_menu, library, beside)` adds the editor's entry points to the
main window: File › New Instance of Material…, the Parameters dock, and opening instances from
the Library (listed under their parent material).
"""

from __future__ import annotations

import copy
import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QAction, QUndoCommand, QUndoStack
from PySide6.QtWidgets import (
    QDockWidget,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QMenu,
    QMessageBox,
    QPushButton,
    QSplitter,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.docks import add_dock
from matedit.app.library import KIND_ROLE, PATH_ROLE, LibraryPanel
from matedit.app.menus import insert_after
from matedit.app.parameter_panel import ParameterPanel
from matedit.app.turns import turns
from matedit.app.viewport import ViewportWidget
from matedit.compiler import CompileError, compile_document
from matedit.io.document import FileResolver, FormatError
from matedit.io.instance import (
    InstanceDocument,
    InstanceError,
    ResolvedInstance,
    is_instance_file,
    load_instance,
    new_instance,
    resolve,
    save_instance,
)

if TYPE_CHECKING:
    from matedit.app.controller import DocumentController
    from matedit.app.document_actions import DocumentActions
    from matedit.app.documents import DocumentTabs

INSTANCE_FILTER = "Material instances (*.json)"


class InstanceEditor(QWidget):
    """One instance: parameter panel on the left, preview on the right."""

    message = Signal(str)
    dirtyChanged = Signal(bool)

    def __init__(self, doc: InstanceDocument, parent=None) -> None:
        super().__init__(parent)
        self.setWindowFlag(Qt.WindowType.Window)
        self.doc = doc
        self.resolver = FileResolver()
        self.resolved: ResolvedInstance = resolve(doc)
        self.compiled = None
        self._uniform_of: dict[str, str] = {}  # parameter -> uniform, of `compiled`
        self.compile_count = 0
        self.dirty = False
        self.undo_stack = QUndoStack(self)  # the main window's Edit › Undo, in its tab
        self.undo_stack.cleanChanged.connect(self._clean_changed)  # a slot: Qt disconnects it
        self.panel = ParameterPanel()
        self.view = ViewportWidget()
        self.chain_label = QLabel()
        self.chain_label.setWordWrap(True)
        self.chain_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.problems_label = QLabel()
        self.problems_label.setWordWrap(True)
        self.problems_label.setStyleSheet("color: #e0a040;")
        self.save_button = QPushButton("Save")
        self.save_button.clicked.connect(self.save)
        left = QWidget()
        ll = QVBoxLayout(left)
        ll.setContentsMargins(0, 0, 0, 0)
        ll.addWidget(self.chain_label)
        ll.addWidget(self.problems_label)
        ll.addWidget(self.panel, 1)
        bar = QHBoxLayout()
        bar.addStretch(1)
        bar.addWidget(self.save_button)
        ll.addLayout(bar)
        split = QSplitter()
        split.addWidget(left)
        split.addWidget(self.view)
        split.setStretchFactor(1, 1)
        split.setSizes([380, 520])
        lay = QVBoxLayout(self)
        lay.setContentsMargins(6, 6, 6, 6)
        lay.addWidget(split)
        self.resize(1000, 620)
        self.panel.valueEdited.connect(self.set_value)
        self.panel.overrideToggled.connect(self._override_toggled)
        self.panel.resetRequested.connect(self.reset)
        self._rebuild()
        self._recompile()

    # --- state ---------------------------------------------------------------------------
    @property
    def parameters(self):
        return self.resolved.parameters

    def value(self, name: str) -> Any:
        return self.resolved.values[name]

    def _base(self) -> Path:
        return Path(self.doc.path).parent if self.doc.path else Path.cwd()

    def _title(self) -> str:
        return f"{self.name}{' *' if self.dirty else ''} — instance — matedit"

    def _rebuild(self) -> None:
        r = self.resolved
        names = [Path(p).name for p in r.chain]
        self.chain_label.setText("Instance chain: " + " → ".join(names))
        self.problems_label.setText("\n".join(p.format() for p in r.problems))
        self.problems_label.setVisible(bool(r.problems))
        self.panel.set_parameters(r.parameters, r.values, set(self.doc.parameters) &
                                  set(r.parameters), self._base())
        self._apply_live()
        self.setWindowTitle(self._title())

    def _set_dirty(self, dirty: bool = True) -> None:
        if dirty != self.dirty:
            self.dirty = dirty
            self.dirtyChanged.emit(dirty)
        self.setWindowTitle(self._title())

    def _clean_changed(self, clean: bool) -> None:
        self._set_dirty(not clean)

    def _re_resolve(self) -> None:
        self.resolved = resolve(self.doc)

    # --- compile and values ------------------------------------------------------------
    def _recompile(self) -> None:
        try:
            self.compiled = compile_document(self.resolved.document, self.resolver, "glsl330")
        except CompileError as exc:
            self.message.emit(f"cannot compile the instance: {exc}")
            return
        self.compile_count += 1
        self._uniform_of = self._uniform_names()  # one map per compile, not per slider step
        self._apply_live()
        self.view.set_material(self.compiled)
        self.view.set_values(self._uniforms(), self._textures())

    def _apply_live(self) -> None:
        if self.compiled is None:
            return
        used = {u.parameter for u in self.compiled.ir.uniforms if u.parameter}
        used |= {t.parameter for t in self.compiled.ir.textures}
        by_port = self._uniform_of
        self.panel.set_live({n for n, p in self.parameters.items()
                             if p.type == "switch" or n in used or n in by_port})

    def _uniform_names(self) -> dict[str, str]:
        """Parameter -> its uniform in the compiled instance: `p_<name>` for a parameter
        node, the stack port's input uniform for a layer's input (none where compiled out)."""
        if self.compiled is None:
            return {}
        at = {(u.node, u.port): u.name for u in self.compiled.ir.uniforms}
        compiled = set(at.values())
        out = {}
        for n, p in self.parameters.items():
            if p.type in ("scalar", "vector", "color"):
                name = f"p_{n}" if p.port == "value" else at.get((p.node, p.port))
                if name and name in compiled:
                    out[n] = name
        return out

    def _uniforms(self) -> dict[str, Any]:
        names = self._uniform_of
        return {names[n]: v for n, v in self.resolved.values.items() if n in names}

    def _textures(self) -> dict[str, Path | None]:
        out: dict[str, Path | None] = {}
        for n, v in self.resolved.values.items():
            if self.parameters[n].type == "texture":
                out[f"t_{n}"] = (self._base() / v) if v else None
        return out

    def _push(self, name: str) -> None:
        """A value edit: a uniform or texture update, or a permutation for a switch."""
        kind = self.parameters[name].type
        if kind == "switch":
            self._recompile()
        elif kind == "texture":
            self.view.set_values({}, {f"t_{name}": self._textures()[f"t_{name}"]})
        else:
            uniform = self._uniform_of.get(name)
            if uniform:
                self.view.set_values({uniform: self.resolved.values[name]}, {})

    def set_value(self, name: str, value: Any) -> None:
        """Override `name` with `value` (an edit of a row overrides it), undoably; the
        steps of one drag of one row are one undo step."""
        if name not in self.parameters:
            return
        if self.parameters[name].type == "texture" and value and Path(value).is_absolute():
            value = Path(os.path.relpath(value, self._base())).as_posix()  # file-relative
        self.undo_stack.push(_OverrideEdit(self, name, copy.deepcopy(value), True))

    def _apply_override(self, name: str, value: Any, present: bool) -> None:
        """`name` overridden with `value`, or (not `present`) back to the parent's."""
        if present:
            self.doc.parameters[name] = copy.deepcopy(value)
        else:
            self.doc.parameters.pop(name, None)
        self._re_resolve()
        self.panel.update_row(name, self.resolved.values[name], present)
        self._set_dirty(not self.undo_stack.isClean())
        self._push(name)

    def _override_toggled(self, name: str, on: bool) -> None:
        if on:
            self.set_value(name, self.resolved.values[name])
        else:
            self.reset(name)

    def reset(self, name: str) -> None:
        """Reset to the parent's value: the override is removed from the file (undoably)."""
        if name not in self.doc.parameters:
            return
        self.undo_stack.push(_OverrideEdit(self, name, None, False))

    def embed(self) -> None:
        """A document tab of the main window from now on, not a window of its own."""
        self.setWindowFlag(Qt.WindowType.Window, False)
        self.layout().setContentsMargins(0, 0, 0, 0)

    @property
    def name(self) -> str:
        return self.doc.name or (Path(self.doc.path).stem if self.doc.path else "instance")

    # --- files ------------------------------------------------------------------------
    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        try:
            save_instance(self.doc, resolved=self.resolved)
        except OSError as exc:
            QMessageBox.warning(self, "Save failed", f"{self.doc.path}: {exc}")
            return False
        self.undo_stack.setClean()
        self._set_dirty(False)
        self.message.emit(f"saved {self.doc.path}")
        return True

    def save_as(self, path: str | Path | None = None) -> bool:
        if path is None:
            path, _ = file_dialogs.save_file(self, "Save instance as", "", INSTANCE_FILTER)
            if not path:
                return False
        save_instance(self.doc, path, resolved=self.resolved)
        self._re_resolve()
        self._rebuild()
        self.undo_stack.setClean()
        self._set_dirty(False)
        return True

    def closeEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self.dirty:
            answer = QMessageBox.question(
                self, "Unsaved instance", f"Save changes to {self._title()}?",
                QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
                | QMessageBox.StandardButton.Cancel)
            if answer == QMessageBox.StandardButton.Cancel or (
                    answer == QMessageBox.StandardButton.Save and not self.save()):
                event.ignore()
                return
        super().closeEvent(event)


class _OverrideEdit(QUndoCommand):
    """One override set (or removed, `present` False) in an instance editor; consecutive
    settings of one parameter merge (a drag)."""

    ID = 7301

    def __init__(self, editor: InstanceEditor, name: str, value: Any, present: bool) -> None:
        super().__init__(f"{'override' if present else 'reset'} {name}")
        self.editor, self.name = editor, name
        self.new, self.new_present = value, present
        self.old_present = name in editor.doc.parameters
        self.old = copy.deepcopy(editor.doc.parameters.get(name))

    def id(self) -> int:  # noqa: A003 - Qt's name
        return self.ID

    def mergeWith(self, other) -> bool:  # noqa: N802 - Qt's name
        if not isinstance(other, _OverrideEdit) or other.name != self.name or \
                not (self.new_present and other.new_present):
            return False
        self.new = other.new
        return True

    def redo(self) -> None:
        self.editor._apply_override(self.name, self.new, self.new_present)

    def undo(self) -> None:
        self.editor._apply_override(self.name, self.old, self.old_present)


def open_instance(path: str | Path, parent=None) -> InstanceEditor:
    """An editor on an instance file; raises FormatError or InstanceError."""
    return InstanceEditor(load_instance(path), parent)


def create_instance(parent_file: str | Path, path: str | Path, parent=None) -> InstanceEditor:
    """Writes a new instance of `parent_file` (a material or instance) at `path`, with no
    overrides, and opens it."""
    doc = new_instance(parent_file, path)
    resolved = resolve(doc)
    save_instance(doc, resolved=resolved)
    return InstanceEditor(doc, parent)


# --- main window hooks ------------------------------------------------------------------

class InstanceHost(Protocol):
    """What the instance editor's entry points need of the main window."""

    controller: DocumentController
    actions: DocumentActions
    documents: DocumentTabs

    def status(self, text: str) -> None: ...


class Instances:
    """The instance editor's part of the main window: File › New Instance of Material…, the
    Parameters dock, the Library's instance entries, and the editors opened."""

    def __init__(self, window: QMainWindow, host: InstanceHost, file_menu: QMenu,
                 library: LibraryPanel, beside: QDockWidget) -> None:
        self.window = window
        self.host = host
        self.library = library
        self.editors: list[InstanceEditor] = []
        self.new_action = QAction("New &Instance of Material…", window)
        self.new_action.setObjectName("file.new_instance")
        self.new_action.setToolTip("Create a material instance of the open material (or a "
                                   "chosen file)")
        self.new_action.triggered.connect(lambda: self.new_instance_dialog())
        insert_after(file_menu, "file.new", [self.new_action])
        self.parameters_panel = MaterialParameters(host.controller)
        self.parameters_dock = add_dock(window, "Parameters", "parametersDock",
                                        self.parameters_panel,
                                        Qt.DockWidgetArea.RightDockWidgetArea)
        window.tabifyDockWidget(beside, self.parameters_dock)
        beside.raise_()
        library.instanceOpenRequested.connect(self.open)
        library.refreshed.connect(self._attach)
        if library.listed:  # it listed its files before this was connected
            self._attach(library.files)
        library.instanceCreateRequested.connect(lambda p: self.new_instance_dialog(p))

    def instances_of_open(self) -> list[tuple[str, Path]]:
        """(name, file) of every instance whose parent is the open material's file, among the
        Library's files and those beside the material (what the A/B split offers as A)."""
        doc = self.host.actions.document
        if doc is None or doc.path is None or doc.is_function:
            return []
        target = Path(doc.path).resolve()
        candidates = list(self.library.files)
        try:
            candidates += sorted(Path(doc.path).parent.glob("*.json"))
        except OSError:
            pass
        out: dict[Path, str] = {}
        for f in candidates:
            real = f.resolve()
            if real in out or real == target or not is_instance_file(f):
                continue
            try:
                inst = load_instance(f)
                if inst.parent_path().resolve() == target:
                    out[real] = inst.name or f.stem
            except (FormatError, ValueError, OSError):
                continue
        return sorted(((name, path) for path, name in out.items()), key=lambda e: e[0].lower())

    def _attach(self, files: list[Path]) -> None:  # the Library's instances, under parents
        attach_instances(self.library.items("material"), files, PATH_ROLE, KIND_ROLE)

    def _show(self, editor: InstanceEditor) -> InstanceEditor:
        """The editor in a document tab of the window, with its undo and menus."""
        self.editors.append(editor)
        editor.message.connect(self.host.status)
        self.host.documents.add_instance(editor)
        return editor

    def open(self, path: str) -> InstanceEditor | None:
        """An editor on the instance file `path` (a warning if it cannot be read)."""
        try:
            return self._show(open_instance(path))
        except (FormatError, InstanceError) as exc:
            QMessageBox.warning(self.window, "Cannot open instance", str(exc))
            return None

    def create(self, parent_file: str | Path, path: str | Path) -> InstanceEditor:
        """Writes a new instance of `parent_file` at `path` and opens it."""
        return self._show(create_instance(parent_file, path))

    def new_instance_dialog(self, parent_file: str | None = None) -> None:
        """Of the open material (or, unsaved, of a chosen file), saved where the user says."""
        window = self.window
        if parent_file is None:
            doc = self.host.actions.document
            parent_file = str(doc.path) if doc is not None and doc.path else None
        if parent_file is None:
            parent_file, _ = file_dialogs.open_file(window, "Instance of which material?",
                                                    "", INSTANCE_FILTER)
            if not parent_file:
                return
        stem = Path(parent_file).stem
        path, _ = file_dialogs.save_file(window, "Save the new instance as",
                                         str(Path(parent_file).with_name(f"{stem}_inst.json")),
                                         INSTANCE_FILTER)
        if path:
            try:
                self.create(parent_file, path)
            except (FormatError, InstanceError, OSError) as exc:
                QMessageBox.warning(window, "Cannot create instance", str(exc))


# --- a material's own parameters, grouped (the Parameters dock) ---------------------------

# The Parameters dock builds its rows this many to a turn of the event loop. A row costs the
# UI thread 3-13 ms (its field's widgets), and Qt's layout and paint of the dock follow in the
# same block: six a turn made blocks of 70-120 ms right after opening a file.
ROWS_PER_TURN = 1
# the settings that hold a parameter's value (a switch's, a texture's), not its presentation
_VALUES = ("value", "path")


class MaterialParameters(ParameterPanel):
    """The open material's parameters, grouped and ordered; edits are undoable commands
    (values as uniforms, a switch as a structural edit)."""

    def __init__(self, controller, parent=None) -> None:
        super().__init__(parent)
        self.controller = controller
        self._signature: object = None
        self._params: dict = {}
        self._pending = False  # a macro's events arrived: refreshed once, at its end
        controller.changed.connect(self._changed)
        controller.batchEnded.connect(self._batch_ended)
        controller.documentReplaced.connect(self._refresh_later)
        self.valueEdited.connect(self._edit)
        self.refresh()

    @property
    def settled(self) -> bool:
        """The rows show the document as it is (no rebuild waiting or under way)."""
        return not (self._pending or turns().pending(self, "refresh") or self.building)

    def _refresh_later(self) -> None:
        """Another document, or a macro's end: rebuilt in a turn of the UI work queue
        (matedit.app.turns), so that opening a file into a new tab (the document replaced
        twice in one event) builds the rows once, and the Layers panel's rows, the GLSL
        dock's text and these are short blocks with input, paints and timers between them."""
        turns().add(self, "refresh", lambda: self.refresh(first_now=False))

    def _changed(self, _event) -> None:
        if self.controller.batching:  # deleting or pasting many nodes: one rebuild, not one each
            self._pending = True
        else:
            self.refresh()

    def _batch_ended(self) -> None:
        if self._pending:  # after the macro's own event, in one of its own
            self._pending = False
            self._refresh_later()

    def refresh(self, first_now: bool = True) -> None:
        """The rows for the document as it is (ParameterPanel.set_parameters's `first_now`:
        False from the deferred rebuild, whose first rows then come a turn later)."""
        from matedit.io.instance import material_parameters

        doc = self.controller.document
        params = material_parameters(doc) if not doc.is_function else {}
        values = {n: p.default for n, p in params.items()}
        # what the rows are made of; a switch's or a texture's current value (its setting
        # `value` or `path`) is not: toggling one updates its row like any value
        signature = [(n, p.type, p.node,
                      repr(sorted((k, v) for k, v in p.settings.items() if k not in _VALUES)))
                     for n, p in params.items()]
        base = Path(doc.path).parent if doc.path else None
        if signature != self._signature:
            self._signature = signature
            self.set_parameters(params, values, None, base, per_turn=ROWS_PER_TURN,
                                first_now=first_now)
        else:
            for n, v in values.items():
                self.update_row(n, v)
        self._params = params

    def _edit(self, name: str, value: Any) -> None:
        from matedit.graph.commands import SetSetting, SetValue

        p = self._params.get(name)
        if p is None:
            return
        if p.type == "switch":
            cmd = SetSetting(p.node, "value", bool(value), text=f"switch {name}")
        elif p.type == "texture":
            from matedit.app.paths import reference_for

            ref = reference_for(self.controller.document, value) if value else ""
            cmd = SetSetting(p.node, "path", ref, text=f"set {name}")
        else:
            cmd = SetValue(p.node, "value", value, text=f"set {name}")
        self.controller.push(cmd)


# --- library: instances under their parent material --------------------------------------

def attach_instances(material_items: list[QTreeWidgetItem], files: list[Path],
                     path_role, kind_role) -> list[QTreeWidgetItem]:
    """Adds each instance file as a child of its parent's item (instances of instances
    under their parent instance); returns the items added."""
    by_path = {str(Path(it.data(0, path_role)).resolve()): it for it in material_items}
    pending: list[tuple[Path, InstanceDocument]] = []
    for f in files:
        if not is_instance_file(f):
            continue
        try:
            pending.append((f, load_instance(f)))
        except FormatError:
            continue
    added: list[QTreeWidgetItem] = []
    progress = True
    while pending and progress:  # parents first, whatever the file order
        progress = False
        for f, doc in list(pending):
            try:
                parent_item = by_path.get(str(doc.parent_path().resolve()))
            except ValueError:  # a library name that leads nowhere
                parent_item = None
            if parent_item is None:
                continue
            it = QTreeWidgetItem(parent_item, [doc.name or f.stem])
            it.setData(0, path_role, str(f.resolve()))
            it.setData(0, kind_role, "instance")
            it.setToolTip(0, f"Instance of {Path(doc.parent).name}\n{doc.description}\n{f}")
            _queue_thumbnail(it, f)
            by_path[str(f.resolve())] = it
            added.append(it)
            pending.remove((f, doc))
            progress = True
    return added


def _queue_thumbnail(item: QTreeWidgetItem, path: Path) -> None:
    """The item's thumbnail, made later from the event loop in steps, one a turn of the UI
    work queue (matedit.app.turns): a thumbnail takes 35-70 ms on the UI thread of a 2-core
    machine, too long for one block, and zero-delay calls would all run in one stretch."""
    key = f"thumbnail {id(item)}"
    steps = _thumbnail(item, path)

    def step() -> None:
        if next(steps, _DONE) is not _DONE:
            turns().add(None, key, step)

    turns().add(None, key, step)


_DONE = object()


def _thumbnail(item: QTreeWidgetItem, path: Path) -> Iterator[None]:
    """The instance's base colour on a sphere, from the CPU evaluator (no GL needed), in
    three steps (each yields): the instance resolved, its material lowered, then evaluated
    and set as the item's icon."""
    try:
        from PySide6.QtGui import QIcon, QPixmap

        from matedit.app.previews import preview_sphere, to_image
        from matedit.compiler.cpu_eval import evaluate
        from matedit.compiler.lower import lower_document

        r = resolve(load_instance(path))
        yield
        ir = lower_document(r.document, FileResolver())
        yield
        surf, inside = preview_sphere(24)
        out = evaluate(ir, surf)
        img = to_image(out["baseColor"], inside, 24)
        if img is not None:
            item.setIcon(0, QIcon(QPixmap.fromImage(img)))
    except Exception:  # decoration: a broken instance (or a refreshed-away item) shows none
        return
