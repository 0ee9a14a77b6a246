"""A MaterialX document as a matedit material: `matedit import FILE.mtlx -o OUT.json`.

One `surfacematerial` is read (`import_mtlx`: the only one, or the one named), or every one
(`import_all`, a file each); its surface must be a standard_surface,
open_pbr_surface, gltf_pbr or UsdPreviewSurface (SURFACES maps each one's inputs to our
attributes). Its inputs may be values or connections into nodegraphs (or top-level nodes) of
the stdlib nodes that matedit.interop.mtlx_map maps from our catalogue, read back here; any
other node is an error naming it, never a silent drop. Every error is collected, so one run
names every unsupported node.

Nothing is dropped silently: every input the surface, a converted node or the
surfacematerial sets (not at its definition's default) that is not read exactly (dropped,
approximated, clamped) is a warning line naming the file, material, input, value and node
(`_Importer.warnings`, handed to the caller's `warnings` list). The base weight multiplies
the base colour and is never cavity on its own (BASE_WEIGHT).

The file is untrusted: it is read bounded (`read_bounded`), without XIncludes; MaterialX
names become matedit node ids and parameter names only through the identifier rule
(`mangle`, then `valid_id` / `identifier_problem`); numbers must be finite; image file names
must be relative and stay text in the document (they are never read here).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from matedit.graph.model import DocumentKind, Link, MaterialDocument, Node, valid_id
from matedit.graph.names import identifier_problem, mangle
from matedit.graph.nodes import THIN_WALLED, Role, definition, kind_for
from matedit.graph.numbers import gpu_number_problem
from matedit.interop import mtlx_map
from matedit.interop.mtlx_colorspace import WORKING, from_materialx
from matedit.io.atomic import read_bounded
from matedit.nodes.textures import ADDRESS_MODES, FILTER_TYPES

MAX_MTLX_BYTES = 16 << 20
MAX_NODES = 20000

# Surface category -> attribute -> (input, scale input or None, scale factor).
SURFACES: dict[str, dict[str, tuple[str, str | None, float]]] = {
    "standard_surface": {
        "baseColor": ("base_color", None, 1.0), "metallic": ("metalness", None, 1.0),
        "roughness": ("specular_roughness", None, 1.0),
        "normal": ("normal", None, 1.0), "emissive": ("emission_color", "emission", 1.0),
        "opacity": ("opacity", None, 1.0)},
    "open_pbr_surface": {
        "baseColor": ("base_color", None, 1.0), "metallic": ("base_metalness", None, 1.0),
        "roughness": ("specular_roughness", None, 1.0),
        "normal": ("geometry_normal", None, 1.0),
        # emission_luminance is in nits; 1000 nits is our emissive 1.0
        "emissive": ("emission_color", "emission_luminance", 1e-3),
        "opacity": ("geometry_opacity", None, 1.0)},
    "gltf_pbr": {
        "baseColor": ("base_color", None, 1.0), "metallic": ("metallic", None, 1.0),
        "roughness": ("roughness", None, 1.0), "cavity": ("occlusion", None, 1.0),
        "normal": ("normal", None, 1.0), "emissive": ("emissive", "emissive_strength", 1.0),
        "opacity": ("alpha", None, 1.0)},
    "UsdPreviewSurface": {
        "baseColor": ("diffuseColor", None, 1.0), "metallic": ("metallic", None, 1.0),
        "roughness": ("roughness", None, 1.0), "cavity": ("occlusion", None, 1.0),
        "normal": ("normal", None, 1.0), "emissive": ("emissiveColor", None, 1.0),
        "opacity": ("opacity", None, 1.0)},
}
# Surface category -> lobe attribute -> (input, weight input or None), read only where the
# file sets the input (the surfaces' own defaults, such as standard_surface's coat_roughness
# 0.1, would otherwise turn on code for a lobe the material does not use). A weight multiplies
# the colour (sheen x sheen_color is our sheenColor).
LOBES: dict[str, dict[str, tuple[str, str | None]]] = {
    "standard_surface": {
        "specularColor": ("specular_color", None), "ior": ("specular_IOR", None),
        "coat": ("coat", None), "coatRoughness": ("coat_roughness", None),
        "coatColor": ("coat_color", None), "coatIor": ("coat_IOR", None),
        "coatNormal": ("coat_normal", None), "sheenColor": ("sheen_color", "sheen"),
        "sheenRoughness": ("sheen_roughness", None),
        "anisotropy": ("specular_anisotropy", None),
        "anisotropyDirection": ("specular_rotation", None),
        # subsurface_scale is 1 / our thickness: the mean free path radius x scale is our
        # radius / thickness, all the shading reads (docs/shading.md, Subsurface)
        "subsurface": ("subsurface", None), "subsurfaceColor": ("subsurface_color", None),
        "subsurfaceRadius": ("subsurface_radius", None), "thickness": ("subsurface_scale", None),
        # the thin film's thickness in nm, as ours (docs/materialx.md)
        "thinFilmThickness": ("thin_film_thickness", None),
        "thinFilmIor": ("thin_film_IOR", None)},
    "open_pbr_surface": {
        "specularColor": ("specular_color", None), "ior": ("specular_ior", None),
        "coat": ("coat_weight", None), "coatRoughness": ("coat_roughness", None),
        "coatColor": ("coat_color", None), "coatIor": ("coat_ior", None),
        "coatNormal": ("geometry_coat_normal", None), "sheenColor": ("fuzz_color", "fuzz_weight"),
        "sheenRoughness": ("fuzz_roughness", None),
        "anisotropy": ("specular_roughness_anisotropy", None),
        # the tangent rotated about the normal by a constant angle (our export's)
        "anisotropyDirection": ("geometry_tangent", None),
        # the mean free path subsurface_radius x subsurface_radius_scale, at our thickness 1
        "subsurface": ("subsurface_weight", None), "subsurfaceColor": ("subsurface_color", None),
        "subsurfaceRadius": ("subsurface_radius_scale", "subsurface_radius"),
        # thin_film_thickness in micrometres (libraries/bxdf/open_pbr_surface.mtlx scales it
        # by 1000 to nm), scaled by thin_film_weight: weight 0 is no film (ours: thickness 0)
        "thinFilmThickness": ("thin_film_thickness", "thin_film_weight"),
        "thinFilmIor": ("thin_film_ior", None)},
    "gltf_pbr": {
        "ior": ("ior", None), "coat": ("clearcoat", None),
        "coatRoughness": ("clearcoat_roughness", None), "coatNormal": ("clearcoat_normal", None),
        "sheenColor": ("sheen_color", None), "sheenRoughness": ("sheen_roughness", None),
        "anisotropy": ("anisotropy_strength", None),
        "anisotropyDirection": ("anisotropy_rotation", None),
        # KHR_materials_specular, _transmission, _volume and _iridescence, as ours (the
        # iridescence thickness in nm, times its weight; thickness 0: thin-walled, below)
        "specularColor": ("specular_color", None), "transmission": ("transmission", None),
        "attenuationColor": ("attenuation_color", None),
        "attenuationDistance": ("attenuation_distance", None),
        "thinFilmThickness": ("iridescence_thickness", "iridescence"),
        "thinFilmIor": ("iridescence_ior", None)},
    "UsdPreviewSurface": {
        "ior": ("ior", None), "coat": ("clearcoat", None),
        "coatRoughness": ("clearcoatRoughness", None)},
}
# Transmission, read apart from LOBES (docs/materialx.md, Transmission): category ->
# (weight, colour, depth, thin-walled flag). The colour is a surface tint at depth 0 and the
# absorption colour reached at `depth` otherwise (both surfaces' rule).
TRANSMISSION: dict[str, tuple[str, str, str, str]] = {
    "standard_surface": ("transmission", "transmission_color", "transmission_depth",
                         "thin_walled"),
    "open_pbr_surface": ("transmission_weight", "transmission_color", "transmission_depth",
                         "geometry_thin_walled"),
}
# The base weight and the specular weight: category -> (base, specular). The base weight
# scales the diffuse and (through base_color) the metal's reflectivity, both surfaces' own
# graphs: it multiplies our baseColor, exactly, and is never cavity. The specular weight
# scales the dielectric reflection; we have no counterpart (F90 stays 1), except where both
# weights come from one source: that darkens the surface's lighting, our cavity (what our
# export writes), exactly where the surface has no coat, sheen, subsurface or transmission.
BASE_WEIGHT: dict[str, tuple[str, str]] = {
    "standard_surface": ("base", "specular"),
    "open_pbr_surface": ("base_weight", "specular_weight"),
}
# The lobes base and specular do not darken, where cavity does (the reading above warns).
_OTHER_LOBES: dict[str, tuple[str, ...]] = {
    "standard_surface": ("coat", "sheen", "subsurface", "transmission"),
    "open_pbr_surface": ("coat_weight", "fuzz_weight", "subsurface_weight",
                         "transmission_weight"),
}
# Surface inputs that take a colour for a scalar of ours: the first channel is read.
_FIRST_CHANNEL = {("standard_surface", "opacity")}
# Where our sheen clamps its roughness (docs/shading.md, Sheen).
SHEEN_MIN_ROUGHNESS = 0.3

# Rotations of the anisotropy direction from the tangent: standard_surface's in turns (0..1),
# glTF's in radians.
_ROTATION_TO_RADIANS = {"standard_surface": 2.0 * 3.141592653589793, "gltf_pbr": 1.0}

# Surfaces whose normal input is world space (a normalmap node is expected there); the
# UsdPreviewSurface normal is tangent space already.
WORLD_NORMAL = {"standard_surface", "open_pbr_surface", "gltf_pbr"}

# MaterialX category -> (our kind, {MaterialX input: our input}) for one-to-one nodes, from
# the catalogue (NodeDef.mtlx and mtlx_reads).
DIRECT: dict[str, tuple[str, dict[str, str]]] = mtlx_map.direct()
# Our kind for each stdlib node or export recipe the importer reads back.
_kind = mtlx_map.kind_mapped_to
_WIDTH = {"float": 1, "integer": 1, "vector2": 2, "vector3": 3, "color3": 3, "vector4": 4,
          "color4": 4}


# The inputs each converted node category reads (DIRECT's read their ports); any other
# input a file sets on one is a warning (`_Importer.unread`).
_READS: dict[str, set[str]] = {
    "extract": {"in", "index"}, "separate2": {"in"}, "separate3": {"in"},
    "separate4": {"in"}, "combine2": {"in1", "in2"}, "combine3": {"in1", "in2", "in3"},
    "combine4": {"in1", "in2", "in3", "in4"}, "convert": {"in"}, "texcoord": {"index"},
    "position": {"space"}, "normal": {"space"}, "rotate2d": {"in", "amount"},
    "viewdirection": set(), "time": set(), "constant": {"value"}, "dot": {"in"},
    "image": {"file", "uaddressmode", "vaddressmode", "filtertype", "texcoord"},
    "normalmap": {"in", "scale", "normal", "tangent", "bitangent"},
    "switch": {"which", *(f"in{k}" for k in range(1, 11))},
}
# hextiledimage's inputs -> our Hex-Tiled Texture's
_HEXTILED = {"tiling": "tiling", "rotation": "rotation", "rotationrange": "rotation_range",
             "scale": "scale", "scalerange": "scale_range", "offset": "offset",
             "offsetrange": "offset_range", "falloff": "falloff",
             "falloffcontrast": "falloff_contrast", "lumacoeffs": "luma"}
_READS["hextiledimage"] = {"file", "texcoord", *_HEXTILED}


def connected(inp) -> bool:
    return bool(inp.getNodeName() or inp.getNodeGraphString() or inp.getInterfaceName()
                or inp.getOutputString())


def value_text(inp) -> str:
    """An input's value as a warning shows it: a number, a tuple (0.96, 0.64, 0.54), a
    quoted string, or where it is connected from."""
    if inp.getNodeGraphString():
        return f"(from nodegraph {inp.getNodeGraphString()} output {inp.getOutputString()})"
    if inp.getNodeName():
        return f"(from node {inp.getNodeName()})"
    if inp.getInterfaceName():
        return f"(from interface input {inp.getInterfaceName()})"
    text = inp.getValueString()
    if inp.getType() in _WIDTH or inp.getType() == "boolean":
        try:
            vals = [float(x) for x in text.split(",")]
        except ValueError:
            return repr(text[:60])
        shown = [f"{v:.6g}" for v in vals]
        return shown[0] if len(shown) == 1 else f"({', '.join(shown)})"
    return repr(text[:60])


def is_default(inp, nodedef) -> bool:
    """Whether `inp` is a constant equal to its node definition's default (setting it changes
    nothing, so not reading it loses nothing)."""
    if connected(inp) or nodedef is None:
        return False
    d = nodedef.getActiveInput(inp.getName())
    if d is None or d.getDefaultGeomPropString():
        return False
    a, b = inp.getValueString().strip(), d.getValueString().strip()
    if a == b:
        return True
    try:
        va = [float(x) for x in a.split(",")]
        vb = [float(x) for x in b.split(",")]
    except ValueError:
        return a.lower() == b.lower()
    return len(va) == len(vb) and all(x == y for x, y in zip(va, vb))


class MtlxImportError(ValueError):
    """Errors of one import, one line each (the first is the exception's message)."""

    def __init__(self, messages: list[str]) -> None:
        self.messages = messages
        super().__init__(messages[0])


@dataclass
class Src:
    """Where a value comes from in the matedit graph: a node's output, or a constant."""

    node: str | None = None
    port: str | None = None
    value: Any = None
    width: int = 1


def _floats(text: str, where: str) -> list[float]:
    """The numbers of a MaterialX value string, each under the float32 rule every format
    follows (matedit.graph.numbers); ValueError naming `where` (node and input) otherwise."""
    try:
        vals = [float(x) for x in text.split(",")] if text.strip() else []
    except ValueError:
        raise ValueError(f"{where}: value {text[:40]!r} is not a number list") from None
    for v in vals:
        why = gpu_number_problem(v)
        if why:
            raise ValueError(f"{where}: {why} (in {text[:40]!r})")
    return vals


def _computed(vals: list[float], where: str) -> list[float]:
    """Constants the importer folds (a colour times its weight): the same rule, so a product
    of two representable numbers that overflows is an error, not an infinity in the file."""
    for v in vals:
        why = gpu_number_problem(v)
        if why:
            raise ValueError(f"{where}: the folded {why}")
    return vals


class _Importer:
    def __init__(self, source: Path, out: Path, doc, lib, material: str = "") -> None:
        self.source = source
        self.out = out
        self.mxdoc = doc
        self.lib = lib
        self.material = material
        self.errors: list[str] = []
        self.warnings: list[str] = []
        self.mapped: set[str] = set()  # the surface's inputs read exactly
        self.noted: set[str] = set()  # the surface's inputs already warned about
        self.mat = MaterialDocument(kind=DocumentKind.MATERIAL, path=out)
        self.ids: set[str] = set()
        self.done: dict[tuple[tuple[str, ...], str, str], Src | None] = {}
        self.params: dict[str, Src] = {}
        self.count = 0
        # Stdlib nodes MaterialX implements as a nodegraph of other stdlib nodes (tiledimage,
        # place2d, gltf_image...) are read through that nodegraph (`expand`): the instances
        # being expanded, outermost first, each with its implementation. An interface input
        # of the implementation reads the instance's input, or the definition's default.
        self.stack: list[tuple[Any, Any]] = []
        # outermost expanded instance (by name path) -> the node, and its inputs read
        self.instances: dict[str, Any] = {}
        self.iface_read: dict[str, set[str]] = {}
        # images whose default is read (the border colour of constant addressing)
        self.image_default: set[tuple[tuple[str, ...], str]] = set()

    # --- helpers ---------------------------------------------------------------------------
    def err(self, what: str) -> None:
        msg = f"{self.source.name}: {what}"
        if msg not in self.errors:
            self.errors.append(msg)

    def warn(self, what: str) -> None:
        """A `warning:` line: something of the file not represented exactly."""
        where = f"material {self.material}: " if self.material else ""
        msg = f"{self.source.name}: {where}{what}"
        if msg not in self.warnings:
            self.warnings.append(msg)

    def warn_input(self, node, inp, why: str) -> None:
        """The warning naming input `inp` of `node`, its value and why (ends in `; dropped`
        or `; approximated`)."""
        self.warn(f"{inp.getName()} {value_text(inp)} of {node.getCategory()} "
                  f"{self.name_of(node)} {why}")

    def unread(self, node, read) -> None:
        """Warn about every input `node` sets (not at its definition's default) that the
        conversion did not read (`read`: the names it did)."""
        nd = node.getNodeDef()
        for inp in node.getInputs():
            if inp.getName() in read or is_default(inp, nd):
                continue
            if self.stack and inp.getInterfaceName():
                continue  # the instance's input: checked on the instance (`build`)
            self.warn_input(node, inp, "is not supported; dropped")

    def new_id(self, hint: str) -> str:
        base = mangle(hint, 56)
        if not valid_id(base):
            base = f"n_{base}"[:56].strip("_")
        if not valid_id(base):
            base = "node"
        nid, k = base, 1
        while nid in self.ids:
            k += 1
            nid = f"{base}_{k}"
        self.ids.add(nid)
        return nid

    def add(self, hint: str, kind: str, settings=None, values=None, depth=0) -> str:
        self.count += 1
        if self.count > MAX_NODES:
            raise MtlxImportError([f"{self.source.name}: more than {MAX_NODES} nodes"])
        nid = self.new_id(hint)
        pos = (-260.0 * (depth + 1), 110.0 * (self.count % 40))
        self.mat.graph.nodes[nid] = Node(nid, kind, pos, dict(settings or {}),
                                         dict(values or {}))
        return nid

    def connect(self, src: Src, nid: str, port: str) -> None:
        if src is None:
            return
        if src.node is None:
            v = src.value
            self.mat.graph.nodes[nid].values[port] = v[0] if len(v) == 1 else list(v)
        else:
            self.mat.graph.links.add(Link(src.node, src.port, nid, port))

    def name_of(self, el) -> str:
        return el.getNamePath() if el is not None else "?"

    # --- stdlib nodes implemented as nodegraphs ---------------------------------------------
    def scope(self) -> tuple[str, ...]:
        """The instances being expanded: a node of an implementation is converted once per
        instance (two tiledimages share the library's nodegraph, not their inputs)."""
        return tuple(inst.getNamePath() for inst, _ in self.stack)

    def hint(self, node) -> str:
        """A node's id hint: its name, or inside an expansion the outermost instance's name
        (the image itself) or that name and the inner node's."""
        if not self.stack:
            return node.getName()
        outer = self.stack[0][0].getName()
        return outer if node.getCategory() == "image" else f"{outer}_{node.getName()}"

    def where(self, node) -> str:
        if not self.stack:
            return f"node {self.name_of(node)}"
        inst = self.stack[0][0]
        return f"node {self.name_of(inst)} ({inst.getCategory()}, its {node.getName()})"

    def in_implementation(self, inp, level: int | None = None) -> bool:
        """Whether `inp` belongs to a node of the implementation expanded at `level` (the
        innermost one by default), so its interface name is an input of that instance."""
        level = len(self.stack) if level is None else level
        if level <= 0:
            return False
        node = inp.getParent()
        graph = node.getParent() if node is not None else None
        return graph is not None and graph.getNamePath() == self.stack[level - 1][1].getNamePath()

    def record(self, iface: str, level: int) -> None:
        if level == 1:
            self.iface_read.setdefault(self.stack[0][0].getNamePath(), set()).add(iface)

    def outer_input(self, node, name: str):
        """The element that gives `node`'s input `name` its value, through the interface of
        each implementation being expanded: the instance's own input, or its definition's
        input (the default) where the instance does not set it; None where neither has it."""
        inp = node.getInput(name)
        level = len(self.stack)
        while inp is not None and inp.getInterfaceName() and self.in_implementation(inp, level):
            inst, ng = self.stack[level - 1]
            iface = inp.getInterfaceName()
            self.record(iface, level)
            outer = inst.getInput(iface)
            if outer is None:
                nd = inst.getNodeDef()
                return nd.getActiveInput(iface) if nd is not None else None
            inp, level = outer, level - 1
        if inp is None:
            nd = node.getNodeDef()
            return nd.getActiveInput(name) if nd is not None else None
        return inp

    def interface_src(self, iface: str, depth: int, where: str) -> Src | None:
        """An interface input of the innermost implementation: the instance's input, read
        where the instance is, or its definition's default."""
        inst, _ng = frame = self.stack[-1]
        self.record(iface, len(self.stack))
        outer = inst.getInput(iface)
        self.stack.pop()
        try:
            if outer is not None:
                return self.input_el(outer, depth, f"node {self.name_of(inst)}: input {iface}")
            nd = inst.getNodeDef()
            d = nd.getActiveInput(iface) if nd is not None else None
            if d is None:
                return None
            if d.getDefaultGeomPropString():
                return self.geometry_src(inst, iface, d.getDefaultGeomPropString())
            if not d.getValueString() or d.getType() not in _WIDTH:
                return None
            try:
                return Src(value=_floats(d.getValueString(), where), width=_WIDTH[d.getType()])
            except ValueError as exc:
                self.err(str(exc))
                return None
        finally:
            self.stack.append(frame)

    def implementation(self, node):
        """The nodegraph MaterialX implements `node`'s definition with; None for a node
        implemented in code (hextiledimage, image) or without a definition."""
        import MaterialX as mx

        nd = node.getNodeDef()
        impl = nd.getImplementation() if nd is not None else None
        return impl if isinstance(impl, mx.NodeGraph) else None

    def push(self, node, impl) -> None:
        if not self.stack:
            self.instances.setdefault(node.getNamePath(), node)
            self.iface_read.setdefault(node.getNamePath(), set())
        self.stack.append((node, impl))

    def expand(self, node, impl, output: str, depth: int) -> Src | None:
        """`node` read through its definition's nodegraph: MaterialX's own definition of
        the node in the stdlib nodes it is made of (the same graph its code generators
        emit), so each of those is read by its own rule and nothing else is assumed."""
        out = impl.getOutput(output)
        if out is None:
            self.err(f"{self.where(node)}: unknown output {output!r}")
            return None
        self.push(node, impl)
        try:
            return self.output_el(out, depth)
        finally:
            self.stack.pop()

    # --- inputs ----------------------------------------------------------------------------
    def input_src(self, node, name: str, depth: int) -> Src | None:
        """The source of input `name` of MaterialX `node`: None when unset (our default)."""
        inp = node.getInput(name)
        if inp is None:
            return None
        return self.input_el(inp, depth, f"node {self.name_of(node)}: input {name}")

    def input_el(self, inp, depth: int, where: str) -> Src | None:
        width = _WIDTH.get(inp.getType(), 0)
        iface = inp.getInterfaceName()
        if iface and self.in_implementation(inp):
            return self.interface_src(iface, depth, where)
        if iface:
            graph = inp.getParent().getParent()
            gin = graph.getInput(iface) if graph is not None else None
            if gin is None:
                self.err(f"{where}: interface input {iface!r} not found")
                return None
            return self.parameter(gin, where)
        graph_name, out_name = inp.getNodeGraphString(), inp.getOutputString()
        node_name = inp.getNodeName()
        if graph_name:
            ng = self.mxdoc.getNodeGraph(graph_name)
            out = ng.getOutput(out_name) if ng is not None else None
            if out is None:
                self.err(f"{where}: nodegraph output {graph_name}.{out_name} not found")
                return None
            return self.output_el(out, depth)
        if node_name:
            scope = inp.getParent().getParent()
            up = scope.getNode(node_name) if scope is not None else None
            if up is None:
                self.err(f"{where}: node {node_name!r} not found")
                return None
            return self.node_src(up, out_name or "out", depth + 1)
        if not inp.getValueString():
            return None
        if width == 0:
            self.err(f"{where}: unsupported input type {inp.getType()!r}")
            return None
        try:
            vals = _floats(inp.getValueString(), where)
        except ValueError as exc:
            self.err(str(exc))
            return None
        if len(vals) != width:
            self.err(f"{where}: expected {width} numbers, got {len(vals)}")
            return None
        self.value_attributes(inp)
        return Src(value=vals, width=width)

    def value_attributes(self, inp) -> None:
        """A constant's colour space and unit, which MaterialX applies and we do not."""
        node = inp.getParent()
        space = inp.getActiveColorSpace() if inp.getType() in ("color3", "color4") else ""
        if space and space != WORKING:
            self.warn_input(node, inp, f"is in colour space {space!r}, read as {WORKING} "
                            "without conversion; approximated")
        if inp.getUnit():
            self.warn_input(node, inp, f"has unit {inp.getUnit()!r}, not converted; "
                            "approximated")

    def output_el(self, out, depth: int) -> Src | None:
        graph = out.getParent()
        up = graph.getNode(out.getNodeName()) if out.getNodeName() else None
        if up is None:
            if out.getInterfaceName() and graph.getInput(out.getInterfaceName()) is not None:
                return self.parameter(graph.getInput(out.getInterfaceName()),
                                      f"output {self.name_of(out)}")
            self.err(f"output {self.name_of(out)}: not connected to a node")
            return None
        return self.node_src(up, out.getOutputString() or "out", depth + 1)

    def parameter(self, gin, where: str) -> Src | None:
        key = gin.getNamePath()
        if key in self.params:
            return self.params[key]
        t = gin.getType()
        if gin.getNodeName() or gin.getNodeGraphString():
            self.err(f"{where}: interface input {gin.getName()!r} is connected upstream; only "
                     "values are supported")
            return None
        try:
            vals = _floats(gin.getValueString(), f"node {self.name_of(gin.getParent())}: "
                           f"interface input {gin.getName()}")
        except ValueError as exc:
            self.err(str(exc))
            return None
        self.value_attributes(gin)
        name = gin.getName()
        if identifier_problem(name):
            name = mangle(name)
        if identifier_problem(name):
            name = f"p_{name}"
        if identifier_problem(name):
            self.err(f"interface input {gin.getName()!r}: not usable as a parameter name "
                     f"({identifier_problem(name)})")
            return None
        width = _WIDTH.get(t, 0)
        if len(vals) != width:
            self.err(f"interface input {gin.getName()}: {t} needs {width} numbers")
            return None
        if width == 1:
            nid = self.add(name, kind_for(Role.SCALAR_PARAMETER),
                           {"name": name, "ui_min": min(0.0, vals[0]),
                            "ui_max": max(1.0, vals[0])}, {"value": vals[0]})
            src = Src(nid, "value", width=1)
        elif width == 3:
            nid = self.add(name, kind_for(Role.COLOR_PARAMETER), {"name": name}, {"value": vals})
            src = Src(nid, "color", width=3)
        elif width == 4:
            nid = self.add(name, kind_for(Role.VECTOR_PARAMETER), {"name": name}, {"value": vals})
            src = Src(nid, "value", width=4)
        else:  # vector2: a vec4 parameter, masked
            nid = self.add(name, kind_for(Role.VECTOR_PARAMETER), {"name": name},
                           {"value": vals + [0.0, 0.0]})
            m = self.add(f"{name}_xy", kind_for(Role.COMPONENT_MASK), {"channels": "xy"})
            self.connect(Src(nid, "value", width=4), m, "value")
            src = Src(m, "result", width=2)
        self.params[key] = src
        return src

    # --- nodes -----------------------------------------------------------------------------
    def node_src(self, node, output: str, depth: int) -> Src | None:
        # by name path: MaterialX hands out a new Python wrapper for each look-up, so a
        # node read twice (a shared subgraph) is converted once
        key = (self.scope(), node.getNamePath(), output)
        if key in self.done:
            return self.done[key]
        if depth > 2000:
            self.err(f"node {self.name_of(node)}: the graph is too deep")
            return None
        src = self.convert(node, output, depth)
        self.done[key] = src
        return src

    def convert(self, node, output: str, depth: int) -> Src | None:
        src = self._convert(node, output, depth)
        cat = node.getCategory()
        read = set(DIRECT[cat][1]) if cat in DIRECT else _READS.get(cat)
        if read is not None and (self.scope(), node.getNamePath()) in self.image_default:
            read = read | {"default"}
        if read is not None:  # (an unsupported node is an error already)
            self.unread(node, read)
        return src

    def _convert(self, node, output: str, depth: int) -> Src | None:
        cat = node.getCategory()
        name = self.hint(node)
        t = node.getType()
        width = _WIDTH.get(t, 0)
        where = self.where(node)
        if cat in DIRECT:
            kind, ports = DIRECT[cat]
            nid = self.add(name, kind, depth=depth)
            for mxin, ours in ports.items():
                self.connect(self.input_src(node, mxin, depth), nid, ours)
            self._defaults(node, nid, ports)
            return Src(nid, definition(kind).outputs[0].name, width=width)
        if cat == "extract":
            idx = self.index(node, where)
            if idx is None:
                return None
            nid = self.add(name, kind_for(Role.COMPONENT_MASK), {"channels": "xyzw"[idx]},
                           depth=depth)
            self.connect(self.input_src(node, "in", depth), nid, "value")
            return Src(nid, "result", width=1)
        if cat in ("separate2", "separate3", "separate4"):
            port = {"outx": "x", "outy": "y", "outz": "z", "outw": "w", "outr": "x",
                    "outg": "y", "outb": "z", "outa": "w"}.get(output)
            if port is None:
                self.err(f"{where}: unknown output {output!r}")
                return None
            nid = self.add(name, _kind("extract_each"), depth=depth)
            self.connect(self.input_src(node, "in", depth), nid, "value")
            return Src(nid, port, width=1)
        if cat in ("combine2", "combine3", "combine4"):
            k = int(cat[-1])
            nid = self.add(name, _kind("combine_n"), depth=depth)
            for i, port in enumerate("xyzw"[:k]):
                s = self.input_src(node, f"in{i + 1}", depth)
                self.connect(s if s is not None else Src(value=[0.0]), nid, port)
            return Src(nid, {2: "xy", 3: "xyz", 4: "xyzw"}[k], width=k)
        if cat == "convert":
            inp = node.getInput("in")
            w_in = _WIDTH.get(inp.getType(), 0) if inp is not None else 1
            s = self.input_src(node, "in", depth)
            if s is None:
                s = Src(value=[0.0] * max(w_in, 1), width=max(w_in, 1))
            if w_in == width:  # vector3 <-> color3
                nid = self.add(name, kind_for(Role.REROUTE), depth=depth)
                self.connect(s, nid, "value")
                return Src(nid, "value", width=width)
            if w_in == 1 and width in (2, 3, 4):
                nid = self.add(name, _kind("combine_n"), depth=depth)
                for port in "xyzw"[:width]:
                    self.connect(s, nid, port)
                return Src(nid, {2: "xy", 3: "xyz", 4: "xyzw"}[width], width=width)
            if w_in > width >= 1:
                nid = self.add(name, kind_for(Role.COMPONENT_MASK), {"channels": "xyzw"[:width]},
                               depth=depth)
                self.connect(s, nid, "value")
                return Src(nid, "result", width=width)
            self.err(f"{where}: convert {inp.getType() if inp is not None else 'float'} to "
                     f"{t} is not supported")
            return None
        if cat == "texcoord":
            idx_in = self.outer_input(node, "index")
            if idx_in is not None and connected(idx_in):
                self.err(f"{where}: input index: only a constant texture coordinate set is "
                         "supported")
                return None
            text = idx_in.getValueString().strip() if idx_in is not None else ""
            if text not in ("", "0"):  # our meshes carry one UV set
                self.warn_input(idx_in.getParent(), idx_in, "names a texture coordinate set "
                                "matedit does not have (one UV set): set 0 is read; "
                                "approximated")
            nid = self.add(name, _kind("tiled_texcoord"), depth=depth)
            return Src(nid, "uv", width=2)
        if cat == "switch":
            return self.switch(node, depth, where, width)
        if cat in ("position", "normal"):
            space = node.getInputValue("space") if node.getInput("space") else "object"
            if space != "world":
                self.err(f"{where}: {cat} in {space} space is not supported (world only)")
                return None
            nid = self.add(name, _kind(cat), depth=depth)
            return Src(nid, "position" if cat == "position" else "normal", width=3)
        if cat == "rotate2d":
            # rotate2d turns clockwise by amount degrees about 0: ours by -amount
            amount = self.input_src(node, "amount", depth) or Src(value=[0.0])
            neg = self.add(f"{name}_ccw", _kind("multiply"), values={"b": -1.0}, depth=depth)
            self.connect(amount, neg, "a")
            nid = self.add(name, _kind("rotate_about_pivot"), values={"pivot": [0.0, 0.0]},
                           depth=depth)
            self.connect(self.input_src(node, "in", depth) or Src(value=[0.0, 0.0]), nid, "uv")
            self.connect(Src(neg, "result"), nid, "angle")
            return Src(nid, "uv", width=2)
        if cat == "viewdirection":
            v = self.add(f"{name}_eye", _kind("negated_viewdirection"), depth=depth)
            nid = self.add(name, _kind("multiply"), values={"b": [-1.0, -1.0, -1.0]}, depth=depth)
            self.connect(Src(v, "direction", width=3), nid, "a")
            return Src(nid, "result", width=3)
        if cat == "time":
            nid = self.add(name, _kind("time"), depth=depth)
            return Src(nid, "seconds", width=1)
        if cat == "constant":
            s = self.input_src(node, "value", depth)
            return s if s is not None else Src(value=[0.0] * max(width, 1), width=max(width, 1))
        if cat == "dot":
            nid = self.add(name, kind_for(Role.REROUTE), depth=depth)
            self.connect(self.input_src(node, "in", depth), nid, "value")
            return Src(nid, "value", width=width)
        if cat == "image":
            return self.image(node, depth, where, width)
        if cat == "hextiledimage":
            return self.hextiled(node, depth, where, width)
        impl = self.implementation(node)
        if impl is not None:
            return self.expand(node, impl, output, depth)
        self.err(f"{where}: unsupported MaterialX node {cat!r} (type {t})")
        return None

    def switch(self, node, depth: int, where: str, width: int) -> Src | None:
        """switch by a constant `which` (place2d's operation order, say): input
        in(floor(which) + 1), clamped to in1..in10; the others are never read."""
        w = self.outer_input(node, "which")
        if w is not None and connected(w):
            self.err(f"{where}: input which: only a constant is supported")
            return None
        try:
            vals = _floats(w.getValueString() if w is not None else "0", f"{where}: input which")
        except ValueError as exc:
            self.err(str(exc))
            return None
        k = min(max(int(math.floor(vals[0])) if vals else 0, 0), 9)
        src = self.input_src(node, f"in{k + 1}", depth)
        return src if src is not None else Src(value=[0.0] * max(width, 1),
                                               width=max(width, 1))

    def index(self, node, where: str) -> int | None:
        """extract's index: an integer 0 to 3 given as a value (None after an error)."""
        idx_in = node.getInput("index")
        if idx_in is None:
            return 0
        text = idx_in.getValueString()
        iw = f"{where}: input index"
        try:
            vals = _floats(text, iw)
        except ValueError as exc:
            self.err(str(exc))
            return None
        if len(vals) != 1 or not vals[0].is_integer() or not 0 <= vals[0] <= 3:
            self.err(f"{iw}: must be an integer 0 to 3 given as a value, got {text[:40]!r}")
            return None
        return int(vals[0])

    def _defaults(self, node, nid: str, ports: dict[str, str]) -> None:
        """Unset MaterialX inputs take the node definition's defaults, not ours."""
        nd = node.getNodeDef()
        if nd is None:
            return
        values = self.mat.graph.nodes[nid].values
        linked = {lk.dst_port for lk in self.mat.graph.links if lk.dst == nid}
        for mxin, ours in ports.items():
            if ours in values or ours in linked or node.getInput(mxin) is not None:
                continue
            d = nd.getActiveInput(mxin)
            if d is not None and d.getDefaultGeomPropString():
                self._geometry_default(node, nid, ours, d.getDefaultGeomPropString())
                continue
            if d is None or not d.getValueString():
                continue
            try:
                vals = _floats(d.getValueString(), mxin)
            except ValueError:
                continue
            values[ours] = vals[0] if len(vals) == 1 else vals

    def _geometry_default(self, node, nid: str, ours: str, geomprop: str) -> None:
        """An unset input that MaterialX reads from the geometry (reflect's normal is the
        world normal): the same geometry node of ours, or an error naming it."""
        src = self.geometry_src(node, ours, geomprop)
        if src is not None:
            self.connect(src, nid, ours)

    def geometry_src(self, node, ours: str, geomprop: str) -> Src | None:
        name = self.hint(node)
        if geomprop == "Nworld":
            return Src(self.add(f"{name}_{ours}", _kind("normal")), "normal", width=3)
        if geomprop == "UV0":
            return Src(self.add(f"{name}_{ours}", _kind("tiled_texcoord")), "uv", width=2)
        self.err(f"{self.where(node)}: input {ours!r} defaults to the geometric "
                 f"property {geomprop!r}, which is not supported: connect it")
        return None

    def image_file(self, node, where: str):
        """(the file input, its relative path), or None after an error."""
        file_in = self.outer_input(node, "file")
        file = file_in.getValueString() if file_in is not None else ""
        if not file or Path(file).is_absolute() or "\0" in file or ":" in file:
            self.err(f"{where}: image file must be a relative path, got {file[:60]!r}")
            return None
        return file_in, file

    def texture_parameter(self, node, file_in, file: str, where: str, depth: int) -> str | None:
        """A Texture Parameter of the node's file, in its colour space (None after an
        error): the file's path relative to the output, never read here."""
        srgb, space = False, ""
        if node.getType() in ("color3", "color4"):  # MaterialX decodes colour types only
            active = file_in.getActiveColorSpace()
            found = from_materialx(active)
            if found is None:
                self.err(f"{where}: unknown colour space {active!r} on its file")
                return None
            srgb, space = found
        target = (self.source.parent / file)
        rel = Path(os.path.relpath(os.path.abspath(target),
                                   os.path.abspath(self.out.parent))).as_posix()
        pname = self.new_id(f"{self.hint(node)}_file")
        self.ids.discard(pname)
        settings = {"name": pname, "path": rel, "srgb": srgb}
        if space:
            settings["color_space"] = space
        return self.add(pname, kind_for(Role.TEXTURE_PARAMETER), settings, depth=depth)

    def hextiled(self, node, depth: int, where: str, width: int) -> Src | None:
        """hextiledimage as our Hex-Tiled Texture: the same tiles, randomisation and blend
        (its `default` is the colour of a missing file only: unread, so it warns)."""
        found = self.image_file(node, where)
        if found is None:
            return None
        tex = self.texture_parameter(node, *found, where, depth)
        if tex is None:
            return None
        nid = self.add(self.hint(node), kind_for(Role.HEX_TILED_TEXTURE), depth=depth)
        self.connect(Src(tex, "texture"), nid, "texture")
        uv = self.input_src(node, "texcoord", depth)
        if uv is not None:
            self.connect(uv, nid, "uv")
        for mxin, ours in _HEXTILED.items():
            self.connect(self.input_src(node, mxin, depth), nid, ours)
        self._defaults(node, nid, _HEXTILED)
        return Src(nid, "rgba", width=4) if width == 4 else Src(nid, "rgb", width=3)

    def image(self, node, depth: int, where: str, width: int) -> Src | None:
        found = self.image_file(node, where)
        if found is None:
            return None
        file_in, file = found
        modes = []
        for opt in ("uaddressmode", "vaddressmode"):
            el = self.outer_input(node, opt)
            text = el.getValueString().strip() if el is not None else ""
            if el is not None and connected(el) or (text or "periodic") not in ADDRESS_MODES:
                self.err(f"{where}: {opt} {value_text(el) if el is not None else ''} is not "
                         f"supported ({', '.join(ADDRESS_MODES)}, as a constant)")
                return None
            modes.append(ADDRESS_MODES.index(text or "periodic"))
        el = self.outer_input(node, "filtertype")
        ftype = el.getValueString().strip() if el is not None else ""
        if el is not None and connected(el) or (ftype or "linear") not in (*FILTER_TYPES,
                                                                           "cubic"):
            self.err(f"{where}: filtertype {value_text(el) if el is not None else ''} is not "
                     "supported (closest, linear or cubic, as a constant)")
            return None
        if ftype == "cubic":  # MaterialX's GLSL renderer binds it as GL_LINEAR too
            self.warn_input(el.getParent(), el, "is read as linear (bilinear) filtering; "
                            "approximated")
        closest = FILTER_TYPES.index("closest") if ftype == "closest" else 0
        default = None
        if ADDRESS_MODES.index("constant") in modes:  # the border colour
            d = self.outer_input(node, "default")
            if d is not None and connected(d):
                self.err(f"{where}: input default: only a constant is supported under "
                         "constant addressing (it is the border colour)")
                return None
            try:
                vals = _floats(d.getValueString(), f"{where}: input default") \
                    if d is not None else []
            except ValueError as exc:
                self.err(str(exc))
                return None
            default = (vals * 4 if len(vals) == 1 else vals + [0.0] * 4)[:4]
            self.image_default.add((self.scope(), node.getNamePath()))
        name = self.hint(node)
        tex = self.texture_parameter(node, file_in, file, where, depth)
        if tex is None:
            return None
        if modes == [0, 0] and not closest:
            nid = self.add(name, kind_for(Role.TEXTURE_SAMPLE), depth=depth)
        else:  # MaterialX's addressing and filter, exactly (tests/test_texture_addressed.py)
            values: dict[str, Any] = {"u_address": float(modes[0]),
                                      "v_address": float(modes[1]), "filter": float(closest)}
            if default is not None:
                values["default_color"] = default
            nid = self.add(name, kind_for(Role.ADDRESSED_TEXTURE_SAMPLE), values=values,
                           depth=depth)
        self.connect(Src(tex, "texture"), nid, "texture")
        uv = self.input_src(node, "texcoord", depth)
        if uv is not None:
            self.connect(uv, nid, "uv")
        if width == 1:
            return Src(nid, "r", width=1)
        if width == 3:
            return Src(nid, "rgb", width=3)
        if width == 4:
            return Src(nid, "rgba", width=4)
        m = self.add(f"{name}_xy", kind_for(Role.COMPONENT_MASK), {"channels": "xy"},
                     depth=depth)
        self.connect(Src(nid, "rgba", width=4), m, "value")
        return Src(m, "result", width=2)

    # --- the surface -----------------------------------------------------------------------
    def surface_input(self, shader, name: str) -> Src | None:
        inp = shader.getInput(name)
        if inp is not None:
            self.mapped.add(name)
            return self.input_el(inp, 0, f"node {self.name_of(shader)}: input {name}")
        nd = shader.getNodeDef()
        d = nd.getActiveInput(name) if nd is not None else None
        if d is None or not d.getValueString():
            return None
        try:
            return Src(value=_floats(d.getValueString(), name),
                       width=_WIDTH.get(d.getType(), 1))
        except ValueError:
            return None

    def _set_or_zero(self, shader, name: str) -> bool:
        """Whether the surface sets `name` to something other than a constant 0."""
        inp = shader.getInput(name)
        if inp is None:
            return False
        if connected(inp):
            return True
        try:
            return any(v != 0.0 for v in _floats(inp.getValueString() or "0", name))
        except ValueError:
            return True

    def _upstream(self, inp) -> tuple:
        """What a connected input reads, through a nodegraph output to its node: two inputs
        from different outputs of one node output read the same thing."""
        if inp.getNodeGraphString():
            ng = self.mxdoc.getNodeGraph(inp.getNodeGraphString())
            o = ng.getOutput(inp.getOutputString()) if ng is not None else None
            if o is not None:
                return (ng.getName(), o.getNodeName(), o.getOutputString(),
                        o.getInterfaceName())
        return (inp.getNodeGraphString(), inp.getNodeName(), inp.getOutputString(),
                inp.getInterfaceName())

    def _grey(self, inp) -> bool:
        """Whether a connected colour input is a float made a colour (a convert node from a
        float: every channel the same), as our export writes a scalar into one."""
        graph, node, _out, _iface = self._upstream(inp)
        scope = self.mxdoc.getNodeGraph(graph) if graph else self.mxdoc
        up = scope.getNode(node) if scope is not None and node else None
        src = up.getInput("in") if up is not None and up.getCategory() == "convert" else None
        return src is not None and src.getType() == "float"

    def cavity_reading(self, shader, cat: str) -> bool:
        """Whether the base and specular weights (BASE_WEIGHT) are one source: together they
        darken the diffuse, the metal and the dielectric reflection, our cavity (what our
        export writes; docs/materialx.md, The base weight). A base weight alone never is.
        Exact on a surface with no other lobe; `approximations` warns otherwise."""
        if cat not in BASE_WEIGHT:
            return False
        b, sp = (shader.getInput(n) for n in BASE_WEIGHT[cat])
        if b is None or sp is None:
            return False
        if connected(b) or connected(sp):
            return connected(b) and connected(sp) and self._upstream(b) == self._upstream(sp)
        return b.getValueString().strip() == sp.getValueString().strip()

    def build(self, shader) -> MaterialDocument:
        cat = shader.getCategory()
        table = dict(SURFACES[cat])
        if cat in BASE_WEIGHT:
            base, specular = BASE_WEIGHT[cat]
            if self.cavity_reading(shader, cat):  # read after the roughness, as gltf_pbr's
                table = {k: v for k, v in table.items() if k not in ("normal", "emissive",
                                                                     "opacity")}
                table["cavity"] = (base, None, 1.0)
                table.update({k: SURFACES[cat][k] for k in ("normal", "emissive", "opacity")})
                self.mapped.add(specular)
            else:  # the base weight multiplies the base colour, exactly
                inp, _, factor = table["baseColor"]
                table["baseColor"] = (inp, base, factor)
        make = self.add("make", kind_for(Role.MAKE_ATTRIBUTES))
        out = self.add("out", kind_for(Role.MATERIAL_OUTPUT))
        self.mat.graph.nodes[out].position = (260.0, 0.0)
        self.mat.graph.nodes[make].position = (0.0, 0.0)
        self.connect(Src(make, "attributes"), out, "attributes")
        for attr, (inp, scale, factor) in table.items():
            if attr == "normal":
                self.normal(shader, inp, cat in WORLD_NORMAL, make)
                continue
            if attr == "opacity" and cat == "gltf_pbr" and not self.gltf_alpha(shader):
                continue
            src = self.surface_input(shader, inp)
            if src is None:
                continue
            if src.width == 3 and attr in ("metallic", "roughness", "cavity", "opacity", "coat",
                                           "coatRoughness", "coatIor"):
                el = shader.getInput(inp)
                if el is not None and (len(set(src.value)) > 1 if src.node is None
                                       else not self._grey(el)):
                    self.noted.add(inp)
                    self.warn_input(shader, el, f"is a colour; our {attr} is a scalar, its first "
                                    "channel is read; approximated")
                if src.node is None:
                    src = Src(value=src.value[:1], width=1)
                else:
                    m = self.add(f"{attr}_x", kind_for(Role.COMPONENT_MASK), {"channels": "x"})
                    self.connect(src, m, "value")
                    src = Src(m, "result", width=1)
            if scale is not None:
                w = self.surface_input(shader, scale)
                if w is None:
                    w = Src(value=[1.0], width=1)
                if w.node is None and src.node is None:
                    try:
                        src = Src(value=_computed([v * w.value[0] * factor for v in src.value],
                                                  f"node {self.name_of(shader)}: inputs {inp} "
                                                  f"and {scale}"), width=src.width)
                    except ValueError as exc:
                        self.err(str(exc))
                        continue
                elif not (w.node is None and w.value[0] * factor == 1.0):
                    mul = self.add(f"{attr}_weight", _kind("multiply"))
                    self.connect(src, mul, "a")
                    if w.node is None:
                        self.connect(Src(value=[w.value[0] * factor]), mul, "b")
                    else:
                        scaled = w
                        if factor != 1.0:
                            s = self.add(f"{attr}_units", _kind("multiply"), values={"b": factor})
                            self.connect(w, s, "a")
                            scaled = Src(s, "result")
                        self.connect(scaled, mul, "b")
                    src = Src(mul, "result", width=src.width)
            self.connect(src, make, attr)
        self.lobes(shader, cat, make)
        if cat in TRANSMISSION:
            self.transmission(shader, cat, make, out)
        if cat == "gltf_pbr":
            self.gltf_volume(shader, make, out)
        self.approximations(shader, cat)
        for path, inst in self.instances.items():  # an expanded node's own inputs
            self.unread(inst, self.iface_read.get(path, set()))
        nd = shader.getNodeDef()
        for el in shader.getInputs():  # the rule: nothing the file sets is dropped silently
            name = el.getName()
            if name in self.mapped or name in self.noted or is_default(el, nd):
                continue
            self.warn_input(shader, el, "is not supported; dropped")
        return self.mat

    def gltf_volume(self, shader, make: str, out: str) -> None:
        """KHR_materials_volume's thickness: 0 (its default) is a thin-walled part, our
        Material Output's thin_walled where the material transmits; above 0 our thickness."""
        t = self.constant(shader, "thickness")
        if t is not None and t[0] <= 0.0:
            if shader.getInput("thickness") is not None:
                self.mapped.add("thickness")
            if self._set_or_zero(shader, "transmission"):
                self.mat.graph.nodes[out].settings[THIN_WALLED] = True
            return
        src = self.surface_input(shader, "thickness")
        if src is not None:
            self.connect(src, make, "thickness")

    def gltf_alpha(self, shader) -> bool:
        """Whether gltf_pbr's alpha is read (our opacity): under alpha_mode 0 (OPAQUE, the
        default) glTF ignores it, so it is not; MASK's cutoff is not ours (read as blending)."""
        mode_in = shader.getInput("alpha_mode")
        mode = mode_in.getValueString().strip() if mode_in is not None else "0"
        if mode_in is not None and connected(mode_in):
            mode = "?"
        if mode_in is not None:
            self.mapped.add("alpha_mode")
        alpha = shader.getInput("alpha")
        if mode == "2":
            return True
        if mode == "1":
            self.noted.add("alpha_mode")
            self.warn_input(shader, mode_in, "(MASK) is read as blending by alpha: the "
                            "alpha_cutoff test is not supported; approximated")
            self.mapped.add("alpha_cutoff")
            return True
        if mode not in ("0", ""):
            self.noted.add("alpha_mode")
            self.warn_input(shader, mode_in, "is not supported (0, 1 or 2 as a constant); "
                            "alpha is dropped")
        if alpha is not None and not is_default(alpha, shader.getNodeDef()):
            self.noted.add("alpha")
            self.warn_input(shader, alpha, "has no effect under alpha_mode 0 (OPAQUE); "
                            "dropped")
        self.mapped.add("alpha_cutoff")  # read by MASK only
        return False

    def constant(self, shader, name: str) -> list[float] | None:
        """The surface's constant value of `name` (set, else its default); None where it is
        connected or not a number list."""
        inp = shader.getInput(name)
        if inp is not None and connected(inp):
            return None
        nd = shader.getNodeDef()
        el = inp if inp is not None else (nd.getActiveInput(name) if nd is not None else None)
        if el is None:
            return None
        try:
            return [float(x) for x in el.getValueString().split(",")]
        except ValueError:
            return None

    def approximations(self, shader, cat: str) -> None:
        """Warnings for inputs read, but not exactly (`noted`, so they warn once)."""
        def note(name: str, why: str) -> None:
            el = shader.getInput(name)
            if el is not None and name not in self.noted:
                self.noted.add(name)
                self.warn_input(shader, el, why)

        if cat in BASE_WEIGHT and self.cavity_reading(shader, cat):
            base = BASE_WEIGHT[cat][0]
            others = [n for n in _OTHER_LOBES[cat] if self._set_or_zero(shader, n)]
            if others and self.constant(shader, base) != [1.0]:
                note(base, f"is, with {BASE_WEIGHT[cat][1]} from the same source, read as "
                     f"our cavity, which darkens the {', '.join(others)} lobe too; "
                     "approximated")
        elif cat in BASE_WEIGHT:
            specular = BASE_WEIGHT[cat][1]
            if self.constant(shader, specular) != [1.0]:
                note(specular, "is not supported (we have no specular weight); dropped")
        if cat == "gltf_pbr" and self.constant(shader, "specular") != [1.0]:
            note("specular", "is not supported (we have no specular weight); dropped")
        metal = {"standard_surface": "metalness", "open_pbr_surface": "base_metalness"}.get(cat)
        if metal is not None and self.constant(shader, metal) != [0.0]:
            tint = self.constant(shader, "specular_color")
            if tint != [1.0, 1.0, 1.0]:
                note("specular_color", f"tints the dielectric's F0 only: the metal's edge "
                     f"colour it also is in {cat} is not supported; approximated")
        sheen = {"standard_surface": "sheen_roughness", "open_pbr_surface": "fuzz_roughness",
                 "gltf_pbr": "sheen_roughness"}.get(cat)
        if sheen is not None and shader.getInput(sheen) is not None:
            r = self.constant(shader, sheen)
            if r is None:
                note(sheen, f"is clamped to at least {SHEEN_MIN_ROUGHNESS:g} by our sheen; "
                     "approximated where it is lower")
            elif r[0] < SHEEN_MIN_ROUGHNESS:
                note(sheen, f"is clamped to {SHEEN_MIN_ROUGHNESS:g} by our sheen; approximated")
        if cat == "open_pbr_surface" and (shader.getInput("thin_film_thickness") is not None
                                          or shader.getInput("thin_film_weight") is not None):
            w = self.constant(shader, "thin_film_weight")
            if w is None or w[0] not in (0.0, 1.0):
                note("thin_film_weight", "scales the film's thickness (ours has no film "
                     "weight); approximated")
        if cat == "gltf_pbr" and (shader.getInput("iridescence_thickness") is not None
                                  or shader.getInput("iridescence") is not None):
            w = self.constant(shader, "iridescence")
            if w is None or w[0] not in (0.0, 1.0):
                note("iridescence", "scales the film's thickness (ours has no film weight); "
                     "approximated")
        if cat in ("gltf_pbr", "UsdPreviewSurface") and self.constant(shader, "occlusion") \
                != [1.0]:
            note("occlusion", "is read as our cavity, which darkens direct light too (this "
                 "surface's occlusion darkens indirect light only); approximated")

    def transmission(self, shader, cat: str, make: str, out: str) -> None:
        """The transmission inputs (TRANSMISSION): weight, tint or absorption colour by the
        depth, and the thin-walled flag (the Material Output's setting)."""
        weight, color, depth, thin = TRANSMISSION[cat]
        flag = shader.getInput(thin)
        if flag is not None:
            self.mapped.add(thin)
            if flag.getConnectedNode() is not None or flag.getNodeGraphString():
                self.err(f"node {self.name_of(shader)}: input {thin}: only a constant is "
                         "supported (our thin_walled is the material output's setting)")
            elif flag.getValueString().strip().lower() in ("true", "1"):
                self.mat.graph.nodes[out].settings[THIN_WALLED] = True
        if shader.getInput(weight) is not None:
            src = self.surface_input(shader, weight)
            if src is not None:
                self.connect(src, make, "transmission")
        c = self.surface_input(shader, color) if shader.getInput(color) is not None else None
        d = self.surface_input(shader, depth) if shader.getInput(depth) is not None else None
        if d is not None and (d.node is not None or d.value[0] > 0.0):
            self.connect(d, make, "attenuationDistance")
            if c is not None:
                self.connect(c, make, "attenuationColor")
        elif c is not None:
            self.connect(c, make, "transmissionColor")

    def lobes(self, shader, cat: str, make: str) -> None:
        """The lobes beyond the talk that the file sets (LOBES)."""
        where = f"node {self.name_of(shader)}"
        for attr, (inp, weight) in LOBES.get(cat, {}).items():
            if shader.getInput(inp) is None and (weight is None or
                                                 shader.getInput(weight) is None):
                continue
            if attr == "coatNormal":
                self.normal(shader, inp, cat in WORLD_NORMAL, make, "coatNormal")
                continue
            if inp == "geometry_tangent":
                d = self.tangent_direction(shader, inp)
                if d is not None:  # else not read: the rule warns it dropped
                    self.mapped.add(inp)
                    self.connect(d, make, attr)
                continue
            src = self.surface_input(shader, inp)
            if src is None:
                continue
            if attr == "anisotropyDirection":
                if src.node is not None:
                    self.err(f"{where}: input {inp}: only a constant anisotropy rotation is "
                             "supported")
                    continue
                angle = src.value[0] * _ROTATION_TO_RADIANS[cat]
                src = Src(value=[math.cos(angle), math.sin(angle), 0.0], width=3)
            if attr == "thickness":  # standard_surface's subsurface_scale: 1 / thickness
                if src.node is None:
                    if src.value[0] <= 0.0:
                        self.err(f"{where}: input {inp}: subsurface_scale must be positive")
                        continue
                    src = Src(value=[1.0 / src.value[0]], width=1)
                else:
                    inv = self.add("thickness_of_scale", _kind("divide"), values={"a": 1.0})
                    self.connect(src, inv, "b")
                    src = Src(inv, "result", width=1)
            if attr == "thinFilmThickness" and cat == "open_pbr_surface":  # um to our nm
                if src.node is None:
                    src = Src(value=[1000.0 * src.value[0]], width=1)
                else:
                    nm = self.add("thin_film_nm", _kind("multiply"), values={"b": 1000.0})
                    self.connect(src, nm, "a")
                    src = Src(nm, "result", width=1)
            if weight is not None:
                w = self.surface_input(shader, weight)
                if w is not None and w.node is not None:
                    mul = self.add(f"{attr}_weight", _kind("multiply"))
                    self.connect(src, mul, "a")
                    self.connect(w, mul, "b")
                    src = Src(mul, "result", width=src.width)
                elif w is not None and src.node is None:
                    src = Src(value=[v * w.value[0] for v in src.value], width=src.width)
                elif w is not None and w.value[0] != 1.0:
                    mul = self.add(f"{attr}_weight", _kind("multiply"),
                                   values={"b": w.value[0]})
                    self.connect(src, mul, "a")
                    src = Src(mul, "result", width=src.width)
            self.connect(src, make, attr)

    def tangent_direction(self, shader, name: str) -> Src | None:
        """OpenPBR's geometry_tangent as our export writes it (`tangent_rotation` for a
        constant direction; normalize(T x + B y + N z) of the world tangent, bitangent and
        normal for a varying one, whose x, y, z extract one source: that source, our
        tangent-space direction); None for any other tangent."""
        angle = self.tangent_rotation(shader, name)
        if angle is not None:
            return Src(value=[math.cos(angle), math.sin(angle), 0.0], width=3)
        inp = shader.getInput(name)
        ng = self.mxdoc.getNodeGraph(inp.getNodeGraphString()) if inp is not None and \
            inp.getNodeGraphString() else None
        o = ng.getOutput(inp.getOutputString()) if ng is not None else None
        up = ng.getNode(o.getNodeName()) if o is not None and o.getNodeName() else None

        def node(n, port):
            i = n.getInput(port) if n is not None else None
            return i.getConnectedNode() if i is not None else None

        if up is None or up.getCategory() != "normalize":
            return None
        tbn = node(up, "in")
        tb = node(tbn, "in1")
        terms = [node(tb, "in1"), node(tb, "in2"), node(tbn, "in2")]
        if tbn is None or tb is None or tbn.getCategory() != "add" or tb.getCategory() != "add":
            return None
        sources = []
        for i, (term, geo) in enumerate(zip(terms, ("tangent", "bitangent", "normal"))):
            g, ex = node(term, "in1"), node(term, "in2")
            if term is None or term.getCategory() != "multiply" or g is None or \
                    g.getCategory() != geo or g.getInputValue("space") not in (None, "world") \
                    or ex is None or ex.getCategory() != "extract" or \
                    self.index(ex, f"node {self.name_of(ex)}") != i:
                return None
            sources.append(node(ex, "in"))
        if sources[0] is None or any(s != sources[0] for s in sources):
            return None
        return self.input_src(terms[0].getInput("in2").getConnectedNode(), "in", 1)

    def tangent_rotation(self, shader, name: str) -> float | None:
        """OpenPBR's geometry_tangent as our export writes it, the world tangent rotated
        about the world normal by a constant angle (a rotate3d node, which turns clockwise
        about its axis): our anisotropy direction's angle, anticlockwise from the tangent, in
        radians; None for any other tangent."""
        inp = shader.getInput(name)
        up = None
        if inp is not None and inp.getNodeGraphString():
            ng = self.mxdoc.getNodeGraph(inp.getNodeGraphString())
            o = ng.getOutput(inp.getOutputString()) if ng is not None else None
            up = ng.getNode(o.getNodeName()) if o is not None and o.getNodeName() else None
        if up is None or up.getCategory() != "rotate3d":
            return None

        def source(port: str) -> str:
            i = up.getInput(port)
            n = i.getConnectedNode() if i is not None else None
            if n is None or n.getInputValue("space") not in (None, "world"):
                return ""
            return n.getCategory()

        amount = up.getInput("amount")
        if source("in") != "tangent" or source("axis") != "normal" or amount is None \
                or connected(amount):
            return None
        try:
            deg = _floats(amount.getValueString(), f"node {self.name_of(up)}: input amount")
        except ValueError as exc:
            self.err(str(exc))
            return None
        return -math.radians(deg[0])  # rotate3d turns clockwise about its axis

    def normal(self, shader, name: str, world: bool, make: str, port: str = "normal") -> None:
        inp = shader.getInput(name)
        if inp is None:
            return
        self.mapped.add(name)
        if not world:
            src = self.surface_input(shader, name)
            if src is not None:
                self.connect(src, make, port)
            return
        if not connected(inp):  # one world direction everywhere: not a tangent-space map
            self.noted.add(name)
            self.warn_input(shader, inp, "is a constant world-space normal (ours is the "
                            "surface's own normal, or a tangent-space map); dropped")
            return
        up = None
        if inp.getNodeGraphString():
            ng = self.mxdoc.getNodeGraph(inp.getNodeGraphString())
            o = ng.getOutput(inp.getOutputString()) if ng is not None else None
            up = ng.getNode(o.getNodeName()) if o is not None and o.getNodeName() else None
        elif inp.getNodeName():
            up = self.mxdoc.getNode(inp.getNodeName())
        pushed = 0
        # a node made of a normalmap (gltf_normalmap): read through its nodegraph
        while up is not None and up.getCategory() != "normalmap":
            impl = self.implementation(up)
            o = impl.getOutput("out") if impl is not None else None
            if o is None or not o.getNodeName():
                break
            self.push(up, impl)
            pushed += 1
            up = impl.getNode(o.getNodeName())
        try:
            if up is None or up.getCategory() != "normalmap":
                self.err(f"node {self.name_of(shader)}: input {name}: a world-space normal is "
                         "supported only from a normalmap node (a tangent-space normal map)")
                return
            self.normalmap(up, make, port)
        finally:
            del self.stack[len(self.stack) - pushed:]

    def _geometric(self, el, frame: str) -> bool:
        """Whether a normalmap's normal, tangent or bitangent input is the surface's own
        (its definition's default, or a world-space node of that name): our frame."""
        if el is None or el.getDefaultGeomPropString():
            return True
        scope = el.getParent().getParent()
        up = scope.getNode(el.getNodeName()) if el.getNodeName() and scope is not None else None
        if up is None or up.getCategory() != frame:
            return False
        space = self.outer_input(up, "space")
        return space is not None and space.getValueString().strip() == "world"

    def normalmap(self, up, make: str, port: str) -> None:
        """normalmap: (in x 2 - 1) x (scale.x, scale.y, 1) in the surface's tangent frame,
        normalised (MaterialX's definition; ours normalises after the frame too)."""
        where = self.where(up)
        self.unread(up, _READS["normalmap"])
        for frame in ("normal", "tangent", "bitangent"):
            if not self._geometric(self.outer_input(up, frame), frame):
                self.err(f"{where}: a normalmap with its own {frame} input is not supported "
                         f"(only the surface's, or a world-space {frame} node)")
        scale = [1.0, 1.0]
        sc = self.outer_input(up, "scale")
        if sc is not None and connected(sc):
            self.err(f"{where}: input scale: only a constant normalmap scale is supported")
            return
        if sc is not None:
            try:
                vals = _floats(sc.getValueString() or "1", f"{where}: input scale")
            except ValueError as exc:
                self.err(str(exc))
                return
            if len(vals) not in (1, 2):
                self.err(f"{where}: input scale: expected 1 or 2 numbers, got {len(vals)}")
                return
            scale = vals * 2 if len(vals) == 1 else vals
        sx, sy = scale
        enc = self.input_src(up, "in", 1)
        if enc is None:
            return
        if enc.node is None:
            try:
                decoded = _computed([(v * 2.0 - 1.0) * k for v, k in zip(enc.value,
                                                                          (sx, sy, 1.0))],
                                    f"{where}: input in")
            except ValueError as exc:
                self.err(str(exc))
                return
            self.connect(Src(value=decoded, width=3), make, port)
            return
        name = self.hint(up)
        try:  # (2 in - 1) x scale = in x 2 scale - scale
            doubled = _computed([2.0 * sx, 2.0 * sy, 2.0], f"{where}: input scale")
        except ValueError as exc:
            self.err(str(exc))
            return
        two = self.add(f"{name}_x2", _kind("multiply"), values={"b": doubled})
        self.connect(enc, two, "a")
        one = self.add(name, _kind("subtract"), values={"b": [sx, sy, 1.0]})
        self.connect(Src(two, "result", width=3), one, "a")
        self.connect(Src(one, "result", width=3), make, port)


def _load_mtlx(path: Path):
    import MaterialX as mx

    try:
        raw = read_bounded(path, MAX_MTLX_BYTES)
    except FileNotFoundError:
        raise MtlxImportError([f"{path}: no such file"]) from None
    except OSError as exc:
        raise MtlxImportError([f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}"]
                              ) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise MtlxImportError([f"{path}: not UTF-8 text"]) from None
    doc = mx.createDocument()
    opts = mx.XmlReadOptions()
    opts.readXIncludeFunction = None  # never follow XIncludes to other files
    try:
        mx.readFromXmlString(doc, text, mx.FileSearchPath(), opts)
    except Exception as exc:  # MaterialX raises its own parse errors
        msg = " ".join(str(exc).split())[:200]
        raise MtlxImportError([f"{path}: not a MaterialX document: {msg}"]) from None
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    return doc, lib


class SeveralMaterials(MtlxImportError):
    """The document holds several materials and none was chosen (`names`, in order)."""

    def __init__(self, path: Path, names: list[str]) -> None:
        self.names = names
        super().__init__([f"{path}: {len(names)} materials ({_listing(names)}): choose one "
                          "with --material NAME, or import every one with -o DIR"])


def _listing(names: list[str]) -> str:
    return ", ".join(n if n.isprintable() and n.strip() == n and n else repr(n)
                     for n in names)


def _materials(doc) -> list:
    return [m for m in doc.getMaterialNodes() if not m.hasSourceUri()]


def material_names(path: Path) -> list[str]:
    """The names of the document's surfacematerials, in document order (raises
    MtlxImportError for a file that cannot be read)."""
    doc, _ = _load_mtlx(Path(path))
    return [m.getName() for m in _materials(doc)]


def file_stem(name: str) -> str:
    """A material's file name stem, from its name as a checked identifier."""
    stem = mangle(name)
    return stem if identifier_problem(stem) is None else f"m_{stem}"


def output_paths(names: list[str], folder: Path) -> dict[str, Path]:
    """Material name -> FOLDER/STEM.json, stems from `file_stem`, made distinct (also when
    only their case differs, for case-insensitive file systems) by a _2, _3... suffix."""
    taken: set[str] = set()
    out = {}
    for name in names:
        base = stem = file_stem(name)
        k = 1
        while stem.lower() in taken:
            k += 1
            stem = f"{base}_{k}"
        taken.add(stem.lower())
        out[name] = Path(folder) / f"{stem}.json"
    return out


def import_mtlx(path: Path, out: Path, material: str | None = None,
                warnings: list[str] | None = None) -> MaterialDocument:
    """The material of `path` (the one named `material`; without a name the document must
    hold exactly one, else SeveralMaterials) as a matedit document to be saved at `out`;
    raises MtlxImportError with every problem found. Appends to `warnings` one line for each
    input, node or attribute of the file not represented exactly (the rule: nothing is
    dropped silently; docs/materialx.md)."""
    path, out = Path(path), Path(out)
    doc, lib = _load_mtlx(path)
    materials = _materials(doc)
    if not materials:
        raise MtlxImportError([f"{path}: no surfacematerial in the document"])
    if material is not None:
        chosen = [m for m in materials if m.getName() == material]
        if not chosen:
            raise MtlxImportError([f"{path}: no material named {material!r} (materials: "
                                   f"{_listing([m.getName() for m in materials])})"])
        mat = chosen[0]
    elif len(materials) > 1:
        raise SeveralMaterials(path, [m.getName() for m in materials])
    else:
        mat = materials[0]
    return _import_material(path, out, doc, lib, mat, warnings)


def import_all(path: Path, folder: Path,
               warnings: list[str] | None = None) -> dict[Path, MaterialDocument]:
    """Every material of `path`, each as FOLDER/STEM.json (`output_paths`) -> document;
    raises MtlxImportError with every problem of every material (then nothing is returned).
    `warnings` as import_mtlx's, for every material."""
    path = Path(path)
    doc, lib = _load_mtlx(path)
    materials = _materials(doc)
    if not materials:
        raise MtlxImportError([f"{path}: no surfacematerial in the document"])
    paths = output_paths([m.getName() for m in materials], folder)
    out: dict[Path, MaterialDocument] = {}
    errors: list[str] = []
    for mat in materials:
        try:
            out[paths[mat.getName()]] = _import_material(path, paths[mat.getName()], doc, lib,
                                                         mat, warnings)
        except MtlxImportError as exc:
            errors += exc.messages
    if errors:
        raise MtlxImportError(errors)
    return out


def _import_material(path: Path, out: Path, doc, lib, mat,
                     warnings: list[str] | None = None) -> MaterialDocument:
    sin = mat.getInput("surfaceshader")
    shader = None
    if sin is not None and sin.getNodeName():
        shader = doc.getNode(sin.getNodeName())
    if shader is None:
        raise MtlxImportError([f"{path}: node {mat.getName()}: its surfaceshader input is not "
                               "connected to a surface node"])
    if shader.getCategory() not in SURFACES:
        raise MtlxImportError([f"{path}: node {shader.getName()}: unsupported surface "
                               f"{shader.getCategory()!r} (expected "
                               f"{', '.join(SURFACES)})"])
    imp = _Importer(path, out, doc, lib, mat.getName())
    for other in mat.getInputs():  # displacement, a back surface, a volume: not ours
        if other.getName() != "surfaceshader" and (connected(other) or
                                                   other.getValueString()):
            imp.warn(f"{other.getName()} {value_text(other)} of surfacematerial "
                     f"{mat.getName()} is not supported; dropped")
    try:
        result = imp.build(shader)
    except RecursionError:
        raise MtlxImportError([f"{path}: node {shader.getName()}: its graph is too deep to "
                               "import"]) from None
    if imp.errors:
        raise MtlxImportError(imp.errors)
    if warnings is not None:
        warnings += imp.warnings
    name = mat.getName()
    result.name = name if not identifier_problem(mangle(name)) else "imported"
    result.description = f"Imported from {path.name}"
    return result
