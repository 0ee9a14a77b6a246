"""Edit › Collapse to Function and Expand Function on the canvas (matedit.graph.collapse):
the file part (where the function is written, references rebased) and the undo step."""

from __future__ import annotations

import copy
import os
import re
from pathlib import Path
from typing import TYPE_CHECKING

from matedit.app.canvas import placement
from matedit.app.paths import reference_for
from matedit.graph.collapse import (
    CollapseError,
    check_collapsible,
    collapse,
    collapsible,
    expand,
)
from matedit.graph.commands import AddNode, Macro
from matedit.graph.nodes import Role, role_of
from matedit.io import library
from matedit.io.document import rebase_references, reference_fields, save

if TYPE_CHECKING:
    from matedit.app.canvas.view import NodeCanvasView


def ask_function_path(view: NodeCanvasView, suggestion: str) -> str:
    """Where to write the new function (a save dialog); "" when cancelled."""
    from matedit.app import file_dialogs

    path, _ = file_dialogs.save_file(view, "Save the new material function as", suggestion,
                                     "matedit function (*.json)")
    if path and not path.endswith(".json"):
        path += ".json"
    return path


def collapse_selection(view: NodeCanvasView) -> str:
    """The selection becomes a function file and a call in its place (one undo step); the
    call's id, or "" (with the reason in the status bar) when nothing happened."""
    controller = view.controller
    doc = controller.document
    ids = collapsible(doc, view.selected_ids())
    if doc.is_function:
        view.message.emit("Collapse works in materials (a function inside a function: open "
                          "the material)")
        return ""
    if not ids:
        view.message.emit("Nothing to collapse: select nodes other than parameters and "
                          "outputs")
        return ""
    analysis = controller.analysis
    if analysis is None or any(n not in analysis.out_types for n in ids):
        view.message.emit("The material has errors: fix them (Diagnostics) before collapsing")
        return ""
    try:  # before the file is asked for
        check_collapsible(doc, ids)
    except CollapseError as exc:
        view.message.emit(f"Cannot collapse: {exc}")
        return ""
    folder = Path(doc.path).parent if doc.path else Path.cwd()
    if library.inside(folder):
        folder = Path.home()
    stem = re.sub(r"[^a-z0-9]+", "_", (doc.name or "material").lower()).strip("_")
    target = view.ask_function_path(str(folder / f"{stem or 'material'}_function.json"))
    if not target:
        return ""
    target_path = Path(target)
    if library.inside(target_path.parent):
        view.message.emit("The built-in library is read-only: save the function in a folder "
                          "of your own")
        return ""
    name = target_path.stem.replace("_", " ").capitalize()
    try:
        fn, commands, call = collapse(doc, analysis, ids, reference_for(doc, target_path),
                                      name)
        fn.path = Path(doc.path) if doc.path else None  # its references are the material's
        save(fn, target_path)  # atomic; relative references rebased to the function's folder
    except CollapseError as exc:
        view.message.emit(str(exc))
        return ""
    except (OSError, ValueError) as exc:
        view.message.emit(f"Cannot write {target_path.name}: {exc}")
        return ""
    for c in commands:  # the call lands in free space, off the nodes that stay
        if isinstance(c, AddNode):
            shift = placement.free_offset([placement.node_rect(c.node)],
                                          placement.taken_rects(view.scene(), exclude=ids))
            c.node.position = (round(c.node.position[0] + shift.x(), 1),
                               round(c.node.position[1] + shift.y(), 1))
    text = f"collapse {len(ids)} node{'s' if len(ids) != 1 else ''} into {target_path.name}"
    if not controller.push(Macro(commands, text=text)):
        return ""
    view.select_nodes([call])
    view.message.emit(f"Collapsed {len(ids)} node{'s' if len(ids) != 1 else ''} into "
                      f"{target_path.name}")
    return call


def expand_call(view: NodeCanvasView) -> list[str]:
    """The selected function call's nodes in its place (one undo step); the new ids."""
    controller = view.controller
    doc = controller.document
    ids = view.selected_ids()
    node = doc.graph.nodes.get(ids[0]) if len(ids) == 1 else None
    if node is None or role_of(node.kind) != Role.FUNCTION_CALL:
        view.message.emit("Select one Function Call to expand")
        return []
    ref = node.settings.get("function")
    try:
        fn = controller.resolver.resolve(str(ref or ""), doc)
    except (LookupError, ValueError, OSError) as exc:
        view.message.emit(f"Cannot expand: {exc}")
        return []
    inline = copy.deepcopy(fn)  # the resolver's document is shared: rebase a copy
    if doc.path is not None:
        rebase_references(inline, Path(doc.path))  # its references, from the material's folder
    else:  # an unsaved material holds absolute references (made relative on its first save)
        base = Path(os.path.realpath(fn.path)).parent if fn.path else Path.cwd()
        for container, key in reference_fields(inline):
            r = container[key]
            if r and not library.is_library_ref(r) and not Path(r).is_absolute():
                container[key] = Path(os.path.realpath(base / r)).as_posix()
    try:
        commands, new_ids = expand(doc, node.id, inline)
    except CollapseError as exc:
        view.message.emit(str(exc))
        return []
    name = fn.name or Path(str(ref)).stem
    if not controller.push(Macro(commands, text=f"expand {name}")):
        return []
    view.select_nodes(new_ids)
    view.message.emit(f"Expanded {name}: {len(new_ids)} node{'s' if len(new_ids) != 1 else ''}")
    return new_ids
