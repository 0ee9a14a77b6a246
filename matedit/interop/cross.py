"""HLSL and MSL from the Vulkan GLSL (glsl450) target: glslangValidator compiles it to SPIR-V,
spirv-val checks the SPIR-V, spirv-cross writes HLSL (shader model 5.0) or MSL (2.0).

The SPIR-V keeps our set-0 binding numbers (see `matedit.compiler.targets`); HLSL registers
follow them (b5 FrameBlock, b6 MaterialParams, t7/s7 the first texture) and MSL keeps them
as buffer/texture/sampler indices (`--msl-decoration-binding`). The bindings each target ends
up with are read back from the generated source and recorded in the reflection.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from matedit.io.atomic import atomic_write_text, read_bounded

# Tool -> the Debian package that installs it.
TOOLS = {"glslangValidator": "glslang-tools", "spirv-val": "spirv-tools",
         "spirv-cross": "spirv-cross"}
_ARGS = {"hlsl": ["--hlsl", "--shader-model", "50"],
         "msl": ["--msl", "--msl-version", "20000", "--msl-decoration-binding"]}
_LIMIT = 64 << 20
_TIMEOUT = 120


class CrossCompileError(RuntimeError):
    """A tool is missing, or one of them rejected the shader (the message carries its log)."""


def tool(name: str) -> str:
    found = shutil.which(name)
    if not found:
        pkg = TOOLS[name]
        raise CrossCompileError(f"{name} not found: HLSL and MSL need it; install the Debian "
                                f"package {pkg} (apt-get install {pkg})")
    return found


def available() -> bool:
    """Whether every tool the HLSL/MSL targets need is installed."""
    return all(shutil.which(t) for t in TOOLS)


def _run(args: list[str], what: str) -> None:
    try:
        r = subprocess.run(args, capture_output=True, text=True, timeout=_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise CrossCompileError(f"{what}: {Path(args[0]).name} timed out") from None
    if r.returncode != 0:
        log = " ".join((r.stdout + r.stderr).split())[:400]
        raise CrossCompileError(f"{what}: {Path(args[0]).name} failed: {log}")


def to_spirv(text: str, stage: str, folder: Path, hlsl: bool = False) -> Path:
    """Compile GLSL (or HLSL) of `stage` ('vert'|'frag') to a validated SPIR-V file."""
    src = folder / f"{stage}.{'hlsl' if hlsl else 'glsl'}"
    spv = folder / f"{stage}{'.hlsl' if hlsl else ''}.spv"
    atomic_write_text(src, text)
    args = [tool("glslangValidator"), "-V", "-S", stage, "-o", str(spv)]
    if hlsl:
        args += ["-D", "-e", "main"]
    _run([*args, str(src)], f"{stage} stage to SPIR-V")
    _run([tool("spirv-val"), str(spv)], f"{stage} stage SPIR-V validation")
    return spv


def spirv_to(spv: Path, target: str, folder: Path) -> str:
    out = folder / f"{spv.stem}.{target}"
    _run([tool("spirv-cross"), str(spv), *_ARGS[target], "--output", str(out)],
         f"{spv.stem} stage to {target.upper()}")
    return read_bounded(out, _LIMIT).decode("utf-8")


_HLSL_RES = re.compile(r"^\s*(?:cbuffer\s+(\w+)|[\w<>]+\s+(\w+))\s*:\s*register\((\w)(\d+)\)",
                       re.M)
_MSL_RES = re.compile(r"(\w+)\s+\[\[(buffer|texture|sampler)\((\d+)\)\]\]")


def hlsl_bindings(text: str) -> list[dict[str, Any]]:
    return [{"name": m.group(1) or m.group(2), "register": f"{m.group(3)}{m.group(4)}"}
            for m in _HLSL_RES.finditer(text)]


def msl_bindings(text: str) -> list[dict[str, Any]]:
    entry = next((ln for ln in text.splitlines()
                  if ln.startswith(("vertex ", "fragment "))), "")
    return [{"name": m.group(1), "kind": m.group(2), "index": int(m.group(3))}
            for m in _MSL_RES.finditer(entry)]


@dataclass
class CrossCompiled:
    """One material in HLSL or MSL, with the glsl450 compile it came from."""

    target: str
    vertex_text: str
    fragment_text: str
    base: Any  # CompiledMaterial (glsl450)
    bindings: dict[str, list[dict[str, Any]]] = field(default_factory=dict)

    def reflection(self) -> dict[str, Any]:
        r = self.base.reflection()
        r["target"] = self.target
        r["via"] = "glsl450 -> SPIR-V (glslangValidator) -> spirv-cross"
        r["bindings"] = self.bindings
        return r


_VERTEX_CACHE: dict[tuple[str, str], str] = {}  # (glsl450 vertex text, target) -> source


def _translate(text: str, stage: str, targets: list[str]) -> dict[str, str]:
    """One stage to every target: SPIR-V once, then spirv-cross per target in parallel."""
    from concurrent.futures import ThreadPoolExecutor

    with tempfile.TemporaryDirectory(prefix="matedit-cross-") as tmp:
        folder = Path(tmp)
        spv = to_spirv(text, stage, folder)
        if len(targets) == 1:
            return {targets[0]: spirv_to(spv, targets[0], folder)}
        with ThreadPoolExecutor(len(targets)) as pool:
            futures = {t: pool.submit(spirv_to, spv, t, folder) for t in targets}
            return {t: f.result() for t, f in futures.items()}


def cross_compile_many(base, targets: list[str]) -> dict[str, CrossCompiled]:
    """`base` is a glsl450 CompiledMaterial; returns its HLSL and/or MSL translations. The
    vertex stage is the same for every material, so its translation is kept per process."""
    for target in targets:
        if target not in _ARGS:
            raise ValueError(f"unknown cross target {target!r} (expected hlsl or msl)")
    if base.target != "glsl450":
        raise ValueError("cross compilation starts from the glsl450 target")
    missing = [t for t in targets if (base.vertex_text, t) not in _VERTEX_CACHE]
    if missing:
        for t, text in _translate(base.vertex_text, "vert", missing).items():
            _VERTEX_CACHE[(base.vertex_text, t)] = text
    frags = _translate(base.fragment_text, "frag", list(targets))
    out = {}
    for t in targets:
        parse = hlsl_bindings if t == "hlsl" else msl_bindings
        vert = _VERTEX_CACHE[(base.vertex_text, t)]
        out[t] = CrossCompiled(t, vert, frags[t], base,
                               {"vertex": parse(vert), "fragment": parse(frags[t])})
    return out


def check_hlsl(cc: CrossCompiled) -> None:
    """Compile the HLSL back to SPIR-V with glslang's HLSL front end and validate it."""
    with tempfile.TemporaryDirectory(prefix="matedit-hlsl-") as tmp:
        to_spirv(cc.vertex_text, "vert", Path(tmp), hlsl=True)
        to_spirv(cc.fragment_text, "frag", Path(tmp), hlsl=True)
