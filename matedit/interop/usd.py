"""A USD asset of a material, built with usd-core (`pxr`): the preview mesh bound to one
UsdShade Material that carries two networks.

- The universal render context: a `UsdPreviewSurface` on the maps baked over UV space
  (matedit.interop.bake, the glTF export's maps), each read by a `UsdUVTexture` on the `st`
  primvar (`UsdPrimvarReader_float2`): base colour (sRGB), the normal map (raw, scale 2 and
  bias -1 to [-1, 1], +Y up as UsdPreviewSurface expects), occlusion / roughness / metallic
  from the ORM map's r / g / b (raw), emission (sRGB, scaled back to its HDR peak) and
  opacity (raw) where the material writes them; ior, clearcoat and clearcoatRoughness as
  constants (the mean of the field over the bake surface); useSpecularWorkflow 0.
- The `mtlx` render context: the MaterialX export (matedit.interop.mtlx_export: a nodegraph
  feeding one standard_surface) written as UsdShade prims, each MaterialX node a Shader whose
  `info:id` is its MaterialX node definition (ND_standard_surface_surfaceshader, ND_mix_float,
  ND_image_color3, ...), the nodegraph a NodeGraph with the same interface inputs and
  outputs. It carries every lobe UsdPreviewSurface has no input for (sheen, anisotropy,
  transmission, thin film, subsurface, the coat's colour, IOR and normal, specular colour).

Texture coordinates keep matedit's convention, which is USD's (v = 0 at the bottom of the
image). Every file the layer names is given by a path relative to the layer: beside it for
.usda, inside the package for .usdz (whose root layer is usdc, packaged by usd-core's
UsdUtils.CreateNewUsdzPackage, which aligns every file to 64 bytes, stored uncompressed).
A texture file the material reads (an image node's file) is copied beside the layer, so the
asset names no folder of this machine.
"""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from matedit.interop.bake import BakedMap, encode_file
from matedit.io.atomic import atomic_write_bytes, read_bounded, staged_outputs

MAX_TEXTURE_BYTES = 1 << 30
VARYING = 1e-4  # a field whose values spread wider than this over the bake is "varying"
LOBE_SIZE = 32  # the bake surface's side for the lobe fields' means and ranges

# UsdPreviewSurface inputs set from a lobe field's mean: field -> (input, default)
PREVIEW_LOBES = {"ior": ("ior", 1.5), "coat": ("clearcoat", 0.0),
                 "coatRoughness": ("clearcoatRoughness", 0.01)}
# The lobe fields UsdPreviewSurface cannot hold, with the value at which they are off.
UNHELD = {
    "specularColor": (1.0, 1.0, 1.0), "coatColor": (1.0, 1.0, 1.0), "coatIor": 1.5,
    "coatNormal": (0.0, 0.0, 1.0), "sheenColor": (0.0, 0.0, 0.0), "anisotropy": 0.0,
    "subsurface": 0.0, "thinFilmThickness": 0.0, "transmission": 0.0,
    "attenuationDistance": 0.0,
}
# Fields only meaningful while another is on: field -> the field that turns it on.
NEEDS = {"coatColor": "coat", "coatIor": "coat", "coatNormal": "coat",
         "attenuationDistance": "transmission"}


def file_stem(out: Path) -> str:
    """The stem of the files the layer names: OUT's stem with every character but ASCII
    letters, digits, '.', '-' and '_' made '_' (asset paths are UTF-8, and portable)."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", Path(out).stem) or "material"


class UsdExportError(ValueError):
    """The material cannot be written as USD (the message names the reason)."""


@dataclass
class UsdExport:
    out: Path
    layer: bytes  # .usda text, or the .usdz package
    side: dict[str, bytes] = field(default_factory=dict)  # file name beside the layer
    notes: list[str] = field(default_factory=list)

    @property
    def files(self) -> list[Path]:
        if self.out.suffix.lower() == ".usdz":
            return [self.out]
        return [self.out.parent / n for n in self.side] + [self.out]


# --- the lobe fields --------------------------------------------------------------------
def lobe_stats(ir) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """field -> (mean, min, max) over a LOBE_SIZE² bake surface (CPU evaluator) for every
    lobe field the material writes."""
    from matedit.interop.bake import attributes_cpu
    from matedit.nodes.material import ATTRIBUTE_FIELDS

    lobe = {f.name for f in ATTRIBUTE_FIELDS if f.lobe} & set(ir.attributes)
    if not lobe:
        return {}
    values = attributes_cpu(ir, LOBE_SIZE)
    out = {}
    for name in sorted(lobe & set(values)):
        v = np.asarray(values[name], np.float64).reshape(-1, values[name].shape[-1])
        out[name] = (v.mean(axis=0), v.min(axis=0), v.max(axis=0))
    return out


def _range(lo: np.ndarray, hi: np.ndarray) -> str:
    if len(lo) == 1:
        return f"{float(lo[0]):.4g} .. {float(hi[0]):.4g}"
    return (f"({', '.join(f'{x:.3g}' for x in lo)}) .. "
            f"({', '.join(f'{x:.3g}' for x in hi)})")


def _differs(stats, name: str, off) -> bool:
    """Whether the field is anywhere away from its `off` value."""
    _, lo, hi = stats[name]
    off = np.broadcast_to(np.asarray(off, np.float64), lo.shape)
    return bool(np.any(np.abs(lo - off) > VARYING) or np.any(np.abs(hi - off) > VARYING))


def preview_lobes(stats, mtlx: bool) -> tuple[dict[str, float], list[str]]:
    """The UsdPreviewSurface constants of the lobe fields (input -> value) and the notes:
    a field that varies is given its mean; a lobe UsdPreviewSurface has no input for is left
    to the MaterialX network (or, without one, dropped)."""
    values: dict[str, float] = {}
    notes: list[str] = []
    where = ("the mtlx render context's MaterialX network carries it" if mtlx else
             "dropped (no MaterialX network was written)")
    for name, (inp, _default) in PREVIEW_LOBES.items():
        if name not in stats:
            continue
        mean, lo, hi = stats[name]
        if name == "coatRoughness" and "clearcoat" not in values:
            continue
        values[inp] = round(float(mean[0]), 6)
        if float(hi[0] - lo[0]) > VARYING:
            notes.append(f"{name} varies over the surface ({_range(lo, hi)}); "
                         f"UsdPreviewSurface {inp} gets its mean {values[inp]:.6g}; {where}")
    if "ior" in values:
        values["ior"] = max(1.0, values["ior"])
    if "clearcoat" in values and "clearcoatRoughness" not in values:
        values["clearcoatRoughness"] = 0.0  # ours; UsdPreviewSurface's default is 0.01
    if values.get("clearcoat", 0.0) <= 0.0:
        values.pop("clearcoat", None)
        values.pop("clearcoatRoughness", None)
    for name, off in UNHELD.items():
        if name not in stats:
            continue
        gate = NEEDS.get(name)
        if gate and not (gate in stats and _differs(stats, gate, UNHELD.get(gate, 0.0))):
            continue
        if _differs(stats, name, off):
            notes.append(f"{name} has no UsdPreviewSurface input; {where}")
    return values, notes


# --- building the stage -----------------------------------------------------------------
def _png_bytes(m: BakedMap) -> bytes:
    with tempfile.TemporaryDirectory(prefix="matedit-usd-") as tmp:
        p = Path(tmp) / f"{m.name}.png"
        encode_file(p, m)
        return read_bounded(p, MAX_TEXTURE_BYTES)


def _exr_bytes(arr: np.ndarray) -> bytes:
    with tempfile.TemporaryDirectory(prefix="matedit-usd-") as tmp:
        p = Path(tmp) / "baked.exr"
        encode_file(p, BakedMap("baked", arr, False))
        return read_bounded(p, MAX_TEXTURE_BYTES)


def _mesh(stage, path: str, mesh):
    from pxr import Gf, Sdf, UsdGeom, Vt

    m = UsdGeom.Mesh.Define(stage, path)
    pos = np.asarray(mesh.positions, np.float32)
    nrm = np.asarray(mesh.normals, np.float64)
    nrm = (nrm / np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-20))
    idx = np.asarray(mesh.indices, np.int32).reshape(-1)
    m.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    m.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pos))
    m.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(idx) // 3, 3, np.int32)))
    m.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(idx))
    m.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(nrm.astype(np.float32)))
    m.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    m.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(*map(float, lo)), Gf.Vec3f(*map(float, hi))]))
    st = UsdGeom.PrimvarsAPI(m).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                              UsdGeom.Tokens.vertex)
    st.Set(Vt.Vec2fArray.FromNumpy(np.asarray(mesh.uvs, np.float32)))
    return m


def _preview(stage, material, maps: dict[str, str], srgb: set[str], emissive_max: float,
             lobes: dict[str, float]) -> None:
    """The UsdPreviewSurface network (universal render context) on the baked maps."""
    from pxr import Gf, Sdf, UsdShade

    base = material.GetPath().AppendChild("Preview")
    UsdShade.NodeGraph.Define(stage, base)  # a scope for the preview network's nodes
    surf = UsdShade.Shader.Define(stage, base.AppendChild("PreviewSurface"))
    surf.CreateIdAttr("UsdPreviewSurface")
    reader = UsdShade.Shader.Define(stage, base.AppendChild("stReader"))
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
    st = reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)

    def texture(name: str, scale=None, bias=None):
        t = UsdShade.Shader.Define(stage, base.AppendChild(f"{name}Texture"))
        t.CreateIdAttr("UsdUVTexture")
        t.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(f"./{maps[name]}"))
        t.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(st)
        t.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("repeat")
        t.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("repeat")
        t.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set(
            "sRGB" if name in srgb else "raw")
        if scale is not None:
            t.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(*scale))
        if bias is not None:
            t.CreateInput("bias", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(*bias))
        return t

    def connect(inp: str, t, out: str, ty) -> None:
        src = t.GetOutput(out) or t.CreateOutput(out, ty)
        surf.CreateInput(inp, ty).ConnectToSource(src)

    f3, f1 = Sdf.ValueTypeNames.Float3, Sdf.ValueTypeNames.Float
    surf.CreateInput("useSpecularWorkflow", Sdf.ValueTypeNames.Int).Set(0)
    col = texture("base_color")
    surf.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
        col.CreateOutput("rgb", f3))
    nrm = texture("normal", (2.0, 2.0, 2.0, 1.0), (-1.0, -1.0, -1.0, 0.0))
    surf.CreateInput("normal", Sdf.ValueTypeNames.Normal3f).ConnectToSource(
        nrm.CreateOutput("rgb", f3))
    orm = texture("orm")
    connect("occlusion", orm, "r", f1)
    connect("roughness", orm, "g", f1)
    connect("metallic", orm, "b", f1)
    if "emissive" in maps:
        e = float(emissive_max)
        em = texture("emissive", (e, e, e, 1.0) if e != 1.0 else None)
        surf.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
            em.CreateOutput("rgb", f3))
    if "opacity" in maps:
        connect("opacity", texture("opacity"), "r", f1)
        surf.CreateInput("opacityThreshold", f1).Set(0.0)
    for name, value in sorted(lobes.items()):
        surf.CreateInput(name, f1).Set(float(value))
    out = surf.CreateOutput("surface", Sdf.ValueTypeNames.Token)
    material.CreateSurfaceOutput().ConnectToSource(out)


_MX_SDF = {"float": "Float", "integer": "Int", "boolean": "Bool", "color3": "Color3f",
           "color4": "Color4f", "vector2": "Float2", "vector3": "Float3", "vector4": "Float4",
           "matrix33": "Matrix3d", "matrix44": "Matrix4d", "string": "String",
           "filename": "Asset", "surfaceshader": "Token", "displacementshader": "Token",
           "volumeshader": "Token", "material": "Token"}


def _sdf_type(mxtype: str):
    from pxr import Sdf

    if mxtype not in _MX_SDF:
        raise UsdExportError(f"MaterialX type {mxtype!r} has no USD counterpart")
    return getattr(Sdf.ValueTypeNames, _MX_SDF[mxtype])


def _sdf_value(mxtype: str, value):
    from pxr import Gf, Sdf

    if mxtype == "filename":
        return Sdf.AssetPath(str(value))
    if mxtype in ("float",):
        return float(value)
    if mxtype == "integer":
        return int(value)
    if mxtype == "boolean":
        return bool(value)
    if mxtype == "string":
        return str(value)
    parts = [float(x) for x in value.asTuple()]
    return {"color3": Gf.Vec3f, "color4": Gf.Vec4f, "vector2": Gf.Vec2f,
            "vector3": Gf.Vec3f, "vector4": Gf.Vec4f}[mxtype](*parts)


class _MtlxWriter:
    """A MaterialX document (the export's: top-level surface shader and material, one
    nodegraph) as UsdShade prims under the Material."""

    def __init__(self, stage, material, text: str, files: dict[str, str]) -> None:
        import MaterialX as mx

        from matedit.interop.mtlx_colorspace import stdlib

        self.mx = mx
        self.stage, self.material = stage, material
        self.files = files  # the document's file value -> the name beside the layer
        self.doc = mx.createDocument()
        mx.readFromXmlString(self.doc, text)
        # the document's own elements, not the library's implementation graphs
        self.own_graphs = [g.getName() for g in self.doc.getNodeGraphs()]
        self.own_nodes = [n.getName() for n in self.doc.getNodes()]
        self.doc.importLibrary(stdlib())
        self.prims: dict[tuple[str, str], object] = {}  # (graph, node) -> Shader
        self.graphs: dict[str, object] = {}

    def nodedef(self, node) -> str:
        nd = node.getNodeDef()
        if nd is None:
            raise UsdExportError(f"MaterialX node {node.getName()} ({node.getCategory()}) "
                                 "has no node definition")
        return nd.getName()

    def shader(self, parent, node):
        from pxr import UsdShade

        s = UsdShade.Shader.Define(self.stage, parent.GetPath().AppendChild(node.getName()))
        s.CreateIdAttr(self.nodedef(node))
        nd = node.getNodeDef()
        for out in nd.getActiveOutputs():
            s.CreateOutput(out.getName(), _sdf_type(out.getType()))
        return s

    def value(self, usd_input, mx_input) -> None:
        t = mx_input.getType()
        v = mx_input.getValue()
        if t == "filename":
            v = self.files.get(str(v), str(v))
            usd_input.Set(_sdf_value(t, f"./{v}"))
        else:
            usd_input.Set(_sdf_value(t, v))
        cs = mx_input.getColorSpace()
        if cs:
            usd_input.GetAttr().SetColorSpace(cs)

    @staticmethod
    def connect(dest, source, what: str) -> None:
        if not source:
            raise UsdExportError(f"MaterialX {what}: its source is not in the network")
        dest.ConnectToSource(source)

    def inputs(self, prim, node, graph: str, graph_prim) -> None:
        for inp in node.getInputs():
            u = prim.CreateInput(inp.getName(), _sdf_type(inp.getType()))
            what = f"input {node.getName()}.{inp.getName()}"
            if inp.getInterfaceName():
                self.connect(u, graph_prim.GetInput(inp.getInterfaceName()), what)
            elif inp.getNodeName():
                src = self.prims[(graph, inp.getNodeName())]
                self.connect(u, src.GetOutput(inp.getOutputString() or "out"), what)
            elif inp.getNodeGraphString():
                ng = self.graphs[inp.getNodeGraphString()]
                self.connect(u, ng.GetOutput(inp.getOutputString()), what)
            elif inp.getValueString():
                self.value(u, inp)

    def graph(self, ng) -> None:
        from pxr import UsdShade

        prim = UsdShade.NodeGraph.Define(self.stage,
                                         self.material.GetPath().AppendChild(ng.getName()))
        self.graphs[ng.getName()] = prim
        for inp in ng.getInputs():
            u = prim.CreateInput(inp.getName(), _sdf_type(inp.getType()))
            if inp.getValueString():
                self.value(u, inp)
        nodes = ng.getNodes()
        for node in nodes:  # every node first, then the connections (any order in a graph)
            self.prims[(ng.getName(), node.getName())] = self.shader(prim, node)
        for node in nodes:
            self.inputs(self.prims[(ng.getName(), node.getName())], node, ng.getName(), prim)
        for out in ng.getOutputs():
            o = prim.CreateOutput(out.getName(), _sdf_type(out.getType()))
            src = self.prims[(ng.getName(), out.getNodeName())]
            self.connect(o, src.GetOutput(out.getOutputString() or "out"),
                         f"output {ng.getName()}.{out.getName()}")

    def write(self) -> None:
        for name in self.own_graphs:
            self.graph(self.doc.getNodeGraph(name))
        shaders = [n for n in map(self.doc.getNode, self.own_nodes)
                   if n.getType() == "surfaceshader"]
        if len(shaders) != 1:
            raise UsdExportError(f"the MaterialX export holds {len(shaders)} surface shaders")
        (sh,) = shaders
        s = self.shader(self.material, sh)
        self.inputs(s, sh, "", None)
        self.material.CreateSurfaceOutput("mtlx").ConnectToSource(s.GetOutput("out"))
        self.material.GetPrim().SetCustomDataByKey("config:mtlx:version",
                                                   self.doc.getVersionString())


@dataclass
class MtlxPart:
    """The MaterialX export to carry: its text, its baked images (document file name ->
    pixels) and the copies of the texture files it reads (the name beside the layer, which
    the document's image nodes name, -> the file)."""

    text: str
    images: dict[str, np.ndarray]
    textures: dict[str, Path]


def build(out: Path, maps: list[BakedMap], mesh, name: str, emissive_max: float,
          stats, mtlx: MtlxPart | None, notes=()) -> UsdExport:
    """The asset (see the module notes). `stats`: `lobe_stats`; `mtlx`: the MaterialX
    network to carry, None for the preview network alone; `notes`: earlier notes."""
    from pxr import Sdf, Tf, Usd, UsdGeom, UsdShade

    out = Path(out)
    stem = file_stem(out)
    lobes, lobe_notes = preview_lobes(stats, mtlx is not None)
    side: dict[str, bytes] = {}
    files: dict[str, str] = {}
    srgb = set()
    for m in maps:
        file = f"{stem}_{m.name}.png"
        side[file] = _png_bytes(m)
        files[m.name] = file
        if m.srgb:
            srgb.add(m.name)
    mx_files: dict[str, str] = {}
    if mtlx is not None:
        for doc_name, arr in mtlx.images.items():
            file = Path(doc_name).name  # the export's names start with the stem too
            if file in side:
                raise UsdExportError(f"{out}: two textures would be named {file}")
            side[file] = _exr_bytes(arr)
            mx_files[doc_name] = file
        for file, src in sorted(mtlx.textures.items()):
            if file in side:
                raise UsdExportError(f"{out}: two textures would be named {file}")
            try:
                side[file] = read_bounded(src, MAX_TEXTURE_BYTES)
            except OSError as exc:
                raise UsdExportError(f"{src}: cannot copy the texture into the asset: "
                                     f"{exc.strerror or exc}") from None

    layer = Sdf.Layer.CreateAnonymous(".usda")
    stage = Usd.Stage.Open(layer)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/Root")
    stage.SetDefaultPrim(root.GetPrim())
    prim_name = Tf.MakeValidIdentifier(re.sub(r"[^A-Za-z0-9_]", "_", name) or "material")
    mesh_prim = _mesh(stage, f"/Root/{prim_name}", mesh)
    UsdGeom.Scope.Define(stage, "/Root/Materials")
    material = UsdShade.Material.Define(stage, f"/Root/Materials/{prim_name}")
    _preview(stage, material, files, srgb, emissive_max, lobes)
    if mtlx is not None:
        _MtlxWriter(stage, material, mtlx.text, mx_files).write()
    binding = UsdShade.MaterialBindingAPI.Apply(mesh_prim.GetPrim())
    binding.Bind(material)
    text = layer.ExportToString()
    all_notes = list(notes) + lobe_notes
    if out.suffix.lower() == ".usdz":
        return UsdExport(out, _package(stem, layer, side), {}, all_notes)
    return UsdExport(out, text.encode("utf-8"), side, all_notes)


def export_baked(doc, resolver, attrs: dict[str, np.ndarray], ir, mesh, out: Path,
                 size: int, arkit: bool = False) -> UsdExport:
    """The asset of `doc` from its bake (`bake.bake_attributes`: the attributes and the
    optimised IR) on `mesh`: the MaterialX export (of the lowered document, its baked nodes
    `size` texels wide) carried where it can be written, else a note says why not. With
    `arkit` (a .usdz for AR Quick Look and other viewers of Apple's usdz profile), the
    preview network alone: that profile allows no other shader and no EXR file, and a note
    says so. Raises CompileError, UsdExportError."""
    from matedit.compiler.lower import lower_document
    from matedit.interop import mtlx_export
    from matedit.interop.bake import maps_from
    from matedit.interop.export import stem_of

    attrs = dict(attrs)
    emax = float(max(1.0, np.max(attrs["emissive"])))
    attrs["emissive"] = attrs["emissive"] / emax
    maps = maps_from(attrs, ir.attributes, "png")
    lowered = lower_document(doc, resolver)
    notes: list[str] = []
    mtlx = None
    if arkit:
        notes.append("ARKit profile: UsdPreviewSurface on the baked PNG maps only (no "
                     "MaterialX network: the profile allows no other shader)")
        return build(out, maps, mesh, stem_of(doc), emax, lobe_stats(ir), None, notes)
    try:
        copies = texture_copies(lowered, out)
        mx = mtlx_export.export_ir(  # its bakes as EXR beside the layer, like the copies
            lowered, out, size, file_stem(out), "standard_surface", "exr",
            texture_files={name: file for name, (file, _) in copies.items()}, side="")
        mtlx = MtlxPart(mx.text, {p.name: a.pixels for p, a in mx.images.items()},
                        dict(copies.values()))
        notes += [f"node {node}: baked to an image for the MaterialX network ({why})"
                  for node, why in mx.baked]
    except mtlx_export.MtlxExportError as exc:
        notes.append(f"no MaterialX network (the mtlx render context): {exc}")
    return build(out, maps, mesh, stem_of(doc), emax, lobe_stats(ir), mtlx, notes)


def _package(stem: str, layer, side: dict[str, bytes]) -> bytes:
    """The .usdz package: the layer as usdc (the root, first), then the textures."""
    from pxr import Sdf, UsdUtils

    with tempfile.TemporaryDirectory(prefix="matedit-usdz-") as tmp:
        folder = Path(tmp)
        root = folder / f"{stem}.usdc"
        crate = Sdf.Layer.CreateNew(str(root))
        crate.TransferContent(layer)
        crate.Save()
        for file, data in side.items():
            atomic_write_bytes(folder / file, data)
        package = folder / f"{stem}.usdz"
        if not UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(root)), str(package)):
            raise UsdExportError(f"{stem}.usdz: usd-core could not create the package")
        return read_bounded(package, 4 * MAX_TEXTURE_BYTES)


def write(result: UsdExport) -> None:
    """The layer and the textures beside it, together or not at all (the layer last)."""
    if not result.side:
        atomic_write_bytes(result.out, result.layer)
        return
    with staged_outputs(result.out.parent) as stage:
        for file, data in result.side.items():
            stage.write_bytes(result.out.parent / file, data)
        stage.write_bytes(result.out, result.layer)


def texture_copies(ir, out: Path) -> dict[str, tuple[str, Path]]:
    """texture name -> (the name of its copy beside the layer, the file) for every texture
    of `ir` with a file: the MaterialX network reads the copies (the asset names no folder
    of this machine, and a name in any encoding becomes a portable one)."""
    stem = file_stem(out)
    out_map = {}
    for k, t in enumerate(sorted((t for t in ir.textures if t.path), key=lambda t: t.name)):
        suffix = re.sub(r"[^A-Za-z0-9.]", "_", Path(t.path).suffix.lower())
        out_map[t.name] = (f"{stem}_texture{k}{suffix}", Path(t.path))
    return out_map
