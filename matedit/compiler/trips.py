"""How many times each instruction of a SPIR-V module runs: loop trip counts for `cost`.

Pure. A static count sees a loop body once; a loop of 8 octaves costs 8 bodies. `weights`
walks each function's structured control flow (OpLoopMerge / OpSelectionMerge, as glslang and
spirv-opt emit it) and evaluates the scalar values it can: constants, the uniform block members
whose current values the caller gives (`values`, by OpMemberName: matedit's `u_<node>_<port>`),
and the integer, float, comparison and logic instructions computed from them. A branch on a
known value follows its one side; on an unknown one, both (each block is counted as if it ran,
like a static count). A loop runs iteration after iteration while a block of it branches back
to its header, so a loop whose exit is known (its induction variable against a constant bound,
an early exit on a node's value such as the fBm's octave count) is counted once per iteration
it runs, and one whose exit depends on a value only known at run time (a varying, a texel, a
light count) is counted at its bound when the induction variable has one. A loop that does not
end within MAX_TRIPS iterations is counted once (its figure is then static) and reported.
"""

from __future__ import annotations

import math
import operator
import struct
from dataclasses import dataclass, field
from typing import Any

MAX_TRIPS = 256
_MASK = 0xFFFFFFFF
_UNKNOWN = object()


@dataclass
class Block:
    label: str
    start: int  # index of the OpLabel in the module body
    end: int  # index of the terminator
    merge: str | None = None  # OpLoopMerge's merge block: this block is a loop header


@dataclass
class Trips:
    """Per body instruction, how many times it runs; `loops`: (header label, iterations or
    None where the loop was counted once) in module order, outermost run of each."""

    weights: list[int]
    loops: list[tuple[str, int | None]] = field(default_factory=list)


class _Tables:
    def __init__(self, globals_: list[tuple[str | None, str, list[str]]],
                 values: dict[str, Any]) -> None:
        self.types: dict[str, tuple[str, int]] = {}  # id -> ("float"|"int"|"uint"|"bool", 32)
        self.consts: dict[str, Any] = {}
        self.member_names: dict[tuple[str, int], str] = {}
        self.pointee: dict[str, str] = {}  # pointer type -> pointee type
        self.var_type: dict[str, str] = {}  # global variable -> its pointee type
        self.glsl_std = set()
        raw_consts: list[tuple[str, str, str]] = []
        for rid, op, args in globals_:
            if op == "OpTypeFloat" and rid:
                self.types[rid] = ("float", int(args[0]))
            elif op == "OpTypeInt" and rid:
                self.types[rid] = ("int" if args[1] == "1" else "uint", int(args[0]))
            elif op == "OpTypeBool" and rid:
                self.types[rid] = ("bool", 1)
            elif op == "OpConstant" and rid and len(args) >= 2:
                raw_consts.append((rid, args[0], args[1]))
            elif op in ("OpConstantTrue", "OpConstantFalse") and rid:
                self.consts[rid] = op == "OpConstantTrue"
            elif op == "OpMemberName" and len(args) >= 3:
                self.member_names[(args[0], int(args[1]))] = args[2].strip('"')
            elif op == "OpTypePointer" and rid and len(args) >= 2:
                self.pointee[rid] = args[1]
            elif op == "OpVariable" and rid and args:
                self.var_type[rid] = self.pointee.get(args[0], "")
            elif op == "OpExtInstImport" and rid and args and args[0] == '"GLSL.std.450"':
                self.glsl_std.add(rid)
        for rid, ty, text in raw_consts:
            kind = self.types.get(ty)
            if kind is None:
                continue
            try:
                self.consts[rid] = _f32(float(text)) if kind[0] == "float" else \
                    int(text, 0) & _MASK
            except (ValueError, OverflowError):
                pass
        self.values = values


def _f32(x: float) -> float:
    return struct.unpack("f", struct.pack("f", x))[0]


def _signed(x: int) -> int:
    return x - (1 << 32) if x & 0x80000000 else x


def _blocks(body: list[tuple[str | None, str, list[str]]]) -> list[list[Block]]:
    """The blocks of each function, in module order."""
    out: list[list[Block]] = []
    cur: Block | None = None
    for i, (rid, op, args) in enumerate(body):
        if op == "OpFunction":
            out.append([])
        elif op == "OpLabel":
            cur = Block(rid or "", i, i)
        elif op == "OpLoopMerge" and cur is not None:
            cur.merge = args[0]
        elif op in _TERMINATORS and cur is not None:
            cur.end = i
            out[-1].append(cur)
            cur = None
    return out


_COMPARE = {"LessThan": operator.lt, "LessThanEqual": operator.le,
            "GreaterThan": operator.gt, "GreaterThanEqual": operator.ge,
            "Equal": operator.eq, "NotEqual": operator.ne}
_TERMINATORS = frozenset({"OpBranch", "OpBranchConditional", "OpSwitch", "OpReturn",
                          "OpReturnValue", "OpKill", "OpUnreachable", "OpTerminateInvocation"})


class _Walker:
    def __init__(self, body, tables: _Tables, blocks: list[Block]) -> None:
        self.body = body
        self.t = tables
        self.blocks = blocks
        self.index = {b.label: k for k, b in enumerate(blocks)}
        self.succ: list[list[str]] = [self._targets(b) for b in blocks]
        self.env: dict[str, Any] = {}
        self.counts = [0] * len(blocks)
        self.loops: list[tuple[str, int | None]] = []

    def _targets(self, b: Block) -> list[str]:
        _, op, args = self.body[b.end]
        if op == "OpBranch":
            return [args[0]]
        if op == "OpBranchConditional":
            return [args[1], args[2]]
        if op == "OpSwitch":
            return [args[1], *args[3::2]]
        return []

    def region(self, head: int, stops: frozenset[str]) -> list[int]:
        """Blocks reachable from `head` without entering `stops` or coming back to head."""
        seen = {head}
        todo = [head]
        while todo:
            k = todo.pop()
            for t in self.succ[k]:
                j = self.index.get(t)
                if j is None or t in stops or j in seen:
                    continue
                seen.add(j)
                todo.append(j)
        return sorted(seen)

    def run(self, head: int, stops: frozenset[str], mult: int, entry_pred: str | None,
            is_loop: bool) -> None:
        """Runs the construct headed by `head` (a loop's iterations, or a function body once),
        adding `mult` per run to each block's count."""
        b = self.blocks[head]
        inner_stops = stops | {b.merge} if (is_loop and b.merge is not None) else stops
        blocks = self.region(head, frozenset(inner_stops))
        inside = set(blocks)
        # blocks of nested loops are run by their own header
        nested: dict[int, list[int]] = {}
        owned_by_nested: set[int] = set()
        for k in blocks:
            if k != head and k not in owned_by_nested and self.blocks[k].merge:
                sub = self.region(k, frozenset(inner_stops | {self.blocks[k].merge or ""}))
                nested[k] = sub
                owned_by_nested.update(j for j in sub if j != k)
        local = [0] * len(self.blocks)
        saved = self.counts
        self.counts = local
        preds: dict[int, list[str | None]] = {head: [entry_pred]}
        phis = [rid for rid, op, _a in self.body[b.start + 1:b.end] if op == "OpPhi" and rid]
        states: set[tuple] = set()
        trips = 0
        ended = cycle = False
        while trips < (MAX_TRIPS if is_loop else 1) and not cycle:
            trips += 1
            live = {head}
            back: list[str] = []
            decided = False  # a known condition chose whether to leave or go round
            for k in blocks:
                if k not in live or k in owned_by_nested:
                    continue
                blk = self.blocks[k]
                if k in nested and k != head:
                    self.run(k, frozenset(inner_stops), 1, _pred(preds.get(k)), True)
                    m = self.index.get(blk.merge or "")
                    if m is not None and m in inside:
                        live.add(m)
                        preds.setdefault(m, []).append(None)
                    continue
                local[k] += 1
                taken = self._execute(blk, preds.get(k, []))
                if len(taken) == 1 and len(set(self.succ[k])) > 1 and any(
                        self.index.get(t) not in inside or self.index.get(t) == head
                        for t in self.succ[k]):
                    decided = True
                if k == head and is_loop:  # the same state twice: it runs for ever
                    state = tuple(self.env.get(r, _UNKNOWN) for r in phis)
                    if state in states:
                        cycle = True
                        break
                    states.add(state)
                for t in taken:
                    j = self.index.get(t)
                    if j == head:
                        if is_loop:
                            back.append(blk.label)
                        continue
                    if j is None or j not in inside:
                        continue
                    live.add(j)
                    preds.setdefault(j, []).append(blk.label)
            if cycle or (is_loop and back and not decided):
                cycle = True  # no known condition decides its end: it would run for ever
                break
            nxt: list[str | None] = [back[0]] if len(back) == 1 else [None]
            preds = {head: nxt}
            if not is_loop or not back:
                ended = True
                break
        self.counts = saved
        if is_loop:
            self.loops.append((b.label, trips if ended else None))
        if ended:
            for k, n in enumerate(local):
                self.counts[k] += n * mult
        else:  # no end in sight: the loop is counted once, statically
            for k in blocks:
                self.counts[k] += mult
            self._forget(blocks)

    def _forget(self, blocks: list[int]) -> None:
        for k in blocks:
            blk = self.blocks[k]
            for rid, _op, _args in self.body[blk.start:blk.end]:
                if rid:
                    self.env.pop(rid, None)

    def _execute(self, blk: Block, preds: list[str | None]) -> list[str]:
        """Evaluates the block's values; the targets its terminator may branch to."""
        for rid, op, args in self.body[blk.start + 1:blk.end]:
            if rid is None:
                continue
            if op == "OpPhi":
                vals = {args[i + 1]: args[i] for i in range(1, len(args) - 1, 2)}
                got = {self._val(vals[p]) if p in vals else _UNKNOWN for p in preds} \
                    if preds and None not in preds else {_UNKNOWN}
                v = got.pop() if len(got) == 1 else _UNKNOWN
            else:
                v = self._eval(op, args)
            if v is _UNKNOWN:
                self.env.pop(rid, None)
            else:
                self.env[rid] = v
        _, op, args = self.body[blk.end]
        if op == "OpBranchConditional":
            c = self._val(args[0])
            if c is True:
                return [args[1]]
            if c is False:
                return [args[2]]
            return [args[1], args[2]]
        if op == "OpSwitch":
            sel = self._val(args[0])
            cases = {int(args[i], 0) & _MASK: args[i + 1] for i in range(2, len(args) - 1, 2)}
            if isinstance(sel, int) and not isinstance(sel, bool):
                return [cases.get(sel, args[1])]
            return [args[1], *cases.values()]
        return self.succ[self.index[blk.label]]

    def _val(self, ident: str) -> Any:
        if ident in self.env:
            return self.env[ident]
        return self.t.consts.get(ident, _UNKNOWN)

    def _eval(self, op: str, args: list[str]) -> Any:  # noqa: C901 - one table of opcodes
        t = self.t
        if op == "OpAccessChain" and len(args) >= 3:
            struct_ty = t.var_type.get(args[1])
            idx = self._val(args[2])
            if struct_ty is None or len(args) != 3 or not isinstance(idx, int):
                return _UNKNOWN
            name = t.member_names.get((struct_ty, idx))
            return ("member", name) if name in t.values else _UNKNOWN
        if op == "OpLoad":
            p = self._val(args[1]) if len(args) >= 2 else _UNKNOWN
            if isinstance(p, tuple) and p[0] == "member":
                return self._typed(args[0], t.values[p[1]])
            return _UNKNOWN
        ty = t.types.get(args[0]) if args else None
        if ty is None:
            return _UNKNOWN
        if op == "OpExtInst":
            if args[1] not in t.glsl_std:
                return _UNKNOWN
            xs = [self._val(a) for a in args[3:]]
            if any(x is _UNKNOWN or isinstance(x, tuple) for x in xs):
                return _UNKNOWN
            return self._std(args[2], ty, xs)
        xs = [self._val(a) for a in args[1:]]
        if any(x is _UNKNOWN or isinstance(x, tuple) for x in xs):
            return _UNKNOWN
        try:
            return self._op(op, ty, xs)
        except (ArithmeticError, ValueError, TypeError, IndexError):
            return _UNKNOWN

    def _typed(self, ty_id: str, value: Any) -> Any:
        ty = self.t.types.get(ty_id)
        if ty is None or isinstance(value, (list, tuple)):
            return _UNKNOWN
        try:
            if ty[0] == "float":
                return _f32(float(value))
            if ty[0] == "bool":
                return bool(value)
            return int(value) & _MASK
        except (ValueError, TypeError, OverflowError):
            return _UNKNOWN

    def _op(self, op: str, ty: tuple[str, int], xs: list[Any]) -> Any:  # noqa: C901
        kind = ty[0]
        if op == "OpCopyObject":
            return xs[0]
        if op == "OpSelect":
            return xs[1] if xs[0] else xs[2]
        if kind == "float":
            f = {"OpFAdd": lambda a, b: a + b, "OpFSub": lambda a, b: a - b,
                 "OpFMul": lambda a, b: a * b, "OpFDiv": lambda a, b: a / b}.get(op)
            if f is not None:
                return _f32(f(*xs))
            if op == "OpFNegate":
                return -xs[0]
            if op == "OpConvertSToF":
                return _f32(float(_signed(xs[0])))
            if op == "OpConvertUToF":
                return _f32(float(xs[0]))
            return _UNKNOWN
        if kind in ("int", "uint"):
            if op == "OpConvertFToS" or op == "OpConvertFToU":
                return int(math.trunc(xs[0])) & _MASK
            if op == "OpBitcast":
                return xs[0] if isinstance(xs[0], int) and not isinstance(xs[0], bool) \
                    else _UNKNOWN
            a = xs[0]
            b = xs[1] if len(xs) > 1 else 0
            g = {"OpIAdd": a + b, "OpISub": a - b, "OpIMul": a * b,
                 "OpBitwiseAnd": a & b, "OpBitwiseOr": a | b, "OpBitwiseXor": a ^ b,
                 "OpShiftLeftLogical": a << (b & 31), "OpShiftRightLogical": a >> (b & 31),
                 "OpSNegate": -a, "OpNot": ~a}.get(op, _UNKNOWN)
            return g if g is _UNKNOWN else g & _MASK
        if kind == "bool":
            if op == "OpLogicalNot":
                return not xs[0]
            a, b = xs[0], xs[1]
            if op.startswith("OpS"):
                a, b = _signed(a), _signed(b)
            for prefix in ("OpS", "OpU", "OpFOrd", "OpFUnord", "OpI", "OpLogical"):
                if op.startswith(prefix) and op[len(prefix):] in _COMPARE:
                    return bool(_COMPARE[op[len(prefix):]](a, b))
            if op == "OpLogicalAnd":
                return bool(a and b)
            if op == "OpLogicalOr":
                return bool(a or b)
        return _UNKNOWN

    @staticmethod
    def _std(name: str, ty: tuple[str, int], xs: list[Any]) -> Any:
        if ty[0] == "float":
            if name in ("FClamp", "NClamp"):
                return min(max(xs[0], xs[1]), xs[2])
            if name in ("FMin", "NMin"):
                return min(xs)
            if name in ("FMax", "NMax"):
                return max(xs)
            if name == "FAbs":
                return abs(xs[0])
            if name == "Floor":
                return float(math.floor(xs[0]))
            if name == "Ceil":
                return float(math.ceil(xs[0]))
            return _UNKNOWN
        if ty[0] == "int" and name in ("SClamp", "SMin", "SMax"):
            s = [_signed(x) for x in xs]
            r = min(max(s[0], s[1]), s[2]) if name == "SClamp" else \
                (min(s) if name == "SMin" else max(s))
            return r & _MASK
        if ty[0] == "uint" and name in ("UClamp", "UMin", "UMax"):
            return min(max(xs[0], xs[1]), xs[2]) if name == "UClamp" else \
                (min(xs) if name == "UMin" else max(xs))
        return _UNKNOWN


def _pred(preds: list[str | None] | None) -> str | None:
    return preds[0] if preds and len(preds) == 1 else None


def weights(body: list[tuple[str | None, str, list[str]]],
            globals_: list[tuple[str | None, str, list[str]]],
            values: dict[str, Any] | None = None) -> Trips:
    """How many times each body instruction runs (see the module's docstring)."""
    tables = _Tables(globals_, dict(values or {}))
    out = [1] * len(body)
    loops: list[tuple[str, int | None]] = []
    for blocks in _blocks(body):
        if not blocks:
            continue
        w = _Walker(body, tables, blocks)
        w.run(0, frozenset(), 1, None, False)
        loops.extend(w.loops)
        for k, blk in enumerate(blocks):
            for i in range(blk.start, blk.end + 1):
                out[i] = w.counts[k]
    return Trips(out, loops)
