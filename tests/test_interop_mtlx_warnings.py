"""The MaterialX import's rule: nothing the file sets is dropped silently.

Each document in tests/data/mtlx (written for these tests, see tests/data/mtlx/README.md)
and each of MaterialX's own examples that imports (tests/data/mtlx/examples) sets inputs of
one surface (standard_surface, open_pbr_surface, gltf_pbr,
UsdPreviewSurface), some of them with no counterpart here. For every input a surface sets
(listed with MaterialX's own API) the test asks: is it named in a warning, or does the value
it stands for arrive in our attributes (CPU evaluation of the imported material, within
1e-6)? The expected attribute of each input is this test's own reading of each surface's
specification (`RULES`), not the importer's table.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import MaterialX as mx
import numpy as np
import pytest

DATA = Path(__file__).parent / "data" / "mtlx"
FILES = sorted(DATA.glob("*.mtlx"))
# MaterialX's own example documents (tests/data/mtlx/examples/README.md): every one that
# imports is checked by the same rule; the refused ones are errors naming the node
# (tests/test_interop_mtlx_examples.py).
REFUSED_EXAMPLES = {"standard_surface_marble_solid"}  # fractal3d, an object-space position
EXAMPLES = [p for p in sorted((DATA / "examples").glob("*.mtlx"))
            if p.stem not in REFUSED_EXAMPLES]
TOL = 1e-6  # float64 CPU evaluation of constants: only the folding's rounding


def _mul(*xs):
    out = np.ones(3)
    for x in xs:
        out = out * np.asarray(x, dtype=np.float64)
    return out


# Surface -> [(the inputs it reads, our attribute, value from those inputs)]. Each input's
# value is the one set, else the surface's default (its node definition). A rule is checked
# where the file sets one of its inputs and no warning names any of them.
RULES = {
    "standard_surface": [
        (("base", "base_color"), "baseColor", lambda b, c: _mul(b, c)),
        (("normal",), "normal", None),  # world space: from a normalmap node only
        (("coat_normal",), "coatNormal", None),
        (("metalness",), "metallic", lambda m: m),
        (("specular_roughness",), "roughness", lambda r: r),
        (("specular_IOR",), "ior", lambda i: i),
        (("specular_color",), "specularColor", lambda c: c),
        (("emission", "emission_color"), "emissive", lambda e, c: _mul(e, c)),
        (("opacity",), "opacity", lambda o: o[:1]),
        (("coat",), "coat", lambda c: c),
        (("coat_color",), "coatColor", lambda c: c),
        (("coat_roughness",), "coatRoughness", lambda r: r),
        (("coat_IOR",), "coatIor", lambda i: i),
        (("sheen", "sheen_color"), "sheenColor", lambda w, c: _mul(w, c)),
        (("sheen_roughness",), "sheenRoughness", lambda r: r),
        (("specular_anisotropy",), "anisotropy", lambda a: a),
        # the rotation in turns from the tangent
        (("specular_rotation",), "anisotropyDirection",
         lambda t: [math.cos(2 * math.pi * t[0]), math.sin(2 * math.pi * t[0]), 0.0]),
        (("subsurface",), "subsurface", lambda s: s),
        (("subsurface_color",), "subsurfaceColor", lambda c: c),
        (("subsurface_radius",), "subsurfaceRadius", lambda r: r),
        (("subsurface_scale",), "thickness", lambda s: [1.0 / s[0]]),
        (("thin_film_thickness",), "thinFilmThickness", lambda t: t),
        (("thin_film_IOR",), "thinFilmIor", lambda i: i),
        (("transmission",), "transmission", lambda t: t),
        (("transmission_depth",), "attenuationDistance", lambda d: d),
    ],
    "open_pbr_surface": [
        (("base_weight", "base_color"), "baseColor", lambda b, c: _mul(b, c)),
        (("geometry_normal",), "normal", None),
        (("geometry_coat_normal",), "coatNormal", None),
        (("base_metalness",), "metallic", lambda m: m),
        (("specular_roughness",), "roughness", lambda r: r),
        (("specular_ior",), "ior", lambda i: i),
        (("specular_color",), "specularColor", lambda c: c),
        (("specular_roughness_anisotropy",), "anisotropy", lambda a: a),
        # luminance in nits: 1000 nits is our emissive 1
        (("emission_luminance", "emission_color"), "emissive",
         lambda e, c: _mul(np.asarray(e) / 1000.0, c)),
        (("geometry_opacity",), "opacity", lambda o: o),
        (("coat_weight",), "coat", lambda c: c),
        (("coat_color",), "coatColor", lambda c: c),
        (("coat_roughness",), "coatRoughness", lambda r: r),
        (("coat_ior",), "coatIor", lambda i: i),
        (("fuzz_weight", "fuzz_color"), "sheenColor", lambda w, c: _mul(w, c)),
        (("fuzz_roughness",), "sheenRoughness", lambda r: r),
        (("subsurface_weight",), "subsurface", lambda s: s),
        (("subsurface_color",), "subsurfaceColor", lambda c: c),
        # the mean free path radius x radius_scale, at our thickness 1
        (("subsurface_radius_scale", "subsurface_radius"), "subsurfaceRadius",
         lambda c, r: _mul(c, r)),
        # micrometres (ours nm), times its weight (warned about where not 0 or 1)
        (("thin_film_thickness", "thin_film_weight"), "thinFilmThickness",
         lambda t, w: [1000.0 * t[0] * w[0]]),
        (("thin_film_ior",), "thinFilmIor", lambda i: i),
        (("transmission_weight",), "transmission", lambda t: t),
        (("transmission_depth",), "attenuationDistance", lambda d: d),
    ],
    "gltf_pbr": [
        (("base_color",), "baseColor", lambda c: c),
        (("normal",), "normal", None),
        (("clearcoat_normal",), "coatNormal", None),
        (("metallic",), "metallic", lambda m: m),
        (("roughness",), "roughness", lambda r: r),
        (("occlusion",), "cavity", lambda o: o),
        (("ior",), "ior", lambda i: i),
        (("specular_color",), "specularColor", lambda c: c),
        (("transmission",), "transmission", lambda t: t),
        (("alpha",), "opacity", lambda a: a),
        (("emissive", "emissive_strength"), "emissive", lambda e, s: _mul(e, s)),
        (("clearcoat",), "coat", lambda c: c),
        (("clearcoat_roughness",), "coatRoughness", lambda r: r),
        (("sheen_color",), "sheenColor", lambda c: c),
        (("sheen_roughness",), "sheenRoughness", lambda r: r),
        (("anisotropy_strength",), "anisotropy", lambda a: a),
        (("anisotropy_rotation",), "anisotropyDirection",  # radians
         lambda t: [math.cos(t[0]), math.sin(t[0]), 0.0]),
        (("iridescence_thickness", "iridescence"), "thinFilmThickness",
         lambda t, w: [t[0] * w[0]]),
        (("iridescence_ior",), "thinFilmIor", lambda i: i),
        (("thickness",), "thickness", lambda t: t),
        (("attenuation_distance",), "attenuationDistance", lambda d: d),
        (("attenuation_color",), "attenuationColor", lambda c: c),
    ],
    "UsdPreviewSurface": [
        (("diffuseColor",), "baseColor", lambda c: c),
        (("normal",), "normal", lambda n: n),  # tangent space
        (("emissiveColor",), "emissive", lambda c: c),
        (("metallic",), "metallic", lambda m: m),
        (("roughness",), "roughness", lambda r: r),
        (("clearcoat",), "coat", lambda c: c),
        (("clearcoatRoughness",), "coatRoughness", lambda r: r),
        (("opacity",), "opacity", lambda o: o),
        (("ior",), "ior", lambda i: i),
        (("occlusion",), "cavity", lambda o: o),
    ],
}
# Inputs that are our Material Output's settings, or select a reading, rather than values.
SETTINGS = {("standard_surface", "thin_walled"), ("open_pbr_surface", "geometry_thin_walled"),
            ("gltf_pbr", "alpha_mode")}


def _transmission_colour(values):
    """standard_surface's and OpenPBR's transmission_color: a tint at depth 0, the absorption
    colour reached at transmission_depth otherwise (both surfaces' own rule)."""
    depth = values("transmission_depth")
    return ("attenuationColor" if depth[0] > 0 else "transmissionColor"), values(
        "transmission_color")


def _materials(path: Path):
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(path))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    for mat in doc.getMaterialNodes():
        shader = doc.getNode(mat.getInput("surfaceshader").getNodeName())
        yield doc, mat, shader


def _cases():
    for path in FILES + EXAMPLES:
        for _doc, mat, _shader in _materials(path):
            yield pytest.param(path, mat.getName(), id=f"{path.stem}-{mat.getName()}")


def _writes(doc, attr: str) -> bool:
    """Whether the imported graph gives the Make Attributes input `attr` a value or a wire."""
    make = next(n for n in doc.graph.nodes.values() if n.kind == "make_attributes")
    return attr in make.values or any(lk.dst == make.id and lk.dst_port == attr
                                      for lk in doc.graph.links)


def _same_value(a: str, b: str) -> bool:
    try:
        return [float(x) for x in a.split(",")] == [float(x) for x in b.split(",")]
    except ValueError:
        return a.strip().lower() == b.strip().lower()


def _one_value(sets: dict, cat: str) -> bool:
    """The file sets the base and specular weights to one constant (our export's cavity)."""
    names = {"standard_surface": ("base", "specular"),
             "open_pbr_surface": ("base_weight", "specular_weight")}.get(cat)
    return names is not None and all(n in sets for n in names) and len(
        {sets[n].getValueString() for n in names}) == 1


def _named(warnings: list[str], shader, name: str) -> bool:
    return any(re.search(rf": {re.escape(name)} .* of {shader.getCategory()} "
                         rf"{re.escape(shader.getName())} ", w) for w in warnings)


def test_the_test_data_is_what_it_claims():
    assert len(FILES) >= 7
    cats = {s.getCategory() for p in FILES for _d, _m, s in _materials(p)}
    assert cats == set(RULES)
    for p in FILES:
        doc = mx.createDocument()
        mx.readFromXmlFile(doc, str(p))
        lib = mx.createDocument()
        mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
        doc.importLibrary(lib)
        ok, msg = doc.validate()
        assert ok, f"{p.name}: {msg}"


@pytest.mark.parametrize("path, material", list(_cases()))
def test_every_input_set_is_mapped_or_named_in_a_warning(path, material, tmp_path):
    from matedit.compiler.api import lower_and_optimise
    from matedit.graph.nodes import THIN_WALLED
    from matedit.interop import bake
    from matedit.interop.mtlx_import import import_mtlx
    from matedit.io.document import FileResolver

    warnings: list[str] = []
    doc = import_mtlx(path, tmp_path / "out.json", material, warnings)
    assert all(w.startswith(f"{path.name}: material {material}: ") for w in warnings)
    assert all(w.endswith(("; dropped", "; approximated", "approximated where it is lower"))
               for w in warnings), warnings
    _d, _m, shader = next(t for t in _materials(path) if t[1].getName() == material)
    cat = shader.getCategory()
    nd = shader.getNodeDef()
    sets = {i.getName(): i for i in shader.getInputs()}
    warned = {n for n in sets if _named(warnings, shader, n)}

    def values(name: str) -> list[float]:
        el = sets.get(name) or nd.getActiveInput(name)
        return [float(x) for x in el.getValueString().split(",")]

    textured = any(i.getNodeName() or i.getNodeGraphString() for i in sets.values())
    ir = lower_and_optimise(doc, FileResolver())
    a = None if textured else bake.attributes_cpu(ir, 2)
    covered = set(warned)
    # Inputs set at their definition's default change nothing: reading them or not is exact
    # (gltf_pbr's thickness 0 is its no-volume default, not our thickness 0).
    defaults = {n for n, i in sets.items() if not (i.getNodeName() or i.getNodeGraphString())
                and nd.getActiveInput(n) is not None
                and _same_value(i.getValueString(), nd.getActiveInput(n).getValueString())}
    for inputs, attr, f in RULES[cat]:
        if not any(n in sets for n in inputs) or all(n in defaults or n not in sets
                                                     for n in inputs):
            continue
        if any(n in warned for n in inputs):  # the warning names the approximated product
            covered.update(n for n in inputs if n in sets)
            continue
        if inputs[0] in ("base", "base_weight") and _one_value(sets, cat):
            continue  # base and specular as one: our cavity (its own test below)
        covered.update(n for n in inputs if n in sets)
        if a is None or f is None:  # connected: the attribute is written
            assert _writes(doc, attr), attr
            continue
        expect = np.asarray(f(*[values(n) for n in inputs]), dtype=np.float64).ravel()
        got = np.asarray(a[attr][0, 0], dtype=np.float64).ravel()
        np.testing.assert_allclose(got, expect, atol=TOL, err_msg=f"{material} {attr}")
    if "transmission_color" in sets and "transmission_color" not in warned:
        attr, expect = _transmission_colour(values)
        if a is None:
            assert _writes(doc, attr), attr
        else:
            np.testing.assert_allclose(a[attr][0, 0], expect, atol=TOL, err_msg=attr)
        covered.add("transmission_color")
    out = next(n for n in doc.graph.nodes.values() if n.kind == "material_output")
    for c, name in SETTINGS:
        if c == cat and name in sets and name not in warned:
            covered.add(name)
            if "thin_walled" in name:
                assert bool(out.settings.get(THIN_WALLED, False)) == (
                    sets[name].getValueString() == "true")
    if _one_value(sets, cat):
        covered.update(n for n in ("base", "specular", "base_weight", "specular_weight",
                                   "base_color") if n in sets)
    silent = set(sets) - covered - defaults
    assert not silent, f"{material}: inputs set but neither mapped nor warned about: {silent}"


def test_the_warnings_name_what_each_file_drops(tmp_path):
    """What each document's inputs without a counterpart are (this test's own list)."""
    from matedit.interop.mtlx_import import import_mtlx

    expect = {
        ("ss_coated_copper", "Copper"): {"specular", "specular_color", "diffuse_roughness",
                                         "coat_anisotropy", "coat_affect_color"},
        ("ss_glass", "Glass"): {"transmission_dispersion", "transmission_extra_roughness",
                                "transmission_scatter"},
        ("ss_glass", "Pane"): set(),
        ("ss_velvet_jade", "Velvet"): {"sheen_roughness"},  # below our sheen's 0.3
        ("ss_velvet_jade", "Jade"): {"subsurface_anisotropy"},
        ("ss_velvet_jade", "Dusty"): {"displacementshader"},
        ("open_pbr_all", "Lacquer"): {"specular_weight", "thin_film_weight",
                                      "base_diffuse_roughness", "coat_darkening",
                                      "coat_roughness_anisotropy"},
        ("open_pbr_all", "Honey"): {"transmission_scatter", "transmission_dispersion_scale"},
        ("gltf_pbr_all", "Bottle"): {"specular", "occlusion", "dispersion"},
        ("gltf_pbr_all", "Leaf"): {"alpha"},  # alpha_mode OPAQUE ignores it
        ("usd_preview_all", "Tile"): {"occlusion", "useSpecularWorkflow", "specularColor",
                                      "opacityThreshold", "displacement"},
        ("ss_nodegraph", "Tile"): {"in1", "in2", "default", "frameoffset", "fps"},
    }
    seen = set()
    for path in FILES:
        for _d, mat, _s in _materials(path):
            key = (path.stem, mat.getName())
            seen.add(key)
            warnings: list[str] = []
            import_mtlx(path, tmp_path / "out.json", mat.getName(), warnings)
            named = {w.split(": ", 2)[2].split(" ", 1)[0] for w in warnings}
            assert named == expect[key], (key, warnings)
    assert seen == set(expect)


def test_base_multiplies_the_base_colour_and_is_never_cavity(tmp_path):
    """standard_surface's base (OpenPBR's base_weight) is the diffuse weight and scales the
    metal's reflectivity through base_color: our baseColor times base, for a dielectric, a
    metal and a glass alike; cavity stays 1 (it would darken the specular too)."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.interop.mtlx_import import import_mtlx
    from matedit.io.document import FileResolver

    cases = [("standard_surface", "base", "metalness", 0.0, ""),
             ("standard_surface", "base", "metalness", 1.0, ""),
             ("standard_surface", "base", "metalness", 0.0,
              '<input name="transmission" type="float" value="1" />'),
             ("standard_surface", "base", "metalness", 0.0,
              '<input name="specular" type="float" value="0.5" />'),
             ("open_pbr_surface", "base_weight", "base_metalness", 0.0, ""),
             ("open_pbr_surface", "base_weight", "base_metalness", 1.0, "")]
    for i, (cat, base, metal, m, extra) in enumerate(cases):
        f = tmp_path / f"b{i}.mtlx"
        f.write_text(
            f'<?xml version="1.0"?>\n<materialx version="1.39"><{cat} name="S" '
            f'type="surfaceshader"><input name="{base}" type="float" value="0.25" />'
            '<input name="base_color" type="color3" value="0.8, 0.4, 0.2" />'
            f'<input name="{metal}" type="float" value="{m}" />{extra}</{cat}>'
            '<surfacematerial name="M" type="material"><input name="surfaceshader" '
            'type="surfaceshader" nodename="S" /></surfacematerial></materialx>\n')
        doc = import_mtlx(f, tmp_path / f"b{i}.json")
        ir = lower_and_optimise(doc, FileResolver())
        assert not _writes(doc, "cavity"), (cat, extra)
        a = bake.attributes_cpu(ir, 2)
        np.testing.assert_allclose(a["baseColor"][0, 0], [0.2, 0.1, 0.05], atol=TOL)
        assert a["cavity"][0, 0, 0] == 1.0


def test_base_and_specular_as_one_value_read_back_as_cavity(tmp_path):
    """Our export writes cavity to base and specular alike; both scale every lobe of a
    surface without coat, sheen, subsurface or transmission, which is our cavity."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.interop.mtlx_import import import_mtlx
    from matedit.io.document import FileResolver

    warnings: list[str] = []
    doc = import_mtlx(DATA / "ss_velvet_jade.mtlx", tmp_path / "d.json", "Dusty", warnings)
    a = bake.attributes_cpu(lower_and_optimise(doc, FileResolver()), 2)
    assert a["cavity"][0, 0, 0] == pytest.approx(0.7, abs=TOL)
    np.testing.assert_allclose(a["baseColor"][0, 0], [0.5, 0.45, 0.4], atol=TOL)
    assert not any("specular " in w or " base " in w for w in warnings)


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True)


def test_cli_prints_the_warnings_and_strict_refuses(tmp_path):
    src = DATA / "ss_coated_copper.mtlx"
    out = tmp_path / "copper.json"
    r = _cli("import", str(src), "-o", str(out))
    assert r.returncode == 0, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 5 and all(ln.startswith("warning: ss_coated_copper.mtlx: material "
                                                 "Copper: ") for ln in lines), lines
    assert ("warning: ss_coated_copper.mtlx: material Copper: specular 0 of standard_surface "
            "SR_copper is not supported") in r.stderr
    assert "coat_affect_color 0.3 of standard_surface SR_copper is not supported; dropped" \
        in r.stderr
    assert str(DATA) not in r.stderr  # the file's name, not this machine's folder
    assert out.exists()
    strict = tmp_path / "strict.json"
    r = _cli("import", str(src), "-o", str(strict), "--strict")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 5 and all(ln.startswith("error: ") for ln in lines), lines
    assert not strict.exists()
    folder = tmp_path / "all"
    r = _cli("import", str(DATA / "ss_velvet_jade.mtlx"), "-o", str(folder), "--strict")
    assert r.returncode == 2 and "Dusty" in r.stderr  # its displacement shader
    assert not folder.exists() or not any(folder.iterdir())
    clean = tmp_path / "pane.json"
    r = _cli("import", str(DATA / "ss_glass.mtlx"), "-o", str(clean), "--material", "Pane",
             "--strict")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert clean.exists()
