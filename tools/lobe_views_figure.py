"""docs/figures/lobe_views.png: samples rendered by `matedit render --view`, labelled.

    .venv/bin/python tools/lobe_views_figure.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "figures" / "lobe_views.png"
TILE = 160
# (sample, view, label), four a row
TILES = [
    ("car_paint", "lit", "Car paint: lit"), ("car_paint", "base", "base only"),
    ("car_paint", "coat", "coat only"), ("car_paint", "specular", "specular only"),
    ("velvet", "lit", "Velvet: lit"), ("velvet", "sheen", "sheen only"),
    ("brushed_steel", "lit", "Brushed steel: lit"),
    ("brushed_steel", "anisotropy", "anisotropy direction"),
    ("skin", "lit", "Skin: lit"), ("skin", "subsurface", "subsurface only"),
    ("honey", "lit", "Honey: lit"), ("honey", "transmission", "transmission only"),
    ("soap_bubble", "lit", "Soap bubble: lit"), ("soap_bubble", "transmission",
                                                 "transmission only"),
    ("oil_slick_metal", "lit", "Oil slick: lit"), ("oil_slick_metal", "thin-film",
                                                   "film thickness"),
]


def main() -> int:
    import numpy as np
    import OpenImageIO as oiio

    from matedit.io.atomic import atomic_write_bytes
    from matedit.io.images import read_image

    with tempfile.TemporaryDirectory() as tmp:
        tiles = []
        for sample, view, _ in TILES:
            png = Path(tmp) / f"{sample}_{view}.png"
            subprocess.run([sys.executable, "-m", "matedit", "render",
                            str(ROOT / "graphs" / "materials" / f"{sample}.json"),
                            "--view", view, "-o", str(png), "--size", f"{TILE}x{TILE}"],
                           check=True, cwd=ROOT)
            tiles.append(read_image(png).pixels[..., :3])
        rows = [np.concatenate(tiles[i:i + 4], 1) for i in range(0, len(tiles), 4)]
        img = np.concatenate(rows, 0).astype(np.float32)
        h, w, _ = img.shape
        buf = oiio.ImageBuf(oiio.ImageSpec(w, h, 3, oiio.FLOAT))
        buf.set_pixels(oiio.ROI(0, w, 0, h, 0, 1, 0, 3), img)
        for i, (_, _, label) in enumerate(TILES):
            oiio.ImageBufAlgo.render_text(buf, (i % 4) * TILE + 6, (i // 4) * TILE + TILE - 6,
                                          label, 13, "", [1, 1, 1])
        made = Path(tmp) / "figure.png"
        buf.write(str(made))
        atomic_write_bytes(OUT, made.read_bytes())
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
