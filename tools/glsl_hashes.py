"""The sha256 of the generated GLSL of every sample graph, per (sample, target, entry).

    python tools/glsl_hashes.py           print the hashes as JSON
    python tools/glsl_hashes.py --regen   rewrite tests/data/glsl_hashes.json
    python tools/glsl_hashes.py --check   compare with tests/data/glsl_hashes.json

tests/test_glsl_stable.py checks that the generated text has not changed. A change that is
meant to change it (shading work, a new entry) reruns this with --regen and commits the file.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HASHES = ROOT / "tests" / "data" / "glsl_hashes.json"


def samples() -> list[Path]:
    """Every sample material, layer and instance under graphs/ (functions and layers are
    material functions, compiled through the materials that call them)."""
    from matedit.resources import graphs_dir

    root = graphs_dir()
    return sorted(p for sub in ("materials", "layers", "instances")
                  for p in (root / sub).glob("*.json"))


def compute() -> dict[str, str]:
    from matedit.compiler.api import compile_document
    from matedit.compiler.schedule import Entry
    from matedit.compiler.targets import TARGETS
    from matedit.io.document import FileResolver
    from matedit.io.instance import load_effective
    from matedit.resources import graphs_dir

    root = graphs_dir()
    out: dict[str, str] = {}
    for path in samples():
        doc, _ = load_effective(path)
        if doc.is_function:  # a layer: compiled through the materials that stack it
            continue
        name = path.relative_to(root).as_posix()
        resolver = FileResolver()
        for target in TARGETS:
            base = compile_document(doc, resolver, target, Entry.FORWARD)
            for entry in Entry:
                c = base.variant(entry)
                text = c.vertex_text + "\0" + c.fragment_text + "\0" + \
                    json.dumps(c.reflection(), sort_keys=True)
                out[f"{name} {target} {entry.value}"] = hashlib.sha256(text.encode()).hexdigest()
    return out


def main(argv: list[str]) -> int:
    now = compute()
    if "--regen" in argv:
        HASHES.write_text(json.dumps(now, indent=1, sort_keys=True) + "\n")
        print(f"wrote {len(now)} hashes to {HASHES.relative_to(ROOT)}")
        return 0
    if "--check" in argv:
        was = json.loads(HASHES.read_text())
        changed = sorted(k for k in was.keys() | now.keys() if was.get(k) != now.get(k))
        for k in changed:
            print("changed:", k)
        print(f"{len(now)} hashes, {len(changed)} changed")
        return 1 if changed else 0
    print(json.dumps(now, indent=1, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main(sys.argv[1:]))
