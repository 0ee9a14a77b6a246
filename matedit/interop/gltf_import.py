"""A glTF 2.0 asset's materials as matedit materials: `matedit import FILE.gltf|glb -o OUT`.

Each glTF material becomes a material document: a Make Attributes node fed by constants (the
factors) and by Texture Parameter / Texture Sample nodes for its textures (factor x texture,
glTF's rule), built with the MaterialX importer's graph helpers (mtlx_import's `_Importer`:
node ids through the identifier rule, links, warnings) and laid out in columns by their
distance from the output (`layout`). The core metallic-roughness model and the
KHR_materials_ior, _specular, _clearcoat, _sheen, _anisotropy, _transmission, _volume,
_iridescence and _emissive_strength extensions are read (docs/gltf-usd.md, glTF import);
KHR_texture_transform becomes Tiling and Offset / Rotate UV nodes in glTF's UV convention.

Images the asset embeds (a buffer view of the .glb's or a .bin's buffer, or a data: URI)
are extracted to files next to the output, named after it (`embedded_name`); an image the
.gltf names by a relative URI stays where it is and is referred to from the output's folder.
An absolute URI, one with a scheme, or one that leaves the asset's folder is an error.

Nothing is dropped silently: every property the material sets (not at glTF's default) that
is not represented exactly (dropped, approximated, clamped) is a warning naming the file,
material, property and value. The file is untrusted: it is read bounded, every number is
checked (finite, float32), names become node ids only through the identifier rule, and
buffer ranges, image sizes and counts are checked before anything is written.
"""

from __future__ import annotations

import base64
import binascii
import json
import math
import os
import struct
import urllib.parse
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pygltflib as g

from matedit.graph.model import MaterialDocument
from matedit.graph.names import identifier_problem, mangle
from matedit.graph.nodes import THIN_WALLED, Role, kind_for
from matedit.graph.numbers import gpu_number_problem
from matedit.interop import mtlx_map
from matedit.interop.mtlx_import import Src, _Importer, file_stem, output_paths
from matedit.io.atomic import read_bounded

MAX_GLTF_BYTES = 256 << 20  # the .gltf or .glb, and each .bin it names
MAX_IMAGE_BYTES = 64 << 20
MAX_IMAGE_SIDE = 16384
MAX_MATERIALS = 1000
MAX_TEXTURES = 4096
SHEEN_MIN_ROUGHNESS = 0.3  # where our sheen clamps its roughness (docs/shading.md, Sheen)

_kind = mtlx_map.kind_mapped_to
_ARITH = mtlx_map.arithmetic()
# The samplers the renderer uses for every texture (matedit/render/textures.py).
_SUPPORTED_SAMPLER = {"magFilter": (None, g.LINEAR),
                      "minFilter": (None, g.LINEAR_MIPMAP_LINEAR),
                      "wrapS": (None, g.REPEAT), "wrapT": (None, g.REPEAT)}
_GL_NAMES = {g.NEAREST: "NEAREST", g.LINEAR: "LINEAR", g.NEAREST_MIPMAP_NEAREST:
             "NEAREST_MIPMAP_NEAREST", g.LINEAR_MIPMAP_NEAREST: "LINEAR_MIPMAP_NEAREST",
             g.NEAREST_MIPMAP_LINEAR: "NEAREST_MIPMAP_LINEAR", g.LINEAR_MIPMAP_LINEAR:
             "LINEAR_MIPMAP_LINEAR", g.REPEAT: "REPEAT", g.CLAMP_TO_EDGE: "CLAMP_TO_EDGE",
             g.MIRRORED_REPEAT: "MIRRORED_REPEAT"}
_MIME = {"image/png": ".png", "image/jpeg": ".jpg"}

# Properties of a material and of its parts that the import reads (any other is a warning).
_MATERIAL_KEYS = {"name", "pbrMetallicRoughness", "normalTexture", "occlusionTexture",
                  "emissiveTexture", "emissiveFactor", "alphaMode", "alphaCutoff",
                  "doubleSided", "extensions", "extras"}
_PBR_KEYS = {"baseColorFactor", "baseColorTexture", "metallicFactor", "roughnessFactor",
             "metallicRoughnessTexture", "extensions", "extras"}
# Extension -> its properties (name -> default; None: a texture).
EXTENSIONS: dict[str, dict[str, Any]] = {
    "KHR_materials_ior": {"ior": 1.5},
    "KHR_materials_specular": {"specularFactor": 1.0, "specularTexture": None,
                               "specularColorFactor": [1.0, 1.0, 1.0],
                               "specularColorTexture": None},
    "KHR_materials_clearcoat": {"clearcoatFactor": 0.0, "clearcoatTexture": None,
                                "clearcoatRoughnessFactor": 0.0,
                                "clearcoatRoughnessTexture": None,
                                "clearcoatNormalTexture": None},
    "KHR_materials_sheen": {"sheenColorFactor": [0.0, 0.0, 0.0], "sheenColorTexture": None,
                            "sheenRoughnessFactor": 0.0, "sheenRoughnessTexture": None},
    "KHR_materials_anisotropy": {"anisotropyStrength": 0.0, "anisotropyRotation": 0.0,
                                 "anisotropyTexture": None},
    "KHR_materials_transmission": {"transmissionFactor": 0.0, "transmissionTexture": None},
    "KHR_materials_volume": {"thicknessFactor": 0.0, "thicknessTexture": None,
                             "attenuationDistance": math.inf,
                             "attenuationColor": [1.0, 1.0, 1.0]},
    "KHR_materials_iridescence": {"iridescenceFactor": 0.0, "iridescenceTexture": None,
                                  "iridescenceIor": 1.3, "iridescenceThicknessMinimum": 100.0,
                                  "iridescenceThicknessMaximum": 400.0,
                                  "iridescenceThicknessTexture": None},
    "KHR_materials_emissive_strength": {"emissiveStrength": 1.0},
}


class GltfImportError(ValueError):
    """Errors of one import, one line each (the first is the exception's message)."""

    def __init__(self, messages: list[str]) -> None:
        self.messages = messages
        super().__init__(messages[0])


class SeveralMaterials(GltfImportError):
    def __init__(self, path: Path, names: list[str]) -> None:
        self.names = names
        super().__init__([f"{path}: {len(names)} materials ({', '.join(map(repr, names))}): "
                          "choose one with --material NAME, or import every one with -o DIR"])


@dataclass
class Asset:
    """A loaded asset: its JSON, its binary chunk (a .glb's), and where it lies."""

    path: Path
    json: dict
    blob: bytes | None
    buffers: dict[int, bytes] = field(default_factory=dict)


@dataclass
class ImportResult:
    """One material: its document, and the embedded images to write beside it."""

    document: MaterialDocument
    images: dict[Path, bytes]
    reads: set[Path] = field(default_factory=set)  # the asset's files it refers to


def shown(v: Any) -> str:
    """A value as a warning shows it: 0.5, (1, 0.5, 0.25), or the JSON text."""
    if isinstance(v, bool) or v is None:
        return json.dumps(v)
    if isinstance(v, (int, float)):
        return f"{v:.6g}"
    if isinstance(v, list) and all(isinstance(x, (int, float)) for x in v):
        return f"({', '.join(f'{x:.6g}' for x in v)})"
    text = json.dumps(v, sort_keys=True)
    return text if len(text) <= 80 else text[:77] + "..."


# --- reading the file ---------------------------------------------------------------------
def _parse_glb(path: Path, raw: bytes) -> tuple[dict, bytes | None]:
    if len(raw) < 20:
        raise GltfImportError([f"{path}: not a GLB file (too short)"])
    magic, version, length = struct.unpack_from("<III", raw, 0)
    if magic != 0x46546C67:
        raise GltfImportError([f"{path}: not a GLB file (no glTF magic)"])
    if version != 2:
        raise GltfImportError([f"{path}: GLB version {version} is not supported (2 only)"])
    if length != len(raw):
        raise GltfImportError([f"{path}: GLB header says {length} bytes, the file has "
                               f"{len(raw)}"])
    at, text, blob = 12, None, None
    while at + 8 <= len(raw):
        size, kind = struct.unpack_from("<II", raw, at)
        at += 8
        if at + size > len(raw):
            raise GltfImportError([f"{path}: GLB chunk of {size} bytes runs past the end"])
        chunk = raw[at:at + size]
        at += size + (-size % 4)
        if kind == 0x4E4F534A and text is None:
            text = chunk
        elif kind == 0x004E4942 and blob is None:
            blob = chunk
    if text is None:
        raise GltfImportError([f"{path}: GLB file without a JSON chunk"])
    return _parse_json(path, text), blob


def _parse_json(path: Path, raw: bytes) -> dict:
    """The asset's JSON under matedit's JSON rules (matedit.io.jsontext: UTF-8, no duplicate
    keys, no NaN, at most 64 levels deep, numbers a 64-bit float holds)."""
    from matedit.io.jsontext import JSONTextError, parse_json

    try:
        doc = parse_json(raw)
    except JSONTextError as exc:
        msg = " ".join(str(exc).split())[:160]
        raise GltfImportError([f"{path}: not a glTF document (bad JSON: {msg})"]) from None
    if not isinstance(doc, dict) or not isinstance(doc.get("asset"), dict):
        raise GltfImportError([f"{path}: not a glTF document (no asset object)"])
    version = doc["asset"].get("version")
    if not isinstance(version, str) or not version.startswith("2."):
        raise GltfImportError([f"{path}: asset version {version!r} is not supported (glTF "
                               "2.x only)"])
    return doc


def load_asset(path: Path) -> Asset:
    path = Path(path)
    try:
        raw = read_bounded(path, MAX_GLTF_BYTES)
    except FileNotFoundError:
        raise GltfImportError([f"{path}: no such file"]) from None
    except OSError as exc:
        raise GltfImportError([f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}"]
                              ) from None
    if path.suffix.lower() == ".glb" or raw[:4] == b"glTF":
        doc, blob = _parse_glb(path, raw)
    else:
        doc, blob = _parse_json(path, raw), None
    required = doc.get("extensionsRequired") or []
    if not isinstance(required, list):
        raise GltfImportError([f"{path}: extensionsRequired is not a list"])
    unknown = [e for e in required if e not in EXTENSIONS and e != "KHR_texture_transform"]
    if unknown:
        raise GltfImportError([f"{path}: requires extensions matedit does not read: "
                               f"{', '.join(map(str, unknown))}"])
    return Asset(path, doc, blob)


def _items(asset: Asset, key: str, limit: int) -> list:
    items = asset.json.get(key, [])
    if not isinstance(items, list):
        raise GltfImportError([f"{asset.path}: {key} is not a list"])
    if len(items) > limit:
        raise GltfImportError([f"{asset.path}: more than {limit} {key}"])
    return items


def material_names(path: Path) -> list[str]:
    """The names of the asset's materials, in order (an unnamed one: material_N)."""
    return _names(load_asset(Path(path)))


def _names(asset: Asset) -> list[str]:
    out = []
    for i, m in enumerate(_items(asset, "materials", MAX_MATERIALS)):
        name = m.get("name") if isinstance(m, dict) else None
        out.append(name if isinstance(name, str) and name else f"material_{i}")
    return out


def embedded_name(target: Path, image: int, mime: str) -> Path:
    """Where an embedded image of a material saved at `target` is written: beside it, as
    STEM_imageN.png|jpg (N the image's index in the asset)."""
    return target.parent / f"{target.stem}_image{image}{_MIME[mime]}"


# --- the importer --------------------------------------------------------------------------
class _GltfImporter(_Importer):
    def __init__(self, asset: Asset, out: Path, material: str) -> None:
        super().__init__(asset.path, out, None, None, material)
        self.asset = asset
        self.images: dict[Path, bytes] = {}
        self.samples: dict[tuple, str] = {}
        self.reads: set[Path] = set()  # the asset's own files: .bin buffers, images
        self.make = ""
        self.out_node = ""

    # numbers and properties ------------------------------------------------------------------
    def number(self, v: Any, where: str, width: int = 1) -> list[float] | None:
        vals = v if isinstance(v, list) else [v]
        if len(vals) != width or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                         for x in vals):
            self.err(f"material {self.material}: {where}: expected "
                     f"{'a number' if width == 1 else f'{width} numbers'}, got {shown(v)}")
            return None
        for x in vals:
            why = gpu_number_problem(float(x))
            if why:
                self.err(f"material {self.material}: {where}: {why}")
                return None
        return [float(x) for x in vals]

    def prop(self, obj: dict, key: str, default: Any, where: str) -> Any:
        """`obj[key]` checked against the default's shape (the default where unset)."""
        if key not in obj:
            return default
        v = obj[key]
        if default is None:
            return v
        if isinstance(default, list):
            got = self.number(v, f"{where}{key}", len(default))
            return default if got is None else got
        if default == math.inf:  # attenuationDistance: a positive number, +inf unset
            got = self.number(v, f"{where}{key}")
            return default if got is None else got[0]
        got = self.number(v, f"{where}{key}")
        return default if got is None else got[0]

    def unknown_keys(self, obj: dict, known: set[str], where: str) -> None:
        for k, v in obj.items():
            if k == "extras":
                self.warn(f"{where}extras {shown(v)} is application data matedit does not "
                          "read; dropped")
            elif k not in known:
                self.warn(f"{where}{k} {shown(v)} is not a property matedit reads; dropped")

    # textures ----------------------------------------------------------------------------
    def texture(self, info: Any, where: str, srgb: bool, extra: Collection[str] = ()
                ) -> str | None:
        """The Texture Sample node of a textureInfo (None after an error)."""
        if not isinstance(info, dict):
            self.err(f"material {self.material}: {where}: not a textureInfo object")
            return None
        self.unknown_keys(info, {"index", "texCoord", "extensions", "extras"} | set(extra),
                          f"{where}.")
        index = info.get("index")
        textures = _items(self.asset, "textures", MAX_TEXTURES)
        if not isinstance(index, int) or isinstance(index, bool) or not 0 <= index < len(
                textures) or not isinstance(textures[index], dict):
            self.err(f"material {self.material}: {where}.index {shown(index)}: no such "
                     "texture")
            return None
        tex_coord = info.get("texCoord", 0)
        transform = None
        exts = info.get("extensions") or {}
        if not isinstance(exts, dict):
            self.err(f"material {self.material}: {where}.extensions is not an object")
            return None
        for name, ext in exts.items():
            if name != "KHR_texture_transform":
                self.warn(f"{where}.extensions.{name} {shown(ext)} is not supported; dropped")
                continue
            if not isinstance(ext, dict):
                self.err(f"material {self.material}: {where}: KHR_texture_transform is not "
                         "an object")
                return None
            w = f"{where}.KHR_texture_transform."
            self.unknown_keys(ext, {"offset", "rotation", "scale", "texCoord"}, w)
            off = self.prop(ext, "offset", [0.0, 0.0], w)
            rot = self.prop(ext, "rotation", 0.0, w)
            sc = self.prop(ext, "scale", [1.0, 1.0], w)
            if "texCoord" in ext:
                tex_coord = ext["texCoord"]
            if (off, rot, sc) != ([0.0, 0.0], 0.0, [1.0, 1.0]):
                transform = (tuple(off), rot, tuple(sc))
        if tex_coord != 0:
            self.warn(f"{where}.texCoord {shown(tex_coord)} is not supported (matedit has one "
                      "UV set); read from TEXCOORD_0; approximated")
        key = (index, srgb, transform)
        if key in self.samples:
            return self.samples[key]
        tex = textures[index]
        self.unknown_keys(tex, {"sampler", "source", "name", "extensions"},
                          f"{where}: texture {index}: ")
        for name in tex.get("extensions") or {}:
            self.err(f"material {self.material}: {where}: texture {index}: extension {name} "
                     "(an image format matedit does not read) is not supported")
        self.sampler(tex.get("sampler"), f"{where}: texture {index}: ")
        path = self.image_path(tex.get("source"), f"{where}: texture {index}")
        if path is None:
            return None
        pname = self.new_id(f"{where.split('.')[-1]}_{'srgb' if srgb else 'data'}")
        self.ids.discard(pname)
        tp = self.add(pname, kind_for(Role.TEXTURE_PARAMETER),
                      {"name": pname, "path": path, "srgb": srgb}, depth=3)
        sample = self.add(f"{pname}_sample", kind_for(Role.TEXTURE_SAMPLE), depth=2)
        self.connect(Src(tp, "texture"), sample, "texture")
        if transform is not None:
            self.connect(self.transform(*transform), sample, "uv")
        self.samples[key] = sample
        return sample

    def transform(self, offset, rotation: float, scale) -> Src:
        """KHR_texture_transform in our UVs: glTF's v runs down the image, ours up (v_gltf =
        1 - v), so uv' = F(T R S F(uv)) with F the flip (u, 1 - v): Tiling and Offset (scale,
        folded with the first flip: a Texture Coordinate's tiling and offset), Rotate UV (glTF
        turns by -rotation in our frame) and Multiply Add (the offset, with the second flip)."""
        sx, sy = scale
        first = self.add("uv_scale", _kind("tiled_texcoord"),
                         values={"tiling": [sx, -sy], "offset": [0.0, sy]}, depth=4)
        src = Src(first, "uv", width=2)
        if rotation != 0.0:
            rot = self.add("uv_rotate", _kind("rotate_about_pivot"),
                           values={"angle": -math.degrees(rotation), "pivot": [0.0, 0.0]},
                           depth=4)
            self.connect(src, rot, "uv")
            src = Src(rot, "uv", width=2)
        last = self.add("uv_offset", _kind("multiply_then_add"),
                        values={"b": [1.0, -1.0], "c": [offset[0], 1.0 - offset[1]]}, depth=4)
        self.connect(src, last, "a")
        return Src(last, "result", width=2)

    def sampler(self, index: Any, where: str) -> None:
        if index is None:
            return
        samplers = _items(self.asset, "samplers", MAX_TEXTURES)
        if not isinstance(index, int) or not 0 <= index < len(samplers) or not isinstance(
                samplers[index], dict):
            self.err(f"material {self.material}: {where}sampler {shown(index)}: no such "
                     "sampler")
            return
        s = samplers[index]
        self.unknown_keys(s, set(_SUPPORTED_SAMPLER) | {"name", "extensions"},
                          f"{where}sampler {index}: ")
        for key, ok in _SUPPORTED_SAMPLER.items():
            v = s.get(key)
            if v not in ok:
                self.warn(f"{where}sampler {index}: {key} {_GL_NAMES.get(v, shown(v))} is not "
                          "supported (matedit samples with REPEAT and LINEAR_MIPMAP_LINEAR / "
                          "LINEAR); approximated")

    def image_path(self, index: Any, where: str) -> str | None:
        """The path, relative to the output's folder, of image `index`: an external file as it
        lies, an embedded one extracted beside the output (`self.images`)."""
        images = _items(self.asset, "images", MAX_TEXTURES)
        if not isinstance(index, int) or not 0 <= index < len(images) or not isinstance(
                images[index], dict):
            self.err(f"material {self.material}: {where}: source {shown(index)}: no such "
                     "image")
            return None
        img = images[index]
        w = f"material {self.material}: {where}: image {index}"
        uri = img.get("uri")
        if isinstance(uri, str) and not uri.startswith("data:"):
            target = self.relative_file(uri, w)
            if target is None:
                return None
            self.reads.add(target)
            if not os.path.isfile(target):
                self.warn(f"{where}: image {index}: uri {uri[:80]!r}: no such file beside "
                          f"{self.asset.path.name}; the material refers to it (the preview "
                          "shows a checker)")
            return Path(os.path.relpath(os.path.abspath(target),
                                        os.path.abspath(self.out.parent))).as_posix()
        if isinstance(uri, str):
            data = self.data_uri(uri, w, MAX_IMAGE_BYTES)
        elif isinstance(img.get("bufferView"), int):
            data = self.buffer_view(img["bufferView"], w)
        else:
            self.err(f"{w}: neither a uri nor a bufferView")
            return None
        if data is None:
            return None
        mime = _sniff(data)
        if mime is None:
            self.err(f"{w}: not a PNG or JPEG image")
            return None
        side = _png_size(data) if mime == "image/png" else _jpeg_size(data)
        if side is None or max(side) > MAX_IMAGE_SIDE or min(side) < 1:
            self.err(f"{w}: image size {side} is not supported (1 to {MAX_IMAGE_SIDE} pixels "
                     "a side)")
            return None
        dest = embedded_name(self.out, index, mime)
        self.images[dest] = data
        return dest.name

    def relative_file(self, uri: str, where: str) -> Path | None:
        """A relative URI of the asset as a file in its folder (an error otherwise)."""
        text = urllib.parse.unquote(uri)
        parsed = urllib.parse.urlsplit(uri)
        folder = self.asset.path.parent
        if parsed.scheme or parsed.netloc or "\0" in text or text.startswith(("/", "\\")) \
                or Path(text).is_absolute() or (len(text) > 1 and text[1] == ":"):
            self.err(f"{where}: uri {uri[:80]!r} must be a relative path")
            return None
        target = folder / text
        inside = os.path.normpath(os.path.abspath(target))
        base = os.path.normpath(os.path.abspath(folder))
        real_ok = True
        if os.path.lexists(target):
            real_ok = os.path.realpath(target).startswith(os.path.realpath(folder) + os.sep)
        if not inside.startswith(base + os.sep) or not real_ok:
            self.err(f"{where}: uri {uri[:80]!r} leaves the folder of {self.asset.path.name}")
            return None
        return target

    def data_uri(self, uri: str, where: str, limit: int) -> bytes | None:
        head, _, payload = uri.partition(",")
        if not head.endswith(";base64"):
            self.err(f"{where}: a data: uri must be base64")
            return None
        if len(payload) > limit * 4 // 3 + 4:
            self.err(f"{where}: data: uri larger than {limit >> 20} MiB")
            return None
        try:
            return base64.b64decode(payload, validate=True)
        except (binascii.Error, ValueError):
            self.err(f"{where}: data: uri is not valid base64")
            return None

    def buffer(self, index: Any, where: str) -> bytes | None:
        if index in self.asset.buffers:
            return self.asset.buffers[index]
        buffers = _items(self.asset, "buffers", MAX_TEXTURES)
        if not isinstance(index, int) or not 0 <= index < len(buffers) or not isinstance(
                buffers[index], dict):
            self.err(f"{where}: buffer {shown(index)}: no such buffer")
            return None
        b = buffers[index]
        uri = b.get("uri")
        length = b.get("byteLength")
        if not isinstance(length, int) or length < 0 or length > MAX_GLTF_BYTES:
            self.err(f"{where}: buffer {index}: byteLength {shown(length)} is not supported "
                     f"(0 to {MAX_GLTF_BYTES >> 20} MiB)")
            return None
        data: bytes | None
        if uri is None:
            data = self.asset.blob if index == 0 else None
            if data is None:
                self.err(f"{where}: buffer {index}: no uri and no GLB binary chunk")
                return None
        elif isinstance(uri, str) and uri.startswith("data:"):
            data = self.data_uri(uri, f"{where}: buffer {index}", MAX_GLTF_BYTES)
        elif isinstance(uri, str):
            target = self.relative_file(uri, f"{where}: buffer {index}")
            if target is None:
                return None
            self.reads.add(target)
            try:
                data = read_bounded(target, MAX_GLTF_BYTES)
            except OSError as exc:
                self.err(f"{where}: buffer {index}: {target.name}: cannot read: "
                         f"{getattr(exc, 'strerror', None) or exc}")
                return None
        else:
            self.err(f"{where}: buffer {index}: uri is not a string")
            return None
        if data is None:
            return None
        if len(data) < length:
            self.err(f"{where}: buffer {index}: byteLength {length} but {len(data)} bytes")
            return None
        self.asset.buffers[index] = data
        return data

    def buffer_view(self, index: int, where: str) -> bytes | None:
        views = _items(self.asset, "bufferViews", 1 << 20)
        if not 0 <= index < len(views) or not isinstance(views[index], dict):
            self.err(f"{where}: bufferView {index}: no such buffer view")
            return None
        v = views[index]
        data = self.buffer(v.get("buffer"), f"{where}: bufferView {index}")
        if data is None:
            return None
        off, length = v.get("byteOffset", 0), v.get("byteLength")
        if not isinstance(off, int) or not isinstance(length, int) or off < 0 or length < 0 \
                or off + length > len(data) or length > MAX_IMAGE_BYTES:
            self.err(f"{where}: bufferView {index}: range {shown(off)} + {shown(length)} is "
                     f"outside its buffer ({len(data)} bytes) or larger than "
                     f"{MAX_IMAGE_BYTES >> 20} MiB")
            return None
        return data[off:off + length]

    # terms ---------------------------------------------------------------------------------
    def term(self, factor: list[float], info: Any, port: str, where: str, srgb: bool,
             extra: Collection[str] = ()) -> Src | None:
        """factor x texture channel(s) `port` (glTF's rule), or the factor alone."""
        width = len(factor)
        if info is None:
            return Src(value=list(factor), width=width)
        sample = self.texture(info, where, srgb, extra)
        if sample is None:
            return None
        src = Src(sample, port, width=width)
        if all(f == 1.0 for f in factor):
            return src
        mul = self.add(f"{where.split('.')[-1]}_factor", _ARITH.multiply,
                       values={"b": factor[0] if width == 1 else list(factor)}, depth=1)
        self.connect(src, mul, "a")
        return Src(mul, "result", width=width)

    def normal_map(self, info: Any, where: str, port: str) -> None:
        """A tangent-space normal map: (2 t - 1) (scale, scale, 1) (the shading normalises)."""
        if not isinstance(info, dict):
            self.err(f"material {self.material}: {where}: not a textureInfo object")
            return
        s = self.prop(info, "scale", 1.0, f"{where}.")
        sample = self.texture(info, where, False, {"scale"})
        if sample is None:
            return
        two = self.add(f"{port}_decode", _ARITH.multiply,
                       values={"b": [2.0 * s, 2.0 * s, 2.0]}, depth=1)
        self.connect(Src(sample, "rgb", width=3), two, "a")
        one = self.add(f"{port}_map", _ARITH.subtract, values={"b": [s, s, 1.0]}, depth=1)
        self.connect(Src(two, "result", width=3), one, "a")
        self.connect(Src(one, "result", width=3), self.make, port)

    def set(self, attr: str, src: Src | None) -> None:
        if src is not None:
            self.connect(src, self.make, attr)

    # the material ----------------------------------------------------------------------------
    def build(self, m: dict) -> MaterialDocument:
        self.make = self.add("make", kind_for(Role.MAKE_ATTRIBUTES))
        self.out_node = self.add("out", kind_for(Role.MATERIAL_OUTPUT))
        self.connect(Src(self.make, "attributes"), self.out_node, "attributes")
        self.unknown_keys(m, _MATERIAL_KEYS, "")
        pbr = m.get("pbrMetallicRoughness", {})
        if not isinstance(pbr, dict):
            self.err(f"material {self.material}: pbrMetallicRoughness is not an object")
            pbr = {}
        self.unknown_keys(pbr, _PBR_KEYS, "pbrMetallicRoughness.")
        for name, ext in (pbr.get("extensions") or {}).items():
            self.warn(f"pbrMetallicRoughness.extensions.{name} {shown(ext)} is not supported; "
                      "dropped")
        w = "pbrMetallicRoughness."
        bcf = self.prop(pbr, "baseColorFactor", [1.0, 1.0, 1.0, 1.0], w)
        bct = pbr.get("baseColorTexture")
        base = self.term(bcf[:3], bct, "rgb", f"{w}baseColorTexture", True)
        self.set("baseColor", base)
        mrt = pbr.get("metallicRoughnessTexture")
        self.set("metallic", self.term([self.prop(pbr, "metallicFactor", 1.0, w)], mrt, "b",
                                       f"{w}metallicRoughnessTexture", False))
        self.set("roughness", self.term([self.prop(pbr, "roughnessFactor", 1.0, w)], mrt, "g",
                                        f"{w}metallicRoughnessTexture", False))
        self.alpha(m, bcf[3], bct)
        if m.get("normalTexture") is not None:
            self.normal_map(m["normalTexture"], "normalTexture", "normal")
        if m.get("occlusionTexture") is not None:
            self.occlusion(m["occlusionTexture"])
        exts = m.get("extensions") or {}
        if not isinstance(exts, dict):
            self.err(f"material {self.material}: extensions is not an object")
            exts = {}
        read = {}
        for name, ext in exts.items():
            if name == "KHR_materials_unlit":
                self.warn(f"extensions.KHR_materials_unlit {shown(ext)}: unlit shading is not "
                          "supported (the material is lit); approximated")
            elif name not in EXTENSIONS:
                self.warn(f"extensions.{name} {shown(ext)} is not supported; dropped")
            elif not isinstance(ext, dict):
                self.err(f"material {self.material}: extensions.{name} is not an object")
            else:
                self.unknown_keys(ext, set(EXTENSIONS[name]), f"extensions.{name}.")
                read[name] = {k: self.prop(ext, k, d, f"extensions.{name}.")
                              for k, d in EXTENSIONS[name].items()}
        self.emissive(m, read.get("KHR_materials_emissive_strength"))
        self.extension_lobes(read, base)
        if m.get("doubleSided") not in (None, False):
            self.warn(f"doubleSided {shown(m.get('doubleSided'))} is not supported (a matedit "
                      "material has no back-face setting); dropped")
        layout(self.mat)
        return self.mat

    def vertex_colors(self, index: int) -> None:
        """Warn where a primitive draws this material with vertex colours: glTF multiplies
        the base colour (and alpha) by COLOR_0, which a matedit material cannot carry. The
        meshes are otherwise not read, so a malformed one is passed over."""
        meshes = self.asset.json.get("meshes")
        users = []
        for i, mesh in enumerate(meshes if isinstance(meshes, list) else []):
            prims = mesh.get("primitives") if isinstance(mesh, dict) else None
            for j, prim in enumerate(prims if isinstance(prims, list) else []):
                if (isinstance(prim, dict) and prim.get("material") == index
                        and isinstance(prim.get("attributes"), dict)
                        and "COLOR_0" in prim["attributes"]):
                    users.append(f"meshes[{i}].primitives[{j}]")
        if users:
            more = f" (and {len(users) - 3} more)" if len(users) > 3 else ""
            self.warn(f"COLOR_0 of {', '.join(users[:3])}{more}: glTF multiplies this "
                      "material's base colour and alpha by that vertex colour, which a "
                      "matedit material does not carry; dropped")

    def alpha(self, m: dict, alpha: float, bct: Any) -> None:
        mode = m.get("alphaMode", "OPAQUE")
        cutoff = self.prop(m, "alphaCutoff", 0.5, "")
        if mode == "OPAQUE":
            if alpha != 1.0:
                self.warn(f"pbrMetallicRoughness.baseColorFactor's alpha {shown(alpha)} has no "
                          "effect under alphaMode OPAQUE; dropped")
            if "alphaCutoff" in m:
                self.warn(f"alphaCutoff {shown(cutoff)} has no effect under alphaMode OPAQUE; "
                          "dropped")
            return
        if mode not in ("BLEND", "MASK"):
            self.err(f"material {self.material}: alphaMode {shown(mode)} is not OPAQUE, MASK "
                     "or BLEND")
            return
        src = self.term([alpha], bct, "a", "pbrMetallicRoughness.baseColorTexture", True)
        if src is None:
            return
        if mode == "MASK":  # coverage 1 where alpha >= cutoff, else 0: step(cutoff, alpha)
            if src.node is None:
                src = Src(value=[1.0 if src.value[0] >= cutoff else 0.0])
            else:
                step = self.add("alpha_mask", _kind("floor_step"), values={"edge": cutoff},
                                depth=1)
                self.connect(src, step, "value")
                src = Src(step, "result")
        elif "alphaCutoff" in m:
            self.warn(f"alphaCutoff {shown(cutoff)} has no effect under alphaMode BLEND; "
                      "dropped")
        self.set("opacity", src)

    def occlusion(self, info: Any) -> None:
        if not isinstance(info, dict):
            self.err(f"material {self.material}: occlusionTexture: not a textureInfo object")
            return
        s = self.prop(info, "strength", 1.0, "occlusionTexture.")
        sample = self.texture(info, "occlusionTexture", False, {"strength"})
        if sample is None:
            return
        self.warn(f"occlusionTexture (strength {shown(s)}) is read as our cavity, which "
                  "darkens direct light too (glTF's occlusion darkens indirect light only); "
                  "approximated")
        src = Src(sample, "r")
        if s != 1.0:  # 1 + s (r - 1) = r s + (1 - s)
            mul = self.add("occlusion_strength", _ARITH.multiply, values={"b": s}, depth=1)
            self.connect(src, mul, "a")
            add = self.add("occlusion", _ARITH.add, values={"b": 1.0 - s}, depth=1)
            self.connect(Src(mul, "result"), add, "a")
            src = Src(add, "result")
        self.set("cavity", src)

    def emissive(self, m: dict, strength_ext: dict | None) -> None:
        ef = self.prop(m, "emissiveFactor", [0.0, 0.0, 0.0], "")
        k = strength_ext["emissiveStrength"] if strength_ext else 1.0
        factor = [v * k for v in ef]
        for v in factor:
            if gpu_number_problem(v):
                self.err(f"material {self.material}: emissiveFactor x emissiveStrength: "
                         f"{gpu_number_problem(v)}")
                return
        et = m.get("emissiveTexture")
        if factor == [0.0, 0.0, 0.0]:
            if et is not None:
                self.warn("emissiveTexture has no effect with emissiveFactor (0, 0, 0); "
                          "dropped")
            return
        self.set("emissive", self.term(factor, et, "rgb", "emissiveTexture", True))

    def extension_lobes(self, e: dict[str, dict], base: Src | None) -> None:
        x = "extensions."
        if "KHR_materials_ior" in e:
            ior = e["KHR_materials_ior"]["ior"]
            if ior < 1.0:
                self.warn(f"{x}KHR_materials_ior.ior {shown(ior)} is below 1; read as 1; "
                          "clamped")
                ior = 1.0
            if ior != 1.5:
                self.set("ior", Src(value=[ior]))
        if "KHR_materials_specular" in e:
            s = e["KHR_materials_specular"]
            w = f"{x}KHR_materials_specular."
            color = self.term(s["specularColorFactor"], s["specularColorTexture"], "rgb",
                              f"{w}specularColorTexture", True)
            if s["specularFactor"] != 1.0 or s["specularTexture"] is not None:
                self.warn(f"{w}specularFactor {shown(s['specularFactor'])}"
                          f"{' with specularTexture' if s['specularTexture'] else ''} scales "
                          "glTF's F0 and F90; it is folded into our specularColor (F0), our "
                          "F90 stays 1; approximated")
                weight = self.term([s["specularFactor"]], s["specularTexture"], "a",
                                   f"{w}specularTexture", False)
                color = self.product(color, weight, "specular_weight")
            if color is not None and color.value != [1.0, 1.0, 1.0]:
                self.set("specularColor", color)
        if "KHR_materials_clearcoat" in e:
            c = e["KHR_materials_clearcoat"]
            w = f"{x}KHR_materials_clearcoat."
            if c["clearcoatFactor"] != 0.0:
                self.set("coat", self.term([c["clearcoatFactor"]], c["clearcoatTexture"], "r",
                                           f"{w}clearcoatTexture", False))
                self.set("coatRoughness", self.term(
                    [c["clearcoatRoughnessFactor"]], c["clearcoatRoughnessTexture"], "g",
                    f"{w}clearcoatRoughnessTexture", False))
                if c["clearcoatNormalTexture"] is not None:
                    self.normal_map(c["clearcoatNormalTexture"], f"{w}clearcoatNormalTexture",
                                    "coatNormal")
        if "KHR_materials_sheen" in e:
            s = e["KHR_materials_sheen"]
            w = f"{x}KHR_materials_sheen."
            if s["sheenColorFactor"] != [0.0, 0.0, 0.0]:
                self.set("sheenColor", self.term(s["sheenColorFactor"], s["sheenColorTexture"],
                                                 "rgb", f"{w}sheenColorTexture", True))
                rough = self.term([s["sheenRoughnessFactor"]], s["sheenRoughnessTexture"], "a",
                                  f"{w}sheenRoughnessTexture", False)
                self.set("sheenRoughness", rough)
                if rough is not None and (rough.node is not None or
                                          rough.value[0] < SHEEN_MIN_ROUGHNESS):
                    self.warn(f"{w}sheenRoughnessFactor {shown(s['sheenRoughnessFactor'])} is "
                              f"clamped to at least {SHEEN_MIN_ROUGHNESS:g} by our sheen; "
                              "approximated")
        if "KHR_materials_anisotropy" in e:
            self.anisotropy(e["KHR_materials_anisotropy"], f"{x}KHR_materials_anisotropy.")
        if "KHR_materials_transmission" in e:
            t = e["KHR_materials_transmission"]
            w = f"{x}KHR_materials_transmission."
            if t["transmissionFactor"] != 0.0:
                self.set("transmission", self.term([t["transmissionFactor"]],
                                                   t["transmissionTexture"], "r",
                                                   f"{w}transmissionTexture", False))
                if base is not None:  # glTF tints what passes by the base colour
                    self.set("transmissionColor", base)
                v = e.get("KHR_materials_volume")
                if v is None or v["thicknessFactor"] == 0.0:  # glTF: a thin-walled part
                    self.mat.graph.nodes[self.out_node].settings[THIN_WALLED] = True
        if "KHR_materials_volume" in e:
            self.volume(e["KHR_materials_volume"], f"{x}KHR_materials_volume.")
        if "KHR_materials_iridescence" in e:
            self.iridescence(e["KHR_materials_iridescence"],
                             f"{x}KHR_materials_iridescence.")

    def product(self, a: Src | None, b: Src | None, hint: str) -> Src | None:
        if a is None or b is None:
            return None
        if a.node is None and b.node is None:
            return Src(value=[v * b.value[0] for v in a.value], width=a.width)
        mul = self.add(hint, _ARITH.multiply, depth=1)
        self.connect(a, mul, "a")
        self.connect(b, mul, "b")
        return Src(mul, "result", width=max(a.width, b.width))

    def anisotropy(self, a: dict, w: str) -> None:
        strength, rotation, tex = (a["anisotropyStrength"], a["anisotropyRotation"],
                                   a["anisotropyTexture"])
        if strength == 0.0:
            return
        self.warn(f"{w}anisotropyStrength {shown(strength)}: glTF stretches the roughness by "
                  "its own rule (alpha_t = mix(alpha, 1, strength^2)), not matedit's "
                  "(docs/shading.md); the highlight's length differs; approximated")
        self.set("anisotropy", self.term([strength], tex, "b", f"{w}anisotropyTexture", False))
        if tex is None:
            if rotation != 0.0:
                self.set("anisotropyDirection",
                         Src(value=[math.cos(rotation), math.sin(rotation), 0.0], width=3))
            return
        sample = self.texture(tex, f"{w}anisotropyTexture", False)
        if sample is None:
            return
        # the texture's direction 2 rg - 1, turned by the rotation, in the tangent plane
        dec = self.add("anisotropy_decode", _kind("multiply_then_add"),
                       values={"b": [2.0, 2.0], "c": [-1.0, -1.0]}, depth=1)
        rg = self.add("anisotropy_rg", kind_for(Role.COMPONENT_MASK), {"channels": "xy"},
                      depth=1)
        self.connect(Src(sample, "rgb", width=3), rg, "value")
        self.connect(Src(rg, "result", width=2), dec, "a")
        src = Src(dec, "result", width=2)
        if rotation != 0.0:
            rot = self.add("anisotropy_rotate", _kind("rotate_about_pivot"),
                           values={"angle": math.degrees(rotation), "pivot": [0.0, 0.0]},
                           depth=1)
            self.connect(src, rot, "uv")
            src = Src(rot, "uv", width=2)
        d3 = self.add("anisotropy_direction", kind_for(Role.APPEND), values={"b": 0.0},
                      depth=1)
        self.connect(src, d3, "a")
        self.set("anisotropyDirection", Src(d3, "result", width=3))

    def volume(self, v: dict, w: str) -> None:
        if v["thicknessFactor"] != 0.0:
            self.set("thickness", self.term([v["thicknessFactor"]], v["thicknessTexture"], "g",
                                            f"{w}thicknessTexture", False))
        elif v["thicknessTexture"] is not None:
            self.warn(f"{w}thicknessTexture has no effect with thicknessFactor 0; dropped")
        dist = v["attenuationDistance"]
        if dist != math.inf:
            if dist <= 0.0:
                self.err(f"material {self.material}: {w}attenuationDistance {shown(dist)} must "
                         "be positive")
                return
            self.set("attenuationDistance", Src(value=[dist]))
            if v["attenuationColor"] != [1.0, 1.0, 1.0]:
                self.set("attenuationColor", Src(value=v["attenuationColor"], width=3))
        elif v["attenuationColor"] != [1.0, 1.0, 1.0]:
            self.warn(f"{w}attenuationColor {shown(v['attenuationColor'])} has no effect with "
                      "an infinite attenuationDistance; dropped")

    def iridescence(self, i: dict, w: str) -> None:
        factor, tex = i["iridescenceFactor"], i["iridescenceTexture"]
        if factor == 0.0:
            return
        lo, hi = i["iridescenceThicknessMinimum"], i["iridescenceThicknessMaximum"]
        if i["iridescenceThicknessTexture"] is None:
            thick: Src | None = Src(value=[hi])
        else:
            sample = self.texture(i["iridescenceThicknessTexture"],
                                  f"{w}iridescenceThicknessTexture", False)
            if sample is None:
                return
            mix = self.add("film_thickness", _kind("mix"), values={"a": lo, "b": hi}, depth=1)
            self.connect(Src(sample, "g"), mix, "alpha")
            thick = Src(mix, "result")
        if factor != 1.0 or tex is not None:
            self.warn(f"{w}iridescenceFactor {shown(factor)}"
                      f"{' with iridescenceTexture' if tex is not None else ''} weighs glTF's "
                      "film; ours has no film weight: it scales the film's thickness; "
                      "approximated")
            weight = self.term([factor], tex, "r", f"{w}iridescenceTexture", False)
            thick = self.product(thick, weight, "film_weight")
        self.set("thinFilmThickness", thick)
        if i["iridescenceIor"] != 1.3:
            self.set("thinFilmIor", Src(value=[i["iridescenceIor"]]))


def layout(mat: MaterialDocument) -> None:
    """Columns by the longest path to the output (the output at x = 260, Make Attributes at
    0, each column upstream 260 further left), nodes stacked 110 apart in build order: the
    MaterialX import's columns."""
    graph = mat.graph
    level: dict[str, int] = {}
    downstream: dict[str, set[str]] = {}
    for lk in graph.links:
        downstream.setdefault(lk.src, set()).add(lk.dst)

    def depth(nid: str, seen: frozenset = frozenset()) -> int:
        if nid in level:
            return level[nid]
        outs = [d for d in downstream.get(nid, ()) if d not in seen]
        level[nid] = 1 + max((depth(d, seen | {nid}) for d in outs), default=-1)
        return level[nid]

    rows: dict[int, int] = {}
    for nid, n in graph.nodes.items():
        col = depth(nid)
        row = rows.get(col, 0)
        rows[col] = row + 1
        n.position = (260.0 * (1 - col), 110.0 * row)


def _select(path: Path, asset: Asset, material: str | None) -> list[int]:
    names = _names(asset)
    if not names:
        raise GltfImportError([f"{path}: no material in the asset"])
    if material is not None:
        hits = [i for i, n in enumerate(names) if n == material]
        if not hits:
            raise GltfImportError([f"{path}: no material named {material!r} (materials: "
                                   f"{', '.join(map(repr, names))})"])
        return hits[:1]
    if len(names) > 1:
        raise SeveralMaterials(path, names)
    return [0]


def _import_one(asset: Asset, index: int, name: str, out: Path,
                warnings: list[str] | None) -> ImportResult:
    m = asset.json["materials"][index]
    if not isinstance(m, dict):
        raise GltfImportError([f"{asset.path.name}: material {index} is not an object"])
    imp = _GltfImporter(asset, out, name)
    imp.build(m)
    imp.vertex_colors(index)
    if imp.errors:
        raise GltfImportError(imp.errors)
    if warnings is not None:
        warnings += imp.warnings
    doc = imp.mat
    doc.name = mangle(name) if not identifier_problem(mangle(name)) else "imported"
    doc.description = f"Imported from {asset.path.name}"
    return ImportResult(doc, imp.images, imp.reads)


def import_gltf(path: Path, out: Path, material: str | None = None,
                warnings: list[str] | None = None) -> ImportResult:
    """The material of `path` (the one named; without a name the asset must hold exactly
    one, else SeveralMaterials) as a document to be saved at `out`, with its embedded images
    (path -> bytes, beside `out`); raises GltfImportError with every problem found."""
    path, out = Path(path), Path(out)
    asset = load_asset(path)
    (index,) = _select(path, asset, material)
    return _import_one(asset, index, _names(asset)[index], out, warnings)


def import_all(path: Path, folder: Path,
               warnings: list[str] | None = None) -> dict[Path, ImportResult]:
    """Every material of `path` as FOLDER/STEM.json (mtlx_import.output_paths) -> result."""
    path = Path(path)
    asset = load_asset(path)
    names = _names(asset)
    if not names:
        raise GltfImportError([f"{path}: no material in the asset"])
    paths = output_paths(names, folder)
    if len(set(names)) != len(names):  # two materials of one name: the first is imported
        seen: set[str] = set()
        for n in names:
            if n in seen and warnings is not None:
                warnings.append(f"{path.name}: material {n}: a second material of this name "
                                "is not imported (import it with its own --material run); "
                                "dropped")
            seen.add(n)
    out: dict[Path, ImportResult] = {}
    errors: list[str] = []
    done: set[str] = set()
    for i, n in enumerate(names):
        if n in done:
            continue
        done.add(n)
        try:
            out[paths[n]] = _import_one(asset, i, n, paths[n], warnings)
        except GltfImportError as exc:
            errors += exc.messages
    if errors:
        raise GltfImportError(errors)
    return out


__all__ = ["GltfImportError", "ImportResult", "file_stem", "import_all", "import_gltf",
           "material_names"]


# --- image headers ---------------------------------------------------------------------------
def _sniff(data: bytes) -> str | None:
    if data[:8] == b"\x89PNG\r\n\x1a\n":
        return "image/png"
    if data[:3] == b"\xff\xd8\xff":
        return "image/jpeg"
    return None


def _png_size(data: bytes) -> tuple[int, int] | None:
    if len(data) < 24 or data[12:16] != b"IHDR":
        return None
    w, h = struct.unpack(">II", data[16:24])
    return (w, h)


def _jpeg_size(data: bytes) -> tuple[int, int] | None:
    at = 2
    while at + 9 < len(data):
        if data[at] != 0xFF:
            return None
        marker = data[at + 1]
        if marker in (0xD8, 0x01) or 0xD0 <= marker <= 0xD7:
            at += 2
            continue
        size = int.from_bytes(data[at + 2:at + 4], "big")
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
            h = int.from_bytes(data[at + 5:at + 7], "big")
            w = int.from_bytes(data[at + 7:at + 9], "big")
            return (w, h)
        at += 2 + size
    return None
