"""Recovery files: one per unsaved document, found again after a crash.

Every open document autosaves to its own file in the recovery folder: a document
with a path to `<stem>-<hash of the path>.json`, an untitled one to
`untitled-<key>.json` with a key of its own, so two untitled documents never share
a file. Beside each lies a `.meta` file naming the document, its kind, the time and
the editor process that wrote it. At start-up the editor lists every recovery file
whose writer is no longer running and asks what to do with each; a file is deleted
only once the artist has answered for it (recovered work is deleted when it is saved).
"""

from __future__ import annotations

import hashlib
import json
import os
import time
import uuid
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QVBoxLayout,
    QWidget,
)

RECOVER, DISCARD, KEEP = "recover", "discard", "keep"


def recovery_dir() -> Path:
    """The folder of recovery files, the one place that says where it is:
    `MATEDIT_RECOVERY_DIR` if set (tests, several editors side by side), else
    `matedit.dirs.recovery_dir()` (platformdirs: on Linux `$XDG_DATA_HOME/matedit/recovery`)."""
    override = os.environ.get("MATEDIT_RECOVERY_DIR")
    if override:
        return Path(override)
    from matedit import dirs

    return dirs.recovery_dir()


def new_untitled_key() -> str:
    return uuid.uuid4().hex[:10]


def recovery_path(doc_path: Path | None, untitled_key: str = "") -> Path:
    """The recovery file of a document: one per document path, one per untitled document."""
    if doc_path is None:
        return recovery_dir() / f"untitled-{untitled_key or 'document'}.json"
    key = hashlib.sha1(str(Path(doc_path).resolve()).encode()).hexdigest()[:12]
    stem = Path(doc_path).name.removesuffix(".json")
    return recovery_dir() / f"{stem}-{key}.json"


def meta_path(rec: Path) -> Path:
    return rec.with_suffix(".meta")


def write_meta_text(doc_path: Path | None, name: str, is_function: bool) -> str:
    return json.dumps({"document": str(doc_path) if doc_path else None, "name": name,
                       "kind": "function" if is_function else "material",
                       "time": time.time(), "pid": os.getpid()}, sort_keys=True) + "\n"


def remove_recovery(rec: Path) -> None:
    for p in (rec, meta_path(rec)):
        try:
            p.unlink()
        except OSError:
            pass


@dataclass(frozen=True)
class RecoveryEntry:
    """One recovery file found on disk."""

    rec: Path
    document: Path | None  # the file it recovers; None for untitled work
    name: str
    is_function: bool
    time: float
    pid: int

    @property
    def untitled_key(self) -> str:
        stem = self.rec.stem
        return stem.removeprefix("untitled-") if self.document is None else ""

    def describe(self) -> str:
        when = time.strftime("%Y-%m-%d %H:%M", time.localtime(self.time))
        what = str(self.document) if self.document else "never saved"
        kind = "function" if self.is_function else "material"
        older = ""
        try:
            if self.document and self.document.stat().st_mtime > self.rec.stat().st_mtime:
                older = " (older than the file, which was saved since)"
        except OSError:
            pass
        return f"{self.name} — {kind}, {what}; autosaved {when}{older}"


def _alive(pid: int) -> bool:
    if pid <= 0 or pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by someone else
        return True
    return True


def find_recoveries(skip: set[Path] = frozenset()) -> list[RecoveryEntry]:
    """Every recovery file another editor left behind (not one still running), oldest first.
    `skip`: files that documents open in this process are writing."""
    folder = recovery_dir()
    if not folder.is_dir():
        return []
    skip = {Path(p).resolve() for p in skip}
    out = []
    for rec in sorted(folder.glob("*.json")):
        if rec.resolve() in skip:
            continue
        try:
            meta = json.loads(meta_path(rec).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            meta = {}
        if not isinstance(meta, dict):
            meta = {}
        pid = meta.get("pid") if isinstance(meta.get("pid"), int) else 0
        if _alive(pid):
            continue
        doc = meta.get("document")
        try:
            mtime = rec.stat().st_mtime
        except OSError:
            continue
        name = meta.get("name") if isinstance(meta.get("name"), str) else ""
        out.append(RecoveryEntry(rec, Path(doc) if isinstance(doc, str) and doc else None,
                                 name or (Path(doc).name if isinstance(doc, str) and doc
                                          else "Untitled"),
                                 meta.get("kind") == "function",
                                 float(meta.get("time", mtime)) if isinstance(
                                     meta.get("time", mtime), (int, float)) else mtime, pid))
    return sorted(out, key=lambda e: e.time)


class RecoveryDialog(QDialog):
    """Lists the recovery files found; the checked ones are recovered, the others discarded,
    or all kept for later."""

    def __init__(self, entries: list[RecoveryEntry], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Recover unsaved work")
        self.entries = entries
        self.decision = {e.rec: KEEP for e in entries}
        lay = QVBoxLayout(self)
        text = QLabel("matedit did not close cleanly. It autosaved the work below.\n"
                      "Checked documents are recovered (unsaved until you save them); "
                      "unchecked ones are deleted. Decide later to keep them all.")
        text.setWordWrap(True)
        lay.addWidget(text)
        self.list = QListWidget()
        for e in entries:
            it = QListWidgetItem(e.describe())
            it.setFlags(it.flags() | Qt.ItemFlag.ItemIsUserCheckable)
            it.setCheckState(Qt.CheckState.Checked)
            it.setToolTip(str(e.rec))
            self.list.addItem(it)
        lay.addWidget(self.list, 1)
        buttons = QDialogButtonBox()
        ok = buttons.addButton("Recover checked", QDialogButtonBox.ButtonRole.AcceptRole)
        later = buttons.addButton("Decide later", QDialogButtonBox.ButtonRole.RejectRole)
        ok.clicked.connect(self._recover)
        later.clicked.connect(self.reject)
        lay.addWidget(buttons)
        self.resize(640, 120 + 28 * min(8, len(entries)))

    def _recover(self) -> None:
        for i, e in enumerate(self.entries):
            checked = self.list.item(i).checkState() == Qt.CheckState.Checked
            self.decision[e.rec] = RECOVER if checked else DISCARD
        self.accept()


def ask_recover_all(entries: list[RecoveryEntry], parent: QWidget | None) -> dict[Path, str]:
    dlg = RecoveryDialog(entries, parent)
    dlg.exec()
    return dict(dlg.decision)
