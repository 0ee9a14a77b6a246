"""The Textures dock: thumbnails of one folder's image files, to drag onto the canvas or use.

The folder is the open document's folder (it follows the document), or the home folder for
a new one, until another is typed or browsed to. Every file whose name ends in an extension
matedit reads (`matedit.io.images.READ_FORMATS`) is listed by name; its thumbnail is made
by OpenImageIO on a worker thread (`read_thumbnail`, a band of rows at a time), so a folder
of large images never holds up the window. A file that cannot be read is listed with an
"unreadable" tile and the reason in its tooltip. Thumbnails are kept by path, modification
time and size: when the folder changes (a file watcher), only new or changed files are read.

Dragging a thumbnail drags its file, as the file manager does, so the canvas takes it as a
dropped image. Double-click (or Enter) uses the file: it fills the texture slot of the one
node selected on the canvas when that node has one (as the Inspector's field does), else
adds a Texture Parameter and a Texture Sample on it at the canvas's centre (as an image
dropped on empty canvas does).
"""

from __future__ import annotations

import atexit
import bisect
import os
import weakref
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import shiboken6
from PySide6.QtCore import (
    QCoreApplication,
    QFileSystemWatcher,
    QMimeData,
    QModelIndex,
    QObject,
    QPointF,
    QRunnable,
    QSize,
    QSortFilterProxyModel,
    Qt,
    QThread,
    QThreadPool,
    QTimer,
    QUrl,
    Signal,
)
from PySide6.QtGui import (
    QColor,
    QFont,
    QIcon,
    QImage,
    QPainter,
    QPen,
    QPixmap,
    QStandardItem,
    QStandardItemModel,
)
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListView,
    QSizePolicy,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.canvas.drops import texture_input
from matedit.app.theme import icon
from matedit.graph.nodes import Role, role_of
from matedit.io.images import READ_FORMATS, read_thumbnail

if TYPE_CHECKING:
    from matedit.app.canvas import NodeCanvasView
    from matedit.app.controller import DocumentController

THUMB = 96  # a thumbnail's longer side, pixels
GRID = QSize(THUMB + 22, THUMB + 54)  # a thumbnail and two lines of text under it
CACHE_SIZE = 1024  # thumbnails kept (at most 96x96 RGBA each: under 40 MB)
WATCHED_FILES = 1000  # files watched for in-place rewrites (beyond: the folder only)
PATH_ROLE = Qt.ItemDataRole.UserRole
NAME_ROLE = Qt.ItemDataRole.UserRole + 1  # the file name: what the filter matches
STATE_ROLE = Qt.ItemDataRole.UserRole + 2  # "loading", "ready" or "unreadable"
KEY_ROLE = Qt.ItemDataRole.UserRole + 3  # "modification time:size" of the file listed


@dataclass(frozen=True)
class Thumb:
    """A file's thumbnail (RGBA, its longer side at most THUMB) and what it is, or why
    there is none (`error`)."""

    image: QImage | None = None
    size: tuple[int, int] = (0, 0)  # the file's own pixels
    detail: str = ""  # channels and storage, for the tooltip
    error: str = ""


def image_files(folder: Path) -> list[tuple[str, Path, tuple[int, int]]]:
    """(name, path, (modification time, size)) of the image files in `folder`, by name."""
    found = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return []
    for e in entries:
        if Path(e.name).suffix.lower() not in READ_FORMATS:
            continue
        try:
            if not e.is_file():
                continue
            st = e.stat()
        except OSError:
            continue
        found.append((e.name, Path(e.path), (st.st_mtime_ns, st.st_size)))
    found.sort(key=lambda f: (f[0].casefold(), f[0]))
    return found


def make_thumb(path: Path, size: int = THUMB) -> Thumb:
    """The thumbnail of the image file at `path`, display-encoded: 8- and 16-bit files as
    stored (sRGB or data alike), float files (scene-linear) clipped and sRGB-encoded; a
    single channel as grey, a second one named A as its alpha."""
    try:
        data, dims = read_thumbnail(path, size)
    except (ValueError, OSError) as exc:
        text = " ".join(str(exc).split())
        prefix = f"{path}: "
        return Thumb(error=text[len(prefix):] if text.startswith(prefix) else text)
    px = data.pixels
    c = px.shape[2]
    names = data.channel_names
    alpha = None
    if c <= 2:
        grey = c == 1 or (len(names) > 1 and names[1].upper() == "A")
        rgb = np.repeat(px[:, :, :1], 3, axis=2) if grey else np.concatenate(
            [px[:, :, :2], np.zeros_like(px[:, :, :1])], axis=2)
        alpha = px[:, :, 1] if grey and c == 2 else None
    else:
        rgb = px[:, :, :3]
        alpha = px[:, :, 3] if c >= 4 else None
    rgb = np.clip(rgb, 0.0, 1.0)
    if not data.is_ldr:
        rgb = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)
    a = np.ones(rgb.shape[:2], np.float32) if alpha is None else np.clip(alpha, 0.0, 1.0)
    arr = np.ascontiguousarray((np.dstack([rgb, a]) * 255 + 0.5).astype(np.uint8))
    h, w = arr.shape[:2]
    img = QImage(arr.data, w, h, 4 * w, QImage.Format.Format_RGBA8888).copy()
    storage = "float" if not data.is_ldr else "8-bit" if data.is_8bit else "16-bit"
    channels = "".join(names) if 0 < len(names) <= 4 and all(len(n) == 1 for n in names) \
        else f"{c} channels"
    return Thumb(img, dims, f"{channels}, {storage} {data.format_name}")


_POOLS: weakref.WeakSet[QThreadPool] = weakref.WeakSet()


def _drain_pools() -> None:
    for pool in list(_POOLS):
        if shiboken6.isValid(pool):
            pool.clear()
            pool.waitForDone()


atexit.register(_drain_pools)


class _Results(QObject):
    done = Signal(object, object, object)  # path, (mtime, size), Thumb


class _ThumbJob(QRunnable):
    """Makes one thumbnail on a pool thread and hands it to the browser's thread."""

    def __init__(self, path: Path, key: tuple[int, int], results: _Results) -> None:
        super().__init__()
        self.path, self.key, self.results = path, key, results
        self.setAutoDelete(True)

    def run(self) -> None:
        try:
            thumb = make_thumb(self.path)
        except Exception as exc:  # noqa: BLE001 - a worker thread: report it on the tile
            thumb = Thumb(error=f"cannot make a thumbnail: {exc}")
        self.results.done.emit(self.path, self.key, thumb)


def _tile(text: str, colour: str) -> QIcon:
    """A THUMB-sized square with `text` in its middle: a file being read or unreadable."""
    pix = QPixmap(THUMB, THUMB)
    pix.fill(QColor("#1e2128"))
    p = QPainter(pix)
    p.setPen(QPen(QColor(colour), 1, Qt.PenStyle.DashLine))
    p.drawRect(4, 4, THUMB - 9, THUMB - 9)
    font = QFont(p.font())
    font.setPointSizeF(max(7.0, font.pointSizeF() - 1))
    p.setFont(font)
    p.drawText(pix.rect(), Qt.AlignmentFlag.AlignCenter, text)
    p.end()
    return QIcon(pix)


def _shown(image: QImage) -> QIcon:
    """The thumbnail at the view's icon size: a small image is enlarged (pixels kept
    sharp), since an icon is never drawn larger than its pixmap."""
    if max(image.width(), image.height()) < THUMB:
        image = image.scaled(THUMB, THUMB, Qt.AspectRatioMode.KeepAspectRatio,
                             Qt.TransformationMode.FastTransformation)
    return QIcon(QPixmap.fromImage(image))


class _FileModel(QStandardItemModel):
    """The listed files; a drag carries their file URLs, as a file manager's does."""

    def mimeTypes(self) -> list[str]:  # noqa: N802 - Qt's name
        return ["text/uri-list"]

    def mimeData(self, indexes) -> QMimeData:  # noqa: N802 - Qt's name
        data = QMimeData()
        paths = dict.fromkeys(str(i.data(PATH_ROLE)) for i in indexes if i.data(PATH_ROLE))
        data.setUrls([QUrl.fromLocalFile(p) for p in paths])
        return data

    def supportedDragActions(self) -> Qt.DropAction:  # noqa: N802 - Qt's name
        return Qt.DropAction.CopyAction


def texture_slot(canvas: NodeCanvasView) -> tuple[str, str] | None:
    """(node id, texture input) of the canvas's one selected node when the Inspector shows
    a texture slot for it: a Texture Parameter (input ""), or a node whose texture input
    is free or fed by a Texture Parameter."""
    ids = canvas.selected_ids()
    if len(ids) != 1:
        return None
    graph = canvas.controller.document.graph
    node = graph.nodes.get(ids[0])
    if node is None:
        return None
    if role_of(node.kind) == Role.TEXTURE_PARAMETER:
        return node.id, ""
    port = texture_input(canvas.controller, node.id)
    if not port:
        return None
    link = graph.incoming(node.id, port)
    src = graph.nodes.get(link.src) if link is not None else None
    if link is not None and (src is None or role_of(src.kind) != Role.TEXTURE_PARAMETER):
        return None
    return node.id, port


class TextureBrowser(QWidget):
    """The Textures dock's panel (see the module's description)."""

    def __init__(self, controller: DocumentController, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.controller = controller
        # the canvas a double-click works on (the window's active one); set by its maker
        self.canvas_of: Callable[[], NodeCanvasView | None] = lambda: None
        self.folder_dialog = file_dialogs.existing_folder  # tests replace it
        self.folder: Path | None = None
        self._followed: Path | None = None  # the document folder last followed
        self._stale = True  # the folder changed while the panel was hidden
        # made before the results: destroyed first, it waits for the jobs still running
        self._pool = QThreadPool(self)
        self._pool.setMaxThreadCount(max(1, min(2, QThread.idealThreadCount() - 1)))
        app = QCoreApplication.instance()
        if app is not None:  # no job outlives the application's event loop
            app.aboutToQuit.connect(self.shutdown)
        _POOLS.add(self._pool)  # nor the interpreter, when it exits without an event loop
        self._results = _Results(self)
        self._results.done.connect(self._thumb_done)
        self._cache: OrderedDict[tuple[str, int, int], Thumb] = OrderedDict()
        self._pending: set[tuple[str, int, int]] = set()
        self._items: dict[str, QStandardItem] = {}
        self._loading = _tile("…", "#6b7180")
        self._unreadable = _tile("unreadable", "#d9695f")

        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.setSpacing(4)
        row = QHBoxLayout()
        self.folder_edit = QLineEdit()
        self.folder_edit.setPlaceholderText("Folder of images")
        self.folder_edit.setToolTip("The folder whose images are listed (type one and press "
                                    "Enter, or browse)")
        self.folder_edit.editingFinished.connect(self._folder_typed)
        self.browse = QToolButton()
        self.browse.setIcon(icon("open"))
        self.browse.setToolTip("Choose the folder of images to list")
        self.browse.clicked.connect(self._browse)
        row.addWidget(self.folder_edit, 1)
        row.addWidget(self.browse)
        lay.addLayout(row)
        self.filter_edit = QLineEdit()
        self.filter_edit.setPlaceholderText("Filter: part of a name, or *.exr")
        self.filter_edit.setClearButtonEnabled(True)
        self.filter_edit.textChanged.connect(self._filter)
        lay.addWidget(self.filter_edit)

        self.model = _FileModel(self)
        self.proxy = QSortFilterProxyModel(self)
        self.proxy.setSourceModel(self.model)
        self.proxy.setFilterRole(NAME_ROLE)
        self.proxy.setFilterCaseSensitivity(Qt.CaseSensitivity.CaseInsensitive)
        self.view = QListView()
        self.view.setObjectName("textureList")
        self.view.setViewMode(QListView.ViewMode.IconMode)
        self.view.setMovement(QListView.Movement.Static)
        self.view.setResizeMode(QListView.ResizeMode.Adjust)
        self.view.setIconSize(QSize(THUMB, THUMB))
        self.view.setGridSize(GRID)
        self.view.setWordWrap(True)  # (the name still elided in its middle)
        self.view.setTextElideMode(Qt.TextElideMode.ElideMiddle)
        self.view.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.view.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.view.setDragEnabled(True)
        self.view.setDragDropMode(QAbstractItemView.DragDropMode.DragOnly)
        self.view.setDefaultDropAction(Qt.DropAction.CopyAction)
        self.view.setModel(self.proxy)
        self.view.activated.connect(self._activated)
        lay.addWidget(self.view, 1)
        self.status = QLabel("")
        self.status.setObjectName("emptyHint")
        self.status.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        lay.addWidget(self.status)

        self._watcher = QFileSystemWatcher(self)
        self._watcher.directoryChanged.connect(self._changed)
        self._watcher.fileChanged.connect(self._changed)
        self._rescan_timer = QTimer(self)
        self._rescan_timer.setSingleShot(True)
        self._rescan_timer.setInterval(250)  # a file being written: once it has settled
        self._rescan_timer.timeout.connect(self._rescan_if_shown)
        controller.documentReplaced.connect(self.follow_document)
        controller.undoStackReplaced.connect(self._watch_undo_stack)
        self._stack = None
        self._watch_undo_stack()
        self.follow_document()

    # --- the folder ------------------------------------------------------------------------
    def follow_document(self) -> None:
        """The open document's folder (the home folder for an unsaved one), when it is not
        the one followed last: opening or saving a document elsewhere goes there."""
        path = self.controller.document.path
        folder = Path(path).resolve().parent if path else Path.home()
        if folder != self._followed:
            self._followed = folder
            self.set_folder(folder)

    def _watch_undo_stack(self, *_old) -> None:
        """Save As moves the document without replacing it: its undo stack turns clean."""
        if self._stack is not None and shiboken6.isValid(self._stack):
            self._stack.cleanChanged.disconnect(self._clean_changed)
        self._stack = self.controller.undo_stack
        self._stack.cleanChanged.connect(self._clean_changed)

    def _clean_changed(self, clean: bool) -> None:
        if clean:
            self.follow_document()

    def set_folder(self, folder: str | Path) -> None:
        """List the images of `folder` (watched from now on)."""
        folder = Path(folder).expanduser()
        self.folder = folder
        self.folder_edit.setText(str(folder))
        self.folder_edit.setToolTip(str(folder))
        self._pool.clear()  # jobs of the folder left that have not started
        self._pending.clear()
        self.model.clear()
        self._items.clear()
        watched = self._watcher.files() + self._watcher.directories()
        if watched:
            self._watcher.removePaths(watched)
        if folder.is_dir():
            self._watcher.addPath(str(folder))
        self._stale = True
        self._rescan_if_shown()

    def _folder_typed(self) -> None:
        text = self.folder_edit.text().strip()
        if text and Path(text).expanduser() != self.folder:
            self.set_folder(text)

    def _browse(self) -> None:
        start = str(self.folder) if self.folder is not None and self.folder.is_dir() else \
            str(Path.home())
        chosen = self.folder_dialog(self, "Folder of textures", start)
        if chosen:
            self.set_folder(chosen)

    def _changed(self, _path: str) -> None:
        self._stale = True
        self._rescan_timer.start()

    def showEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        self._rescan_timer.start()  # once the window's layout has settled

    def _rescan_if_shown(self) -> None:
        """A hidden panel reads nothing: it catches up when it is shown."""
        if self._stale and self.isVisible():
            self.rescan()

    # --- the list --------------------------------------------------------------------------
    def rescan(self) -> None:
        """List the folder's image files again: rows for new files, none for removed ones,
        and a thumbnail made for each file that is new or changed since it was read."""
        self._stale = False
        folder = self.folder
        if folder is None or not folder.is_dir():
            self.model.clear()
            self._items.clear()
            self._show_count(f"no such folder: {folder}" if folder is not None else "")
            return
        files = image_files(folder)
        listed = {str(p) for _n, p, _k in files}
        for path in [p for p in self._items if p not in listed]:
            self.model.removeRow(self._items.pop(path).row())
        order = [(str(self.model.item(r).data(NAME_ROLE)).casefold(),
                  str(self.model.item(r).data(NAME_ROLE))) for r in range(self.model.rowCount())]
        for name, path, key in files:
            item = self._items.get(str(path))
            if item is None:
                item = QStandardItem()
                item.setEditable(False)
                item.setData(str(path), PATH_ROLE)
                item.setData(name, NAME_ROLE)
                at = bisect.bisect(order, (name.casefold(), name))
                order.insert(at, (name.casefold(), name))
                self.model.insertRow(at, item)
                self._items[str(path)] = item
            if item.data(KEY_ROLE) != f"{key[0]}:{key[1]}":
                item.setData(f"{key[0]}:{key[1]}", KEY_ROLE)
                self._show(item, path, key)
        watched = set(self._watcher.files())
        new_files = [str(p) for _n, p, _k in files[:WATCHED_FILES] if str(p) not in watched]
        if new_files:
            self._watcher.addPaths(new_files)
        self._show_count()

    def _show(self, item: QStandardItem, path: Path, key: tuple[int, int]) -> None:
        ck = (str(path), *key)
        thumb = self._cache.get(ck)
        if thumb is not None:
            self._cache.move_to_end(ck)
            self._apply(item, thumb)
            return
        item.setIcon(self._loading)
        item.setText(f"{path.name}\n…")
        item.setToolTip(f"{path.name}: making its thumbnail…")
        item.setData("loading", STATE_ROLE)
        if ck not in self._pending:
            self._pending.add(ck)
            self._pool.start(_ThumbJob(path, key, self._results))

    def _thumb_done(self, path: Path, key: tuple[int, int], thumb: Thumb) -> None:
        ck = (str(path), *key)
        self._pending.discard(ck)
        self._cache[ck] = thumb
        while len(self._cache) > CACHE_SIZE:
            self._cache.popitem(last=False)
        item = self._items.get(str(path))
        if item is not None and item.data(KEY_ROLE) == f"{key[0]}:{key[1]}":
            self._apply(item, thumb)
            self._show_count()

    def _apply(self, item: QStandardItem, thumb: Thumb) -> None:
        name = str(item.data(NAME_ROLE))
        flags = item.flags()
        if thumb.image is None:
            item.setIcon(self._unreadable)
            item.setText(f"{name}\nunreadable")
            item.setToolTip(f"{name} cannot be read:\n{thumb.error}")
            item.setData("unreadable", STATE_ROLE)
            item.setFlags(flags & ~Qt.ItemFlag.ItemIsDragEnabled)
            return
        w, h = thumb.size
        item.setIcon(_shown(thumb.image))
        item.setText(f"{name}\n{w}×{h}")
        item.setToolTip(f"{item.data(PATH_ROLE)}\n{w} × {h} pixels, {thumb.detail}")
        item.setData("ready", STATE_ROLE)
        item.setFlags(flags | Qt.ItemFlag.ItemIsDragEnabled)

    def _show_count(self, text: str = "") -> None:
        if not text:
            items = list(self._items.values())
            bad = sum(1 for it in items if it.data(STATE_ROLE) == "unreadable")
            waiting = sum(1 for it in items if it.data(STATE_ROLE) == "loading")
            text = f"{len(items)} image{'s' if len(items) != 1 else ''}" if items else \
                "no images in this folder"
            if self.proxy.rowCount() != len(items):
                text += f", {self.proxy.rowCount()} shown"
            if bad:
                text += f", {bad} unreadable"
            if waiting:
                text += f", reading {waiting}…"
        self.status.setText(text)

    def _filter(self, text: str) -> None:
        text = text.strip()
        if any(ch in text for ch in "*?["):
            self.proxy.setFilterWildcard(text)
        else:
            self.proxy.setFilterFixedString(text)
        self._show_count()

    # --- using a file ----------------------------------------------------------------------
    def _activated(self, index: QModelIndex) -> None:
        path = index.data(PATH_ROLE)
        if not path:
            return
        if index.data(STATE_ROLE) == "unreadable":
            self.status.setText(f"{Path(path).name} cannot be read")
            return
        self.use_file(Path(path))

    def use_file(self, path: Path) -> list[str]:
        """The file into the canvas's selected texture slot (`texture_slot`), or a new
        Texture Parameter and Texture Sample on it at the canvas's centre (as an image
        dropped on empty canvas makes), selected: the ids of the nodes filled or added."""
        canvas = self.canvas_of()
        if canvas is None:
            return []
        slot = texture_slot(canvas)
        if slot is not None:
            return [slot[0]] if canvas.fill_texture_slot(slot[0], slot[1], path) else []
        centre = canvas.mapToScene(canvas.viewport().rect().center())
        added = canvas.add_texture(path, centre - QPointF(115, 40))  # the pair, centred
        if added:
            canvas.select_nodes(added)
        return added

    def shutdown(self) -> None:
        """No job waits or runs on: the window is closing."""
        self._pool.clear()
        self._pool.waitForDone()
