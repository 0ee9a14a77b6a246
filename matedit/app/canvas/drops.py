"""Files dropped on the node canvas: images become textures, function files calls, and
material files are opened (a mix-in of `NodeCanvasView`)."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QPointF

from matedit.app.canvas.placement import place
from matedit.app.paths import reference_for
from matedit.graph.commands import AddNode, Connect, SetSetting
from matedit.graph.model import Link
from matedit.graph.nodes import Role, kind_for, role_of

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
        Texture Sample (dropped on a node with a texture input, or on a Texture Parameter,
        it fills that node's texture slot); a function file becomes a call to it; a
        material file is opened. The ids of the nodes added or filled."""
        added: list[str] = []
        at = QPointF(scene_pos)
        target = self._texture_target(scene_pos)
        for path in paths:
            if path.suffix.lower() in IMAGE_SUFFIXES and target is not None:
                if self.fill_texture_slot(target[0], target[1], path):
                    added.append(target[0])
                target = None  # one image a slot: the next makes a sample of its own
            elif path.suffix.lower() in IMAGE_SUFFIXES:
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

    def _texture_target(self, scene_pos: QPointF) -> tuple[str, str] | None:
        """(node id, texture input) of the node under `scene_pos` that takes an image:
        a Texture Parameter ("" for its own file) or a node with a texture input."""
        from matedit.app.canvas.node_item import NodeItem

        item = next((it for it in self.scene().items(scene_pos) if isinstance(it, NodeItem)),
                    None)
        if item is None:
            return None
        node = self.controller.document.graph.nodes.get(item.node_id)
        if node is None:
            return None
        if role_of(node.kind) == Role.TEXTURE_PARAMETER:
            return node.id, ""
        port = texture_input(self.controller, node.id)
        return (node.id, port) if port else None

    def fill_texture_slot(self, node_id: str, port: str, path: Path | str) -> bool:
        """A node's texture slot takes the image at `path`, as one undo step: the Texture
        Parameter wired into `port` (or the parameter `node_id` itself, port "") gets the
        file; an input with none gets a new parameter on that file, wired in, left of it."""
        graph = self.controller.document.graph
        node = graph.nodes.get(node_id)
        if node is None:
            return False
        link = graph.incoming(node_id, port) if port else None
        param = node_id if not port else link.src if link is not None and \
            role_of(graph.nodes[link.src].kind) == Role.TEXTURE_PARAMETER else None
        if not str(path):  # cleared: the parameter keeps its place, with no image
            return param is not None and self.controller.push(SetSetting(param, "path", ""))
        path = Path(path)
        ref = reference_for(self.controller.document, path)
        srgb = guess_srgb(path)
        if param is not None:
            ok = self.controller.push_all([SetSetting(param, "srgb", srgb),
                                           SetSetting(param, "path", ref)],
                                          f"texture {path.name}")
        else:
            tp = self._new_node(kind_for(Role.TEXTURE_PARAMETER),
                                QPointF(node.position[0] - 230, node.position[1]),
                                {"path": ref, "srgb": srgb})
            if tp is None:
                return False
            place(tp, self.scene())
            ok = self.controller.push_all([AddNode(tp), Connect(Link(tp.id, "texture",
                                                                     node_id, port))],
                                          f"texture {path.name}")
        if ok:
            self.message.emit(f"{path.name}: {'sRGB colour' if srgb else 'linear'} texture "
                              f"in {node.label or node_id}")
        return ok

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


def texture_input(controller, node_id: str) -> str:
    """The node's first texture input, by its analysed type ("" if it has none)."""
    a = controller.analysis
    ports = a.ports.get(node_id) if a is not None else None
    for p in (ports.inputs if ports is not None else ()):
        if p.type == "texture2d":
            return p.name
    return ""
