"""Files dropped on the node canvas: images become textures, function files calls, and
material files are opened (a mix-in of `NodeCanvasView`)."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QPointF

from matedit.app.paths import reference_for
from matedit.graph.commands import AddNode, Connect
from matedit.graph.model import Link
from matedit.graph.nodes import Role, kind_for

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tga", ".tif", ".tiff", ".exr", ".hdr", ".bmp")


def guess_srgb(path: Path) -> bool:
    """Whether an image file holds sRGB-encoded colour: 8-bit (or 16-bit integer) colour
    images do; EXR/HDR (float, scene-linear) and single-channel data (masks, heights) don't."""
    if path.suffix.lower() in (".exr", ".hdr"):
        return False
    try:
        from matedit.io.images import read_image

        data = read_image(path)
    except (ValueError, OSError):
        return True  # unreadable now: a colour image is the common case; the checker shows
    return data.is_ldr and data.channels >= 3


class CanvasDrops:
    """Drag-and-drop of files onto the canvas (needs the view's `controller`, `_new_node`,
    `add_node_at`, `select_nodes`, `refuse`, `message` and `materialOpenRequested`)."""

    @staticmethod
    def _dropped_paths(mime) -> list[Path]:
        if not mime.hasUrls():
            return []
        return [Path(u.toLocalFile()) for u in mime.urls() if u.isLocalFile() and
                Path(u.toLocalFile()).suffix.lower() in (*IMAGE_SUFFIXES, ".json")]

    def dragEnterEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self._dropped_paths(event.mimeData()):
            event.acceptProposedAction()
        else:
            super().dragEnterEvent(event)

    def dragMoveEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self._dropped_paths(event.mimeData()):
            event.acceptProposedAction()
        else:
            super().dragMoveEvent(event)

    def dropEvent(self, event) -> None:  # noqa: N802 - Qt's name
        paths = self._dropped_paths(event.mimeData())
        if not paths:
            super().dropEvent(event)
            return
        self.drop_files(paths, self.mapToScene(event.position().toPoint()))
        event.acceptProposedAction()

    def drop_files(self, paths: list[Path], scene_pos: QPointF) -> list[str]:
        """Files dropped at `scene_pos`: an image becomes a Texture Parameter wired into a
        Texture Sample; a function file becomes a call to it; a material file is opened.
        The ids of the nodes added."""
        added: list[str] = []
        at = QPointF(scene_pos)
        for path in paths:
            if path.suffix.lower() in IMAGE_SUFFIXES:
                added += self.add_texture(path, at)
            elif path.suffix.lower() == ".json":
                from matedit.io.document import FormatError, load

                try:
                    doc = load(path)
                except (FormatError, OSError) as exc:
                    self.refuse(f"{path.name}: {exc}")
                    continue
                if not doc.is_function:
                    self.materialOpenRequested.emit(str(path))
                    continue
                ref = reference_for(self.controller.document, path)
                nid = self.add_node_at(kind_for(Role.FUNCTION_CALL), at, {"function": ref})
                if nid:
                    added.append(nid)
            at = at + QPointF(30, 120)
        if added:
            self.select_nodes(added)
        return added

    def add_texture(self, path: Path, scene_pos: QPointF) -> list[str]:
        """A Texture Parameter on `path` (sRGB guessed from the file) wired into a new Texture
        Sample, as one undo step; their ids."""
        srgb = guess_srgb(path)
        tp = self._new_node(kind_for(Role.TEXTURE_PARAMETER), scene_pos, {
            "path": reference_for(self.controller.document, path), "srgb": srgb})
        if tp is None:
            return []
        ts = self._new_node(kind_for(Role.TEXTURE_SAMPLE), scene_pos + QPointF(230, 0), None)
        if ts is None:
            return []
        if ts.id == tp.id:  # both took the first free id of their stems: keep them apart
            ts.id = self.controller.document.graph.new_id("textureSample") + "b"
        ok = self.controller.push_all([AddNode(tp), AddNode(ts),
                                       Connect(Link(tp.id, "texture", ts.id, "texture"))],
                                      f"add texture {path.name}")
        if ok:
            self.message.emit(f"{path.name}: {'sRGB colour' if srgb else 'linear'} texture")
        return [tp.id, ts.id] if ok else []

