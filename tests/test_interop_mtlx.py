"""`matedit export OUT.mtlx` (and later `matedit import`): checked by MaterialX itself.

- every sample's document passes MaterialX's own `validate()` with its stdlib loaded;
- every nodegraph output, generated to GLSL by MaterialX's own GLSL generator and drawn
  on the bake plane (UV square, z = 0, +Z normal, camera far above) on EGL, matches our CPU
  evaluator of the same quantity at the texel centres within 2e-3 (float32 GPU maths
  against float64, and baked EXR images read at their texel centres).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from matedit.resources import graphs_dir

mx = pytest.importorskip("MaterialX")
SAMPLES = sorted((graphs_dir() / "materials").glob("*.json"))
SIZE = 24


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mtlx")
    notes = {}
    for path in SAMPLES:
        r = cli("export", str(path), "-o", str(folder / f"{path.stem}.mtlx"), "--size",
                str(SIZE))
        assert r.returncode == 0, r.stderr
        notes[path.stem] = r.stderr
    return folder, notes


def load_with_stdlib(path: Path):
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(path))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    return doc


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_exported_mtlx_validates(exported, path):
    folder, notes = exported
    out = folder / f"{path.stem}.mtlx"
    doc = load_with_stdlib(out)
    ok, msg = doc.validate()
    assert ok, msg
    text = out.read_text()
    assert str(folder) not in text and str(graphs_dir()) not in text
    surfaces = [n for n in doc.getNodes() if n.getCategory() == "standard_surface"]
    assert len(surfaces) == 1
    assert [m.getName() for m in doc.getMaterialNodes()] == [f"M_{path.stem}"]
    # Every image the document references was written beside it, and is reported.
    images = doc.getNodeGraph(f"NG_{path.stem}").getNodes("image")
    for img in images:
        file = img.getInputValue("file")
        assert "/" not in file and (folder / file).is_file()
        assert f"node {img.getName().removesuffix('_baked').rsplit('_', 1)[0]}" in \
            notes[path.stem]
    for line in notes[path.stem].splitlines():
        assert line.startswith("note: ") and "baked to an image" in line


# standard_surface input -> (our attribute, how the surface input relates to it)
SURFACE_INPUTS = {
    "base_color": "baseColor", "base": "cavity", "specular": "cavity",
    "metalness": "metallic", "specular_roughness": "roughness",
    "normal": "normal", "emission_color": "emissive", "opacity": "opacity",
}


@pytest.mark.gl
@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_materialx_glsl_of_each_output_matches_cpu(ctx, exported, path):
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load
    from tests.mtlx_gpu import MtlxDrawer

    folder, _ = exported
    doc = load_with_stdlib(folder / f"{path.stem}.mtlx")
    cpu = bake.attributes_cpu(lower_and_optimise(load(path), FileResolver()), SIZE)
    shader = next(n for n in doc.getNodes() if n.getCategory() == "standard_surface")
    drawer = MtlxDrawer(ctx, SIZE)
    checked = []
    try:
        for inp in shader.getInputs():
            if not inp.getNodeGraphString():
                continue
            out = doc.getNodeGraph(inp.getNodeGraphString()).getOutput(inp.getOutputString())
            got = drawer.draw(doc, out, folder)
            want = cpu[SURFACE_INPUTS[inp.getName()]]
            if inp.getName() == "normal":  # normalmap on T = +X, B = +Y, N = +Z
                want = want / np.linalg.norm(want, axis=-1, keepdims=True)
            k = want.shape[-1]
            if inp.getName() == "opacity":
                got, k = got[..., :1], 1
            np.testing.assert_allclose(got[..., :k], want, atol=2e-3,
                                       err_msg=f"{path.stem}: {inp.getName()}")
            checked.append(inp.getName())
    finally:
        drawer.release()
    print(path.stem, "checked", checked)
    assert "base_color" in checked, checked
