"""A glTF 2.0 asset of a material: the preview mesh (with tangents) and a metallic-roughness
material on the baked maps (matedit.interop.bake), built with pygltflib.

.glb holds everything in one file; .gltf is the JSON plus OUT.bin beside it (the images are
buffer views of OUT.bin, so no other file is written). Texture coordinates are flipped to
glTF's convention (v = 0 at the top of the image); the tangents and the normal map keep
matedit's (+Y up, bitangent = cross(normal, tangent) * w), which is glTF's.
"""

from __future__ import annotations

import os
import tempfile
import urllib.parse
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pygltflib as g

from matedit.interop.bake import BakedMap, encode_file
from matedit.io.atomic import atomic_write_bytes, read_bounded, staged_outputs


def _png_bytes(m: BakedMap) -> bytes:
    with tempfile.TemporaryDirectory(prefix="matedit-gltf-") as tmp:
        p = Path(tmp) / f"{m.name}.png"
        encode_file(p, m)
        return read_bounded(p, 1 << 30)


class _Blob:
    def __init__(self) -> None:
        self.data = bytearray()
        self.views: list[g.BufferView] = []

    def add(self, raw: bytes, target: int | None = None, stride: int | None = None) -> int:
        while len(self.data) % 4:
            self.data.append(0)
        self.views.append(g.BufferView(buffer=0, byteOffset=len(self.data),
                                       byteLength=len(raw), target=target, byteStride=stride))
        self.data += raw
        return len(self.views) - 1


def build(maps: list[BakedMap], mesh, name: str, emissive_max: float = 1.0,
          lobes: LobeExport | None = None) -> tuple[g.GLTF2, bytes]:
    """The glTF document (without its buffer's uri) and its binary buffer; `lobes`: the
    KHR_materials_* extensions of the lobe fields (`lobe_extensions`)."""
    by = {m.name: m for m in maps}
    blob = _Blob()
    accessors: list[g.Accessor] = []

    def accessor(arr: np.ndarray, kind: str, ctype: int, target: int, bounds=False) -> int:
        raw = np.ascontiguousarray(arr).tobytes()
        view = blob.add(raw, target)
        acc = g.Accessor(bufferView=view, componentType=ctype, count=len(arr), type=kind)
        if bounds:
            acc.min = [float(x) for x in arr.min(axis=0)]
            acc.max = [float(x) for x in arr.max(axis=0)]
        accessors.append(acc)
        return len(accessors) - 1

    pos = np.asarray(mesh.positions, np.float32)
    nrm = np.asarray(mesh.normals, np.float64)
    nrm = (nrm / np.linalg.norm(nrm, axis=1, keepdims=True)).astype(np.float32)
    tan = np.asarray(mesh.tangents, np.float64)
    t3 = tan[:, :3] / np.linalg.norm(tan[:, :3], axis=1, keepdims=True)
    tan = np.concatenate([t3, np.where(tan[:, 3:] < 0, -1.0, 1.0)], 1).astype(np.float32)
    uv = np.asarray(mesh.uvs, np.float32).copy()
    uv[:, 1] = 1.0 - uv[:, 1]
    idx = np.asarray(mesh.indices, np.uint32).reshape(-1)
    attrs = g.Attributes(
        POSITION=accessor(pos, g.VEC3, g.FLOAT, g.ARRAY_BUFFER, bounds=True),
        NORMAL=accessor(nrm, g.VEC3, g.FLOAT, g.ARRAY_BUFFER),
        TANGENT=accessor(tan, g.VEC4, g.FLOAT, g.ARRAY_BUFFER),
        TEXCOORD_0=accessor(uv, g.VEC2, g.FLOAT, g.ARRAY_BUFFER))
    indices = accessor(idx, g.SCALAR, g.UNSIGNED_INT, g.ELEMENT_ARRAY_BUFFER)

    images: list[g.Image] = []
    textures: list[g.Texture] = []

    def texture(m: BakedMap) -> int:
        images.append(g.Image(bufferView=blob.add(_png_bytes(m)), mimeType="image/png",
                              name=m.name))
        textures.append(g.Texture(sampler=0, source=len(images) - 1))
        return len(textures) - 1

    base = by["base_color"]
    alpha = "opacity" in by
    if alpha:  # glTF keeps coverage in the base colour's alpha
        base = BakedMap("base_color", np.concatenate([base.pixels, by["opacity"].pixels], -1),
                        True)
    orm = texture(by["orm"])
    mat = g.Material(
        name=name,
        pbrMetallicRoughness=g.PbrMetallicRoughness(
            baseColorTexture=g.TextureInfo(index=texture(base)),
            metallicRoughnessTexture=g.TextureInfo(index=orm),
            metallicFactor=1.0, roughnessFactor=1.0),
        normalTexture=g.NormalMaterialTexture(index=texture(by["normal"])),
        occlusionTexture=g.OcclusionTextureInfo(index=orm),
        alphaMode=g.BLEND if alpha else g.OPAQUE,
        doubleSided=False,
    )
    extensions = []
    if "emissive" in by:
        mat.emissiveTexture = g.TextureInfo(index=texture(by["emissive"]))
        mat.emissiveFactor = [1.0, 1.0, 1.0]
        if emissive_max > 1.0:
            mat.extensions = {"KHR_materials_emissive_strength":
                              {"emissiveStrength": float(emissive_max)}}
            extensions.append("KHR_materials_emissive_strength")
    if lobes is not None and lobes.extensions:
        mat.extensions = {**(mat.extensions or {}), **lobes.extensions}
        extensions += sorted(lobes.extensions)
    doc = g.GLTF2(
        asset=g.Asset(version="2.0", generator="matedit"),
        scene=0, scenes=[g.Scene(nodes=[0])],
        nodes=[g.Node(mesh=0, name=name)],
        meshes=[g.Mesh(name=name, primitives=[g.Primitive(attributes=attrs, indices=indices,
                                                           material=0, mode=g.TRIANGLES)])],
        materials=[mat], textures=textures, images=images,
        samplers=[g.Sampler(magFilter=g.LINEAR, minFilter=g.LINEAR_MIPMAP_LINEAR,
                            wrapS=g.REPEAT, wrapT=g.REPEAT)],
        accessors=accessors, bufferViews=blob.views,
        extensionsUsed=extensions,
    )
    return doc, bytes(blob.data)


def files_for(out: Path, maps: list[BakedMap], mesh, name: str,
              emissive_max: float = 1.0, lobes: LobeExport | None = None) -> dict[Path, bytes]:
    """Output path -> bytes for OUT.glb, or OUT.gltf and OUT.bin."""
    doc, data = build(maps, mesh, name, emissive_max, lobes)
    if out.suffix.lower() == ".glb":
        doc.buffers = [g.Buffer(byteLength=len(data))]
        doc.set_binary_blob(data)
        return {out: b"".join(doc.save_to_bytes())}
    bin_path = out.with_suffix(".bin")
    doc.buffers = [g.Buffer(uri=buffer_uri(bin_path), byteLength=len(data))]
    return {out: doc.gltf_to_json().encode("utf-8"), bin_path: data}


def buffer_uri(path: Path) -> str:
    """The relative URI of a file beside the .gltf: its name's bytes percent-encoded (RFC
    3986), so spaces, '#', '%' and non-UTF-8 bytes reach a reader as the same name."""
    return urllib.parse.quote(os.fsencode(path.name), safe="")


def write(files: dict[Path, bytes]) -> None:
    """Write the asset: OUT.glb alone, or OUT.bin and OUT.gltf together or not at all (the
    .gltf moved into place last), so a new .gltf never sits beside an old .bin."""
    if len(files) == 1:
        ((p, data),) = files.items()
        atomic_write_bytes(p, data)
        return
    order = sorted(files, key=lambda p: p.suffix.lower() == ".gltf")
    with staged_outputs(order[0].parent) as stage:
        for p in order:
            stage.write_bytes(p, files[p])


# --- the lobes beyond the talk's fields: KHR_materials_* factors ---------------------------
VARYING = 1e-4  # a field whose values spread wider than this over the bake is "varying"


@dataclass(frozen=True)
class LobeExport:
    """The KHR_materials_* extensions of a material's lobe fields, and what could not be
    said exactly (`notes`, one line each, for the command line's `note:` lines)."""

    extensions: dict[str, dict]
    notes: tuple[str, ...]


def _stats(values: dict[str, np.ndarray], name: str) -> tuple[np.ndarray, np.ndarray,
                                                              np.ndarray]:
    v = np.asarray(values[name], np.float64).reshape(-1, np.asarray(values[name]).shape[-1])
    return v.mean(axis=0), v.min(axis=0), v.max(axis=0)


def _default(name: str) -> float:
    from matedit.nodes.material import ATTRIBUTE_FIELDS

    return float(next(f.default for f in ATTRIBUTE_FIELDS if f.name == name))


def lobe_extensions(values: dict[str, np.ndarray], written, thin_walled: bool) -> LobeExport:
    """The lobe fields the material writes (`written`), evaluated over the bake surface
    (`values`: field -> (..., k)), as glTF extension factors. A field that varies over the
    surface is exported as its mean, with a note naming its range (no lobe map is baked)."""
    ext: dict[str, dict] = {}
    notes: list[str] = []
    written = set(written)

    seen: dict[str, list[float] | float] = {}

    def factor(name: str) -> list[float] | float:  # noted once however often asked
        if name in seen:
            return seen[name]
        mean, lo, hi = _stats(values, name)
        if np.max(hi - lo) > VARYING:
            rng = (f"{float(lo[0]):.4g} .. {float(hi[0]):.4g}" if len(lo) == 1 else
                   f"({', '.join(f'{x:.3g}' for x in lo)}) .. "
                   f"({', '.join(f'{x:.3g}' for x in hi)})")
            notes.append(f"{name} varies over the surface ({rng}); glTF gets its mean "
                         f"(no {name} map is baked)")
        out = [round(float(x), 6) for x in mean]
        seen[name] = out[0] if len(out) == 1 else out
        return seen[name]

    def scalar(name: str) -> float:
        v = factor(name)
        return float(v[0] if isinstance(v, list) else v)

    def vector(name: str) -> list[float]:
        v = factor(name)
        return v if isinstance(v, list) else [v]

    def has(name: str) -> bool:
        return name in written and name in values

    if has("ior") and factor("ior") != 1.5:
        ext["KHR_materials_ior"] = {"ior": max(1.0, scalar("ior"))}
    if has("specularColor"):
        color = factor("specularColor")
        if color != [1.0, 1.0, 1.0]:
            ext["KHR_materials_specular"] = {"specularFactor": 1.0,
                                             "specularColorFactor": color}
    if has("coat") and scalar("coat") > 0.0:
        cc = {"clearcoatFactor": factor("coat")}
        if has("coatRoughness"):
            cc["clearcoatRoughnessFactor"] = factor("coatRoughness")
        ext["KHR_materials_clearcoat"] = cc
        if has("coatColor") and factor("coatColor") != [1.0, 1.0, 1.0]:
            notes.append("coatColor (the coat's tint) has no glTF counterpart "
                         "(KHR_materials_clearcoat is untinted); dropped")
        if has("coatIor") and factor("coatIor") != 1.5:
            notes.append("coatIor has no glTF counterpart (KHR_materials_clearcoat is 1.5); "
                         "dropped")
        if has("coatNormal"):
            notes.append("coatNormal is not baked (no clearcoatNormalTexture); the coat "
                         "takes the geometric normal")
    if has("sheenColor"):
        color = factor("sheenColor")
        if color != [0.0, 0.0, 0.0]:
            sh = {"sheenColorFactor": color}
            if has("sheenRoughness"):
                sh["sheenRoughnessFactor"] = factor("sheenRoughness")
            ext["KHR_materials_sheen"] = sh
    if has("anisotropy") and scalar("anisotropy") > 0.0:
        an: dict = {"anisotropyStrength": factor("anisotropy")}
        if has("anisotropyDirection"):
            d = vector("anisotropyDirection")
            an["anisotropyRotation"] = round(float(np.arctan2(d[1], d[0])), 6)
        ext["KHR_materials_anisotropy"] = an
        notes.append("anisotropy: glTF stretches the roughness by its own rule "
                     "(alpha_t = mix(alpha, 1, strength^2)), not matedit's (docs/shading.md); "
                     "the highlight's length differs")
    if has("transmission") and scalar("transmission") > 0.0:
        ext["KHR_materials_transmission"] = {"transmissionFactor": factor("transmission")}
        if has("transmissionColor") and factor("transmissionColor") != [1.0, 1.0, 1.0]:
            notes.append("transmissionColor: glTF tints transmitted light by the base colour; "
                         "the separate tint is dropped")
        if not thin_walled:
            vol: dict = {"thicknessFactor": factor("thickness") if "thickness" in values
                         else _default("thickness")}
            if has("attenuationDistance") and scalar("attenuationDistance") > 0.0:
                vol["attenuationDistance"] = factor("attenuationDistance")
                if has("attenuationColor"):
                    vol["attenuationColor"] = factor("attenuationColor")
            ext["KHR_materials_volume"] = vol
    if has("thinFilmThickness"):
        mean, lo, hi = _stats(values, "thinFilmThickness")
        if float(hi[0]) > 0.0:
            # without a thickness texture glTF's film is iridescenceThicknessMaximum thick
            ir = {"iridescenceFactor": 1.0,
                  "iridescenceThicknessMaximum": round(float(mean[0]), 3)}
            if has("thinFilmIor"):
                ir["iridescenceIor"] = factor("thinFilmIor")
            if float(hi[0] - lo[0]) > VARYING:
                notes.append(f"thinFilmThickness varies over the surface ({float(lo[0]):.4g} "
                             f".. {float(hi[0]):.4g} nm); glTF gets its mean "
                             f"{float(mean[0]):.4g} nm (no iridescence thickness map)")
            ext["KHR_materials_iridescence"] = ir
    if has("subsurface") and float(_stats(values, "subsurface")[2][0]) > 0.0:
        notes.append("subsurface has no ratified glTF extension; dropped (the base colour "
                     "keeps the diffuse)")
    return LobeExport(ext, tuple(notes))


LOBE_SIZE = 32  # the bake surface's side for the lobe fields' mean and range


def lobes_of(ir) -> LobeExport:
    """`lobe_extensions` of an optimised IR: its lobe fields evaluated by the CPU twin over
    a LOBE_SIZE² bake surface (the factors are means, so a small surface is enough)."""
    from matedit.compiler.lower import THIN_WALLED_DEFINE
    from matedit.interop.bake import attributes_cpu
    from matedit.nodes.material import ATTRIBUTE_FIELDS

    lobe_fields = {f.name for f in ATTRIBUTE_FIELDS if f.lobe}
    if not lobe_fields & set(ir.attributes):
        return LobeExport({}, ())
    values = attributes_cpu(ir, LOBE_SIZE)
    return lobe_extensions(values, ir.attributes, THIN_WALLED_DEFINE in ir.defines)
