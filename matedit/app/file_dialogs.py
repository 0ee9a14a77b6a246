"""Every file dialog of the editor, in one place: open a file, save a file, pick a folder.

The signatures are QFileDialog's static functions' (so a panel can hold one as a
replaceable attribute). The dialog is Qt's own, the same on every platform, opened in
the detail view with the Name column as wide as the longest name it lists (its default
width truncates names like ``rusty_painted_metal.instance.json``).
"""

from __future__ import annotations

from PySide6.QtWidgets import QFileDialog, QHeaderView, QSplitter, QTreeView, QWidget

SIZE = (900, 560)
SIDEBAR = 170  # the places list's width: names like 'Computer' unclipped


def make_dialog(parent: QWidget | None, caption: str, directory: str = "",
                filter: str = "", *, mode: str = "open") -> QFileDialog:  # noqa: A002 - Qt's
    """The dialog, not yet shown. `mode`: "open" (an existing file), "save" or "folder"."""
    dlg = QFileDialog(parent, caption, directory, filter)
    dlg.setOption(QFileDialog.Option.DontUseNativeDialog, True)
    if mode == "save":
        dlg.setAcceptMode(QFileDialog.AcceptMode.AcceptSave)
        dlg.setFileMode(QFileDialog.FileMode.AnyFile)
    elif mode == "folder":
        dlg.setFileMode(QFileDialog.FileMode.Directory)
        dlg.setOption(QFileDialog.Option.ShowDirsOnly, True)
    else:
        dlg.setFileMode(QFileDialog.FileMode.ExistingFile)
    dlg.setViewMode(QFileDialog.ViewMode.Detail)
    dlg.resize(*SIZE)
    for view in dlg.findChildren(QTreeView):  # Name, Size, Type as wide as they need
        head = view.header()
        for section in range(max(head.count() - 1, 0)):
            head.setSectionResizeMode(section, QHeaderView.ResizeMode.ResizeToContents)
        head.setStretchLastSection(True)
    splitter = dlg.findChild(QSplitter, "splitter")  # the places sidebar | the files
    if splitter is not None and splitter.count() == 2:
        splitter.setSizes([SIDEBAR, SIZE[0] - SIDEBAR])
    return dlg


def _run(dlg: QFileDialog) -> tuple[str, str]:
    """(path, chosen filter); ("", "") if cancelled."""
    try:
        if dlg.exec() and dlg.selectedFiles():
            return dlg.selectedFiles()[0], dlg.selectedNameFilter()
        return "", ""
    finally:
        dlg.deleteLater()


def open_file(parent: QWidget | None, caption: str = "", directory: str = "",
              filter: str = "") -> tuple[str, str]:  # noqa: A002 - Qt's name
    """(path, chosen filter); ("", "") if cancelled."""
    return _run(make_dialog(parent, caption, directory, filter, mode="open"))


def save_file(parent: QWidget | None, caption: str = "", directory: str = "",
              filter: str = "") -> tuple[str, str]:  # noqa: A002 - Qt's name
    """(path, chosen filter); ("", "") if cancelled."""
    return _run(make_dialog(parent, caption, directory, filter, mode="save"))


def existing_folder(parent: QWidget | None, caption: str = "", directory: str = "") -> str:
    """A folder's path; "" if cancelled."""
    return _run(make_dialog(parent, caption, directory, mode="folder"))[0]
