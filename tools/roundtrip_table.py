"""The round-trip table of docs/materialx.md (`## Round trip`): `matedit export --check` of
every sample in graphs/materials to .mtlx, .glb and .usda, at the sizes below, its mean and max
CIEDE2000 per sample.

    python tools/roundtrip_table.py            # print the table
    python tools/roundtrip_table.py --write    # and replace the section in docs/materialx.md

tests/test_export_check.py reads the table back and holds a few samples to it."""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "materialx.md"
HEADING = "## Round trip"
BAKE_SIZE = 64
RENDER_SIZE = 64
FORMATS = (".mtlx", ".glb", ".usda")
LINE = re.compile(r"round trip: mean ΔE ([\d.]+) max ΔE ([\d.]+)")


def measure(sample: Path, suffix: str, folder: Path) -> tuple[float, float] | str:
    """(mean, max) ΔE00 of `matedit export SAMPLE -o OUT{suffix} --check` at the table's
    sizes, or the export's own `error:` line when the format cannot take the sample."""
    out = folder / f"{sample.stem}{suffix}"
    r = subprocess.run([sys.executable, "-m", "matedit", "export", str(sample), "-o", str(out),
                        "--size", str(BAKE_SIZE), "--check", "--check-size",
                        str(RENDER_SIZE)], capture_output=True, text=True, cwd=ROOT)
    m = LINE.search(r.stderr)
    if r.returncode == 2 and r.stderr.startswith("error: ") and "--check" not in r.stderr:
        return r.stderr.strip().removeprefix("error: ")
    if r.returncode != 0 or m is None:
        raise SystemExit(f"{sample.name} {suffix}: {r.stderr.strip()[-400:]}")
    return float(m.group(1)), float(m.group(2))


def table(samples: list[Path]) -> str:
    rows = ["| sample | " + " | ".join(f"{s} {w}" for s in FORMATS for w in ("mean", "max"))
            + " |", "|---" * (1 + 2 * len(FORMATS)) + "|"]
    refused = []
    with tempfile.TemporaryDirectory() as tmp:
        for s in samples:
            cells = []
            for suffix in FORMATS:
                folder = Path(tmp) / suffix.lstrip(".") / s.stem
                folder.mkdir(parents=True)
                got = measure(s, suffix, folder)
                if isinstance(got, str):
                    cells += ["no export", "no export"]
                    refused.append(f"`{s.stem}` to `{suffix}`: {got.split(': ', 1)[-1]}")
                else:
                    cells += [f"{got[0]:.2f}", f"{got[1]:.2f}"]
            rows.append(f"| `{s.stem}` | " + " | ".join(cells) + " |")
            print(rows[-1], file=sys.stderr)
    notes = "".join(f"\n\nNo export: {r}" for r in refused)
    return "\n".join(rows) + notes


def section(body: str) -> str:
    return f"""{HEADING}

`matedit export FILE -o OUT --check` reads what it wrote back (MaterialX through the
importer; glTF as its own baked maps on a metallic-roughness material; USD as its
UsdPreviewSurface on its own maps), renders the original and the round trip alike and prints
their CIEDE2000 difference on the display image, over the pixels the mesh covers
(docs/cli.md, `export`). Every sample, exported with the defaults (MaterialX:
`open_pbr_surface`, PNG maps) at `--size {BAKE_SIZE}` and rendered at `--check-size
{RENDER_SIZE}` (sphere, studio): mean and max ΔE00.
Made by `python tools/roundtrip_table.py --write`; tests/test_export_check.py holds a few
samples within 1.5 times their row.

A mean ΔE00 under about 1 is a difference hard to see side by side. What the figures hold:
the maps baked at {BAKE_SIZE} texels (a pattern finer than that is lost, in both formats
where MaterialX bakes a node), what glTF has no place for (lobe fields that vary over the
surface go out as their means, subsurface is dropped; the export's `note:` lines name them),
what UsdPreviewSurface has no input for (every lobe but the coat and the IOR: the USD
column is what a viewer of the preview network draws; the asset's MaterialX network
carries the rest but is not read back) and what the MaterialX importer approximates (its
`note: ... round trip import:` lines).
The max is a few pixels, mostly at highlights and silhouettes.

{body}
"""


def replace_section(text: str, new: str) -> str:
    start = text.find(HEADING + "\n")
    if start < 0:
        return text.rstrip("\n") + "\n\n" + new
    nxt = text.find("\n## ", start + len(HEADING))
    return text[:start] + new + (text[nxt + 1:] if nxt >= 0 else "")


def read_table(text: str) -> dict[str, dict[str, tuple[float, float]]]:
    """sample -> {suffix: (mean, max)} from the doc's table."""
    out = {}
    start = text.find(HEADING + "\n")
    for line in text[start:].splitlines():
        m = re.match(r"\| `([\w-]+)` \|" + r" ([\d.]+|no export) \|" * (2 * len(FORMATS)),
                     line)
        if m:
            v = [None if x == "no export" else float(x) for x in m.groups()[1:]]
            out[m.group(1)] = {suffix: (v[2 * i], v[2 * i + 1])
                               for i, suffix in enumerate(FORMATS) if v[2 * i] is not None}
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--write", action="store_true", help="replace the section in the doc")
    ap.add_argument("samples", nargs="*", help="sample names (default: all)")
    args = ap.parse_args()
    folder = ROOT / "graphs" / "materials"
    samples = sorted(folder.glob("*.json"))
    if args.samples:
        samples = [folder / f"{n}.json" for n in args.samples]
    body = table(samples)
    print(body)
    if args.write:
        from matedit.io.atomic import atomic_write_text

        atomic_write_text(DOC, replace_section(DOC.read_text(), section(body)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
