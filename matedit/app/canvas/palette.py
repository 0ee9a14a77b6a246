"""The node palette: a search box over the node catalogue, opened with Tab on the canvas.

Typing filters by title, kind, category and description (substrings first, then a
fuzzy in-order match of the letters); Up/Down pick, Enter adds, Escape closes.
Opened from a wire dropped on empty canvas it lists only the kinds that can take
that wire (the caller passes the filter).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from PySide6.QtCore import QEvent, QObject, QPoint, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import (
    QFrame,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QVBoxLayout,
    QWidget,
)

from matedit.app.canvas import constants as C
from matedit.graph import nodes

KIND_ROLE = Qt.ItemDataRole.UserRole + 1


@dataclass(frozen=True)
class PaletteEntry:
    kind: str
    title: str
    category: str
    description: str


def catalogue() -> list[PaletteEntry]:
    """Every node kind, by category then title."""
    return [PaletteEntry(d.kind, d.title, cat, d.description)
            for cat, defs in nodes.categories().items() for d in defs]


def _fuzzy(token: str, text: str) -> float | None:
    """A score for `token`'s letters appearing in order in `text` (tighter is better)."""
    pos, gaps, last = 0, 0, -1
    for ch in token:
        i = text.find(ch, pos)
        if i < 0:
            return None
        if last >= 0:
            gaps += i - last - 1
        last, pos = i, i + 1
    return max(1.0, 25.0 - gaps)


def score(query: str, entry: PaletteEntry) -> float | None:
    """How well `entry` matches `query` (None: not at all). Every word must match somewhere."""
    total = 0.0
    title, kind = entry.title.lower(), entry.kind.lower()
    words = title.replace("(", " ").split()
    for token in query.lower().split():
        best = None
        i = title.find(token)
        if i >= 0:
            best = 100.0 - i + (60.0 if i == 0 else 0.0) + (30.0 if any(
                w.startswith(token) for w in words) else 0.0) + (40.0 if token == title else 0.0)
        for text, base in ((kind, 70.0), (entry.category.lower(), 40.0),
                           (entry.description.lower(), 15.0)):
            if token in text:
                best = max(best or 0.0, base)
        if best is None:
            best = _fuzzy(token, title) or _fuzzy(token, kind.replace("_", ""))
        if best is None:
            return None
        total += best
    return total


def search(query: str, entries: list[PaletteEntry]) -> list[PaletteEntry]:
    """Matching entries, best first (ties by title)."""
    scored = [(s, e) for e in entries if (s := score(query, e)) is not None]
    scored.sort(key=lambda se: (-se[0], se[1].title))
    return [e for _, e in scored]


class NodePalette(QFrame):
    """A floating search list over the canvas; emits `chosen(kind)` or `cancelled()`."""

    chosen = Signal(str)
    cancelled = Signal()
    docsRequested = Signal(str)  # F1 on an entry: that kind's documentation

    def __init__(self, parent: QWidget) -> None:
        super().__init__(parent)
        self.setObjectName("nodePalette")
        self.setFrameShape(QFrame.Shape.StyledPanel)
        self.setStyleSheet(
            "#nodePalette { background: #23272f; border: 1px solid #4b5468; border-radius: 6px; }"
            "QLineEdit { background: #1b1e24; color: #e4e7ec; border: 1px solid #3d4350;"
            " border-radius: 4px; padding: 4px 6px; font-size: 13px; }"
            "QListWidget { background: transparent; color: #d5d9e0; border: none;"
            " font-size: 12px; outline: none; }"
            "QListWidget::item { padding: 2px 4px; }"
            "QListWidget::item:selected { background: #3d5a99; color: white; border-radius: 3px; }"
            "QLabel { color: #9aa1ae; font-size: 11px; }")
        self.hint = QLabel(self)
        self.search = QLineEdit(self)
        self.search.setPlaceholderText("Search nodes…")
        self.search.setClearButtonEnabled(True)
        self.list = QListWidget(self)
        self.list.setUniformItemSizes(True)
        self.list.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.about = QLabel(self)
        self.about.setWordWrap(True)
        self.about.setMinimumHeight(30)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(8, 8, 8, 8)
        lay.setSpacing(6)
        lay.addWidget(self.hint)
        lay.addWidget(self.search)
        lay.addWidget(self.list, 1)
        lay.addWidget(self.about)
        self.resize(300, 400)
        self._entries = catalogue()
        self.out_of_place: frozenset[str] = frozenset()  # kinds ranked last in this document
        self._filter: Callable[[str], bool] | None = None
        self.search.textChanged.connect(self._refill)
        self.search.installEventFilter(self)
        self.list.itemActivated.connect(self._activate)
        self.list.itemClicked.connect(self._activate)
        self.list.currentItemChanged.connect(self._describe)
        self.hide()

    # --- opening and closing -----------------------------------------------------------------
    def popup(self, at: QPoint, accept: Callable[[str], bool] | None = None,
              hint: str = "Add node") -> None:
        """Show at `at` (parent coordinates, kept inside the parent) with an optional filter."""
        self._filter = accept
        self.hint.setText(hint)
        self.search.clear()
        self._refill()
        parent = self.parentWidget()
        x = max(4, min(at.x(), parent.width() - self.width() - 4))
        y = max(4, min(at.y(), parent.height() - self.height() - 4))
        self.move(x, y)
        self.show()
        self.raise_()
        self.search.setFocus(Qt.FocusReason.PopupFocusReason)

    def close_palette(self, cancelled: bool = True) -> None:
        if self.isVisible():
            self.hide()
            if cancelled:
                self.cancelled.emit()

    # --- list --------------------------------------------------------------------------------
    def visible_kinds(self) -> list[str]:
        return [self.list.item(i).data(KIND_ROLE) for i in range(self.list.count())
                if self.list.item(i).data(KIND_ROLE)]

    def _refill(self) -> None:
        query = self.search.text().strip()
        entries = [e for e in self._entries if self._filter is None or self._filter(e.kind)]
        # Kinds that belong to the other kind of document go last (stable: rank kept).
        entries.sort(key=lambda e: e.kind in self.out_of_place)
        self.list.clear()
        if query:
            found = search(query, entries)
            found.sort(key=lambda e: e.kind in self.out_of_place)
            for e in found:
                self._add_entry(e, show_category=True)
        else:
            category = None
            order = {c: i for i, c in enumerate(dict.fromkeys(e.category for e in entries))}
            for e in sorted(entries, key=lambda e: order[e.category]):
                if e.category != category:
                    category = e.category
                    self._add_header(category)
                self._add_entry(e, show_category=False)
        first = next((i for i in range(self.list.count())
                      if self.list.item(i).data(KIND_ROLE)), None)
        if first is not None:
            self.list.setCurrentRow(first)
        else:
            self.about.setText("No node matches." if query else "")

    def _add_header(self, category: str) -> None:
        item = QListWidgetItem(category.upper())
        f = QFont()
        f.setPixelSize(10)
        f.setBold(True)
        item.setFont(f)
        item.setForeground(QBrush(C.category_color(category).lighter(190)))
        item.setFlags(Qt.ItemFlag.NoItemFlags)
        self.list.addItem(item)

    def _add_entry(self, e: PaletteEntry, show_category: bool) -> None:
        text = f"{e.title}    ·  {e.category}" if show_category else f"   {e.title}"
        item = QListWidgetItem(text)
        item.setData(KIND_ROLE, e.kind)
        item.setToolTip(e.description)
        item.setForeground(QBrush(QColor("#e4e7ec")))
        self.list.addItem(item)

    def _describe(self, current, _previous=None) -> None:
        kind = current.data(KIND_ROLE) if current is not None else None
        d = nodes.REGISTRY.get(kind) if kind else None
        self.about.setText(d.description if d else "")

    def _step(self, delta: int) -> None:
        n = self.list.count()
        row = self.list.currentRow()
        for _ in range(n):
            row = (row + delta) % n if n else 0
            if self.list.item(row).data(KIND_ROLE):
                self.list.setCurrentRow(row)
                return

    def _activate(self, item: QListWidgetItem | None = None) -> None:
        item = item or self.list.currentItem()
        kind = item.data(KIND_ROLE) if item is not None else None
        if kind:
            self.hide()
            self.chosen.emit(kind)

    # --- keys --------------------------------------------------------------------------------
    def eventFilter(self, obj: QObject, event: QEvent) -> bool:
        if obj is self.search and event.type() == QEvent.Type.KeyPress:
            key = event.key()
            if key in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
                self._activate()
                return True
            if key == Qt.Key.Key_Escape:
                self.close_palette()
                return True
            if key in (Qt.Key.Key_Down, Qt.Key.Key_Up):
                self._step(1 if key == Qt.Key.Key_Down else -1)
                return True
            if key in (Qt.Key.Key_PageDown, Qt.Key.Key_PageUp):
                self._step(8 if key == Qt.Key.Key_PageDown else -8)
                return True
            if key == Qt.Key.Key_F1:
                item = self.list.currentItem()
                if item is not None and item.data(KIND_ROLE):
                    self.docsRequested.emit(item.data(KIND_ROLE))
                return True
        return super().eventFilter(obj, event)
