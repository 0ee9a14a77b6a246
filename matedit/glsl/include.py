"""A small `#include` mechanism for GLSL that keeps `#line` mapping.

`#include "name.glsl"` is resolved relative to the including file, then to the
library roots. Each file is spliced once (like `#pragma once`). Every spliced
run of lines is preceded by `#line L S`, where S is the file's source-string
number and L = S * LINE_STRIDE + N encodes the source in the line as well: Mesa
loses the source number of many diagnostics (its parser's default location
resets it to 0) but always keeps the line. `Assembly.locate` / `map_log` turn a
driver's `S:L` back into `file:N` (GLSL >= 330 / ESSL 300 `#line` semantics).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from matedit.resources import shaders_dir

_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
# Locations at the start of a log line: Mesa "0:12(3): error: ...", glslang
# "ERROR: 0:12: ...", NVIDIA-style "0(12) : error ...". Anchored so that code quoted
# inside a message (say `vec3(1)`) is never rewritten.
_ERROR_LOC = re.compile(
    r"^(?P<lead>\s*(?:(?:ERROR|WARNING|error|warning):\s*)?)"
    r"(?:(?P<src>\d+):(?P<line>\d+)(?=\(\d+\)|:)|(?P<src3>\d+)\((?P<line3>\d+)\))",
    re.MULTILINE,
)
# Lines per source string in the encoded `#line` numbers (files are far shorter).
LINE_STRIDE = 100_000
# packHalf2x16 and friends are GLSL 4.20 (ESSL 3.00): at GLSL 3.30 a shader that uses them
# (shaders/gbuffer.glsl) has this ahead of every declaration, in its prelude.
PACKING_EXTENSION = "#extension GL_ARB_shading_language_packing : require"


def _desktop_before(version: str, core: int) -> bool:
    """Whether `version` (a #version argument) is desktop GLSL older than `core`."""
    return not version.endswith(" es") and int(version.split()[0]) < core


def packing_prelude(version: str) -> str:
    """PACKING_EXTENSION where `version` (a #version argument) lacks the packing functions,
    else nothing."""
    return PACKING_EXTENSION if _desktop_before(version, 420) else ""


# GL_ARB_derivative_control's macro is defined wherever a compiler knows the extension, its
# functions only once enabled: the define says this prelude enabled it.
DERIVATIVE_EXTENSION = ("#extension GL_ARB_derivative_control : enable\n"
                        "#define MATEDIT_DERIVATIVE_CONTROL 1")


def derivative_prelude(version: str) -> str:
    """DERIVATIVE_EXTENSION where `version` is desktop GLSL before 4.50 (dFdxFine is core
    from 4.50; ESSL 3.00 has no fine derivatives), else nothing. `enable`, not `require`:
    where the driver lacks it, shaders/layer_guard.glsl evaluates every layer."""
    return DERIVATIVE_EXTENSION if _desktop_before(version, 450) else ""


def _line_directive(line: int, source: int) -> str:
    """`#line` making the next line `line` of source string `source`, source also encoded."""
    return f"#line {source * LINE_STRIDE + line} {source}"


class IncludeError(Exception):
    """A missing or circular include, naming the file and line that asked for it."""


@dataclass
class Assembly:
    """GLSL text with its provenance: source-string number -> file name."""

    text: str
    sources: list[str] = field(default_factory=list)

    def locate(self, source: int, line: int) -> tuple[str, int]:
        """(file, line) of a driver's (source string, line); the line's encoding wins."""
        if line >= LINE_STRIDE:
            source, line = divmod(line, LINE_STRIDE)
        if 0 <= source < len(self.sources):
            return self.sources[source], line
        return f"<source {source}>", line

    def map_log(self, log: str) -> str:
        """Rewrite the `S:N` location that starts each compiler log line as `file:N`."""

        def repl(m: re.Match) -> str:
            src = m.group("src") or m.group("src3")
            line = m.group("line") or m.group("line3")
            name, n = self.locate(int(src), int(line))
            return f"{m.group('lead')}{name}:{n}"

        return _ERROR_LOC.sub(repl, log)


@dataclass(frozen=True)
class _Parsed:
    """A file's lines split at its `#include` lines: `chunks[k]` is the text (lines joined by
    newlines, None when there are none) before include k, `includes[k]` its (line number,
    name)."""

    chunks: tuple[str | None, ...]
    includes: tuple[tuple[int, str], ...]


def _parse(text: str) -> _Parsed:
    if "include" not in text:  # generated text: one chunk, no line to look at
        lines = text.splitlines()
        return _Parsed(("\n".join(lines) if lines else None,), ())
    chunks: list[str | None] = []
    includes: list[tuple[int, str]] = []
    run: list[str] = []
    for i, line in enumerate(text.splitlines(), start=1):
        m = _INCLUDE.match(line) if "include" in line else None
        if m is None:
            run.append(line)
            continue
        chunks.append("\n".join(run) if run else None)
        includes.append((i, m.group(1)))
        run = []
    chunks.append("\n".join(run) if run else None)
    return _Parsed(tuple(chunks), tuple(includes))


# Library files parsed once per version of the file: (mtime_ns, size) -> its parse. Every
# compile splices the same few dozen files, so a structural edit re-reads none of them; an
# edited shader (a new mtime or size) is read again.
_FILES: dict[Path, tuple[int, int, _Parsed]] = {}
# Where an include name was found, and a file's name relative to the roots: the lookups are
# stat and resolve calls, and the same few dozen repeat on every compile.
_FOUND: dict[tuple[str, Path | None, tuple[Path, ...]], Path] = {}
_NAMES: dict[tuple[Path, tuple[Path, ...]], str] = {}


def _parsed_file(path: Path) -> _Parsed:
    st = path.stat()
    hit = _FILES.get(path)
    if hit is not None and hit[0] == st.st_mtime_ns and hit[1] == st.st_size:
        return hit[2]
    parsed = _parse(path.read_text())
    _FILES[path] = (st.st_mtime_ns, st.st_size, parsed)
    return parsed


class Assembler:
    """Splices includes; one instance per generated shader (source numbering is per shader)."""

    def __init__(self, roots: list[Path] | None = None, first_source: int = 0) -> None:
        self.roots = [Path(r) for r in (roots or [shaders_dir()])]
        self.sources: list[str] = [f"<generated {i}>" for i in range(first_source)]
        self._seen: set[Path] = set()

    def _name(self, path: Path) -> str:
        key = (path, tuple(self.roots))
        if key not in _NAMES:
            _NAMES[key] = self._relative_name(path)
        return _NAMES[key]

    def _relative_name(self, path: Path) -> str:
        for root in self.roots:
            try:
                return path.resolve().relative_to(root.resolve()).as_posix()
            except ValueError:
                continue
        return str(path)

    def _resolve(self, name: str, base: Path | None, where: str) -> Path:
        key = (name, base, tuple(self.roots))
        found = _FOUND.get(key)
        if found is not None:
            return found
        candidates = ([base / name] if base else []) + [r / name for r in self.roots]
        for c in candidates:
            if c.is_file():
                _FOUND[key] = c.resolve()
                return _FOUND[key]
        raise IncludeError(f'{where}: cannot find include "{name}"')

    def source_number(self, name: str) -> int:
        self.sources.append(name)
        return len(self.sources) - 1

    def include(self, name: str) -> str:
        """The text of a library file (and what it includes), if not already spliced."""
        return self._splice(self._resolve(name, None, "<assembler>"), stack=())

    def expand(self, text: str, name: str, base: Path | None = None) -> str:
        """Expand includes inside generated text, numbering it as its own source string."""
        return self._expand_lines(text, name, base, stack=())

    def _splice(self, path: Path, stack: tuple[Path, ...]) -> str:
        if path in stack:
            chain = " -> ".join(self._name(p) for p in (*stack, path))
            raise IncludeError(f"circular include: {chain}")
        if path in self._seen:
            return ""
        self._seen.add(path)
        try:
            parsed = _parsed_file(path)
        except OSError as e:  # found once, gone (or unreadable) now: look again next time
            _FOUND.clear()
            raise IncludeError(f"cannot read include {self._name(path)}: {e.strerror}") from e
        return self._expand(parsed, self._name(path), path.parent, (*stack, path))

    def _expand_lines(self, text: str, name: str, base: Path | None, stack: tuple) -> str:
        return self._expand(_parse(text), name, base, stack)

    def _expand(self, parsed: _Parsed, name: str, base: Path | None, stack: tuple) -> str:
        src = self.source_number(name)
        out = [_line_directive(1, src)]
        if parsed.chunks[0] is not None:
            out.append(parsed.chunks[0])
        for (i, target_name), chunk in zip(parsed.includes, parsed.chunks[1:]):
            target = self._resolve(target_name, base, f"{name}:{i}")
            spliced = self._splice(target, stack)
            if spliced:
                out.append(spliced)
            # Back in this file: the next line is line i + 1 (GLSL >= 330 semantics).
            out.append(_line_directive(i + 1, src))
            if chunk is not None:
                out.append(chunk)
        return "\n".join(out)

    def assembly(self, text: str) -> Assembly:
        return Assembly(text=text, sources=list(self.sources))


def assemble(
    body: str,
    version: str = "330 core",
    includes: list[str] | None = None,
    name: str = "<main>",
    roots: list[Path] | None = None,
    prelude: str = "",
) -> Assembly:
    """`#version`, an optional prelude (defines, precision), library includes, then `body`."""
    asm = Assembler(roots)
    parts = [f"#version {version}"]
    if prelude:
        parts.append(asm.expand(prelude, "<prelude>"))
    for inc in includes or []:
        spliced = asm.include(inc)
        if spliced:
            parts.append(spliced)
    parts.append(asm.expand(body, name))
    return asm.assembly("\n".join(parts) + "\n")
