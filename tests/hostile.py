"""Shared machinery of the hostile-input suite: documents as raw JSON, the command line run
in-process, and the one rule every case must end in.

The rule: exit 0 with GLSL that passes glslangValidator for every target and contains no text
of the file, or exit 2 with every stderr line an `error: ...` line. Never a traceback, an
internal error (exit 1), or a hang (pytest-timeout ends a case after 20 s).
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import shutil
import subprocess
from pathlib import Path

GLSLANG = shutil.which("glslangValidator")
STAGE_FLAGS = {"glsl330": [], "glsl450": ["-V"], "essl300": []}

# A marker that must never reach generated code, in payloads that try to break out of a
# comment, a line, an identifier or a string.
MARK = "PWNED"
PAYLOADS = [
    f"x\n#error {MARK}\n",
    f"x\\\nfloat {MARK} = 1.0;",
    f"x */ float {MARK}; /*",
    f"x\r\n#define {MARK} 1",
    f"{MARK}\u2028#error",
    f"p\u00f6wer{MARK}",
    f"gl_{MARK}",
    f"a__{MARK}",
    f"{MARK}" + "x" * 300,
    f"void {MARK}() {{}}",
    f"{MARK}\x00nul",
    f"../../{MARK}",
]


_LIB: set[str] = set()


def _library() -> set[str]:
    """Lines of the shipped GLSL library (our own comments may use non-ASCII)."""
    if not _LIB:
        from matedit.resources import shaders_dir

        for f in shaders_dir().rglob("*.glsl"):
            _LIB.update(l.strip() for l in f.read_text(encoding="utf-8").splitlines())
    return _LIB


def base_material() -> dict:
    """color parameter -> make_attributes <- scalar parameter * constant; one comment."""
    return {
        "format": "matedit.material", "version": 2, "name": "m", "description": "d",
        "nodes": [
            {"id": "col", "kind": "color_parameter", "position": [0, 0],
             "settings": {"name": "tint"}, "values": {"value": [0.8, 0.2, 0.1]}},
            {"id": "r", "kind": "scalar_parameter", "position": [0, 100],
             "settings": {"name": "rough"}, "values": {"value": 0.4}},
            {"id": "m", "kind": "multiply", "position": [200, 100], "values": {"b": 0.5}},
            {"id": "make", "kind": "make_attributes", "position": [400, 0]},
            {"id": "out", "kind": "material_output", "position": [600, 0]},
        ],
        "links": [
            {"from": ["col", "color"], "to": ["make", "baseColor"]},
            {"from": ["r", "value"], "to": ["m", "a"]},
            {"from": ["m", "result"], "to": ["make", "roughness"]},
            {"from": ["make", "attributes"], "to": ["out", "attributes"]},
        ],
        "comments": [{"id": "c1", "text": "note", "rect": [0, 0, 10, 10],
                      "color": [0.3, 0.3, 0.3]}],
    }


def function_doc(inputs=(("a", "float"),), outputs=(("result", "float"),), body=None) -> dict:
    nodes = [{"id": f"i{k}", "kind": "function_input", "position": [0, 80 * k],
              "settings": {"name": n, "type": t, "default": 0.5}}
             for k, (n, t) in enumerate(inputs)]
    nodes += [{"id": f"o{k}", "kind": "function_output", "position": [300, 80 * k],
               "settings": {"name": n, "type": t}} for k, (n, t) in enumerate(outputs)]
    links = [{"from": ["i0", "value"], "to": ["o0", "value"]}] if body is None else body
    return {"format": "matedit.function", "version": 2, "name": "f", "nodes": nodes,
            "links": links}


def write(path: Path, raw: dict | str) -> Path:
    path.write_text(raw if isinstance(raw, str) else json.dumps(raw), encoding="utf-8")
    return path


def cli(*args: str) -> tuple[int, str, str]:
    """`matedit ARGS` in this process: (status, stdout, stderr)."""
    from matedit.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main([str(a) for a in args])
    return rc, out.getvalue(), err.getvalue()


def assert_clean_failure(rc: int, err: str) -> None:
    assert rc == 2, f"expected exit 2, got {rc}: {err}"
    lines = [l for l in err.splitlines() if l.strip()]
    assert lines, "exit 2 without an error line"
    assert all(l.startswith(("error: ", "warning: ")) for l in lines), err
    assert any(l.startswith("error: ") for l in lines), err
    assert "Traceback" not in err and "internal" not in err, err


def glslang_ok(frag: Path, target: str) -> tuple[bool, str]:
    args = [GLSLANG, "-S", "frag", *STAGE_FLAGS[target], str(frag)]
    if target == "glsl450":
        args += ["-o", str(frag.with_suffix(".spv"))]
    r = subprocess.run(args, capture_output=True, text=True, timeout=60)
    return r.returncode == 0, r.stdout[-2000:]


def check_compile(doc_path: Path, out_dir: Path, forbidden: list[str],
                  targets=("glsl330", "glsl450", "essl300")) -> int:
    """Validate and compile for all targets; assert the rule. Returns the compile status."""
    vrc, _, verr = cli("validate", doc_path)
    rc, _, err = cli("compile", doc_path, "-o", out_dir, "--target", "all")
    assert rc in (0, 2), f"compile exit {rc}: {err}"
    assert vrc in (0, 2), f"validate exit {vrc}: {verr}"
    # validate and compile agree: what validate accepts compiles, what it refuses does not
    assert (vrc == 0) == (rc == 0), f"validate {vrc} vs compile {rc}:\n{verr}\n{err}"
    if rc == 2:
        assert_clean_failure(rc, err)
        assert_clean_failure(vrc, verr)
        return rc
    stem = doc_path.name[:-5] if doc_path.name.endswith(".json") else doc_path.stem
    for target in targets:
        frag = out_dir / f"{stem}.{target}.frag"
        vert = out_dir / f"{stem}.{target}.vert"
        text = frag.read_text(encoding="utf-8") + vert.read_text(encoding="utf-8")
        odd = [l for l in text.splitlines() if not l.isascii() and l.strip() not in _library()]
        assert not odd, f"{frag}: non-ASCII text not from the shading library: {odd[:3]}"
        # A function's identifier is made from its file name, reduced to [A-Za-z0-9_] and
        # bounded: the one place a file's text may show, as a checked identifier.
        assert all(len(w) <= 64 for w in re.findall(r"\bfn_[A-Za-z0-9_]+", text))
        bare = re.sub(r"\bfn_[A-Za-z0-9_]+", "fn_", text)
        for word in forbidden:
            assert word not in bare, f"{frag}: file text {word!r} reached the GLSL"
        if GLSLANG:
            ok, log = glslang_ok(frag, target)
            assert ok, f"{frag} ({target}) fails glslang:\n{log}"
    refl = (out_dir / f"{stem}.reflection.json").read_text(encoding="utf-8")
    assert str(doc_path.parent.resolve()) not in refl and str(out_dir) not in refl
    return rc
