"""Reading a glTF asset's material back as a matedit material on its own maps: the glTF
round trip of `matedit export --check` (matedit.commands.export_check).

The asset's first material: its base colour (and alpha), metallic-roughness (and occlusion,
our cavity), normal and emissive images are taken out of its buffer into a work folder and
read by graphs/interop/gltf_metallic_roughness.json, with the material's factors and
emissive strength; the KHR_materials_* factors matedit's exporter writes become the constant
lobe fields they came from (`LOBE_EXTENSIONS`, the inverse of
matedit.interop.gltf.lobe_extensions). A missing texture reads as a 1 x 1 neutral one."""

from __future__ import annotations

from pathlib import Path

import numpy as np

TEMPLATE = ("interop", "gltf_metallic_roughness.json")


class GltfReadbackError(ValueError):
    """The asset cannot be read back (the message names the file)."""


def _flat_png(path: Path, rgb) -> None:
    import OpenImageIO as oiio

    from matedit.io.images import write_oiio

    px = np.full((1, 1, 3), np.rint(np.asarray(rgb) * 255), np.uint8)
    write_oiio(path, oiio.ImageSpec(1, 1, 3, "uint8"), px)


def filled_template(paths: dict[str, str], values: dict, lobes: dict, opaque: bool,
                    work: Path):
    """The TEMPLATE material reading the images `paths` (texture parameter name -> file),
    with its parameters set to `values` and its MaterialAttributes node's lobe fields to
    `lobes`; `opaque`: its opacity input unwired. Named as if saved in `work`."""
    from matedit.graph.nodes import Role, role_of
    from matedit.io.document import load
    from matedit.resources import graphs_dir

    doc = load(graphs_dir().joinpath(*TEMPLATE))
    for n in doc.graph.nodes.values():
        name = n.settings.get("name")
        if role_of(n.kind) == Role.TEXTURE_PARAMETER and name in paths:
            n.settings["path"] = paths[name]
        elif role_of(n.kind) == Role.MAKE_ATTRIBUTES:
            n.values.update(lobes)
        elif name in values:
            n.values["value"] = values[name]
    if opaque:
        doc.graph.links = {lk for lk in doc.graph.links if lk.dst_port != "opacity"}
    doc.path = work / "roundtrip.json"
    return doc


def read_material(out: Path, work: Path):
    """(the material document, its notes) of the asset `out`, its images written into the
    folder `work` (module notes); raises GltfReadbackError."""
    import pygltflib

    from matedit.io.atomic import atomic_write_bytes

    try:
        g = pygltflib.GLTF2().load(str(out))
    except Exception as exc:  # pygltflib raises what its parsers raise
        raise GltfReadbackError(f"{out}: cannot read the export back: {exc}") from None
    if not g.materials:
        raise GltfReadbackError(f"{out}: the asset has no material")
    mat = g.materials[0]
    blob = g.binary_blob() if out.suffix.lower() == ".glb" else None
    if blob is None and g.buffers and g.buffers[0].uri:
        import os
        import urllib.parse

        from matedit.io.atomic import read_bounded

        uri = g.buffers[0].uri  # percent-encoded bytes of the file name (gltf.buffer_uri)
        if uri.startswith("data:") or "/" in uri:
            raise GltfReadbackError(f"{out}: its buffer is not a file beside it")
        try:
            blob = read_bounded(out.parent / os.fsdecode(urllib.parse.unquote_to_bytes(uri)),
                                1 << 31)
        except OSError as exc:
            raise GltfReadbackError(f"{out}: cannot read its buffer: "
                             f"{exc.strerror or exc}") from None

    def image(info, name: str, default) -> str:
        path = work / f"{name}.png"
        if info is None:
            _flat_png(path, default)
            return str(path)
        img = g.images[g.textures[info.index].source]
        if img.bufferView is None or blob is None:
            raise GltfReadbackError(f"{out}: image {info.index} is not in the asset's buffer")
        view = g.bufferViews[img.bufferView]
        start = view.byteOffset or 0
        atomic_write_bytes(path, blob[start:start + view.byteLength])
        return str(path)

    pbr = mat.pbrMetallicRoughness or pygltflib.PbrMetallicRoughness()
    paths = {
        "base_color_texture": image(pbr.baseColorTexture, "base_color", (1.0, 1.0, 1.0)),
        "metallic_roughness_texture": image(pbr.metallicRoughnessTexture, "mr",
                                            (1.0, 1.0, 1.0)),
        "normal_texture": image(mat.normalTexture, "normal", (0.5, 0.5, 1.0)),
        "emissive_texture": image(mat.emissiveTexture, "emissive", (1.0, 1.0, 1.0)),
    }
    strength = ((mat.extensions or {}).get("KHR_materials_emissive_strength") or {}).get(
        "emissiveStrength", 1.0)
    values = {
        "base_color_factor": list((pbr.baseColorFactor or [1, 1, 1, 1])[:3]),
        "metallic_factor": 1.0 if pbr.metallicFactor is None else pbr.metallicFactor,
        "roughness_factor": 1.0 if pbr.roughnessFactor is None else pbr.roughnessFactor,
        "emissive_factor": list(mat.emissiveFactor or [0.0, 0.0, 0.0]),
        "emissive_strength": float(strength),
    }
    # the template reads opacity from the alpha
    doc = filled_template(paths, values, lobe_fields(mat.extensions or {}),
                          opaque=mat.alphaMode in (None, "OPAQUE"), work=work)
    unread = sorted(set(mat.extensions or {}) - set(LOBE_EXTENSIONS)
                    - {"KHR_materials_emissive_strength"})
    notes = []
    if unread:
        notes.append(f"round trip import: {', '.join(unread)} not read back")
    return doc, notes


# glTF extension -> (its factor, the MaterialAttributes field it came from): the inverse of
# matedit.interop.gltf.lobe_extensions for the factors it writes
LOBE_EXTENSIONS: dict[str, tuple[tuple[str, str], ...]] = {
    "KHR_materials_ior": (("ior", "ior"),),
    "KHR_materials_specular": (("specularColorFactor", "specularColor"),),
    "KHR_materials_clearcoat": (("clearcoatFactor", "coat"),
                                ("clearcoatRoughnessFactor", "coatRoughness")),
    "KHR_materials_sheen": (("sheenColorFactor", "sheenColor"),
                            ("sheenRoughnessFactor", "sheenRoughness")),
    "KHR_materials_anisotropy": (("anisotropyStrength", "anisotropy"),),
    "KHR_materials_transmission": (("transmissionFactor", "transmission"),),
    "KHR_materials_volume": (("thicknessFactor", "thickness"),
                             ("attenuationDistance", "attenuationDistance"),
                             ("attenuationColor", "attenuationColor")),
    "KHR_materials_iridescence": (("iridescenceThicknessMaximum", "thinFilmThickness"),
                                  ("iridescenceIor", "thinFilmIor")),
}


def lobe_fields(extensions: dict) -> dict:
    """MaterialAttributes field -> constant value from the material's KHR_materials_*
    extensions (LOBE_EXTENSIONS; the anisotropy's rotation as a direction in the tangent
    plane)."""
    import math

    out: dict = {}
    for ext, pairs in LOBE_EXTENSIONS.items():
        data = extensions.get(ext)
        if not isinstance(data, dict):
            continue
        for key, field in pairs:
            v = data.get(key)
            if isinstance(v, (int, float)) and math.isfinite(v):
                out[field] = float(v)
            elif isinstance(v, list) and len(v) == 3 and all(
                    isinstance(x, (int, float)) and math.isfinite(x) for x in v):
                out[field] = [float(x) for x in v]
        if ext == "KHR_materials_anisotropy" and isinstance(
                data.get("anisotropyRotation"), (int, float)):
            a = float(data["anisotropyRotation"])
            out["anisotropyDirection"] = [math.cos(a), math.sin(a), 0.0]
    return out


