"""Reading a USD export's UsdPreviewSurface back as a matedit material: the USD round trip
of `matedit export --check` (matedit.commands.export_check).

What most USD viewers draw is the material's universal surface, the UsdPreviewSurface
network on the baked maps: that is what is read back. Its diffuse colour, ORM (occlusion,
roughness and metallic in R, G and B, as the glTF export packs them) and normal textures
and its emissive texture with its scale become the texture parameters and factors of
graphs/interop/gltf_metallic_roughness.json (the glTF round trip's template); its clearcoat,
clearcoatRoughness and ior constants become the lobe fields they came from
(matedit.interop.usd.PREVIEW_LOBES). The textures are taken from beside a .usda or out of
a .usdz into a work folder; a texture input the network does not connect reads as a 1 x 1
neutral image. The MaterialX network of the mtlx render context is not read back, nor a
separate opacity map (notes say so), so their loss shows in the figure."""

from __future__ import annotations

import zipfile
from pathlib import Path

MAX_TEXTURE_BYTES = 1 << 30


class UsdReadbackError(ValueError):
    """The asset cannot be read back (the message names the file)."""


def _surface(out: Path):
    """The stage and the UsdPreviewSurface bound to its first mesh."""
    from pxr import Usd, UsdGeom, UsdShade

    stage = Usd.Stage.Open(str(out))
    if stage is None:
        raise UsdReadbackError(f"{out}: usd-core cannot open it")
    meshes = [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    if not meshes:
        raise UsdReadbackError(f"{out}: the stage has no mesh")
    material, _ = UsdShade.MaterialBindingAPI(meshes[0]).ComputeBoundMaterial()
    if not material:
        raise UsdReadbackError(f"{out}: the mesh {meshes[0].GetPath()} has no material bound")
    shader, _, _ = material.ComputeSurfaceSource()
    if not shader or shader.GetIdAttr().Get() != "UsdPreviewSurface":
        raise UsdReadbackError(f"{out}: material {material.GetPath()} has no "
                               "UsdPreviewSurface")
    return stage, shader


def _texture_of(inp):
    """The UsdUVTexture shader connected to `inp` (None if it holds a value)."""
    from pxr import UsdShade

    if not inp or not inp.HasConnectedSource():  # an input not authored is not valid
        return None
    (info, *_rest) = inp.GetConnectedSources()[0]
    shader = UsdShade.Shader(info.source.GetPrim())
    return shader if shader.GetIdAttr().Get() == "UsdUVTexture" else None


def _texture_bytes(out: Path, asset) -> bytes:
    """The bytes of the texture file `asset` (an Sdf.AssetPath) names: inside the .usdz, or
    beside the .usda (a relative name without folders, as matedit's export writes)."""
    from matedit.io.atomic import read_bounded

    name = asset.path[2:] if asset.path.startswith("./") else asset.path
    if not name or "/" in name or "\\" in name or name.startswith("."):
        raise UsdReadbackError(f"{out}: texture {asset.path!r} is not a file beside the layer")
    if out.suffix.lower() == ".usdz":
        try:
            with zipfile.ZipFile(out) as z:
                info = z.getinfo(name)
                if info.file_size > MAX_TEXTURE_BYTES:
                    raise UsdReadbackError(f"{out}: texture {name} is too large")
                return z.read(info)
        except KeyError:
            raise UsdReadbackError(f"{out}: the package holds no {name}") from None
        except (OSError, zipfile.BadZipFile) as exc:
            raise UsdReadbackError(f"{out}: cannot read the package: {exc}") from None
    try:
        return read_bounded(out.parent / name, MAX_TEXTURE_BYTES)
    except OSError as exc:
        raise UsdReadbackError(f"{out.parent / name}: cannot read the texture: "
                               f"{exc.strerror or exc}") from None


def read_material(out: Path, work: Path):
    """(the material document, its notes) of the USD asset `out`, its textures written into
    the folder `work` (module notes); raises UsdReadbackError."""
    from matedit.interop.gltf_readback import _flat_png, filled_template
    from matedit.interop.usd import PREVIEW_LOBES
    from matedit.io.atomic import atomic_write_bytes

    out = Path(out)
    _stage, surf = _surface(out)  # the stage owns the shader's prim: keep it alive

    def image(inputs: tuple[str, ...], name: str, default) -> tuple[str, object]:
        path = work / f"{name}.png"
        for inp in inputs:
            tex = _texture_of(surf.GetInput(inp))
            if tex is not None:
                atomic_write_bytes(path, _texture_bytes(out, tex.GetInput("file").Get()))
                return str(path), tex
        _flat_png(path, default)
        return str(path), None

    base, _ = image(("diffuseColor",), "base_color", (1.0, 1.0, 1.0))
    orm, _ = image(("roughness", "metallic", "occlusion"), "orm", (1.0, 1.0, 1.0))
    normal, _ = image(("normal",), "normal", (0.5, 0.5, 1.0))
    emissive, em_tex = image(("emissiveColor",), "emissive", (1.0, 1.0, 1.0))
    strength, em_factor = 1.0, [0.0, 0.0, 0.0]
    if em_tex is not None:
        em_factor = [1.0, 1.0, 1.0]
        scale = em_tex.GetInput("scale")
        if scale and scale.Get() is not None:
            strength = float(scale.Get()[0])
    elif surf.GetInput("emissiveColor") and surf.GetInput("emissiveColor").Get() is not None:
        em_factor = [float(x) for x in surf.GetInput("emissiveColor").Get()]
    paths = {"base_color_texture": base, "metallic_roughness_texture": orm,
             "normal_texture": normal, "emissive_texture": emissive}
    values = {"base_color_factor": [1.0, 1.0, 1.0], "metallic_factor": 1.0,
              "roughness_factor": 1.0, "emissive_factor": em_factor,
              "emissive_strength": strength}
    lobes = {}
    for field, (inp, _default) in PREVIEW_LOBES.items():
        i = surf.GetInput(inp)
        if i and i.Get() is not None:
            lobes[field] = float(i.Get())
    # the template reads opacity from the base colour's alpha; the preview's opacity is a
    # map of its own, not read back
    doc = filled_template(paths, values, lobes, opaque=True, work=work)
    notes = ["round trip import: the UsdPreviewSurface network (what USD viewers draw); "
             "the MaterialX network is not read back"]
    if _texture_of(surf.GetInput("opacity")) is not None:
        notes.append("round trip import: the opacity map is not read back")
    return doc, notes
