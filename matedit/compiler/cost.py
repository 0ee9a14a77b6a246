"""What a compiled material costs, read from its SPIR-V disassembly (`spirv-dis` text).

Pure: no GL, no Qt, no subprocess; `matedit.commands.stats` runs the tools and hands the text
here. Two things are read:

* `count`: the figures of a whole module: instructions in function bodies by class (ALU,
  texture, memory, control), texture samples, the samplers and interface inputs the code
  reads.
* `attribute`: the same instructions split by owner. The module is compiled with glslang's
  `-gV` (NonSemantic.Shader.DebugInfo.100) and optimised with `spirv-opt -O`, which keeps the
  debug scopes through inlining: every instruction carries its line and the chain of call
  sites it was inlined through (`DebugScope` / `DebugInlinedAt`). The caller's `owner`
  function maps that chain (innermost line first) to a key; `None` is the caller's
  "unattributed" key. Lines are matedit's encoded `#line` numbers (source * 100000 + line,
  `matedit.glsl.include`), so a line says which file it is in.

Both take optional `weights` (`matedit.compiler.trips`): how many times each instruction runs,
so a loop counts once per iteration (dynamic counts); without them each instruction counts
once (static). Owners' figures sum to the module's either way. Code that
spirv-opt shares between nodes (a common subexpression, a hoisted load) keeps the location
of the copy it kept; `attribute` splits it evenly between that owner and the others that use
its value without being fed by it (the caller says which uses are inputs). Code folded to a
constant is no instruction at all and costs nothing. Owner keys are paths, 'root/inner/...':
keys with the same root (the part before the first '/') are one owner's.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

# Opcodes that are not executed work: structure, declarations, debug information.
_SKIP = frozenset({
    "OpLabel", "OpVariable", "OpPhi", "OpSelectionMerge", "OpLoopMerge", "OpLine", "OpNoLine",
    "OpFunction", "OpFunctionParameter", "OpFunctionEnd", "OpUnreachable", "OpUndef",
})
_MEMORY = frozenset({
    "OpLoad", "OpStore", "OpAccessChain", "OpInBoundsAccessChain", "OpCopyMemory",
    "OpCopyObject", "OpSampledImage", "OpImage",
})
_CONTROL = frozenset({
    "OpBranch", "OpBranchConditional", "OpSwitch", "OpReturn", "OpReturnValue", "OpKill",
    "OpTerminateInvocation", "OpDemoteToHelperInvocation", "OpFunctionCall",
})
# Texture instructions; the first group are samples (they read texels).
_SAMPLE = re.compile(r"OpImage(Sparse)?(Sample\w*|Fetch|Gather|DrefGather|Read)$")
_TEXTURE = re.compile(r"OpImage(Sparse)?\w*$")

_INSTR = re.compile(r"^\s*(?:(%[\w.]+)\s*=\s*)?(Op\w+)(.*)$")


@dataclass
class Figures:
    """Instruction counts of a module or of one owner's share of it."""

    alu: int = 0
    texture: int = 0
    memory: int = 0
    control: int = 0
    samples: int = 0

    @property
    def instructions(self) -> int:
        return self.alu + self.texture + self.memory + self.control

    def add(self, cls: str, sample: bool, n: int = 1) -> None:
        setattr(self, cls, getattr(self, cls) + n)
        if sample:
            self.samples += n

    def as_dict(self) -> dict[str, int]:
        return {"instructions": self.instructions, "alu": self.alu, "texture": self.texture,
                "memory": self.memory, "control": self.control, "samples": self.samples}


@dataclass
class Module:
    """The parts of a disassembled module that counting needs."""

    body: list[tuple[str | None, str, list[str]]]  # (result id, opcode, operands) in functions
    constants: dict[str, int] = field(default_factory=dict)  # integer constants by id
    storage: dict[str, str] = field(default_factory=dict)  # global variable -> storage class
    builtins: set[str] = field(default_factory=set)  # ids decorated BuiltIn
    debug_sets: set[str] = field(default_factory=set)  # ids of NonSemantic imports
    inlined: dict[str, tuple[int, str | None]] = field(default_factory=dict)  # DebugInlinedAt
    ext: dict[str, str] = field(default_factory=dict)  # OpExtInst result id -> its instruction
    globals: list[tuple[str | None, str, list[str]]] = field(default_factory=list)  # the rest


def parse(text: str) -> Module:
    """A module from `spirv-dis` output (friendly or raw ids)."""
    m = Module([])
    in_function = False
    for line in text.splitlines():
        hit = _INSTR.match(line)
        if not hit:
            continue
        rid, op, rest = hit.group(1), hit.group(2), hit.group(3)
        args = _operands(rest)
        if op == "OpFunction":
            in_function = True
        if in_function:
            m.body.append((rid, op, args))
            if op == "OpFunctionEnd":
                in_function = False
            continue
        m.globals.append((rid, op, args))
        if op == "OpExtInstImport" and args and args[0].startswith('"NonSemantic.'):
            m.debug_sets.add(rid or "")
        elif op == "OpConstant" and rid and len(args) >= 2:
            try:
                m.constants[rid] = int(args[1])
            except ValueError:
                pass
        elif op == "OpVariable" and rid and len(args) >= 2:
            m.storage[rid] = args[1]
        elif op == "OpDecorate" and len(args) >= 2 and args[1] == "BuiltIn":
            m.builtins.add(args[0])
        elif op == "OpExtInst" and rid and len(args) >= 3 and args[1] in m.debug_sets:
            m.ext[rid] = args[2]
            if args[2] == "DebugInlinedAt" and len(args) >= 5:
                m.inlined[rid] = (m.constants.get(args[3], -1),
                                  args[5] if len(args) > 5 else None)
    return m


def _operands(rest: str) -> list[str]:
    """Operands of one instruction; a quoted string stays one operand."""
    out: list[str] = []
    for tok in re.finditer(r'"(?:[^"\\]|\\.)*"|\S+', rest):
        out.append(tok.group(0))
    return out


def _classify(op: str) -> tuple[str, bool] | None:
    """(class, is a sample) of an executed opcode, or None for one that is not work."""
    if op in _SKIP:
        return None
    if op in _MEMORY:
        return "memory", False
    if op in _CONTROL:
        return "control", False
    if _TEXTURE.match(op) and op not in ("OpImage",):
        return "texture", bool(_SAMPLE.match(op))
    return "alu", False


def _is_debug(m: Module, op: str, args: list[str]) -> bool:
    return op == "OpExtInst" and len(args) >= 2 and args[1] in m.debug_sets


@dataclass
class Totals:
    figures: Figures
    samplers: int  # UniformConstant images/samplers the code reads
    inputs: int  # interface inputs (varyings) the code reads, built-ins excluded
    outputs: int


def count(m: Module, weights: list[int] | None = None) -> Totals:
    """The module's figures; with `weights` (`trips.weights`), each instruction counts as many
    times as it runs."""
    fig = Figures()
    loaded: set[str] = set()
    stored: set[str] = set()
    for i, (_, op, args) in enumerate(m.body):
        if _is_debug(m, op, args):
            continue
        c = _classify(op)
        if c is None:
            continue
        fig.add(*c, 1 if weights is None else weights[i])
        if op == "OpLoad" and len(args) >= 2:
            loaded.add(args[1])
        elif op in ("OpAccessChain", "OpInBoundsAccessChain") and len(args) >= 2:
            loaded.add(args[1])
        elif op == "OpStore" and args:
            stored.add(args[0])
    samplers = sum(1 for v in loaded if m.storage.get(v) == "UniformConstant")
    inputs = sum(1 for v in loaded if m.storage.get(v) == "Input" and v not in m.builtins)
    outputs = sum(1 for v in stored if m.storage.get(v) == "Output" and v not in m.builtins)
    return Totals(fig, samplers, inputs, outputs)


def chain_of(m: Module, line: int | None, inlined_at: str | None) -> list[int]:
    """The instruction's line, then each call site it was inlined through, innermost first."""
    out = [] if line is None else [line]
    seen = 0
    while inlined_at is not None and inlined_at in m.inlined and seen < 256:
        site, inlined_at = m.inlined[inlined_at]
        out.append(site)
        seen += 1
    return out


@dataclass
class Owned:
    """One instruction of a function body with its owner: `cls` is (class, is a sample) of
    an executed one, None for one that only passes values on (a phi)."""

    key: str | None
    cls: tuple[str, bool] | None
    rid: str | None
    uses: list[str]
    runs: int = 1  # how many times it runs (`trips.weights`)


def owned(m: Module, owner: Callable[[list[int]], str | None],
          weights: list[int] | None = None) -> list[Owned]:
    """Every instruction that computes or passes a value, with `owner(chain)`. The current
    line and scope carry across block boundaries within a function (spirv-opt leaves the
    first instructions of a merge block, phis and loads, without a scope of their own)."""
    out: list[Owned] = []
    line: int | None = None
    scope_inlined: str | None = None
    cache: dict[tuple[int | None, str | None], str | None] = {}
    for i, (rid, op, args) in enumerate(m.body):
        if op == "OpFunction":
            line, scope_inlined = None, None
            continue
        if op == "OpLine" and len(args) >= 2:
            line = _int(args[1])
            continue
        if _is_debug(m, op, args):
            what = args[2] if len(args) > 2 else ""
            if what == "DebugLine" and len(args) >= 5:
                line = m.constants.get(args[4], line)
            elif what == "DebugScope":
                scope_inlined = args[4] if len(args) > 4 else None
            continue
        c = _classify(op)
        if c is None and op != "OpPhi":
            continue
        key = (line, scope_inlined)
        if key not in cache:
            cache[key] = owner(chain_of(m, line, scope_inlined))
        out.append(Owned(cache[key], c, rid, [a for a in args if a.startswith("%")],
                         1 if weights is None else weights[i]))
    return out


def attribute(m: Module, owner: Callable[[list[int]], str | None],
              shared: Callable[[str, str], bool] | None = None,
              weights: list[int] | None = None) -> dict[str | None, dict]:
    """Each executed instruction's figures (floats) under its owner. With `shared`, an
    instruction owned by a node whose value another owner also uses, where `shared(own,
    other)` says that use is not the other's own input (spirv-opt merged two copies of the
    same code), is split evenly between its owner and those others, with the instructions
    of the owner that compute it. The split moves instructions between owners, never adds
    or drops one: the total is the module's. With `weights`, each instruction counts as many
    times as it runs."""
    ins = owned(m, owner, weights)
    n = len(ins)
    sharers: list[frozenset[str]] = [frozenset()] * n
    if shared is not None:
        defs = {x.rid: i for i, x in enumerate(ins) if x.rid}
        users: list[list[int]] = [[] for _ in range(n)]
        for j, x in enumerate(ins):
            for u in x.uses:
                i = defs.get(u)
                if i is not None and i != j:
                    users[i].append(j)
        for i in range(n - 1, -1, -1):
            ki = ins[i].key
            if ki is None:
                continue  # the shading's own code stays the shading's
            found: set[str] = set()
            for j in users[i]:
                kj = ins[j].key
                if kj is None:
                    continue
                if not shared(ki, kj):
                    if kj == ki or _same_root(ki, kj):
                        found |= sharers[j]  # the owner's own chain: its sharers' too
                    continue
                found.add(kj)
            found.discard(ki)
            sharers[i] = frozenset(found)
    out: dict[str | None, dict] = {}
    for i, x in enumerate(ins):
        if x.cls is None:
            continue
        owners: list[str | None] = [x.key, *sorted(sharers[i])]
        w = x.runs / len(owners)
        cls, sample = x.cls
        for k in owners:
            f = out.setdefault(k, {"alu": 0.0, "texture": 0.0, "memory": 0.0,
                                   "control": 0.0, "samples": 0.0})
            f[cls] += w
            if sample:
                f["samples"] += w
    return out


def _same_root(a: str, b: str) -> bool:
    return a.split("/", 1)[0] == b.split("/", 1)[0]


def instructions(f: dict) -> float:
    """The instructions of one owner's figures from `attribute`."""
    return f["alu"] + f["texture"] + f["memory"] + f["control"]


def _int(text: str) -> int | None:
    try:
        return int(text)
    except ValueError:
        return None
