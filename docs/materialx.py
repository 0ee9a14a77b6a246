"""Writes docs/materialx.md, the MaterialX mapping of every catalogue kind, from the catalogue,
and its import tally of MaterialX's example documents (tests/mtlx_examples.py), keeping
its measured `## Round trip` section at the end (tools/roundtrip_table.py writes it).

    .venv/bin/python docs/materialx.py
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from matedit.interop.mtlx_map import document  # noqa: E402
from matedit.io.atomic import atomic_write_text  # noqa: E402
from tests.mtlx_examples import section  # noqa: E402

# The measured section after the generated part (tools/roundtrip_table.py writes it): kept.
MEASURED = "\n## Round trip\n"

if __name__ == "__main__":
    path = ROOT / "docs" / "materialx.md"
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    tail = old[old.find(MEASURED):] if MEASURED in old else ""
    atomic_write_text(path, document() + "\n" + section() + tail)
    print(ROOT / "docs" / "materialx.md")
