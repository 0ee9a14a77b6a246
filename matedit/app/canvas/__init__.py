"""The node canvas: the material graph as nodes and wires, edited through commands.

Public API (what the main window uses; kept stable):

``NodeCanvasView(controller, parent=None, actions=None)``
    A QGraphicsView over ``controller`` (a ``DocumentController``). It follows the
    controller's document, including ``documentReplaced``.

``view.scene() -> NodeScene``
    The QGraphicsScene mirroring ``controller.document.graph``: items keyed by node
    id (``node_items``), link (``wire_items``) and comment id (``comment_items``);
    no graph state of its own.

Signals on the view:
    ``selectionChangedIds(list)``  selected node ids, sorted, when the selection changes.
    ``functionOpenRequested(str)`` double-click on a function_call node: the absolute
                                   path of its function file (``resolver.path_of``).
    ``message(str)``               a line for the status bar (e.g. why a link was refused).

Methods on the view:
    ``frame_all()``, ``frame_selection()``
    ``select_nodes(ids)``
    ``add_node_at(kind, scene_pos, settings=None) -> node_id`` ('' if refused)
    ``set_node_errors(dict[node_id, str])``   GLSL errors mapped to nodes: red badges.
    ``set_node_preview(node_id, QImage | None)``  a thumbnail in the node.
    ``open_palette(scene_pos=None)``          the searchable node palette.
    Also, for menus: ``delete_selection()``, ``copy_selection()``, ``cut_selection()``,
    ``paste(scene_pos=None)``, ``duplicate_selection()``, ``comment_selection()``,
    ``selected_ids()``, ``toggle_minimap()``.

Commands (menus, context menu, keys) are the action table's (``canvas.actions``, see
``matedit.app.canvas.actions``). Keys (while the canvas has focus): Tab palette;
Delete/Backspace delete; Ctrl+C/X/V/D
copy, cut, paste, duplicate (clipboard: ``application/x-matedit-nodes`` and text JSON);
F frame selection; Home or A frame all; C comment around selection; F2 rename;
F1 node documentation; M minimap;
wheel zoom; middle drag, Alt+drag or Space+drag pan.
"""

from matedit.app.canvas.scene import NodeScene
from matedit.app.canvas.view import NodeCanvasView

__all__ = ["NodeCanvasView", "NodeScene"]
