"""Preview any node in the viewport (Unreal's "Start Previewing Node", Blender's Viewer).

The viewport compiles a copy of the document whose material output is fed by the
previewed socket instead: MaterialAttributes as they are (the shaded material), any
other value as unlit emission on black - a colour as itself, a scalar as grey, a
vector as false colour (xy of a vec2, xyz of a vec4). The document itself never
changes: no undo step, nothing to save.
"""

from __future__ import annotations

from dataclasses import dataclass

from matedit.graph.model import Link, MaterialDocument, Node
from matedit.graph.nodes import Role, kind_for, role_of
from matedit.graph.types import PortType


@dataclass(frozen=True)
class PreviewTarget:
    node_id: str
    port: str

    def label(self) -> str:
        return f"{self.node_id}.{self.port}"


def preview_document(doc: MaterialDocument, target: PreviewTarget,
                     out_type: PortType) -> MaterialDocument:
    """A copy of `doc` whose output shows `target` (of type `out_type`)."""
    g = doc.graph.copy()
    preview = MaterialDocument(doc.kind, g, doc.name, doc.description, doc.path,
                               dict(doc.preview))
    out = next((n for n in sorted(g.nodes.values(), key=lambda n: n.id)
                if role_of(n.kind) == Role.MATERIAL_OUTPUT), None)
    if out is None:
        out = Node(g.new_id("previewOutput"), kind_for(Role.MATERIAL_OUTPUT), (0.0, 0.0))
        g.nodes[out.id] = out
    old = next((lk for lk in g.links if lk.dst == out.id and lk.dst_port == "attributes"),
               None)
    if old is not None:
        g.links.discard(old)
    src: tuple[str, str] = (target.node_id, target.port)
    if out_type == PortType.MATERIAL:
        g.links.add(Link(*src, out.id, "attributes"))
        return preview
    if out_type == PortType.VEC2:  # (x, y, 0)
        nid = g.new_id("previewAppend")
        g.nodes[nid] = Node(nid, kind_for(Role.APPEND), (0.0, 0.0), values={"b": 0.0})
        g.links.add(Link(*src, nid, "a"))
        src = (nid, "result")
    elif out_type == PortType.VEC4:
        nid = g.new_id("previewMask")
        g.nodes[nid] = Node(nid, kind_for(Role.COMPONENT_MASK), (0.0, 0.0), {"channels": "xyz"})
        g.links.add(Link(*src, nid, "value"))
        src = (nid, "result")
    elif not out_type.is_numeric:
        raise ValueError(f"{target.label()} ({out_type}) cannot be shown on the mesh")
    make = g.new_id("previewMake")
    # Black, rough, no specular (cavity 0): only the emission shows, as the value itself.
    g.nodes[make] = Node(make, kind_for(Role.MAKE_ATTRIBUTES), (0.0, 0.0), values={
        "baseColor": [0.0, 0.0, 0.0], "metallic": 0.0, "roughness": 1.0, "cavity": 0.0})
    g.links.add(Link(*src, make, "emissive"))
    g.links.add(Link(make, "attributes", out.id, "attributes"))
    return preview
