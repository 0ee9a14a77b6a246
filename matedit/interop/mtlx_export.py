"""A material as a MaterialX 1.39 document: one nodegraph reproducing the attribute graph,
feeding one surface shader through a `surfacematerial`: `open_pbr_surface` by default
(MaterialX 1.39's own), `standard_surface` or `gltf_pbr` (SURFACE_KINDS). Each attribute
field goes to the surface's input of the same meaning (docs/materialx.md, Export, has the
table): base_color and the metalness; specular_roughness (all three square it into the GGX
alpha); IORs as ours. Our cavity "multiplies all lighting": it becomes the base and specular
weights of OpenPBR and standard_surface (which scale the diffuse and, through base_color,
the metal's reflectance, and the dielectric reflection) and gltf_pbr's occlusion. A field a
surface carries only approximately or not at all is a line in `notes` (the command prints
them as `note:` lines).

The graph comes from the lowered IR (matedit.compiler.lower), before optimisation, so the
nodes are ours, one for one where the catalogue has a mapping (NodeDef.mtlx, read through
matedit.interop.mtlx_map): material function calls are inlined (their nodes named
CALL_NODE), layer stacks are their blends, parameters are the nodegraph's interface inputs,
other unconnected inputs are values. What cannot be
expressed (`BAKE` in the map) is evaluated by the CPU evaluator over UV space (the bake plane
of matedit.interop.bake) into a map in OUT_textures/, read by an `image` node on
texture coordinate 0, and reported; a baked node that reads the position, normal, view or
time is exact on the bake plane only, and the report says so.

The export is self-contained: baked maps and copies of the textures the material reads go
into OUT_textures/ beside OUT.mtlx (`side_folder`), named in the document by relative
paths; `write` puts them in place with the document, or packs them all into OUT.zip. Each
image's file carries its colour space (matedit.interop.mtlx_colorspace: `srgb_texture` for
sRGB, `lin_rec709` for linear, the MaterialX name of an OpenColorIO space); the document's
colour space is `lin_rec709`, so MaterialX decodes a texture as matedit does (an image not
in lin_rec709 is read as a colour type, which MaterialX converts, then made a vector).
Baked maps are 8-bit PNGs (a colour map sRGB-encoded, `srgb_texture`; a data map linear) or
float EXRs in lin_rec709; `detail_notes` says which lose detail at the bake size.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from matedit.compiler import ops
from matedit.compiler.ir import Lit, MaterialIR, Param, Scope, Splat, SurfaceUV, Uni, Var
from matedit.compiler.lower import THIN_WALLED_DEFINE
from matedit.graph import nodes
from matedit.graph.nodes import (
    ATTRIBUTE_FIELDS,
    ATTRIBUTE_NAMES,
    MxBuilder,
    Ref,
    Role,
    kind_for,
    role_of,
)
from matedit.graph.types import PortType
from matedit.interop.mtlx_colorspace import WORKING, materialx_spaces, stdlib, to_materialx
from matedit.interop.mtlx_map import BAKE, MxNode, MxRecipe, mapping
from matedit.io.atomic import read_bounded

MX_TYPE = {PortType.FLOAT: "float", PortType.VEC2: "vector2", PortType.VEC3: "vector3",
           PortType.VEC4: "vector4"}
# The compiler's own ops that stand for a catalogue kind's mapping.
IR_OP_ROLES = {ops.BLEND: Role.MASK_BLEND, ops.MASK: Role.COMPONENT_MASK}
MTLX_VERSION = "1.39"
# The surfaces the export writes (--surface); OpenPBR is MaterialX 1.39's own default.
SURFACE_KINDS = ("open_pbr_surface", "standard_surface", "gltf_pbr")
DEFAULT_SURFACE = "open_pbr_surface"
FORMATS = ("png", "exr")
# A texture the material reads is copied whole; larger files are refused.
MAX_TEXTURE_BYTES = 1 << 30
# The detail check: a band of this many rows of the bake is baked again at twice the size;
# a map whose finer bake, box-filtered to the bake's texels, differs from it by an RMS above
# DETAIL_RMS of the map's range has detail finer than its texels (the note says so).
DETAIL_ROWS = 16
DETAIL_RMS = 1.0 / 255.0
# The thinnest part standard_surface's subsurface_scale = 1 / thickness stands for (metres).
_MIN_THICKNESS = 1e-4


def safe_name(name: str) -> str:
    """A file or element name as text MaterialX can hold: bytes of a file name that are not
    UTF-8 (Python's surrogate escapes) become '_'."""
    return "".join("_" if 0xDC80 <= ord(c) <= 0xDCFF else c for c in name)


class MtlxExportError(ValueError):
    """The material cannot be written as MaterialX (the message names the node)."""


@dataclass
class V:
    """A value both ways: numbers on the bake surface and a MaterialX reference (lazily)."""

    num: Any
    type: PortType
    make: Callable[[], tuple] | None = None  # -> ("value", v) | ("node", node, out) | ...
    geo: bool = False  # depends on position, normal, view or time
    fields: dict[str, V] | None = None
    _ref: tuple | None = None

    def ref(self) -> tuple:
        if self._ref is None:
            self._ref = self.make()
        return self._ref


@dataclass
class BakedImage:
    pixels: np.ndarray  # (N, N, C) float32 linear, row 0 = v = 0
    colour: bool  # an 8-bit sRGB colour map (else linear data, or a float EXR)


@dataclass
class MtlxExport:
    out: Path
    text: str
    images: dict[Path, BakedImage] = field(default_factory=dict)
    baked: list[tuple[str, str]] = field(default_factory=list)
    copies: dict[Path, Path] = field(default_factory=dict)  # side file -> texture it copies
    notes: list[str] = field(default_factory=list)
    zip: Path | None = None  # write one archive of the document and its side files instead

    @property
    def files(self) -> list[Path]:
        if self.zip is not None:
            return [self.zip]
        return [self.out, *self.images, *self.copies]


def _fmt(value, mxtype: str) -> str:
    if mxtype in ("float",):
        v = np.asarray(value, dtype=np.float64).reshape(-1)
        return repr(float(v[0]))
    return ", ".join(repr(float(x)) for x in np.asarray(value, dtype=np.float64).reshape(-1))


def _const(value, t: PortType) -> tuple:
    if t == PortType.FLOAT:
        return ("value", float(np.asarray(value, dtype=np.float64).reshape(-1)[0]))
    v = np.asarray(value, dtype=np.float64).reshape(-1)
    if v.size == 1:
        v = np.repeat(v, t.components)
    return ("value", tuple(float(x) for x in v[: t.components]))


class _Exporter:
    def __init__(self, ir: MaterialIR, size: int, folder: Path, stem: str,
                 kind: str = DEFAULT_SURFACE, fmt: str = "png", side: str = "",
                 rows: tuple[int, int] | None = None) -> None:
        import MaterialX as mx

        from matedit.compiler.cpu_eval import Env
        from matedit.interop.bake import load_textures, surface

        self.mx = mx
        self.ir = ir
        self.size = size
        self.folder = folder
        self.stem = stem = safe_name(stem)
        self.kind = kind
        self.fmt = fmt
        self.side = side  # the side-file folder, relative to the document's
        self.rows = rows  # a band of rows only (the detail check's finer bake)
        self.notes: list[str] = []
        self.copies: dict[Path, Path] = {}  # side file -> the texture file it copies
        self.doc = mx.createDocument()
        self.doc.setVersionString(MTLX_VERSION)
        self.doc.setColorSpace(WORKING)  # images in other spaces are converted to it
        self.ng = self.doc.addNodeGraph(mx.createValidName(f"NG_{stem}"))
        n = size * (size if rows is None else rows[1] - rows[0])
        uniforms = {u.name: u.default for u in ir.uniforms}
        self.env = Env(surface(size, rows), n, uniforms, load_textures(ir),
                       {f.name: f for f in ir.functions})
        self.functions = {f.name: f for f in ir.functions}
        self.uniforms = {u.name: u for u in ir.uniforms}
        self.textures = {t.name: t for t in ir.textures}
        self.names: set[str] = set()
        self.images: dict[Path, BakedImage] = {}
        self.baked: list[tuple[str, str]] = []
        self._uv = None
        self._iface: dict[str, str] = {}
        # texture name -> the file value to write (default: the path relative to folder)
        self.texture_files: dict[str, str] = {}

    # --- MaterialX building blocks ---------------------------------------------------------
    def name(self, hint: str) -> str:
        base = self.mx.createValidName(hint) or "n"
        name, k = base, 1
        while name in self.names:
            k += 1
            name = f"{base}_{k}"
        self.names.add(name)
        return name

    def set_input(self, node, name: str, ref: tuple, mxtype: str) -> None:
        inp = node.addInput(name, mxtype)
        if ref[0] == "value":
            inp.setValueString(_fmt(ref[1], mxtype))
        elif ref[0] == "node":
            inp.setConnectedNode(ref[1])
            if ref[2]:
                inp.setOutputString(ref[2])
        elif ref[0] == "iface":
            inp.setInterfaceName(ref[1])

    def node(self, category: str, mxtype: str, hint: str,
             inputs: list[tuple[str, tuple, str]] = (), strings=()) -> tuple:
        n = self.ng.addNode(category, self.name(hint), mxtype)
        for name, ref, t in inputs:
            self.set_input(n, name, ref, t)
        for name, value in strings:
            n.setInputValue(name, value, "string")
        return ("node", n, None)

    def uv0(self) -> tuple:
        if self._uv is None:
            self._uv = self.node("texcoord", "vector2", "uv0")
        return self._uv

    # --- values ----------------------------------------------------------------------------
    def expr(self, e, table: dict[str, V]) -> V:
        if isinstance(e, (Var, Param)):
            return table[e.name]
        if isinstance(e, Lit):
            from matedit.compiler.cpu_eval import eval_expr

            num = eval_expr(e, {}, self.env)
            if e.type == PortType.MATERIAL:
                return self.attributes_const(num)
            return V(num, e.type, lambda: _const(e.value, e.type))
        if isinstance(e, Uni):
            return self.uniform(e)
        if isinstance(e, SurfaceUV):
            return V(np.asarray(self.env.surface.uv, dtype=np.float64), PortType.VEC2, self.uv0)
        if isinstance(e, Splat):
            inner = self.expr(e.expr, table)
            num = np.repeat(np.asarray(inner.num).reshape(-1, 1), e.type.components, axis=1)

            def make(inner=inner, t=e.type):
                r = inner.ref()
                if r[0] == "value":
                    return _const(r[1], t)
                return self.node("convert", MX_TYPE[t], "convert",
                                 [("in", r, MX_TYPE[inner.type])])
            return V(num, e.type, make, inner.geo)
        raise MtlxExportError(f"cannot express {e!r} in MaterialX")

    def attributes_const(self, num) -> V:
        fields = {}
        for f in ATTRIBUTE_FIELDS:
            t = PortType(f.type)
            fields[f.name] = V(num[f.name], t, lambda d=f.default, t=t: _const(d, t))
        return V(num, PortType.MATERIAL, None, False, fields)

    def uniform(self, e: Uni) -> V:
        if e.type == PortType.TEXTURE:
            return V(self.env.textures.get(e.name), e.type, lambda: ("texture", e.name))
        u = self.uniforms[e.name]
        from matedit.compiler.cpu_eval import _broadcast

        num = _broadcast(self.env.uniforms[e.name], e.type, self.env.n)
        if not u.parameter:
            return V(num, e.type, lambda: _const(u.default, e.type))

        def make():
            if e.name not in self._iface:
                name = self.name(u.parameter)
                inp = self.ng.addInput(name, MX_TYPE[e.type])
                inp.setValueString(_fmt(u.default, MX_TYPE[e.type]))
                self._iface[e.name] = name
            return ("iface", self._iface[e.name])
        return V(num, e.type, make)

    # --- scopes ----------------------------------------------------------------------------
    def scope(self, scope: Scope, params: dict[str, V], prefix: str) -> list[V]:
        table = dict(params)
        for op in scope.ops:
            args = [self.expr(a, table) for a in op.args]
            outs = self.op(op, args, prefix)
            for (port, _), v in zip(op.outs, outs):
                table[op.out(port).name] = v
        return [self.expr(e, table) for _, _, e in scope.outputs]

    def op(self, op, args: list[V], prefix: str) -> list[V]:
        from matedit.compiler.cpu_eval import eval_op

        hint = f"{prefix}{op.node}"
        if op.kind == ops.CALL:
            scope = self.functions[op.data["function"]]
            return self.scope(scope, dict(zip((p for p, _ in scope.params), args)),
                              f"{hint}_")
        nums = eval_op(op, [a.num for a in args], self.env)
        if op.kind == "coat":
            return [self.coat(args, nums[0], hint)]
        if op.kind == ops.FILM:
            return [self.film(args, nums[0], hint)]
        d = nodes.get(op.kind)
        geo = (d is not None and d.geometry) or any(a.geo for a in args)
        kind = kind_for(IR_OP_ROLES[op.kind]) if op.kind in IR_OP_ROLES else op.kind
        entry = mapping(kind) if op.kind != ops.WEIGHT else _WEIGHT
        outs_t = [t for _, t in op.outs]
        if isinstance(entry, MxRecipe) and entry.build is not None:
            makers = entry.build(_Builder(self, op, kind, args, outs_t, hint))
            if makers is not None:
                return [V(num, t, (lambda m=m: m()[0]), geo)
                        for m, num, t in zip(makers, nums, outs_t)]
            entry = BAKE  # the recipe does not take these operand types
        if entry == BAKE:
            return [self.bake(hint, port, num, t, geo, op.kind)
                    for (port, t), num in zip(op.outs, nums)]
        if isinstance(entry, MxNode):
            return [V(nums[0], outs_t[0], self.stdlib_node(entry, kind, args, outs_t[0], hint),
                      geo)]
        own = self._own_recipe(entry)
        if own is None:
            # A kind the catalogue maps to nothing the exporter can write (a lowered kind
            # that reached it, a recipe with no build): refused by name, never guessed.
            what = f"recipe {entry.name!r}" if isinstance(entry, MxRecipe) else repr(entry)
            raise MtlxExportError(f"node {hint}: node kind {kind!r} has no MaterialX mapping "
                                  f"the exporter can write ({what})")
        return own(op, args, nums, outs_t, hint, geo)

    def stdlib_node(self, entry: MxNode, kind: str, args: list[V], t: PortType,
                    hint: str) -> Callable[[], tuple]:
        """The maker of one stdlib node: our inputs to its inputs, its fixed ones added."""
        order = [i.name for i in nodes.REGISTRY[kind].inputs]

        def make():
            ins = [(mxname, args[order.index(ours)].ref(),
                    MX_TYPE[args[order.index(ours)].type]) for ours, mxname in entry.ports]
            ins += [(name, _const(v, t), MX_TYPE[t]) for name, v in entry.fixed]
            strings = [("space", "world")] if entry.category in ("position", "normal") else []
            return self.node(entry.category, MX_TYPE[t], hint, ins, strings)
        return make

    def _own_recipe(self, entry) -> Callable[..., list[V]] | None:
        """The exporter's own recipes (no `build`): values that are not one reference
        (material attributes and their blends) and texture reads."""
        if not isinstance(entry, MxRecipe):
            return None
        return {
            "image_read": self.texture_sample,
            "attributes": lambda op, args, nums, outs_t, hint, geo:
                self.attributes(op, args, nums),
            "blend": lambda op, args, nums, outs_t, hint, geo:
                [self.blend(op, args, nums[0], hint)],
        }.get(entry.name)

    # --- baking ----------------------------------------------------------------------------
    def bake(self, hint: str, port: str, num, t: PortType, geo: bool, kind: str) -> V:
        """A baked node output: an image node reading its map (BakedImage: an 8-bit PNG,
        sRGB for a colour map and linear for a data map, or a float EXR; a PNG map whose
        values leave [0, 1] is an EXR, and the note says so)."""
        def make():
            name = self.name(f"{hint}_{port}_baked")
            h = self.size if self.rows is None else self.rows[1] - self.rows[0]
            arr = np.asarray(num, dtype=np.float32).reshape(h, self.size, -1)
            fmt = self.fmt
            if fmt == "png" and (not np.all(np.isfinite(arr)) or arr.min() < 0.0
                                 or arr.max() > 1.0):
                fmt = "exr"
                self.note(f"node {hint}: its {port} leaves [0, 1] "
                          f"({float(np.nanmin(arr)):.3g} to {float(np.nanmax(arr)):.3g}), so "
                          "its map is a float EXR, not an 8-bit PNG")
            d = nodes.get(kind)
            colour = fmt == "png" and t in (PortType.VEC3, PortType.VEC4) and (
                port == "color" or (d is not None and d.category == "Colour"))
            rel = f"{self.side}/{name}.{fmt}" if self.side else f"{self.stem}_{name}.{fmt}"
            k = 1
            while self.folder / rel in self.copies:  # a copied texture of that name
                k += 1
                rel = f"{self.side}/{name}_{k}.{fmt}"
            self.images[self.folder / rel] = BakedImage(arr, colour)
            why = f"{kind} has no MaterialX stdlib equivalent"
            if geo:
                why += "; it reads position, normal, view or time, so the bake is exact on " \
                       "the flat bake plane only"
            self.baked.append((hint, why))
            # MaterialX decodes colour-typed images only: an sRGB map is read as a colour
            # and converted back to our vector type (as a texture in another space)
            space = "srgb_texture" if colour else WORKING
            itype = {PortType.VEC3: "color3", PortType.VEC4: "color4"}[t] if colour \
                else MX_TYPE[t]
            n = self.ng.addNode("image", name, itype)
            n.setInputValue("file", rel, "filename")
            n.getInput("file").setColorSpace(space)
            self.set_input(n, "texcoord", self.uv0(), "vector2")
            if colour:
                return self.node("convert", MX_TYPE[t], f"{name}_linear",
                                 [("in", ("node", n, None), itype)])
            return ("node", n, None)
        return V(num, t, make, geo)

    def texture_file(self, path: str) -> str:
        """The document's reference to a texture the material reads: a copy in the side
        folder (named as the file, numbered where two share a name), or, for a file that
        does not exist, its path relative to the document's folder (and a note)."""
        src = Path(path)
        for dest, was in self.copies.items():
            if was == src:
                return dest.relative_to(self.folder).as_posix()
        if not self.side or not src.is_file():
            if self.side:
                self.note(f"texture {src.name}: no such file; referenced, not copied")
            return safe_name(Path(os.path.relpath(path, self.folder)).as_posix())
        taken = {d.name.lower() for d in self.copies} | {
            p.name.lower() for p in self.images}
        name, k = safe_name(src.name), 1
        while name.lower() in taken:
            k += 1
            name = safe_name(f"{src.stem}_{k}{src.suffix}")
        dest = self.folder / self.side / name
        self.copies[dest] = src
        return dest.relative_to(self.folder).as_posix()

    def _extract(self, r: tuple, t: PortType, i: int, hint: str) -> tuple:
        n = self.ng.addNode("extract", self.name(f"{hint}_{'xyzw'[i]}"), "float")
        self.set_input(n, "in", r, MX_TYPE[t])
        n.setInputValue("index", i, "integer")
        return ("node", n, None)

    def colorspace(self, info, hint: str) -> str:
        """The MaterialX colour space of a texture (its colour space setting, else its sRGB
        flag); raises MtlxExportError when MaterialX 1.39 has no equivalent."""
        from matedit.shading.colorspace import ColorSpaceError, effective_space

        space = effective_space(getattr(info, "color_space", ""), info.srgb)
        try:
            name = to_materialx(space)
        except ColorSpaceError as exc:
            raise MtlxExportError(f"node {hint}: {exc}") from None
        if name is None:
            raise MtlxExportError(f"node {hint}: colour space {space!r} has no MaterialX "
                                  f"1.39 equivalent (known: "
                                  f"{', '.join(sorted(materialx_spaces()))})")
        return name

    def _to3(self, r: tuple, hint: str) -> tuple:
        if r[0] == "value":
            return ("value", tuple(r[1][:3]))
        return self.node("convert", "vector3", f"{hint}_xyz", [("in", r, "vector4")])

    def texture_sample(self, op, args, nums, outs_t, hint, geo) -> list[V]:
        shared: dict[str, tuple] = {}

        def image() -> tuple:
            if "n" not in shared:
                tex = args[0].ref()
                info = self.textures.get(tex[1]) if tex[0] == "texture" else None
                if info is None:
                    raise MtlxExportError(f"node {hint}: texture input is not a texture "
                                          "parameter")
                space = self.colorspace(info, hint)
                # MaterialX decodes colour-typed values only: an image in another space than
                # the document's is read as color4 (decoded) and converted to vector4.
                decoded = space != WORKING
                n = self.ng.addNode("image", self.name(hint), "color4" if decoded else "vector4")
                if info.path:
                    n.setInputValue("file", self.texture_files.get(info.name)
                                    or self.texture_file(info.path), "filename")
                    n.getInput("file").setColorSpace(space)
                self.set_input(n, "texcoord", args[1].ref(), "vector2")
                shared["n"] = ("node", n, None)
                if decoded:
                    shared["n"] = self.node("convert", "vector4", f"{hint}_linear",
                                            [("in", shared["n"], "color4")])
            return shared["n"]

        makers = [image, lambda: self._to3(image(), hint)] + [
            (lambda i=i: self._extract(image(), PortType.VEC4, i, hint)) for i in range(4)]
        return [V(n, t, m, geo) for n, t, m in zip(nums, outs_t, makers)]

    def attributes(self, op, args, nums) -> list[V]:
        role = role_of(op.kind)
        if role == Role.MAKE_ATTRIBUTES:
            return [V(nums[0], PortType.MATERIAL, None, any(a.geo for a in args),
                      dict(zip(ATTRIBUTE_NAMES, args)))]
        if role != Role.SET_ATTRIBUTES:  # break_attributes
            return [args[0].fields[n] for n in ATTRIBUTE_NAMES]
        fields = dict(args[0].fields)
        for name, v in zip(op.data["fields"], args[1:]):
            fields[name] = v
        return [V(nums[0], PortType.MATERIAL, None, any(a.geo for a in args), fields)]

    def blend(self, op, args, num, hint) -> V:
        a, b = args[0], args[1]
        if role_of(op.kind) == Role.HEIGHT_BLEND:
            bh, lh, c = args[2], args[3], args[4]

            def make_t():
                cm = self.node("max", "float", f"{hint}_c",
                               [("in1", c.ref(), "float"), ("in2", ("value", 1e-5), "float")])
                neg = self.node("multiply", "float", f"{hint}_negc",
                                [("in1", cm, "float"), ("in2", ("value", -1.0), "float")])
                dh = self.node("subtract", "float", f"{hint}_dh",
                               [("in1", lh.ref(), "float"), ("in2", bh.ref(), "float")])
                return self.node("smoothstep", "float", f"{hint}_t",
                                 [("in", dh, "float"), ("low", neg, "float"),
                                  ("high", cm, "float")])
            t = V(None, PortType.FLOAT, make_t)
        else:
            t = args[2]
        fields = {}
        for f in ATTRIBUTE_FIELDS:
            x, y = a.fields[f.name], b.fields[f.name]
            ft = PortType(f.type)

            def make(x=x, y=y, ft=ft, name=f.name):
                m = self.node("mix", MX_TYPE[ft], f"{hint}_{name}",
                              [("fg", y.ref(), MX_TYPE[ft]), ("bg", x.ref(), MX_TYPE[ft]),
                               ("mix", t.ref(), "float")])
                if name == "normal":
                    return self.node("normalize", "vector3", f"{hint}_nrm",
                                     [("in", m, "vector3")])
                if name in ("coatNormal", "anisotropyDirection"):  # nlerp, as the shader
                    return self.node("normalize", "vector3", f"{hint}_{name}_nrm",
                                     [("in", m, "vector3")])
                return m
            fields[f.name] = V(num[f.name], ft, make, a.geo or b.geo or t.geo)
        return V(num, PortType.MATERIAL, None, False, fields)

    def coat(self, args, num, hint) -> V:
        """The `coat` layer blend (coatMaterialAttributes, shaders/nodes/layer_blend.glsl)
        node for node: the coverage w + (1 - w) a is the new coat weight (equal to
        1 - (1 - a)(1 - w)), its share s = w / max(coverage, 1e-6) mixes the coat fields
        towards the layer's roughness, base colour, IOR and normal (the last normalised)."""
        a, b, w = args
        geo = a.geo or b.geo or w.geo
        f = a.fields
        shared: dict[str, tuple] = {}

        def cover():
            if "cover" not in shared:
                rest = self.node("subtract", "float", f"{hint}_rest",
                                 [("in1", ("value", 1.0), "float"), ("in2", w.ref(), "float")])
                below = self.node("multiply", "float", f"{hint}_below",
                                  [("in1", rest, "float"), ("in2", f["coat"].ref(), "float")])
                shared["cover"] = self.node("add", "float", f"{hint}_cover",
                                            [("in1", w.ref(), "float"), ("in2", below, "float")])
            return shared["cover"]

        def share():
            if "share" not in shared:
                floor = self.node("max", "float", f"{hint}_floor",
                                  [("in1", cover(), "float"), ("in2", ("value", 1e-6), "float")])
                shared["share"] = self.node("divide", "float", f"{hint}_share",
                                            [("in1", w.ref(), "float"), ("in2", floor, "float")])
            return shared["share"]

        fields = dict(f)
        fields["coat"] = V(num["coat"], PortType.FLOAT, cover, geo)
        for name, src in (("coatRoughness", "roughness"), ("coatColor", "baseColor"),
                          ("coatIor", "ior"), ("coatNormal", "normal")):
            ft = PortType(next(x.type for x in ATTRIBUTE_FIELDS if x.name == name))

            def make(x=f[name], y=b.fields[src], ft=ft, name=name):
                m = self.node("mix", MX_TYPE[ft], f"{hint}_{name}",
                              [("fg", y.ref(), MX_TYPE[ft]), ("bg", x.ref(), MX_TYPE[ft]),
                               ("mix", share(), "float")])
                if name == "coatNormal":
                    return self.node("normalize", "vector3", f"{hint}_cnrm",
                                     [("in", m, "vector3")])
                return m
            fields[name] = V(num[name], ft, make, geo)
        return V(num, PortType.MATERIAL, None, False, fields)

    def film(self, args, num, hint) -> V:
        """The `film` layer blend (filmMaterialAttributes, shaders/nodes/layer_blend.glsl):
        the thin film's thickness and IOR mixed towards the layer's by w, the rest kept."""
        a, b, w = args
        geo = a.geo or b.geo or w.geo
        fields = dict(a.fields)
        for name in ("thinFilmThickness", "thinFilmIor"):
            def make(x=a.fields[name], y=b.fields[name], name=name):
                return self.node("mix", "float", f"{hint}_{name}",
                                 [("fg", y.ref(), "float"), ("bg", x.ref(), "float"),
                                  ("mix", w.ref(), "float")])
            fields[name] = V(num[name], PortType.FLOAT, make, geo)
        return V(num, PortType.MATERIAL, None, False, fields)

    # --- the surface -----------------------------------------------------------------------
    def surface(self, attrs: V) -> None:
        """The surface shader (`self.kind`, SURFACE_KINDS) reading the attributes, and the
        surfacematerial; `notes` gets a line for each field that surface carries only
        approximately or not at all (docs/materialx.md, Export: the three surfaces)."""
        mx = self.mx
        f = attrs.fields
        shader = self.doc.addNode(self.kind, mx.createValidName(f"SR_{self.stem}"),
                                  "surfaceshader")
        written = set(self.ir.attributes)
        build = {"standard_surface": self._standard, "open_pbr_surface": self._open_pbr,
                 "gltf_pbr": self._gltf}[self.kind]
        outputs = build(f, written)
        for name, t, r in outputs:
            inp = shader.addInput(name, t)
            if t == "boolean":
                inp.setValueString("true" if r[1] else "false")
            elif t == "integer":
                inp.setValueString(str(int(r[1])))
            elif r[0] == "value":
                inp.setValueString(_fmt(r[1], t))
            elif r[0] == "iface":
                # A parameter straight into the surface: route it through a dot node.
                d = self.node("dot", t, f"{name}_param", [("in", r, t)])
                self._output(inp, name, t, d)
            else:
                self._output(inp, name, t, r)
        mat = self.doc.addMaterialNode(mx.createValidName(f"M_{self.stem}"), shader)
        del mat

    def color(self, v: V) -> tuple:
        r = v.ref()
        if r[0] == "value":
            return r
        return self.node("convert", "color3", "to_color3", [("in", r, MX_TYPE[v.type])])

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)

    def _is(self, v: V, value) -> bool:
        r = v.ref()
        return r[0] == "value" and bool(np.allclose(np.ravel(r[1]), np.ravel(value)))

    def _common(self, f: dict, written: set, names: dict[str, str]) -> list:
        """The talk's inputs, by this surface's names (None: not carried)."""
        out: list[tuple[str, str, tuple]] = [
            (names["baseColor"], "color3", self.color(f["baseColor"])),
            (names["metallic"], "float", f["metallic"].ref()),
            (names["roughness"], "float", f["roughness"].ref())]
        if "normal" in written:
            nm = self.normal_map(f["normal"], "normal")
            if nm is not None:
                out.append((names["normal"], "vector3", nm))
        return out

    def _emission(self, f: dict, written: set, color_in: str, weight_in: str,
                  weight: float) -> list:
        if "emissive" not in written or self._is(f["emissive"], (0.0, 0.0, 0.0)):
            return []
        return [(weight_in, "float", ("value", weight)),
                (color_in, "color3", self.color(f["emissive"]))]

    def _opacity(self, f: dict, written: set, name: str, t: str) -> list:
        if "opacity" not in written or self._is(f["opacity"], 1.0):
            return []
        o = f["opacity"].ref()
        if t == "float":
            return [(name, "float", o)]
        c = o if o[0] == "value" else self.node("convert", "color3", "to_opacity",
                                                [("in", o, "float")])
        if c[0] == "value":
            c = ("value", (c[1],) * 3)
        return [(name, "color3", c)]

    def direction_angle(self, f: dict) -> float:
        """The constant anisotropy direction's angle from the tangent (radians)."""
        d = f["anisotropyDirection"].ref()
        if d[0] != "value":
            raise MtlxExportError(
                f"anisotropyDirection: {self.kind} takes the anisotropy direction as a "
                "rotation from the tangent; a varying direction cannot be exported (use a "
                "constant)")
        return math.atan2(float(d[1][1]), float(d[1][0]))

    def _anisotropy_note(self, written: set, theirs: str) -> None:
        if "anisotropy" in written:
            self.note(f"anisotropy: written as {self.kind}'s {theirs}, which stretches the "
                      "roughness by its own rule (ours: alpha x (1 + a) along the direction, "
                      "alpha x (1 - a) across); approximated")

    def _cavity_note(self, f: dict, written: set, lobes: tuple[str, ...]) -> None:
        if "cavity" in written and not self._is(f["cavity"], 1.0):
            others = [x for x in lobes if x in written]
            if others:
                self.note(f"cavity: our cavity darkens the {', '.join(others)} lobe too, "
                          f"which {self.kind}'s base and specular weights do not; "
                          "approximated")

    def _transmission(self, f: dict, written: set, weight: str, color: str,
                      depth: str) -> list:
        """standard_surface's and OpenPBR's rule (docs/materialx.md, Transmission)."""
        out: list[tuple[str, str, tuple]] = []
        if "transmission" in written:
            out.append((weight, "float", f["transmission"].ref()))
        if "attenuationDistance" in written:
            out.append((depth, "float", f["attenuationDistance"].ref()))
            out.append((color, "color3", self.color(f["attenuationColor"])))
            if "transmissionColor" in written:
                self.note(f"transmissionColor: {self.kind}'s transmission_color is the "
                          "absorption colour at transmission_depth when a depth is set; the "
                          "surface tint has no counterpart then; dropped")
        elif "transmissionColor" in written:
            out.append((color, "color3", self.color(f["transmissionColor"])))
        elif "attenuationColor" in written:
            self.note("attenuationColor: without attenuationDistance it changes nothing; "
                      "not written")
        return out

    def _standard(self, f: dict, written: set) -> list:
        out = [("base", "float", f["cavity"].ref())]
        out += self._common(f, written, {"baseColor": "base_color", "metallic": "metalness",
                                         "roughness": "specular_roughness",
                                         "normal": "normal"})
        out.append(("specular", "float", f["cavity"].ref()))
        out += self._emission(f, written, "emission_color", "emission", 1.0)
        out += self._opacity(f, written, "opacity", "color3")
        out += self.lobes(f, written)
        if THIN_WALLED_DEFINE in self.ir.defines:  # the Material Output's setting
            out.append(("thin_walled", "boolean", ("value", True)))
        self._anisotropy_note(written, "specular_anisotropy")
        self._cavity_note(f, written, ("coat", "sheenColor", "subsurface", "transmission"))
        return out

    def lobes(self, f: dict, written: set) -> list[tuple[str, str, tuple]]:
        """standard_surface inputs for the lobes beyond the talk the material writes: the
        same meanings (coat colour a transmittance tint, sheen a weighted colour, IORs), the
        tangent-space coat normal through a normalmap like the base's, and the anisotropy
        direction as standard_surface's rotation (a fraction of a turn from the tangent),
        which MaterialX can only take here from a constant direction."""
        color = self.color
        out: list[tuple[str, str, tuple]] = []
        plain = (("specularColor", "specular_color", "color3"), ("ior", "specular_IOR", "float"),
                 ("coat", "coat", "float"), ("coatRoughness", "coat_roughness", "float"),
                 ("coatColor", "coat_color", "color3"), ("coatIor", "coat_IOR", "float"),
                 ("sheenRoughness", "sheen_roughness", "float"),
                 ("anisotropy", "specular_anisotropy", "float"),
                 ("subsurface", "subsurface", "float"),
                 ("subsurfaceColor", "subsurface_color", "color3"),
                 ("subsurfaceRadius", "subsurface_radius", "color3"),
                 ("thinFilmThickness", "thin_film_thickness", "float"),
                 ("thinFilmIor", "thin_film_IOR", "float"))
        # standard_surface's own defaults differ from ours where they would change the look
        # of a lobe the material turns on: coat_roughness 0.1 (ours 0), sheen_roughness 0.3.
        for ours, theirs, t in plain:
            if ours in written or (ours == "coatRoughness" and "coat" in written):
                out.append((theirs, t, color(f[ours]) if t == "color3" else f[ours].ref()))
        if "sheenColor" in written:
            out.append(("sheen", "float", ("value", 1.0)))
            out.append(("sheen_color", "color3", color(f["sheenColor"])))
            if "sheenRoughness" not in written:
                out.append(("sheen_roughness", "float", ("value", 0.3)))
        if "coatNormal" in written:
            nm = self.normal_map(f["coatNormal"], "coat_normal")
            if nm is not None:
                out.append(("coat_normal", "vector3", nm))
        if "anisotropyDirection" in written:
            turn = self.direction_angle(f) / (2.0 * math.pi)
            out.append(("specular_rotation", "float", ("value", turn % 1.0)))
        if "subsurface" in written and "subsurfaceColor" not in written:
            # standard_surface's subsurface_color default is 0.8; ours is white
            out.append(("subsurface_color", "color3", ("value", [1.0, 1.0, 1.0])))
        if "thinFilmThickness" in written and "thinFilmIor" not in written:
            # standard_surface's thin_film_IOR default is 1.5; ours 1.3 (both nm thickness)
            out.append(("thin_film_IOR", "float", ("value", 1.3)))
        if "thickness" in written:
            out.append(("subsurface_scale", "float", self.inverse_thickness(f["thickness"])))
        out += self._transmission(f, written, "transmission", "transmission_color",
                                  "transmission_depth")
        return out

    def _open_pbr(self, f: dict, written: set) -> list:
        """OpenPBR: the names of standard_surface's meanings (as the importer reads them),
        emission in nits (1000 is our emissive 1), the film in micrometres with weight 1,
        the mean free path as subsurface_radius_scale x subsurface_radius (1 / thickness),
        the anisotropy direction as the tangent rotated about the normal (a constant)."""
        out = [("base_weight", "float", f["cavity"].ref())]
        out += self._common(f, written, {"baseColor": "base_color",
                                         "metallic": "base_metalness",
                                         "roughness": "specular_roughness",
                                         "normal": "geometry_normal"})
        out.append(("specular_weight", "float", f["cavity"].ref()))
        out += self._emission(f, written, "emission_color", "emission_luminance", 1000.0)
        out += self._opacity(f, written, "geometry_opacity", "float")
        plain = (("specularColor", "specular_color", "color3"),
                 ("ior", "specular_ior", "float"),
                 ("anisotropy", "specular_roughness_anisotropy", "float"),
                 ("coat", "coat_weight", "float"), ("coatColor", "coat_color", "color3"),
                 ("coatRoughness", "coat_roughness", "float"),
                 ("subsurface", "subsurface_weight", "float"),
                 ("subsurfaceColor", "subsurface_color", "color3"),
                 ("thinFilmIor", "thin_film_ior", "float"))
        for ours, theirs, t in plain:
            if ours in written:
                out.append((theirs, t, self.color(f[ours]) if t == "color3" else f[ours].ref()))
        if "coat" in written and "coatIor" not in written:
            out.append(("coat_ior", "float", ("value", 1.5)))  # OpenPBR's default is 1.6
        if "coatIor" in written:
            out.append(("coat_ior", "float", f["coatIor"].ref()))
        if "coatNormal" in written:
            nm = self.normal_map(f["coatNormal"], "coat_normal")
            if nm is not None:
                out.append(("geometry_coat_normal", "vector3", nm))
        if "sheenColor" in written:
            out.append(("fuzz_weight", "float", ("value", 1.0)))
            out.append(("fuzz_color", "color3", self.color(f["sheenColor"])))
        if "sheenColor" in written or "sheenRoughness" in written:  # its default is 0.5
            out.append(("fuzz_roughness", "float", f["sheenRoughness"].ref()))
            self.note("sheenColor: written as OpenPBR's fuzz, whose lobe is its own (a "
                      "layer that also dims what is under it); approximated")
        if "subsurface" in written and "subsurfaceColor" not in written:
            out.append(("subsurface_color", "color3", ("value", [1.0, 1.0, 1.0])))
        if "subsurface" in written or "subsurfaceRadius" in written or "thickness" in written:
            # the mean free path radius x scale against our thickness 1: the shading reads
            # radius / thickness only (docs/shading.md, Subsurface)
            out.append(("subsurface_radius_scale", "color3", self.color(f["subsurfaceRadius"])))
            out.append(("subsurface_radius", "float", self.inverse_thickness(f["thickness"])))
            if "thickness" in written:
                self.note("thickness: OpenPBR has no part thickness; folded into "
                          "subsurface_radius (1 / thickness), which keeps radius / thickness, "
                          "all our shading reads; the thickness itself reads back as 1")
        if "thinFilmThickness" in written:
            out.append(("thin_film_weight", "float", ("value", 1.0)))
            out.append(("thin_film_thickness", "float", self.scaled(
                f["thinFilmThickness"], 1e-3, "thin_film_um")))
            if "thinFilmIor" not in written:  # OpenPBR's default is 1.4, ours 1.3
                out.append(("thin_film_ior", "float", ("value", 1.3)))
        if "anisotropyDirection" in written:
            out.append(("geometry_tangent", "vector3", self.rotated_tangent(f)))
        out += self._transmission(f, written, "transmission_weight", "transmission_color",
                                  "transmission_depth")
        if THIN_WALLED_DEFINE in self.ir.defines:
            out.append(("geometry_thin_walled", "boolean", ("value", True)))
        self._anisotropy_note(written, "specular_roughness_anisotropy")
        self._cavity_note(f, written, ("coat", "sheenColor", "subsurface", "transmission"))
        return out

    def _gltf(self, f: dict, written: set) -> list:
        """glTF's PBR (KHR_materials_* as MaterialX's gltf_pbr): cavity as occlusion, the
        clearcoat, sheen, specular, transmission and volume, iridescence (nm, weight 1) and
        anisotropy (rotation in radians); no subsurface, coat colour or coat IOR."""
        out = self._common(f, written, {"baseColor": "base_color", "metallic": "metallic",
                                        "roughness": "roughness", "normal": "normal"})
        if "cavity" in written:
            out.append(("occlusion", "float", f["cavity"].ref()))
            if not self._is(f["cavity"], 1.0):
                self.note("cavity: written as gltf_pbr's occlusion, which darkens indirect "
                          "light only (ours all lighting); approximated")
        out += self._emission(f, written, "emissive", "emissive_strength", 1.0)
        op = self._opacity(f, written, "alpha", "float")
        if op:
            out += op + [("alpha_mode", "integer", ("value", 2))]  # BLEND
        plain = (("specularColor", "specular_color", "color3"), ("ior", "ior", "float"),
                 ("coat", "clearcoat", "float"), ("coatRoughness", "clearcoat_roughness", "float"),
                 ("sheenColor", "sheen_color", "color3"),
                 ("anisotropy", "anisotropy_strength", "float"),
                 ("transmission", "transmission", "float"),
                 ("attenuationColor", "attenuation_color", "color3"),
                 ("attenuationDistance", "attenuation_distance", "float"),
                 ("thinFilmIor", "iridescence_ior", "float"))
        for ours, theirs, t in plain:
            if ours in written:
                out.append((theirs, t, self.color(f[ours]) if t == "color3" else f[ours].ref()))
        if "sheenColor" in written or "sheenRoughness" in written:  # its default is 0
            out.append(("sheen_roughness", "float", f["sheenRoughness"].ref()))
        if "coatNormal" in written:
            nm = self.normal_map(f["coatNormal"], "coat_normal")
            if nm is not None:
                out.append(("clearcoat_normal", "vector3", nm))
        if "thinFilmThickness" in written:
            out.append(("iridescence", "float", ("value", 1.0)))
            out.append(("iridescence_thickness", "float", f["thinFilmThickness"].ref()))
        if "anisotropyDirection" in written:
            out.append(("anisotropy_rotation", "float", ("value", self.direction_angle(f))))
        if THIN_WALLED_DEFINE in self.ir.defines:  # glTF's thin-walled: thickness 0
            out.append(("thickness", "float", ("value", 0.0)))
        elif "thickness" in written or "transmission" in written:
            out.append(("thickness", "float", f["thickness"].ref()))  # 0 would be thin
        for ours in ("coatColor", "coatIor", "subsurface", "subsurfaceColor",
                     "subsurfaceRadius", "transmissionColor"):
            if ours in written and not (ours == "coatIor" and self._is(f[ours], 1.5)):
                self.note(f"{ours}: gltf_pbr has no counterpart; dropped")
        if "thickness" in written and "subsurface" in written:
            self.note("thickness: written as gltf_pbr's volume thickness; its subsurface "
                      "meaning is dropped with the subsurface")
        self._anisotropy_note(written, "anisotropy_strength")
        return out

    def scaled(self, v: V, k: float, hint: str) -> tuple:
        r = v.ref()
        if r[0] == "value":
            return ("value", float(np.ravel(r[1])[0]) * k)
        return self.node("multiply", "float", hint, [("in1", r, "float"),
                                                     ("in2", ("value", k), "float")])

    def rotated_tangent(self, f: dict) -> tuple:
        """OpenPBR's geometry_tangent for the tangent-space anisotropy direction: for a
        constant, the world tangent rotated about the world normal by its angle (degrees,
        rotate3d's unit; MaterialX's rotate3d turns clockwise about its axis, so the amount
        is negated); for a varying one, the direction in world space, normalize(T x +
        B y + N z) of the world tangent, bitangent and normal."""
        t = self.node("tangent", "vector3", "tangent", strings=[("space", "world")])
        n = self.node("normal", "vector3", "normal_axis", strings=[("space", "world")])
        d = f["anisotropyDirection"]
        if d.ref()[0] != "value":
            b = self.node("bitangent", "vector3", "bitangent", strings=[("space", "world")])
            terms = [self.node("multiply", "vector3", f"aniso_{axis}",
                               [("in1", g, "vector3"),
                                ("in2", self._extract(d.ref(), PortType.VEC3, i, "aniso"),
                                 "float")])
                     for i, (axis, g) in enumerate(zip("tbn", (t, b, n)))]
            tb = self.node("add", "vector3", "aniso_tb", [("in1", terms[0], "vector3"),
                                                          ("in2", terms[1], "vector3")])
            s = self.node("add", "vector3", "aniso_tbn", [("in1", tb, "vector3"),
                                                          ("in2", terms[2], "vector3")])
            return self.node("normalize", "vector3", "anisotropy_tangent",
                             [("in", s, "vector3")])
        deg = -math.degrees(self.direction_angle(f))
        return self.node("rotate3d", "vector3", "anisotropy_tangent",
                         [("in", t, "vector3"), ("amount", ("value", deg), "float"),
                          ("axis", n, "vector3")])

    def normal_map(self, v: V, hint: str) -> tuple | None:
        """A tangent-space normal as standard_surface's world normal: encoded to [0, 1] into
        a normalmap node; None for the constant +Z (the surface's own normal)."""
        n = v.ref()
        if n[0] == "value" and tuple(n[1]) == (0.0, 0.0, 1.0):
            return None
        enc = self.node("add", "vector3", f"{hint}_encode", [
            ("in1", self.node("multiply", "vector3", f"{hint}_half",
                              [("in1", n, "vector3"), ("in2", ("value", 0.5), "float")]),
             "vector3"), ("in2", ("value", 0.5), "float")])
        return self.node("normalmap", "vector3", f"{hint}_map", [("in", enc, "vector3")])

    def inverse_thickness(self, v: V) -> tuple:
        """Our thickness as standard_surface's subsurface_scale, 1 / thickness: the shading
        reads only radius / thickness, and standard_surface's mean free path is radius x
        scale (docs/shading.md, Subsurface); the thickness kept off 0 (MIN_SUBSURFACE_RADIUS)."""
        d = v.ref()
        if d[0] == "value":
            return ("value", 1.0 / max(float(np.ravel(d[1])[0]), _MIN_THICKNESS))
        safe = self.node("max", "float", "thickness_min",
                         [("in1", d, "float"), ("in2", ("value", _MIN_THICKNESS), "float")])
        return self.node("divide", "float", "subsurface_scale",
                         [("in1", ("value", 1.0), "float"), ("in2", safe, "float")])

    def _output(self, inp, name: str, t: str, r: tuple) -> None:
        out = self.ng.addOutput(self.name(f"out_{name}"), t)
        out.setConnectedNode(r[1])
        if r[2]:
            out.setOutputString(r[2])
        inp.setNodeGraphString(self.ng.getName())
        inp.setOutputString(out.getName())


# A layer's alpha weight (the IR's own op, ops.WEIGHT): saturate(mask * opacity).
def _weight_recipe(b: MxBuilder):
    return [lambda: b.node("clamp", "float", "", (
        "in", b.node("multiply", "float", "mul", ("in1", b.arg(0)), ("in2", b.arg(1)))),
        ("low", b.value(0.0, "float")), ("high", b.value(1.0, "float")))]


_WEIGHT = MxRecipe("weight", _weight_recipe)
_PORT_TYPE = {mx: t for t, mx in MX_TYPE.items()}


class _Builder:
    """The exporter's side of `MxBuilder`, for one op: references are (MaterialX reference,
    MaterialX type) pairs; nodes are named after the op (its hint) and a suffix."""

    def __init__(self, ex: _Exporter, op, kind: str, args: list[V], outs_t: list[PortType],
                 hint: str) -> None:
        self.ex, self.op, self.args, self.hint = ex, op, args, hint
        self.outs_t = outs_t
        d = nodes.get(kind)
        self.order = [i.name for i in d.inputs] if d is not None else []

    @property
    def result_type(self) -> str:
        return MX_TYPE[self.outs_t[0]]

    @property
    def data(self) -> dict[str, Any]:
        return self.op.data

    @property
    def operands(self) -> int:
        return len(self.args)

    def _arg(self, port: int | str) -> V:
        return self.args[port if isinstance(port, int) else self.order.index(port)]

    def arg(self, port: int | str) -> Ref:
        v = self._arg(port)
        return (v.ref(), MX_TYPE[v.type])

    def arg_type(self, port: int | str) -> str:
        return MX_TYPE[self._arg(port).type]

    def value(self, v, mxtype: str | None = None) -> Ref:
        if mxtype is None:
            return (_const(v, self.outs_t[0]), self.result_type)
        return (("value", v), mxtype)

    def constant(self, ref: Ref):
        return ref[0][1] if ref[0][0] == "value" else None

    def node(self, category: str, mxtype: str | None, suffix: str, *inputs: tuple[str, Ref],
             space: str | None = None) -> Ref:
        t = self.result_type if mxtype is None else mxtype
        name = f"{self.hint}_{suffix}" if suffix else self.hint
        strings = [("space", space)] if space else []
        return (self.ex.node(category, t, name, [(k, r, rt) for k, (r, rt) in inputs],
                             strings), t)

    def extract(self, ref: Ref, index: int) -> Ref:
        return (self.ex._extract(ref[0], _PORT_TYPE[ref[1]], index, self.hint), "float")

    def component(self, source: Ref | int, index: int) -> Ref:
        t = self.arg_type(source) if isinstance(source, int) else source[1]
        if _PORT_TYPE[t].components <= index and t != "float":
            return (("value", 0.0), "float")
        ref = self.arg(source) if isinstance(source, int) else source
        if t == "float" or ref[0][0] != "value":
            return ref if t == "float" else self.extract(ref, index)
        return (("value", float(ref[0][1][index])), "float")

    def combine(self, parts, mxtype: str) -> Ref:
        if len(parts) == 1:
            return parts[0]
        if all(p[0][0] == "value" for p in parts):
            return (("value", tuple(p[0][1] for p in parts)), mxtype)
        return self.node(f"combine{len(parts)}", mxtype, "",
                         *[(f"in{i + 1}", (p[0], "float")) for i, p in enumerate(parts)])

    def uv(self) -> Ref:
        return (self.ex.uv0(), "vector2")


def validate(text: str) -> tuple[bool, str]:
    """MaterialX's own validate() on a document text, with the stdlib loaded."""
    import MaterialX as mx

    doc = mx.createDocument()
    mx.readFromXmlString(doc, text)
    doc.importLibrary(stdlib())
    ok, msg = doc.validate()
    return bool(ok), msg


def side_folder(out: Path) -> str:
    """The folder of an export's side files (baked maps, texture copies), beside OUT.mtlx:
    OUT_textures."""
    return safe_name(f"{Path(out).stem}_textures")


def export_ir(ir: MaterialIR, out: Path, size: int, stem: str, kind: str = DEFAULT_SURFACE,
              fmt: str = "png", zip_it: bool = False, texture_files: dict[str, str] | None = None,
              side: str | None = None) -> MtlxExport:
    """`texture_files`: texture name -> the file value its image nodes get (where a caller
    copies the texture itself, under another name); `side`: the folder of the side files
    beside OUT ("" for none: beside it; default OUT_textures)."""
    if kind not in SURFACE_KINDS:
        raise MtlxExportError(f"surface {kind!r}: not one of {', '.join(SURFACE_KINDS)}")
    out = Path(out)
    ex = _Exporter(ir, size, out.parent, stem, kind, fmt,
                   side_folder(out) if side is None else side)
    ex.texture_files = dict(texture_files or {})
    try:
        (attrs,) = ex.scope(ir.main, {}, "")
        ex.surface(attrs)
    except RecursionError:
        raise MtlxExportError(f"{stem}: the graph is too deep to export to MaterialX") from None
    import MaterialX as mx

    text = mx.writeToXmlString(ex.doc)
    ok, msg = validate(text)
    if not ok:
        raise MtlxExportError(f"{out}: the MaterialX document does not validate: "
                              f"{' '.join(msg.split())[:300]}")
    notes = list(ex.notes)
    if ex.images:
        notes.append(f"{len(ex.images)} baked map(s) at {size} x {size} texels "
                     f"({', '.join(sorted({p.suffix[1:].upper() for p in ex.images}))}; "
                     "--size N to change)")
        notes += detail_notes(ir, ex, size, stem, kind, fmt)
    return MtlxExport(out, text, ex.images, ex.baked, ex.copies, notes,
                      out.with_suffix(".zip") if zip_it else None)


def detail_notes(ir: MaterialIR, ex: _Exporter, size: int, stem: str, kind: str,
                 fmt: str) -> list[str]:
    """A note per baked map with detail finer than its texels: a band of DETAIL_ROWS rows
    in the middle is baked again at 2 x size; where that finer bake, averaged over each
    texel's 2 x 2 sub-texels, differs from the bake by an RMS above DETAIL_RMS of the map's
    range, the bake has lost (or aliased) detail, and --size 2N is suggested."""
    rows = min(size, DETAIL_ROWS)
    j0 = (size - rows) // 2
    fine = _Exporter(ir, 2 * size, ex.folder, stem, kind, "exr", ex.side,
                     rows=(2 * j0, 2 * (j0 + rows)))
    (attrs,) = fine.scope(ir.main, {}, "")
    fine.surface(attrs)  # makes the same images, in the same order, under the same names
    out = []
    by_name = {p.with_suffix("").name: img for p, img in fine.images.items()}
    for path, img in ex.images.items():
        f = by_name.get(path.with_suffix("").name)
        if f is None:
            continue
        coarse = img.pixels[j0:j0 + rows].astype(np.float64)
        x = f.pixels.astype(np.float64)
        down = x.reshape(rows, 2, size, 2, -1).mean(axis=(1, 3))
        span = float(np.nanmax(img.pixels) - np.nanmin(img.pixels))
        rms = float(np.sqrt(np.nanmean((down - coarse) ** 2)))
        if rms > DETAIL_RMS * max(span, 1e-6):
            out.append(f"{path.name}: detail finer than its {size} x {size} texels (a 2x "
                       f"bake differs by RMS {rms / max(span, 1e-6):.2%} of its range); "
                       f"try --size {2 * size}")
    return out


def export(doc, resolver, out: Path, size: int = 512, kind: str = DEFAULT_SURFACE,
           fmt: str = "png", zip_it: bool = False) -> MtlxExport:
    """The MaterialX export of a material document (raises CompileError, MtlxExportError)."""
    from matedit.compiler.lower import lower_document
    from matedit.interop.export import stem_of

    ir = lower_document(doc, resolver)
    return export_ir(ir, Path(out), size, stem_of(doc), kind, fmt, zip_it)


def _encode(path: Path, img: BakedImage) -> None:
    """One baked map: an 8-bit PNG (sRGB-encoded for a colour map) or a float EXR."""
    from matedit.interop.bake import BakedMap, encode_file, linear_to_srgb

    px = img.pixels.astype(np.float64)
    encode_file(path, BakedMap(path.stem, linear_to_srgb(px) if img.colour else px,
                               img.colour))


def write(result: MtlxExport) -> None:
    """The document and its side files (baked maps, texture copies) in OUT_textures, the
    document last, each folder's files together or none; or, with `zip`, one archive of
    them all by their relative names (written whole or not at all)."""
    from matedit.io.atomic import atomic_write_bytes, atomic_write_text, staged_outputs

    out = result.out
    folder = out.parent
    if result.zip is not None:
        import io
        import tempfile
        import zipfile

        buf = io.BytesIO()
        with tempfile.TemporaryDirectory() as tmp, \
                zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr(safe_name(out.name), result.text)
            for path, img in result.images.items():
                staged = Path(tmp) / path.name
                _encode(staged, img)
                z.writestr(path.relative_to(folder).as_posix(), staged.read_bytes())
            for dest, src in result.copies.items():
                z.writestr(dest.relative_to(folder).as_posix(),
                           read_bounded(src, MAX_TEXTURE_BYTES))
        atomic_write_bytes(result.zip, buf.getvalue())
        return
    side = [*result.images, *result.copies]
    if not side:
        atomic_write_text(out, result.text)
        return
    side_dir = side[0].parent
    with staged_outputs(folder) as stage:
        stage.write_text(out, result.text)  # written first, moved into place last
        if side_dir.is_symlink():  # a link planted at the folder's name is replaced
            side_dir.unlink()
        with staged_outputs(side_dir) as files:
            for path, img in result.images.items():
                _encode(files.path(path), img)
            for dest, src in result.copies.items():
                files.write_bytes(dest, read_bounded(src, MAX_TEXTURE_BYTES))
