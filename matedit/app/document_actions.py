"""File handling for the editor: new, open, save, save as, recent files, autosave and
recovery after a crash, and the close prompt.

Saves are atomic (`matedit.io.document.save`). Every 30 s a dirty document is
written to a recovery file in AppDataLocation/recovery/ (atomically too), which a
clean save or close removes; a recovery file newer than its document at open time
means the editor did not close cleanly, and recovering it is offered. Questions to
the artist go through replaceable callables so tests can answer them.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QObject, QSettings, QStandardPaths, QTimer, Signal
from PySide6.QtWidgets import QFileDialog, QMessageBox, QWidget

from matedit.app.controller import DocumentController
from matedit.app.paths import relativise_references
from matedit.graph.model import MaterialDocument
from matedit.io.atomic import atomic_write_text
from matedit.io.document import FormatError, dumps, load, loads, save

AUTOSAVE_MS = 30_000
MAX_RECENT = 10
RECENT_KEY = "files/recent"
FILE_FILTER = "matedit graphs (*.json);;All files (*)"
UNTITLED = "untitled"

SAVE, DISCARD, CANCEL = "save", "discard", "cancel"


def recovery_dir() -> Path:
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    return Path(base or Path.home() / ".matedit") / "recovery"


def recovery_path(doc_path: Path | None) -> Path:
    """The recovery file of a document (one per document path; one for untitled work)."""
    if doc_path is None:
        return recovery_dir() / f"{UNTITLED}.json"
    key = hashlib.sha1(str(Path(doc_path).resolve()).encode()).hexdigest()[:12]
    stem = Path(doc_path).name.removesuffix(".json")
    return recovery_dir() / f"{stem}-{key}.json"


def _meta_path(rec: Path) -> Path:
    return rec.with_suffix(".meta")


def document_title(doc: MaterialDocument) -> str:
    if doc.path is not None:
        return Path(doc.path).name
    return doc.name or "Untitled"


class DocumentActions(QObject):
    """Owns the file-level state of one document controller inside a window."""

    opened = Signal(object)  # Path | None: a document replaced the previous one
    saved = Signal(object)  # Path
    message = Signal(str)

    def __init__(self, window: QWidget, controller: DocumentController) -> None:
        super().__init__(window)
        self.window = window
        self.controller = controller
        self._autosaved_index: int | None = None
        self.autosave_timer = QTimer(self)
        self.autosave_timer.setInterval(AUTOSAVE_MS)
        self.autosave_timer.timeout.connect(self.autosave)
        self.autosave_timer.start()
        # Questions, replaceable by tests.
        self.ask_save_changes: Callable[[str], str] = self._ask_save_changes
        self.ask_recover: Callable[[Path, Path], bool] = self._ask_recover
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
        answer = QMessageBox.question(
            self.window, "Recover unsaved work",
            f"matedit did not close cleanly while editing {doc_path.name}.\n\n"
            f"An autosave from {when} is newer than the file. Recover it?\n"
            "(Recovered work is unsaved until you save it.)",
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.Yes)
        return answer == QMessageBox.StandardButton.Yes

    def _ask_open_path(self) -> str:
        start = str(Path(self.controller.path).parent) if self.controller.path else ""
        path, _ = QFileDialog.getOpenFileName(self.window, "Open a material", start,
                                              FILE_FILTER)
        return path

    def _ask_save_path(self, suggestion: str) -> str:
        path, _ = QFileDialog.getSaveFileName(self.window, "Save the material as", suggestion,
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
        self.controller.replace(MaterialDocument(name="Untitled"))
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

    def open(self, path: str | os.PathLike, ask: bool = True) -> bool:
        """Opens a material (the current one is kept if the file is bad)."""
        from matedit.io.instance import is_instance_file  # instances open in their editor

        if is_instance_file(path) and hasattr(self.parent(), "open_instance"):
            return self.parent().open_instance(str(path)) is not None
        if ask and not self.maybe_save():
            return False
        doc = self.read(path)
        if doc is None:
            return False
        if doc.is_function:
            self.show_error("Not a material", f"{Path(path).name} is a material function; "
                            "open it from the Library to edit it in a tab.")
            return False
        if ask:  # leaving a document the artist has just saved or discarded
            self.discard_recovery()
        recovered = self._offer_recovery(Path(path))
        self.controller.replace(recovered or doc)
        if recovered is not None:
            self.controller.undo_stack.resetClean()  # recovered work is unsaved
        self.add_recent(Path(path))
        self.opened.emit(Path(path))
        return True

    def start(self, path: str | os.PathLike | None, fallback: Path | None) -> None:
        """At start-up: open `path` (or the fallback sample), offering crash recovery."""
        if path is not None and self.open(path, ask=False):
            return
        rec = recovery_path(None)
        if rec.is_file() and self.ask_recover(Path(UNTITLED), rec):
            doc = self._read_recovery(rec, None)
            if doc is not None:
                self.controller.replace(doc)
                self.controller.undo_stack.resetClean()
                self.opened.emit(None)
                return
        if fallback is not None:
            self.open(fallback, ask=False)

    # --- save ------------------------------------------------------------------------------
    def save(self) -> bool:
        if self.document.path is None:
            return self.save_as()
        return self._write(Path(self.document.path))

    def save_as(self) -> bool:
        suggestion = str(self.document.path) if self.document.path else \
            (self.document.name or "material").lower().replace(" ", "_") + ".json"
        path = self.ask_save_path(suggestion)
        if not path:
            return False
        return self._write(Path(path))

    def _write(self, path: Path) -> bool:
        old_path = self.document.path
        old_recovery = recovery_path(old_path)
        try:
            if old_path is None:
                relativise_references(self.document, path)
            save(self.document, path)
        except (OSError, ValueError) as exc:
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
        rec = recovery_path(self.document.path)
        if index == self._autosaved_index and rec.is_file():
            return None
        try:
            atomic_write_text(rec, dumps(self.document))
            atomic_write_text(_meta_path(rec), json.dumps(
                {"document": str(self.document.path) if self.document.path else None,
                 "time": time.time()}) + "\n")
        except (OSError, ValueError) as exc:
            self.message.emit(f"autosave failed: {exc}")
            return None
        self._autosaved_index = index
        self.message.emit(f"autosaved to {rec.name}")
        return rec

    def discard_recovery(self) -> None:
        """The current document's work is saved or knowingly dropped: forget its autosave."""
        self._remove_recovery(recovery_path(self.document.path))
        self._autosaved_index = None

    @staticmethod
    def _remove_recovery(rec: Path) -> None:
        for p in (rec, _meta_path(rec)):
            try:
                p.unlink()
            except FileNotFoundError:
                pass
            except OSError:
                pass

    def _offer_recovery(self, path: Path) -> MaterialDocument | None:
        """The autosave of `path` if it is newer than the file and the artist wants it."""
        rec = recovery_path(path)
        if not rec.is_file():
            return None
        try:
            newer = rec.stat().st_mtime > Path(path).stat().st_mtime
        except OSError:
            newer = True
        if not newer:
            self._remove_recovery(rec)  # stale: the file was saved after it
            return None
        if not self.ask_recover(path, rec):
            self._remove_recovery(rec)
            return None
        return self._read_recovery(rec, path)

    def _read_recovery(self, rec: Path, path: Path | None) -> MaterialDocument | None:
        try:
            return loads(rec.read_text(encoding="utf-8"), str(rec), path)
        except (FormatError, OSError, UnicodeDecodeError) as exc:
            self.show_error("Cannot recover", f"The autosave {rec} is unreadable:\n{exc}")
            self._remove_recovery(rec)
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
