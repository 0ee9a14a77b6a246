"""File handling for the editor: new, open, save, save as, recent files, autosave and
recovery after a crash, and the close prompt.

Saves are atomic (`matedit.io.document.save`). Every 30 s a dirty document is
written to its own recovery file (`matedit.app.recovery`, atomically too), which a
clean save or close removes. At start-up every recovery file left behind is offered,
and one is deleted only once the artist has answered for it. Questions to the artist
go through replaceable callables so tests can answer them.
"""

from __future__ import annotations

import os
import sys
import time
import weakref
from collections.abc import Callable
from pathlib import Path

import shiboken6
from PySide6.QtCore import QObject, QSettings, QTimer, Signal
from PySide6.QtWidgets import QMessageBox, QWidget

from matedit.app import file_dialogs
from matedit.app.controller import DocumentController
from matedit.app.paths import relativise_references
from matedit.app.recovery import DISCARD as REC_DISCARD
from matedit.app.recovery import (
    RECOVER,
    BadRecoveryEntry,
    RecoveryEntry,
    ask_recover_all,
    check_entry_file,
    meta_path,
    new_untitled_key,
    recovery_dir,  # noqa: F401 - part of this module's API (tests, the window)
    recovery_path,
    remove_recovery,
    scan_recoveries,
    skipped_message,
    write_meta_text,
)
from matedit.graph.model import MaterialDocument, Node
from matedit.graph.nodes import Role, kind_for
from matedit.io import library
from matedit.io.atomic import atomic_write_text
from matedit.io.document import FormatError, dumps, load, loads, read_document_text, save

AUTOSAVE_MS = 30_000
MAX_RECENT = 10
RECENT_KEY = "files/recent"
FILE_FILTER = "matedit graphs (*.json);;All files (*)"

SAVE, DISCARD, CANCEL = "save", "discard", "cancel"


def new_material() -> MaterialDocument:
    """What File > New makes: an untitled material with its Material Output in place."""
    doc = MaterialDocument(name="Untitled")
    doc.graph.nodes["out"] = Node("out", kind_for(Role.MATERIAL_OUTPUT), (300.0, 0.0))
    return doc


def document_title(doc: MaterialDocument) -> str:
    if doc.path is not None:
        return Path(doc.path).name
    return doc.name or "Untitled"


def display_name(doc: MaterialDocument) -> str:
    """What a tab or breadcrumb calls a document: its own name, unless that is the
    placeholder of unsaved work and the document has a file now (then the file's stem)."""
    if doc.name and not (doc.name == "Untitled" and doc.path is not None):
        return doc.name
    if doc.path is not None:
        return Path(doc.path).stem
    return doc.name or "Untitled"


def no_mnemonic(text: str) -> str:
    """`text` for a Qt widget that reads '&' as a mnemonic marker (tabs, buttons, menus)."""
    return text.replace("&", "&&")


def _same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file (False when either cannot be resolved)."""
    try:
        return a.resolve() == b
    except (OSError, RuntimeError, ValueError):
        return False



def user_documents_dir() -> Path:
    """The artist's documents folder (Qt's DocumentsLocation; the home folder without one),
    where a copy of a shipped sample is suggested."""
    from PySide6.QtCore import QStandardPaths

    loc = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.DocumentsLocation)
    return Path(loc) if loc and Path(loc).is_dir() else Path.home()

class DocumentActions(QObject):
    """Owns the file-level state of one document controller inside a window."""

    _live: weakref.WeakSet = weakref.WeakSet()  # this process's documents (their autosaves)

    opened = Signal(object)  # Path | None: a document replaced the previous one
    saved = Signal(object)  # Path
    message = Signal(str)

    def __init__(self, window: QWidget, controller: DocumentController) -> None:
        super().__init__(window)
        self.window = window
        self.controller = controller
        self._autosaved_index: int | None = None
        self.untitled_key = new_untitled_key()  # an untitled document's own recovery file
        self.skipped_recoveries: list[str] = []  # the start-up scan's untrusted entries
        DocumentActions._live.add(self)
        self.autosave_timer = QTimer(self)
        self.autosave_timer.setInterval(AUTOSAVE_MS)
        self.autosave_timer.timeout.connect(self.autosave)
        self.autosave_timer.start()
        # Questions, replaceable by tests.
        self.ask_save_changes: Callable[[str], str] = self._ask_save_changes
        self.ask_recover: Callable[[Path, Path], bool] = self._ask_recover
        self.ask_recover_all: Callable[[list[RecoveryEntry]], dict[Path, str]] = \
            lambda entries: ask_recover_all(entries, self.window)
        # Where recovered work goes that this window's material cannot hold (set by the window).
        self.open_recovered_function: Callable[[RecoveryEntry, MaterialDocument], None] | \
            None = None
        self.open_recovered_material: Callable[[RecoveryEntry, MaterialDocument], None] | \
            None = None
        self.open_function: Callable[[Path], None] | None = None  # File > Open on a function
        # An instance file opens in the instance editor (None: it cannot be opened here).
        self.open_instance: Callable[[str], object] | None = None
        # The preview settings saved with a material, for the file it is saved as.
        self.preview_settings: Callable[[Path], dict] | None = None
        self.ask_open_path: Callable[[], str] = self._ask_open_path
        self.ask_save_path: Callable[[str], str] = self._ask_save_path
        self.show_error: Callable[[str, str], None] = self._show_error

    # --- questions -------------------------------------------------------------------------
    def _ask_save_changes(self, name: str) -> str:
        box = QMessageBox(QMessageBox.Icon.Warning, "Unsaved changes",
                          f"Save the changes to {name}?", parent=self.window)
        box.setInformativeText("Your changes are lost if you don't save them.")
        box.setStandardButtons(QMessageBox.StandardButton.Save
                               | QMessageBox.StandardButton.Discard
                               | QMessageBox.StandardButton.Cancel)
        box.setDefaultButton(QMessageBox.StandardButton.Save)
        answer = box.exec()
        return {QMessageBox.StandardButton.Save: SAVE,
                QMessageBox.StandardButton.Discard: DISCARD}.get(
            QMessageBox.StandardButton(answer), CANCEL)

    def _ask_recover(self, doc_path: Path, rec: Path) -> bool:
        when = time.strftime("%Y-%m-%d %H:%M", time.localtime(rec.stat().st_mtime))
        try:
            newer = rec.stat().st_mtime >= Path(doc_path).stat().st_mtime
        except OSError:
            newer = True
        answer = QMessageBox.question(
            self.window, "Recover unsaved work",
            f"matedit did not close cleanly while editing {doc_path.name}.\n\n"
            f"An autosave from {when} is {'newer' if newer else 'OLDER'} than the file. "
            "Recover it?\n(Recovered work is unsaved until you save it; No deletes the "
            "autosave.)",
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.Yes)
        return answer == QMessageBox.StandardButton.Yes

    def _ask_open_path(self) -> str:
        start = str(Path(self.controller.path).parent) if self.controller.path else ""
        path, _ = file_dialogs.open_file(self.window, "Open a material", start,
                                         FILE_FILTER)
        return path

    def _ask_save_path(self, suggestion: str) -> str:
        path, _ = file_dialogs.save_file(self.window, "Save the material as", suggestion,
                                         FILE_FILTER)
        if path and not path.endswith(".json"):
            path += ".json"
        return path

    def _show_error(self, title: str, text: str) -> None:
        QMessageBox.critical(self.window, title, text)

    # --- state -----------------------------------------------------------------------------
    @property
    def document(self) -> MaterialDocument:
        return self.controller.document

    def title(self) -> str:
        return document_title(self.document)

    def recovery_file(self) -> Path:
        """Where this document autosaves (its own file, untitled or not)."""
        return recovery_path(self.document.path, self.untitled_key)

    # --- new / open ------------------------------------------------------------------------
    def maybe_save(self) -> bool:
        """Before the document goes away: True to go on (saved or discarded), False to stop."""
        if not self.controller.dirty:
            return True
        answer = self.ask_save_changes(self.title())
        if answer == SAVE:
            return self.save()
        return answer == DISCARD

    def new(self) -> bool:
        if not self.maybe_save():
            return False
        self.discard_recovery()
        self.untitled_key = new_untitled_key()
        self.controller.replace(new_material())
        self.opened.emit(None)
        return True

    def open_dialog(self) -> bool:
        path = self.ask_open_path()
        return bool(path) and self.open(path)

    def read(self, path: str | os.PathLike) -> MaterialDocument | None:
        """Loads a file, or shows what is wrong with it (naming it) and returns None."""
        try:
            return load(path)
        except FormatError as exc:
            self.show_error("Cannot open file", f"{Path(path).name} cannot be opened.\n\n{exc}")
        except Exception as exc:  # never a traceback for a bad file
            self.show_error("Cannot open file", f"{path}: {type(exc).__name__}: {exc}")
        return None

    def open(self, path: str | os.PathLike, ask: bool = True, offer: bool = True,
             doc: MaterialDocument | None = None) -> bool:
        """Opens a material (the current one is kept if the file is bad); `offer`: ask about
        the file's recovery file, if there is one. An instance opens in its own editor.
        `doc`: the file as the caller has just read it (not read again); when the controller
        shows it already (a tab made for it), it is not replaced again."""
        from matedit.io.instance import is_instance_file  # instances open in their editor

        if doc is None and is_instance_file(path) and self.open_instance is not None:
            return self.open_instance(str(path)) is not None
        doc = doc if doc is not None else self.read(path)
        if doc is None:
            return False
        if doc.is_function:  # a function opens in a canvas tab; the material stays
            if self.open_function is not None:
                self.open_function(Path(path))
                self.add_recent(Path(path))
                return True
            self.show_error("Not a material", f"{Path(path).name} is a material function; "
                            "open it from the Library to edit it in a tab.")
            return False
        if ask and not self.maybe_save():
            return False
        if ask:  # leaving a document the artist has just saved or discarded
            self.discard_recovery()
        recovered = self._offer_recovery(Path(path)) if offer else None
        if recovered is not None or self.controller.document is not doc:
            self.controller.replace(recovered or doc)
        if recovered is not None:
            self.controller.undo_stack.resetClean()  # recovered work is unsaved
        self.add_recent(Path(path))
        self.opened.emit(Path(path))
        return True

    def start(self, path: str | os.PathLike | None, fallback: Path | None) -> None:
        """At start-up: open `path` (or the fallback sample), and offer every recovery file
        that an editor which did not close cleanly left behind, `path`'s among them."""
        try:
            entries, skipped = scan_recoveries(
                skip={a.recovery_file() for a in list(DocumentActions._live)
                      if a is not self and shiboken6.isValid(a)})
        except Exception as exc:  # noqa: BLE001 - the launch never fails for a recovery file
            entries, skipped = [], [f"the recovery folder cannot be read ({exc})"]
        self.skipped_recoveries = skipped
        if skipped:  # once, as the entries are set aside: every one on stderr, the status bar
            for line in skipped:
                print(f"matedit: skipped a damaged recovery file: {line}", file=sys.stderr)
            text = skipped_message(skipped)
            QTimer.singleShot(0, self, lambda: self.message.emit(text))
        decisions = self.ask_recover_all(entries) if entries else {}
        chosen: list[tuple[RecoveryEntry, MaterialDocument]] = []
        for e in entries:
            answer = decisions.get(e.rec)
            if answer == REC_DISCARD:
                remove_recovery(e.rec)
            elif answer == RECOVER:
                doc = self._read_recovery(e.rec, e.document)
                if doc is not None:
                    chosen.append((e, doc))
        target = Path(path).resolve() if path is not None else None
        mine = next((c for c in chosen if not c[0].is_function and c[0].document is not None
                     and target is not None and _same_file(c[0].document, target)), None)
        if mine is None and target is None:
            mine = next((c for c in chosen if not c[0].is_function), None)
        opened = False
        if path is not None:
            opened = self.open(path, ask=False, offer=False)
        if mine is not None and (opened or target is None):
            self._adopt(*mine)
            opened = True
        if not opened and fallback is not None:
            self.open(fallback, ask=False, offer=False)
        for e, doc in chosen:
            if (e, doc) is mine or mine is not None and e == mine[0]:
                continue
            sink = self.open_recovered_function if e.is_function else \
                self.open_recovered_material
            if sink is not None:
                sink(e, doc)
            else:
                self.message.emit(f"{e.name}: kept in {e.rec.name} (nowhere to open it)")

    def _adopt(self, entry: RecoveryEntry, doc: MaterialDocument) -> None:
        """Recovered work becomes this window's document, unsaved, autosaving to the same
        recovery file (deleted once it is saved or knowingly dropped)."""
        self.untitled_key = entry.untitled_key or self.untitled_key
        self.controller.replace(doc)
        self.controller.undo_stack.resetClean()
        self.opened.emit(doc.path)

    # --- save ------------------------------------------------------------------------------
    def save(self) -> bool:
        """Saves to the document's file; a new document, or one opened from the read-only
        built-in library, asks where (a copy in the artist's documents folder, suggested)."""
        if self.document.path is None or library.inside(self.document.path):
            return self.save_as()
        return self._write(Path(self.document.path))

    def save_as(self) -> bool:
        stem = (self.document.name or "material").lower().replace(" ", "_") + ".json"
        if self.document.path is None:
            suggestion = stem
        elif library.inside(self.document.path):  # a copy of a shipped file, in Documents
            suggestion = str(user_documents_dir() / Path(self.document.path).name)
        else:
            suggestion = str(self.document.path)
        path = self.ask_save_path(suggestion)
        if not path:
            return False
        return self._write(Path(path))

    def _write(self, path: Path) -> bool:
        if library.inside(path.parent):
            self.show_error("The built-in library is read-only",
                            f"{path.name} would be written into matedit's own library of "
                            "samples, layers and functions, which updates replace. Save a "
                            "copy in a folder of your own (File ▸ Save As…).")
            return False
        old_path = self.document.path
        old_recovery = self.recovery_file()
        old_name = self.document.name
        # Saved under a new file, a document still called by its placeholder ("Untitled") or
        # by its old file's stem takes the new file's stem as its name.
        if old_path is None or Path(old_path) != path:
            stems = {"", "Untitled"} | ({Path(old_path).stem} if old_path else set())
            if (old_name or "") in stems:
                self.document.name = path.stem
        try:
            if old_path is None:
                relativise_references(self.document, path)
            if self.preview_settings is not None:  # the viewport's mesh and environment
                self.document.preview.update(self.preview_settings(path))
            save(self.document, path)
        except (OSError, ValueError) as exc:
            self.document.name = old_name
            self.show_error("Cannot save", f"{path} could not be saved:\n{exc}")
            return False
        self.controller.undo_stack.setClean()
        for rec in (old_recovery, recovery_path(path)):
            self._remove_recovery(rec)
        self._autosaved_index = None
        self.add_recent(path)
        self.saved.emit(path)
        return True

    # --- autosave and recovery -------------------------------------------------------------
    def autosave(self) -> Path | None:
        """Writes the recovery file if there is unsaved work not yet autosaved."""
        if not self.controller.dirty:
            return None
        index = self.controller.undo_stack.index()
        rec = self.recovery_file()
        if index == self._autosaved_index and rec.is_file():
            return None
        try:
            atomic_write_text(rec, dumps(self.document))
            atomic_write_text(meta_path(rec), write_meta_text(
                self.document.path, display_name(self.document), self.document.is_function))
        except (OSError, ValueError) as exc:
            self.message.emit(f"autosave failed: {exc}")
            return None
        self._autosaved_index = index
        self.message.emit(f"autosaved to {rec.name}")
        return rec

    def discard_recovery(self) -> None:
        """The current document's work is saved or knowingly dropped: forget its autosave."""
        self._remove_recovery(self.recovery_file())
        self._autosaved_index = None

    @staticmethod
    def _remove_recovery(rec: Path) -> None:
        remove_recovery(rec)

    def _offer_recovery(self, path: Path) -> MaterialDocument | None:
        """The autosave of `path` if the artist wants it (declined: it is deleted)."""
        rec = recovery_path(path)
        try:
            if check_entry_file(rec, "recovery file") is None:
                return None
        except BadRecoveryEntry as exc:  # never read: set aside by the next start-up scan
            self.message.emit(f"{rec.name} not offered: {exc}")
            return None
        if not self.ask_recover(path, rec):  # deleted only once the artist has answered
            self._remove_recovery(rec)
            return None
        return self._read_recovery(rec, path)

    def _read_recovery(self, rec: Path, path: Path | None) -> MaterialDocument | None:
        try:  # a regular file within the document size limit, in UTF-8 (never blocks)
            check_entry_file(rec, "recovery file")
            return loads(read_document_text(rec), str(rec), path)
        except (FormatError, BadRecoveryEntry, OSError, UnicodeDecodeError) as exc:
            aside = rec.with_name(rec.name + ".unreadable")
            try:  # kept for a person to look at, never offered again
                os.replace(rec, aside)
            except OSError:
                aside = rec
            self.show_error("Cannot recover", f"The autosave {aside} is unreadable:\n{exc}")
            return None

    def close(self) -> bool:
        """On window close: prompt for unsaved work; True if the window may close."""
        if not self.maybe_save():
            return False
        self.autosave_timer.stop()
        self.discard_recovery()
        return True

    # --- recent files ----------------------------------------------------------------------
    @staticmethod
    def recent_files() -> list[str]:
        raw = QSettings().value(RECENT_KEY, [])
        if isinstance(raw, str):
            raw = [raw]
        return [p for p in (raw or []) if p]

    @staticmethod
    def add_recent(path: Path) -> None:
        p = str(Path(path).resolve())
        files = [f for f in DocumentActions.recent_files() if f != p]
        QSettings().setValue(RECENT_KEY, [p, *files][:MAX_RECENT])

    @staticmethod
    def clear_recent() -> None:
        QSettings().setValue(RECENT_KEY, [])
