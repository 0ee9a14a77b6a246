"""Regenerate tests/data/sample_renders/: the pre-lobe samples and their reference renders.

    python tools/sample_references.py --tree OLD_TREE [--repeat]
    python tools/sample_references.py --tree TREE --renders-only [--repeat]

OLD_TREE is a checkout of the commit before the lobes beyond the talk (issue 23), e.g.
`git worktree add /tmp/old 0fd033b`. The tool copies that tree's graphs/materials,
graphs/layers and graphs/functions into tests/data/sample_renders/graphs/ (the materials
reach their layers and functions by relative paths, so the folder layout is kept), then
renders every material with OLD_TREE's own `matedit render` (`python -P -m matedit` with
OLD_TREE alone on PYTHONPATH, in a fresh MATEDIT_CACHE_DIR so no bake made by newer code is
reused) under RENDER_ARGS, and stores the linear float32 radiance in
tests/data/sample_renders/renders.npz, one array a sample stem.

--repeat renders every sample a second time and prints the largest difference between
the two runs (it is 0 where the renderer is deterministic, as tests/test_sample_renders_
stable.py assumes).

--renders-only keeps the stored graphs and renders them again with TREE's `matedit render`:
for a change that moves every frame on purpose while the shading stays the talk's (issue 29's
new prefiltering of the environment: the tree before it still matched 0fd033b's frames to
1e-5, and the new bake is checked against brute force by tests/test_ibl_prefilter.py).

tests/test_sample_renders_stable.py renders the same stored graphs through the same command
with the current tree and compares.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data" / "sample_renders"

# A fixed view: 64x64 (small enough to store 14 float32 frames under 1 MB, large enough
# that every sample's pattern covers many pixels), the sphere, the studio environment, the
# default light rig, split-sum image-based lighting, no energy compensation.
RENDER_ARGS = ("--size", "64x64", "--mesh", "sphere", "--env", "studio", "--lights", "default",
               "--ibl", "splitsum")


def render(tree: Path, graph: Path, out: Path, env: dict) -> np.ndarray:
    """One `matedit render` of `graph` by the matedit in `tree`, as (H, W, 3) float32."""
    r = subprocess.run([sys.executable, "-P", "-m", "matedit", "render", str(graph), "-o",
                        str(out), *RENDER_ARGS], cwd=tree, env=env, capture_output=True,
                       text=True)
    if r.returncode != 0:
        raise SystemExit(f"{graph.name}: matedit render failed:\n{r.stderr}")
    return read_exr(out)


def read_exr(path: Path) -> np.ndarray:
    """An EXR written by `matedit render` as float32 RGB (its A is 1 everywhere)."""
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise SystemExit(f"{path}: {oiio.geterror()}")
    try:
        px = inp.read_image(0, 0, 0, 3, "float")
    finally:
        inp.close()
    return np.ascontiguousarray(px, dtype=np.float32)


def render_env(tree: Path, cache: str) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    env["MATEDIT_CACHE_DIR"] = cache
    return env


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tree", required=True, type=Path, help="the pre-lobe checkout")
    ap.add_argument("--repeat", action="store_true", help="render twice and report the spread")
    ap.add_argument("--renders-only", action="store_true",
                    help="keep the stored graphs; only render them again with TREE")
    args = ap.parse_args(argv)
    tree = args.tree.resolve()
    if not (tree / "matedit" / "__init__.py").is_file():
        raise SystemExit(f"{tree}: not a matedit checkout")
    graphs = DATA / "graphs"
    if not args.renders_only:
        if graphs.exists():
            shutil.rmtree(graphs)
        for sub in ("materials", "layers", "functions"):
            shutil.copytree(tree / "graphs" / sub, graphs / sub)
    frames: dict[str, np.ndarray] = {}
    with tempfile.TemporaryDirectory() as tmp:
        env = render_env(tree, str(Path(tmp) / "cache"))
        for graph in sorted((graphs / "materials").glob("*.json")):
            frames[graph.stem] = render(tree, graph, Path(tmp) / "a.exr", env)
            if args.repeat:
                again = render(tree, graph, Path(tmp) / "b.exr", env)
                print(f"{graph.stem}: run-to-run max |diff| "
                      f"{float(np.abs(again - frames[graph.stem]).max()):.3g}")
    np.savez_compressed(DATA / "renders.npz", **frames)
    size = sum(p.stat().st_size for p in DATA.rglob("*") if p.is_file())
    print(f"{len(frames)} renders -> {DATA / 'renders.npz'}; folder {size / 1024:.0f} KiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
