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


def build(maps: list[BakedMap], mesh, name: str, emissive_max: float = 1.0) -> tuple[g.GLTF2,
                                                                                    bytes]:
    """The glTF document (without its buffer's uri) and its binary buffer."""
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
              emissive_max: float = 1.0) -> dict[Path, bytes]:
    """Output path -> bytes for OUT.glb, or OUT.gltf and OUT.bin."""
    doc, data = build(maps, mesh, name, emissive_max)
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
