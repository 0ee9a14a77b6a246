"""Writes docs/materialx.md, the MaterialX mapping of every catalogue kind, from the catalogue,
and its import tally of MaterialX's example documents (tests/mtlx_examples.py).

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

if __name__ == "__main__":
    atomic_write_text(ROOT / "docs" / "materialx.md", document() + "\n" + section())
    print(ROOT / "docs" / "materialx.md")
