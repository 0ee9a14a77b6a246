"""Recovery files: one per unsaved document, found again after a crash.

Every open document autosaves to its own file in the recovery folder: a document
with a path to `<stem>-<hash of the path>.json`, an untitled one to
`untitled-<key>.json` with a key of its own, so two untitled documents never share
a file. Beside each lies a `.meta` file naming the document, its kind, the time and
the editor process that wrote it. At start-up the editor lists every recovery file
whose writer is no longer running and asks what to do with each; a file is deleted
only once the artist has answered for it (recovered work is deleted when it is saved).

The folder's contents are untrusted input (a crash can leave half a file, anyone can plant
one): `read_entry` checks every field and file type, and an entry that fails is skipped
with a message and set aside as `*.unreadable`, never read again and never deleted.
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
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

from matedit.io.atomic import pid_running, read_bounded
from matedit.io.document import MAX_FILE_BYTES

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


# What a recovery entry may hold; anything else is a planted or damaged file.
META_MAX_BYTES = 64 * 1024
MAX_PID = 2**31 - 1  # pid_t is a 32-bit signed integer on every platform matedit runs on
MAX_TIME = 253402300799.0  # the last second of the year 9999: time.localtime() takes it
MAX_NAME = 1000
MAX_PATH = 4096
UNREADABLE = ".unreadable"  # a skipped entry is renamed so, for a person to look at


class BadRecoveryEntry(ValueError):
    """A recovery file or its metadata that cannot be trusted; the message says why."""


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
        try:
            when = time.strftime("%Y-%m-%d %H:%M", time.localtime(self.time))
        except (OverflowError, OSError, ValueError):
            when = "at an unknown time"
        what = str(self.document) if self.document else "never saved"
        kind = "function" if self.is_function else "material"
        older = ""
        try:
            if self.document and self.document.stat().st_mtime > self.rec.stat().st_mtime:
                older = " (older than the file, which was saved since)"
        except (OSError, ValueError):
            pass
        return f"{self.name} — {kind}, {what}; autosaved {when}{older}"


def _alive(pid: int) -> bool:
    """Whether another process `pid` runs; False for anything that is not a process id."""
    if not isinstance(pid, int) or isinstance(pid, bool) or not 0 < pid <= MAX_PID \
            or pid == os.getpid():
        return False
    return pid_running(pid)


def check_entry_file(path: Path, what: str) -> os.stat_result | None:
    """The lstat of a recovery or metadata file, which must be a regular file and not a
    link (matedit writes neither as a link); None when it does not exist."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        raise BadRecoveryEntry(f"its {what} cannot be read ({exc})") from None
    if stat.S_ISLNK(st.st_mode):
        raise BadRecoveryEntry(f"its {what} is a symbolic link")
    if not stat.S_ISREG(st.st_mode):
        raise BadRecoveryEntry(f"its {what} is not a regular file (a device, FIFO, socket "
                               "or folder)")
    return st


def _read_meta(meta: Path) -> dict:
    """The metadata beside a recovery file, parsed but not yet checked ({} when absent)."""
    if check_entry_file(meta, "metadata") is None:
        return {}
    try:
        raw = read_bounded(meta, META_MAX_BYTES)
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as exc:
        raise BadRecoveryEntry(f"its metadata cannot be read ({exc})") from None
    try:
        data = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise BadRecoveryEntry("its metadata is not UTF-8 text") from None
    except (ValueError, RecursionError):
        raise BadRecoveryEntry("its metadata is not valid JSON") from None
    if not isinstance(data, dict):
        raise BadRecoveryEntry("its metadata is not a JSON object")
    return data


def _real(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def read_entry(rec: Path) -> RecoveryEntry:
    """A recovery file and its metadata, every field checked: raises BadRecoveryEntry for
    anything an editor could not have written (a pid beyond pid_t, a time that is not a
    finite date, wrong JSON types, files that are links, devices or FIFOs, oversized or
    non-UTF-8 metadata). Absent metadata is allowed: the file's own date stands in."""
    st = check_entry_file(rec, "recovery file")
    if st is None:
        raise BadRecoveryEntry("it went away while being read")
    if st.st_size > MAX_FILE_BYTES:
        raise BadRecoveryEntry(f"it is larger than {MAX_FILE_BYTES >> 20} MiB")
    meta = _read_meta(meta_path(rec))
    pid = meta.get("pid", 0)
    if not isinstance(pid, int) or isinstance(pid, bool) or not 0 <= pid <= MAX_PID:
        raise BadRecoveryEntry(f"its pid {_short(pid)} is not a process id")
    when = meta.get("time", st.st_mtime)
    if not _real(when) or not 0 <= when <= MAX_TIME:  # NaN and inf compare False
        raise BadRecoveryEntry(f"its time {_short(when)} is not a date")
    doc = meta.get("document")
    if doc is not None and not (isinstance(doc, str) and 0 < len(doc) <= MAX_PATH
                                and "\0" not in doc):
        raise BadRecoveryEntry(f"its document {_short(doc)} is not a file path")
    name = meta.get("name", "")
    if not isinstance(name, str) or len(name) > MAX_NAME:
        raise BadRecoveryEntry(f"its name {_short(name)} is not a document name")
    kind = meta.get("kind", "material")
    if kind not in ("material", "function"):
        raise BadRecoveryEntry(f"its kind {_short(kind)} is neither material nor function")
    document = Path(doc) if doc else None
    name = name.strip() or (document.name if document else "Untitled")
    return RecoveryEntry(rec, document, name, kind == "function", float(when), pid)


def _short(value) -> str:
    text = repr(value) if not isinstance(value, int) or isinstance(value, bool) or \
        abs(value) < 10**30 else "(a huge number)"
    return text if len(text) <= 40 else text[:37] + "…"


def set_aside(rec: Path) -> Path | None:
    """Renames an untrusted entry (and its metadata) to *.unreadable, never following a
    link, so it is kept for a person and not offered again; the new name, or None."""
    moved = None
    for p in (rec, meta_path(rec)):
        try:
            os.lstat(p)
        except OSError:
            continue
        aside = p.with_name(p.name + UNREADABLE)
        try:
            os.replace(p, aside)
        except OSError:
            continue
        if p == rec:
            moved = aside
    return moved


def scan_recoveries(skip: set[Path] = frozenset()) -> tuple[list[RecoveryEntry], list[str]]:
    """Every recovery file another editor left behind (not one still running), oldest
    first, and one line for each entry skipped as untrusted (set aside, see `set_aside`).
    `skip`: files that documents open in this process are writing."""
    folder = recovery_dir()
    try:
        if not folder.is_dir():
            return [], []
        found = sorted(folder.glob("*.json"))
    except (OSError, ValueError):
        return [], [f"the recovery folder {folder} cannot be read"]
    skip = {Path(p).resolve() for p in skip}
    out: list[RecoveryEntry] = []
    problems: list[str] = []
    for rec in found:
        try:
            if rec.resolve() in skip:
                continue
        except (OSError, RuntimeError):  # a link loop: read_entry says so
            pass
        try:
            entry = read_entry(rec)
        except BadRecoveryEntry as exc:
            aside = set_aside(rec)
            where = f"; kept as {aside.name}" if aside is not None else ""
            problems.append(f"{rec.name}: {exc}{where}")
            continue
        if _alive(entry.pid):
            continue
        out.append(entry)
    return sorted(out, key=lambda e: e.time), problems


def find_recoveries(skip: set[Path] = frozenset()) -> list[RecoveryEntry]:
    """The entries of `scan_recoveries`, without the lines about skipped ones."""
    return scan_recoveries(skip)[0]


def skipped_message(problems: list[str], shown: int = 2) -> str:
    """One status line for the recovery entries skipped at start-up: the first `shown`
    with their reasons, then how many more ("" when none was skipped)."""
    n = len(problems)
    if not n:
        return ""
    head = f"skipped {n} damaged recovery file{'s' if n != 1 else ''}"
    text = f"{head}: " + "; ".join(problems[:shown])
    return text + (f"; and {n - shown} more" if n > shown else "")


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
