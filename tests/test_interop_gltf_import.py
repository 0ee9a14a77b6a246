"""`matedit import FILE.gltf|glb`: glTF 2.0 materials as matedit materials.

References, independent of the importer:
  - the glTF 2.0 specification's formulas (factor x texture, B = metal, G = rough, the
    normal's (2 t - 1)(scale, scale, 1), occlusion 1 + strength (t - 1), emissive x
    emissiveStrength, MASK's alpha >= cutoff, KHR_texture_transform's T R S in glTF's UVs,
    bilinear REPEAT filtering with v down the image), written here in numpy (`reference`,
    `bilinear_gltf`) and compared with matedit's CPU evaluation of the imported material
    (1e-5: float32 evaluation);
  - matedit's own export (`matedit export X.glb`): every field glTF holds comes back within
    1e-6 for factors and 1/255 for the 8-bit maps (compared encoded, as stored);
  - thirteen materials documents of the Khronos glTF-Sample-Assets (tests/data/gltf/README.md),
    their images replaced by small random ones sampled at random UVs: every property they set
    is either read exactly (the reference agrees, texture transforms included) or named in a
    `warning:` line, and so is a primitive's COLOR_0 that multiplies a material's base colour.
"""

from __future__ import annotations

import base64
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.compiler.api import lower_and_optimise
from matedit.compiler.cpu_eval import evaluate
from matedit.graph.nodes import Role, role_of
from matedit.interop import bake
from matedit.io.document import FileResolver, load, save
from matedit.nodes.twin import SurfaceArrays
from tests.hostile import cli

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data" / "gltf"
KHRONOS = sorted(DATA.glob("*.gltf"))


# --- helpers ---------------------------------------------------------------------------------
def png_bytes(pixels: np.ndarray) -> bytes:
    """An 8-bit PNG of `pixels` (H, W, C) uint8, row 0 the top of the image (file order),
    written here by the PNG specification (no filter, one zlib stream), alpha straight."""
    import struct
    import zlib

    h, w, c = pixels.shape
    color = {1: 0, 2: 4, 3: 2, 4: 6}[c]

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))

    rows = b"".join(b"\0" + np.ascontiguousarray(pixels[j], np.uint8).tobytes()
                    for j in range(h))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, color, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def data_uri(raw: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(raw).decode()


def asset(materials: list[dict], images: list[dict], textures: list[dict] | None = None,
          samplers: list[dict] | None = None, **extra) -> dict:
    doc = {"asset": {"version": "2.0"}, "materials": materials, "images": images,
           "textures": textures if textures is not None else
           [{"source": i} for i in range(len(images))], **extra}
    if samplers is not None:
        doc["samplers"] = samplers
    return doc


def write_json(path: Path, doc: dict) -> Path:
    path.write_text(json.dumps(doc))
    return path


def error_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("error: ")]


def only_one_error(rc: int, err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert rc == 2, err
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


def attributes_at(doc_path: Path, uv: np.ndarray) -> dict:
    """The CPU evaluation of a material at matedit UVs `uv` (N, 2), its textures loaded."""
    ir = lower_and_optimise(load(doc_path), FileResolver())
    n = len(uv)
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    surf = SurfaceArrays(uv.astype(np.float64), np.zeros((n, 3)), up, up)
    tex = bake.load_textures(ir)
    return {k: np.asarray(v, np.float64).reshape(n, -1) for k, v in
            evaluate(ir, surf, textures=tex).items()}


def srgb_decode(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def bilinear_gltf(img: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """glTF's LINEAR / REPEAT sampling of `img` (H, W, C), row 0 the top, at glTF UVs (v
    down the image), texel centres at ((i + 0.5) / W, (j + 0.5) / H)."""
    h, w = img.shape[:2]
    x, y = uv[:, 0] * w - 0.5, uv[:, 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    i0, j0 = x0.astype(int) % w, y0.astype(int) % h
    i1, j1 = (i0 + 1) % w, (j0 + 1) % h
    return ((img[j0, i0] * (1 - fx) + img[j0, i1] * fx) * (1 - fy)
            + (img[j1, i0] * (1 - fx) + img[j1, i1] * fx) * fy)


def gltf_transform(uv: np.ndarray, t: dict | None) -> np.ndarray:
    """KHR_texture_transform: T R S uv, rotation as the extension's matrix."""
    if not t:
        return uv
    ox, oy = t.get("offset", [0.0, 0.0])
    r = t.get("rotation", 0.0)
    sx, sy = t.get("scale", [1.0, 1.0])
    c, s = math.cos(r), math.sin(r)
    u, v = uv[:, 0] * sx, uv[:, 1] * sy
    return np.stack([c * u + s * v + ox, -s * u + c * v + oy], -1)


def reference(m: dict, sample) -> dict[str, np.ndarray]:
    """The glTF specification's values of a material, in our attributes' terms, with
    `sample(textureInfo, srgb)` giving the (N, 4) linear texels a textureInfo reads."""
    out: dict[str, np.ndarray] = {}
    pbr = m.get("pbrMetallicRoughness", {})
    bcf = np.asarray(pbr.get("baseColorFactor", [1, 1, 1, 1]), float)

    def tex(key_obj, key, srgb):
        info = key_obj.get(key)
        return None if info is None else sample(info, srgb)

    base = tex(pbr, "baseColorTexture", True)
    out["baseColor"] = bcf[:3] * (base[:, :3] if base is not None else 1.0)
    alpha = bcf[3] * (base[:, 3:4] if base is not None else 1.0)
    mode = m.get("alphaMode", "OPAQUE")
    if mode == "BLEND":
        out["opacity"] = alpha
    elif mode == "MASK":
        out["opacity"] = (alpha >= m.get("alphaCutoff", 0.5)).astype(float)
    mr = tex(pbr, "metallicRoughnessTexture", False)
    out["metallic"] = pbr.get("metallicFactor", 1.0) * (mr[:, 2:3] if mr is not None else 1.0)
    out["roughness"] = pbr.get("roughnessFactor", 1.0) * (mr[:, 1:2] if mr is not None
                                                          else 1.0)

    def normal(info):
        s = info.get("scale", 1.0)
        n = (2 * sample(info, False)[:, :3] - 1) * np.array([s, s, 1.0])
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    if "normalTexture" in m:
        out["normal"] = normal(m["normalTexture"])
    if "occlusionTexture" in m:
        s = m["occlusionTexture"].get("strength", 1.0)
        out["cavity"] = 1 + s * (sample(m["occlusionTexture"], False)[:, :1] - 1)
    ext = m.get("extensions", {})
    k = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    ef = np.asarray(m.get("emissiveFactor", [0, 0, 0]), float) * k
    em = tex(m, "emissiveTexture", True)
    out["emissive"] = ef * (em[:, :3] if em is not None else 1.0)
    if "KHR_materials_ior" in ext:
        out["ior"] = np.array([ext["KHR_materials_ior"].get("ior", 1.5)])

    def channel(obj, key, srgb, sl):
        return sample(obj[key], srgb)[:, sl] if key in obj else 1.0

    if "KHR_materials_specular" in ext:
        s = ext["KHR_materials_specular"]
        # F0's tint; the specular weight folded in (F90 is not ours: a warning says so)
        out["specularColor"] = (np.asarray(s.get("specularColorFactor", [1, 1, 1]), float)
                                * channel(s, "specularColorTexture", True, slice(0, 3))
                                * s.get("specularFactor", 1.0)
                                * channel(s, "specularTexture", False, slice(3, 4)))
    if "KHR_materials_clearcoat" in ext:
        c = ext["KHR_materials_clearcoat"]
        out["coat"] = c.get("clearcoatFactor", 0.0) * channel(c, "clearcoatTexture", False,
                                                              slice(0, 1))
        out["coatRoughness"] = c.get("clearcoatRoughnessFactor", 0.0) * channel(
            c, "clearcoatRoughnessTexture", False, slice(1, 2))
        if "clearcoatNormalTexture" in c:
            out["coatNormal"] = normal(c["clearcoatNormalTexture"])
    if "KHR_materials_sheen" in ext:
        s = ext["KHR_materials_sheen"]
        out["sheenColor"] = np.asarray(s.get("sheenColorFactor", [0, 0, 0]), float) * channel(
            s, "sheenColorTexture", True, slice(0, 3))
        out["sheenRoughness"] = s.get("sheenRoughnessFactor", 0.0) * channel(
            s, "sheenRoughnessTexture", False, slice(3, 4))
    if "KHR_materials_anisotropy" in ext:
        a = ext["KHR_materials_anisotropy"]
        r = a.get("anisotropyRotation", 0.0)
        out["anisotropy"] = a.get("anisotropyStrength", 0.0) * channel(
            a, "anisotropyTexture", False, slice(2, 3))
        d = (2 * sample(a["anisotropyTexture"], False)[:, :2] - 1 if "anisotropyTexture" in a
             else np.array([[1.0, 0.0]]))
        c, s_ = math.cos(r), math.sin(r)
        out["anisotropyDirection"] = np.stack(
            [c * d[:, 0] - s_ * d[:, 1], s_ * d[:, 0] + c * d[:, 1], 0 * d[:, 0]], -1)
    if "KHR_materials_transmission" in ext:
        t = ext["KHR_materials_transmission"]
        out["transmission"] = t.get("transmissionFactor", 0.0) * channel(
            t, "transmissionTexture", False, slice(0, 1))
        out["transmissionColor"] = out["baseColor"]  # glTF tints what passes by it
    if "KHR_materials_volume" in ext:
        v = ext["KHR_materials_volume"]
        out["thickness"] = v.get("thicknessFactor", 0.0) * channel(v, "thicknessTexture", False,
                                                                   slice(1, 2))
        if "attenuationDistance" in v:
            out["attenuationDistance"] = np.array([v["attenuationDistance"]])
            out["attenuationColor"] = np.asarray(v.get("attenuationColor", [1, 1, 1]), float)
    if "KHR_materials_iridescence" in ext:
        i = ext["KHR_materials_iridescence"]
        weight = i.get("iridescenceFactor", 0.0) * channel(i, "iridescenceTexture", False,
                                                           slice(0, 1))
        lo, hi = (i.get("iridescenceThicknessMinimum", 100.0),
                  i.get("iridescenceThicknessMaximum", 400.0))
        g = channel(i, "iridescenceThicknessTexture", False, slice(1, 2))
        # our film has no weight: the importer scales the thickness by it (a warning says so)
        out["thinFilmThickness"] = weight * (lo + (hi - lo) * g if isinstance(g, np.ndarray)
                                             else hi)
        out["thinFilmIor"] = np.array([i.get("iridescenceIor", 1.3)])
    return out


def properties(obj, prefix: str = "") -> list[str]:
    """Every property path a JSON object sets (leaves: numbers, strings, lists of numbers)."""
    out = []
    for k, v in obj.items():
        path = f"{prefix}{k}"
        if isinstance(v, dict) and v:
            out += properties(v, f"{path}.")
        else:
            out.append(path)
    return out


# --- (b) the Khronos sample documents -----------------------------------------------------------
# The properties the reference above compares (read exactly when the evaluation agrees); any
# other property a file sets must be named by a warning.
COMPARED = {
    "name", "alphaMode", "pbrMetallicRoughness.baseColorFactor",
    "pbrMetallicRoughness.metallicFactor", "pbrMetallicRoughness.roughnessFactor",
    "pbrMetallicRoughness.baseColorTexture.index",
    "pbrMetallicRoughness.metallicRoughnessTexture.index", "normalTexture.index",
    "normalTexture.scale", "emissiveFactor", "emissiveTexture.index",
    "extensions.KHR_materials_emissive_strength.emissiveStrength",
    "extensions.KHR_materials_ior.ior",
    "extensions.KHR_materials_specular.specularColorFactor",
    "extensions.KHR_materials_specular.specularColorTexture.index",
    "extensions.KHR_materials_clearcoat.clearcoatFactor",
    "extensions.KHR_materials_sheen.sheenColorFactor",
    "extensions.KHR_materials_sheen.sheenRoughnessFactor",
    "extensions.KHR_materials_anisotropy.anisotropyStrength",
    "extensions.KHR_materials_anisotropy.anisotropyRotation",
    "extensions.KHR_materials_anisotropy.anisotropyTexture.index",
    "extensions.KHR_materials_transmission.transmissionFactor",
    "extensions.KHR_materials_transmission.transmissionTexture.index",
    "extensions.KHR_materials_volume.thicknessFactor",
    "extensions.KHR_materials_volume.thicknessTexture.index",
    "extensions.KHR_materials_volume.attenuationDistance",
    "extensions.KHR_materials_volume.attenuationColor",
    "extensions.KHR_materials_iridescence.iridescenceIor",
    "extensions.KHR_materials_iridescence.iridescenceTexture.index",
}
# KHR_texture_transform on any textureInfo: the reference samples through it (gltf_transform)
TRANSFORM = ".extensions.KHR_texture_transform."
SRGB_TEXTURES = {"baseColorTexture", "emissiveTexture", "sheenColorTexture",
                 "specularColorTexture"}


def _compared(prop: str) -> bool:
    return prop in COMPARED or (TRANSFORM in prop and prop.rsplit(".", 1)[-1] in
                                {"offset", "rotation", "scale"})


@pytest.mark.parametrize("path", KHRONOS, ids=lambda p: p.stem)
def test_khronos_sample_materials_import_with_every_property_mapped_or_warned(tmp_path, path):
    gltf = json.loads(path.read_text())
    rc, _, err = cli("import", path, "-o", tmp_path / "out")
    assert rc == 0, err
    assert not error_lines(err)
    warnings = [line for line in err.splitlines() if line.startswith("warning: ")]
    # every image a small random texture (linear RGBA, row 0 the top), sampled at random UVs
    # so that texture transforms are compared too
    rng = np.random.default_rng(7)
    images = {i: rng.uniform(0.05, 0.95, (4, 5, 4)) for i in range(len(gltf["images"]))}
    uv_gltf = rng.uniform(-1.0, 2.0, (64, 2))
    for index, m in enumerate(gltf["materials"]):
        stem = "".join(ch if ch.isalnum() else "_" for ch in m["name"])
        out = tmp_path / "out" / f"{stem}.json"
        assert out.is_file(), sorted(p.name for p in (tmp_path / "out").iterdir())
        doc = load(out)
        assert doc.name == stem
        # every texture parameter names the asset's image, relative to the output, in the
        # colour space glTF gives its slot (one image may be read in two spaces)
        params = {(n.settings["path"], n.settings["srgb"]) for n in doc.graph.nodes.values()
                  if role_of(n.kind) is Role.TEXTURE_PARAMETER}
        uris = {os.path.relpath(path.parent / im["uri"], out.parent).replace(os.sep, "/")
                for im in gltf["images"]}
        assert {p for p, _ in params} <= uris
        for prop in properties(m):
            if prop.endswith("Texture.index"):
                slot = prop.split(".")[-2]
                image = gltf["images"][gltf["textures"][_get(m, prop)]["source"]]
                uri = os.path.relpath(path.parent / image["uri"], out.parent).replace(
                    os.sep, "/")
                assert (uri, slot in SRGB_TEXTURES) in params, (prop, params)

        # the spec's values at random UVs, against our evaluation
        got = _evaluate_with_images(doc, path, gltf, images, uv_gltf)

        def sample(info, srgb):
            t = info.get("extensions", {}).get("KHR_texture_transform")
            return bilinear_gltf(images[gltf["textures"][info["index"]]["source"]],
                                 gltf_transform(uv_gltf, t))

        want = reference(m, sample)
        for attr, value in want.items():
            np.testing.assert_allclose(got[attr], np.broadcast_to(value, got[attr].shape),
                                       atol=1e-5, err_msg=f"{path.name} {m['name']} {attr}")
        # KHR_materials_volume: a transmissive surface without thickness is thin-walled
        ext = m.get("extensions", {})
        if ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0):
            thin = ext.get("KHR_materials_volume", {}).get("thicknessFactor", 0.0) == 0.0
            outputs = [n for n in doc.graph.nodes.values()
                       if role_of(n.kind) is Role.MATERIAL_OUTPUT]
            assert [bool(n.settings.get("thin_walled")) for n in outputs] == [thin], m["name"]
        named = [w for w in warnings if f"material {m['name']}:" in w]
        for prop in properties(m):
            if _compared(prop):
                continue
            leaf = prop.split(".")[-1] if not prop.endswith(".index") else prop.split(".")[-2]
            assert any(leaf in w for w in named), f"{path.name} {m['name']}: {prop} is " \
                f"neither compared nor warned about: {named}"
        # glTF multiplies the base colour by a primitive's COLOR_0: not ours, so a warning
        if any(p.get("material") == index and "COLOR_0" in p.get("attributes", {})
               for mesh in gltf.get("meshes", []) for p in mesh["primitives"]):
            assert any("COLOR_0" in w for w in named), (m["name"], named)


def _get(obj: dict, path: str):
    for k in path.split("."):
        obj = obj[k]
    return obj


def _evaluate_with_images(doc, src: Path, gltf: dict, images: dict, uv_gltf: np.ndarray
                          ) -> dict:
    """Our CPU evaluation at glTF UVs `uv_gltf`, each texture its image's pixels (given as
    linear, in file order: row 0 the top, so flipped to our row 0 = v = 0)."""
    ir = lower_and_optimise(doc, FileResolver())
    index = {os.path.realpath(src.parent / im["uri"]): i for i, im in enumerate(gltf["images"])}
    textures = {t.name: np.ascontiguousarray(images[index[os.path.realpath(t.path)]][::-1],
                                             "f4") for t in ir.textures}
    n = len(uv_gltf)
    uv = np.stack([uv_gltf[:, 0], 1.0 - uv_gltf[:, 1]], -1)
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    surf = SurfaceArrays(uv, np.zeros((n, 3)), up, up)
    result = {k: np.asarray(v, np.float64).reshape(n, -1)
              for k, v in evaluate(ir, surf, textures=textures).items()}
    result["normal"] /= np.linalg.norm(result["normal"], axis=1, keepdims=True)
    return result


# --- (c) texels against the glTF specification, and a render ---------------------------------
def _spec_asset(tmp_path: Path) -> tuple[Path, dict, dict[int, np.ndarray]]:
    rng = np.random.default_rng(3)
    imgs = {i: rng.integers(0, 256, (4, 5, 4), dtype=np.uint8) for i in range(3)}
    imgs[0][..., 3] = np.where(imgs[0][..., 3] < 128, 40, 230)  # alpha far from the cutoff
    m = {
        "name": "spec",
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.6, 1.0, 0.9],
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "offset": [0.25, 0.5], "rotation": 0.3, "scale": [2.0, 3.0]}}},
            "metallicFactor": 0.7, "roughnessFactor": 0.9,
            "metallicRoughnessTexture": {"index": 1}},
        "normalTexture": {"index": 2, "scale": 0.5},
        "occlusionTexture": {"index": 1, "strength": 0.6},
        "emissiveTexture": {"index": 2},
        "emissiveFactor": [0.5, 0.25, 1.0],
        "alphaMode": "MASK", "alphaCutoff": 0.4,
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 3.0}},
    }
    doc = asset([m], [{"uri": data_uri(png_bytes(imgs[i]))} for i in range(3)],
                samplers=[{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497,
                           "wrapT": 10497}],
                textures=[{"source": i, "sampler": 0} for i in range(3)])
    return write_json(tmp_path / "spec.gltf", doc), m, imgs


def test_imported_texels_match_the_gltf_specification(tmp_path):
    src, m, imgs = _spec_asset(tmp_path)
    out = tmp_path / "spec.json"
    rc, _, err = cli("import", src, "-o", out)
    assert rc == 0, err
    # the embedded images are extracted beside the output, byte for byte
    doc = json.loads(src.read_text())
    for i in range(3):
        written = tmp_path / f"spec_image{i}.png"
        assert written.read_bytes() == base64.b64decode(doc["images"][i]["uri"].split(",")[1])
    assert "occlusionTexture" in err and err.count("warning: ") == 1, err
    rng = np.random.default_rng(11)
    uv_gltf = rng.uniform(-1.0, 2.0, (400, 2))
    uv_ours = np.stack([uv_gltf[:, 0], 1.0 - uv_gltf[:, 1]], -1)
    got = attributes_at(out, uv_ours)

    def sample(info, srgb):
        t = info.get("extensions", {}).get("KHR_texture_transform")
        img = imgs[info["index"]].astype(np.float64) / 255.0
        if srgb:
            img = np.concatenate([srgb_decode(img[..., :3]), img[..., 3:]], -1)
        return bilinear_gltf(img, gltf_transform(uv_gltf, t))

    want = reference(m, sample)
    got["normal"] /= np.linalg.norm(got["normal"], axis=1, keepdims=True)
    for attr, value in want.items():  # float32 evaluation: 1e-5
        np.testing.assert_allclose(got[attr], np.broadcast_to(value, got[attr].shape),
                                   atol=1e-5, err_msg=attr)
    assert 0 < got["opacity"].mean() < 1  # both sides of the cutoff are exercised


LOBE_SPEC = {
    "name": "lobes",
    "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
    "extensions": {
        "KHR_materials_specular": {"specularColorFactor": [0.9, 0.8, 0.7],
                                   "specularColorTexture": {"index": 1}},
        "KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatTexture": {"index": 2},
                                    "clearcoatRoughnessFactor": 0.6,
                                    "clearcoatRoughnessTexture": {"index": 2},
                                    "clearcoatNormalTexture": {"index": 1, "scale": 0.7}},
        "KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.6, 0.7],
                                "sheenColorTexture": {"index": 0},
                                "sheenRoughnessFactor": 0.9,
                                "sheenRoughnessTexture": {"index": 3}},
        "KHR_materials_anisotropy": {"anisotropyStrength": 0.6, "anisotropyRotation": 0.4,
                                     "anisotropyTexture": {"index": 2}},
        "KHR_materials_transmission": {"transmissionFactor": 0.7,
                                       "transmissionTexture": {"index": 3}},
        "KHR_materials_volume": {"thicknessFactor": 0.2, "thicknessTexture": {"index": 3},
                                 "attenuationDistance": 0.5,
                                 "attenuationColor": [0.9, 0.5, 0.3]},
        "KHR_materials_iridescence": {"iridescenceFactor": 1.0, "iridescenceIor": 1.45,
                                      "iridescenceThicknessMinimum": 150.0,
                                      "iridescenceThicknessMaximum": 600.0,
                                      "iridescenceThicknessTexture": {"index": 1}},
    }}


def test_imported_lobe_textures_match_the_gltf_specification(tmp_path):
    rng = np.random.default_rng(9)
    imgs = {i: rng.integers(0, 256, (3, 4, 4), dtype=np.uint8) for i in range(4)}
    imgs[3][..., 3] = np.maximum(imgs[3][..., 3], 200)  # sheen roughness above our 0.3 clamp
    src = write_json(tmp_path / "lobes.gltf", asset(
        [LOBE_SPEC], [{"uri": data_uri(png_bytes(imgs[i]))} for i in range(4)]))
    out = tmp_path / "lobes.json"
    rc, _, err = cli("import", src, "-o", out)
    assert rc == 0, err
    warned = [line for line in err.splitlines() if line.startswith("warning: ")]
    assert len(warned) == 2 and "anisotropyStrength" in err and "sheenRoughness" in err, err
    uv_gltf = rng.uniform(-1.0, 2.0, (300, 2))
    got = attributes_at(out, np.stack([uv_gltf[:, 0], 1.0 - uv_gltf[:, 1]], -1))

    def sample(info, srgb):
        img = imgs[info["index"]].astype(np.float64) / 255.0
        if srgb:
            img = np.concatenate([srgb_decode(img[..., :3]), img[..., 3:]], -1)
        return bilinear_gltf(img, uv_gltf)

    want = reference(LOBE_SPEC, sample)
    got["coatNormal"] /= np.linalg.norm(got["coatNormal"], axis=1, keepdims=True)
    for attr in ("specularColor", "coat", "coatRoughness", "coatNormal", "sheenColor",
                 "sheenRoughness", "anisotropy", "anisotropyDirection", "transmission",
                 "transmissionColor", "thickness", "attenuationDistance", "attenuationColor",
                 "thinFilmThickness", "thinFilmIor"):  # float32 evaluation: 1e-5 relative
        np.testing.assert_allclose(got[attr], np.broadcast_to(want[attr], got[attr].shape),
                                   rtol=1e-5, atol=1e-5, err_msg=attr)
    assert load(out).graph.nodes["out"].settings.get("thin_walled") in (None, False)


@pytest.mark.gl
def test_imported_material_renders(tmp_path):
    src, _, _ = _spec_asset(tmp_path)
    out = tmp_path / "spec.json"
    assert cli("import", src, "-o", out)[0] == 0
    r = subprocess.run([sys.executable, "-m", "matedit", "render", str(out), "-o",
                        str(tmp_path / "r.png"), "--size", "32x32"], capture_output=True,
                       text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stderr
    from matedit.io.images import read_image

    px = read_image(tmp_path / "r.png").pixels
    assert px.shape[:2] == (32, 32) and float(np.ptp(px[..., :3])) > 0.05


# --- (a) round trip through our export ------------------------------------------------------
LOBES = {"ior": 1.7, "specularColor": [0.9, 0.8, 0.7], "coat": 0.7, "coatRoughness": 0.2,
         "sheenColor": [0.3, 0.2, 0.1], "sheenRoughness": 0.5, "anisotropy": 0.4,
         "anisotropyDirection": [0.0, 1.0, 0.0], "transmission": 0.5,
         "attenuationDistance": 0.3, "attenuationColor": [0.8, 0.6, 0.4], "thickness": 0.05,
         "thinFilmThickness": 400.0, "thinFilmIor": 1.4}
SIZE = 16


def _export(src: Path, out: Path) -> None:
    r = subprocess.run([sys.executable, "-m", "matedit", "export", str(src), "-o", str(out),
                        "--size", str(SIZE)], capture_output=True, text=True, cwd=ROOT,
                       timeout=600)
    assert r.returncode == 0, r.stderr


def _round_trip_material(tmp: Path) -> Path:
    """A material whose seven core fields vary over the surface (a texture of its own) and
    whose lobe fields are the constants LOBES, emissive above 1 and opacity below."""
    rng = np.random.default_rng(5)
    pix = rng.uniform(0.05, 0.95, (SIZE, SIZE, 4)).astype(np.float32)
    from matedit.io.images import write_image

    write_image(tmp / "src.exr", pix)
    doc = material(tmp / "src.json")
    node(doc, "tex", "texture_parameter", settings={"name": "t", "path": "src.exr",
                                                    "srgb": False})
    node(doc, "s", "texture_sample")
    node(doc, "glow", "multiply", values={"b": [2.5, 1.5, 0.5]})
    node(doc, "make", "make_attributes",
         values={**LOBES, "normal": [0.3, -0.2, 0.9327379053088815]})
    node(doc, "out", "material_output")
    link(doc, "tex", "texture", "s", "texture")
    link(doc, "s", "rgb", "make", "baseColor")
    link(doc, "s", "r", "make", "metallic")
    link(doc, "s", "g", "make", "roughness")
    link(doc, "s", "b", "make", "cavity")
    link(doc, "s", "a", "make", "opacity")
    link(doc, "s", "rgb", "glow", "a")
    link(doc, "glow", "result", "make", "emissive")
    link(doc, "make", "attributes", "out", "attributes")
    save(doc, doc.path)
    return doc.path


@pytest.mark.gl
@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_round_trip_through_our_export(tmp_path, suffix):
    src = _round_trip_material(tmp_path)
    exported = tmp_path / f"x{suffix}"
    _export(src, exported)
    out = tmp_path / "back.json"
    rc, _, err = cli("import", exported, "-o", out)
    assert rc == 0, err
    ir_a = lower_and_optimise(load(src), FileResolver())
    ir_b = lower_and_optimise(load(out), FileResolver())
    a, b = bake.attributes_cpu(ir_a, SIZE), bake.attributes_cpu(ir_b, SIZE)
    for name, value in LOBES.items():  # factors: 1e-6
        np.testing.assert_allclose(b[name], np.broadcast_to(value, b[name].shape), atol=1e-6,
                                   err_msg=name)
    strength = json.loads(exported.read_text() if suffix == ".gltf" else
                          _glb_json(exported))["materials"][0]["extensions"][
        "KHR_materials_emissive_strength"]["emissiveStrength"]
    encoded = {  # the 8-bit maps, compared as stored: 1/255
        "baseColor": bake.linear_to_srgb, "emissive": lambda e: bake.linear_to_srgb(
            e / strength), "metallic": lambda x: x, "roughness": lambda x: x,
        "cavity": lambda x: x, "opacity": lambda x: x,
        "normal": lambda n: n / np.linalg.norm(n, axis=-1, keepdims=True) * 0.5 + 0.5}
    for name, enc in encoded.items():
        err_ = np.abs(np.clip(enc(a[name]), 0, 1) - np.clip(enc(b[name]), 0, 1)).max()
        assert err_ <= 1.0 / 255.0 + 1e-6, f"{name}: {err_ * 255:.3f}/255"
    assert b["opacity"].min() < 0.5 < b["opacity"].max()  # the alpha came back (BLEND)
    assert load(out).graph.nodes["out"].settings.get("thin_walled") in (None, False)


def _glb_json(path: Path) -> str:
    raw = path.read_bytes()
    n = int.from_bytes(raw[12:16], "little")
    return raw[20:20 + n].decode()


# --- warnings, --strict, names ------------------------------------------------------------
def _one(tmp: Path, m: dict, images=None, **extra) -> Path:
    images = images if images is not None else []
    return write_json(tmp / "a.gltf", asset([m], images, **extra))


def test_every_dropped_or_approximated_value_is_a_warning_and_strict_refuses(tmp_path):
    img = data_uri(png_bytes(np.full((2, 2, 3), 128, np.uint8)))
    m = {"name": "w", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
                                                                    "texCoord": 1}},
         "doubleSided": True, "extras": {"a": 1},
         "extensions": {"KHR_materials_unlit": {}, "KHR_materials_dispersion":
                        {"dispersion": 0.3},
                        "KHR_materials_specular": {"specularFactor": 0.5},
                        "KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1],
                                                "sheenRoughnessFactor": 0.1}}}
    src = _one(tmp_path, m, [{"uri": img}],
               samplers=[{"wrapS": 33071, "magFilter": 9728}],
               textures=[{"source": 0, "sampler": 0}],
               meshes=[{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]},
                       {"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1},
                                        "material": 0}]}])
    rc, _, err = cli("import", src, "-o", tmp_path / "w.json")
    assert rc == 0, err
    for needle in ("texCoord 1", "doubleSided true", "extras", "KHR_materials_unlit",
                   "KHR_materials_dispersion", "specularFactor 0.5", "wrapS CLAMP_TO_EDGE",
                   "magFilter NEAREST", "sheenRoughnessFactor 0.1",
                   "COLOR_0 of meshes[1].primitives[0]:"):
        assert any(needle in w and w.startswith("warning: a.gltf: material w: ")
                   for w in err.splitlines()), (needle, err)
    for p in tmp_path.glob("w*"):
        p.unlink()
    rc, _, err = cli("import", src, "-o", tmp_path / "w.json", "--strict")
    assert rc == 2 and "(--strict)" in err and "warning:" not in err
    assert not list(tmp_path.glob("w*"))


def test_several_materials_need_a_name_or_a_folder(tmp_path):
    src = write_json(tmp_path / "two.gltf", asset([{"name": "a"}, {"name": "b"}], []))
    line = only_one_error(*cli("import", src, "-o", tmp_path / "x.json")[::2])
    assert "2 materials" in line and "'a'" in line and "'b'" in line
    assert cli("import", src, "-o", tmp_path / "x.json", "--material", "b")[0] == 0
    assert load(tmp_path / "x.json").name == "b"
    rc, _, err = cli("import", src, "-o", tmp_path / "all")
    assert rc == 0, err
    assert sorted(p.name for p in (tmp_path / "all").iterdir()) == ["a.json", "b.json"]


def test_layout_in_columns_without_overlaps(tmp_path):
    src, _, _ = _spec_asset(tmp_path)
    assert cli("import", src, "-o", tmp_path / "spec.json")[0] == 0
    doc = load(tmp_path / "spec.json")
    pos = [n.position for n in doc.graph.nodes.values()]
    assert len(set(pos)) == len(pos)
    by_role = {role_of(n.kind): n.position for n in doc.graph.nodes.values()}
    assert by_role[Role.MATERIAL_OUTPUT][0] > by_role[Role.MAKE_ATTRIBUTES][0] > \
        by_role[Role.TEXTURE_SAMPLE][0] > by_role[Role.TEXTURE_PARAMETER][0]
    for lk in doc.graph.links:  # every link runs left to right
        assert doc.graph.nodes[lk.src].position[0] < doc.graph.nodes[lk.dst].position[0]


# --- (d) hostile inputs: one error line, exit 2, nothing written -------------------------------
def _huge_png() -> bytes:
    raw = png_bytes(np.zeros((1, 1, 3), np.uint8))
    return raw[:16] + (100000).to_bytes(4, "big") + (100000).to_bytes(4, "big") + raw[24:]


HOSTILE = {
    "absolute uri": ({"uri": "/etc/passwd.png"}, "must be a relative path"),
    "scheme uri": ({"uri": "file:///etc/passwd.png"}, "must be a relative path"),
    "escaping uri": ({"uri": "../outside.png"}, "leaves the folder"),
    "escaping encoded uri": ({"uri": "sub/%2E%2E/%2E%2E/outside.png"}, "leaves the folder"),
    "huge image": ({"uri": data_uri(_huge_png())}, "image size"),
    "not an image": ({"uri": "data:image/png;base64," + base64.b64encode(b"text").decode()},
                     "not a PNG or JPEG"),
    "huge buffer view": ({"bufferView": 0}, "outside its buffer"),
}


@pytest.mark.parametrize("case", HOSTILE, ids=str)
def test_hostile_image_references_are_one_error(tmp_path, case):
    image, needle = HOSTILE[case]
    (tmp_path / "sub").mkdir()
    src = write_json(tmp_path / "sub" / "h.gltf", asset(
        [{"name": "h", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}], [image],
        buffers=[{"byteLength": 8, "uri": "data:application/octet-stream;base64,"
                  + base64.b64encode(b"12345678").decode()}],
        bufferViews=[{"buffer": 0, "byteOffset": 4, "byteLength": 1 << 30}]))
    (tmp_path / "outside.png").write_bytes(png_bytes(np.zeros((1, 1, 3), np.uint8)))
    before = sorted(p.name for p in (tmp_path / "sub").iterdir())
    line = only_one_error(*cli("import", src, "-o", tmp_path / "sub" / "o.json")[::2])
    assert needle in line and "h.gltf" in line and "material h" in line, line
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == before


@pytest.mark.parametrize("text,needle", [
    ("{", "bad JSON"), ("[]", "no asset object"), ('{"asset": {"version": "1.0"}}', "2.x"),
    ('{"asset": {"version": "2.0"}, "materials": 3}', "materials is not a list"),
    ('{"asset": {"version": "2.0"}, "materials": [{"pbrMetallicRoughness": {'
     '"baseColorFactor": [1, "x", 0, 1]}}]}', "baseColorFactor"),
    ('{"asset": {"version": "2.0"}, "materials": [{"pbrMetallicRoughness": {'
     '"metallicFactor": 1e39}}]}', "metallicFactor"),
    ('{"asset": {"version": "2.0"}, "materials": [{"alphaMode": "SOMETIMES"}]}', "alphaMode"),
    ('{"asset": {"version": "2.0"}, "extensionsRequired": ["KHR_draco_mesh_compression"]}',
     "KHR_draco_mesh_compression"),
    ("[" * 100000 + "]" * 100000, "nest more than 64 deep"),
    ('{"asset": {"version": "2.0"}, "asset": {}}', "appears twice"),
    ('{"asset": {"version": "2.0"}, "materials": [{"emissiveFactor": [NaN, 0, 0]}]}',
     "bad JSON"),
], ids=["truncated", "array", "version", "materials", "string", "overflow", "alpha",
        "required", "deep", "duplicate key", "NaN"])
def test_malformed_documents_are_one_error(tmp_path, text, needle):
    src = tmp_path / "bad.gltf"
    src.write_text(text)
    line = only_one_error(*cli("import", src, "-o", tmp_path / "o.json")[::2])
    assert needle in line and "bad.gltf" in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.gltf"]


@pytest.mark.parametrize("raw,needle", [
    (b"glTF" + (2).to_bytes(4, "little") + (999).to_bytes(4, "little") + b"\0" * 8,
     "header says"),
    (b"nope" + b"\0" * 30, "no glTF magic"),
    (b"glTF" + (2).to_bytes(4, "little") + (28).to_bytes(4, "little")
     + (100).to_bytes(4, "little") + b"JSON" + b"{}\0\0\0\0\0\0", "runs past the end"),
], ids=["length", "magic", "chunk"])
def test_malformed_glb_is_one_error(tmp_path, raw, needle):
    src = tmp_path / "bad.glb"
    src.write_bytes(raw)
    line = only_one_error(*cli("import", src, "-o", tmp_path / "o.json")[::2])
    assert needle in line, line


# --- outputs: never an input, never through a link ------------------------------------------
def _embedded(tmp: Path, external: str | None = None) -> Path:
    img = data_uri(png_bytes(np.full((2, 2, 3), 200, np.uint8)))
    images = [{"uri": img}] + ([{"uri": external}] if external else [])
    m = {"name": "mat", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}
    if external:
        m["emissiveTexture"] = {"index": 1}
        m["emissiveFactor"] = [1, 1, 1]
    return write_json(tmp / "a.gltf", asset([m], images))


def test_an_extracted_image_never_replaces_an_image_the_asset_reads(tmp_path):
    victim = tmp_path / "mat_image0.png"  # an image the asset names, at an output's name
    victim.write_bytes(b"precious")
    src = _embedded(tmp_path, external="mat_image0.png")
    line = only_one_error(*cli("import", src, "-o", tmp_path / "mat.json")[::2])
    assert "mat_image0.png" in line, line
    assert victim.read_bytes() == b"precious" and not (tmp_path / "mat.json").exists()


def test_a_planted_link_at_an_image_name_is_replaced_not_followed(tmp_path):
    src = _embedded(tmp_path)
    victim = tmp_path / "victim.png"
    victim.write_bytes(b"precious")
    os.symlink(victim, tmp_path / "mat_image0.png")
    rc, _, err = cli("import", src, "-o", tmp_path / "mat.json")
    assert rc == 0, err
    assert victim.read_bytes() == b"precious"
    assert not (tmp_path / "mat_image0.png").is_symlink()
    assert (tmp_path / "mat_image0.png").read_bytes()[:4] == b"\x89PNG"
    text = (tmp_path / "mat.json").read_text()
    assert str(tmp_path) not in text and '"path": "mat_image0.png"' in text


def test_import_into_a_folder_refuses_existing_images_without_overwrite(tmp_path):
    src = _embedded(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    (out / "mat_image0.png").write_bytes(b"older")
    line = only_one_error(*cli("import", src, "-o", out)[::2])
    assert "mat_image0.png" in line and "--overwrite" in line
    assert sorted(p.name for p in out.iterdir()) == ["mat_image0.png"]
    assert cli("import", src, "-o", out, "--overwrite")[0] == 0
    assert sorted(p.name for p in out.iterdir()) == ["mat.json", "mat_image0.png"]


def test_the_output_may_not_be_the_asset(tmp_path):
    src = _embedded(tmp_path)
    src_json = tmp_path / "a.json"
    src_json.write_bytes(src.read_bytes())
    os.symlink(src, tmp_path / "link.json")
    line = only_one_error(*cli("import", src, "-o", tmp_path / "link.json")[::2])
    assert "glTF asset" in line, line


def test_an_image_linked_from_outside_the_folder_is_refused(tmp_path):
    (tmp_path / "sub").mkdir()
    secret = tmp_path / "secret.png"
    secret.write_bytes(png_bytes(np.zeros((1, 1, 3), np.uint8)))
    os.symlink(secret, tmp_path / "sub" / "inside.png")
    src = write_json(tmp_path / "sub" / "l.gltf", asset(
        [{"name": "l", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        [{"uri": "inside.png"}]))
    line = only_one_error(*cli("import", src, "-o", tmp_path / "sub" / "o.json")[::2])
    assert "leaves the folder" in line and "inside.png" in line, line


@pytest.mark.parametrize("buffer,needle", [
    ({"byteLength": 1 << 40}, "byteLength"),
    ({"byteLength": 64, "uri": "data:application/octet-stream;base64,AAAA"}, "but 3 bytes"),
    ({"byteLength": 8, "uri": "missing.bin"}, "cannot read"),
    ({"byteLength": 8, "uri": "data:application/octet-stream;base64,!!!!"}, "base64"),
], ids=["huge", "short", "missing", "bad base64"])
def test_bad_buffers_are_one_error(tmp_path, buffer, needle):
    src = write_json(tmp_path / "b.gltf", asset(
        [{"name": "b", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        [{"bufferView": 0, "mimeType": "image/png"}], buffers=[buffer],
        bufferViews=[{"buffer": 0, "byteLength": 8}]))
    line = only_one_error(*cli("import", src, "-o", tmp_path / "o.json")[::2])
    assert needle in line and "b.gltf" in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.gltf"]


def _png_pixels(raw: bytes) -> np.ndarray:
    """An 8-bit RGBA PNG without filters' pixels, decoded here (filter type 0 rows only)."""
    import struct
    import zlib

    at, idat, w = 8, b"", 0
    while at < len(raw):
        (n,) = struct.unpack(">I", raw[at:at + 4])
        kind = raw[at + 4:at + 8]
        if kind == b"IHDR":
            w = struct.unpack(">I", raw[at + 8:at + 12])[0]
        if kind == b"IDAT":
            idat += raw[at + 8:at + 8 + n]
        at += 12 + n
    rows = zlib.decompress(idat)
    stride = 1 + 4 * w
    assert all(rows[i] == 0 for i in range(0, len(rows), stride))  # unfiltered rows
    return np.frombuffer(bytes(b for i, b in enumerate(rows) if i % stride), np.uint8)


def test_rgba_maps_are_written_and_read_with_straight_alpha(tmp_path):
    """glTF's base colour is not premultiplied: the exporter's RGBA PNG stores the colour as
    given, and matedit reads a PNG's colour as stored (OpenImageIO would otherwise divide
    on writing and multiply on reading)."""
    from matedit.io.images import read_image

    px = np.array([[[0.8, 0.4, 0.2, 0.5]]])
    bake.encode_file(tmp_path / "m.png", bake.BakedMap("m", px, False))
    assert list(_png_pixels((tmp_path / "m.png").read_bytes())) == [204, 102, 51, 128]
    (tmp_path / "p.png").write_bytes(png_bytes(np.array([[[255, 228, 34, 121]]], np.uint8)))
    np.testing.assert_allclose(read_image(tmp_path / "p.png").pixels[0, 0] * 255,
                               [255, 228, 34, 121], atol=1e-3)
