"""IR optimisation passes: constant folding, common subexpressions, dead code.

Each pass keeps the op order (a stable topological order), so the output is
deterministic whatever the order of nodes in the file.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from matedit.compiler import ops
from matedit.compiler.ir import Expr, Lit, Op, Scope, Splat, Var, expr_vars
from matedit.graph.nodes import is_impure
from matedit.graph.types import PortType

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np


# The compiler's own ops whose value depends on more than their operands; catalogue kinds
# declare it (NodeDef.impure: geometry, time, textures, uniforms).
IMPURE_OPS = {ops.CALL}


def _subst(e: Expr, table: dict[str, Expr]) -> Expr:
    if isinstance(e, Var):
        return table.get(e.name, e)
    if isinstance(e, Splat):
        inner = _subst(e.expr, table)
        if isinstance(inner, Lit):
            return Lit((inner.value,) * e.type.components, e.type)
        return Splat(inner, e.type)
    return e


def _as_array(lit: Lit):
    if lit.type == PortType.FLOAT:
        return np.array([lit.value], dtype=np.float64)
    return np.array([lit.value], dtype=np.float64).reshape(1, -1)


def _to_lit(value, t: PortType) -> Lit | None:
    arr = np.asarray(value, dtype=np.float64).reshape(-1)
    if not np.all(np.isfinite(arr)):
        return None  # leave inf/NaN to the GPU rather than writing them as literals
    if t == PortType.FLOAT:
        return Lit(float(arr[0]), t) if arr.size == 1 else None
    if arr.size != t.components:
        return None
    return Lit(tuple(float(x) for x in arr), t)


def remove_unused(scope: Scope) -> None:
    """Drops ops whose outputs reach no scope output."""
    live: set[str] = set()
    for _, _, e in scope.outputs:
        live.update(expr_vars(e))
    kept = []
    for op in reversed(scope.ops):
        for v in op.out_vars().values():
            if v.name in live:
                break
        else:
            continue  # no output of it is read
        kept.append(op)
        for a in op.args:
            if type(a) is Var:
                live.add(a.name)
            else:
                live.update(expr_vars(a))
    kept.reverse()
    scope.ops = kept


def _fold(op: Op) -> list[Lit] | None:
    """The op's outputs as literals when all its operands are literals (numpy evaluation)."""
    args = op.args
    # operands first: most ops read another op's output, and are rejected at once
    if (not args or not all(isinstance(a, Lit) and a.type.is_numeric for a in args)
            or op.kind in IMPURE_OPS or is_impure(op.kind)
            or not all(t.is_numeric for _, t in op.outs)):
        return None
    from matedit.compiler import cpu_eval  # numpy: only when there is something to fold

    lit_args = [a for a in op.args if isinstance(a, Lit)]  # all of them (checked above)
    try:
        values = cpu_eval.eval_op(op, [_as_array(a) for a in lit_args], None)
    except Exception:  # no implementation, or it refused: keep the op
        return None
    lits = [_to_lit(v, t) for v, (_, t) in zip(values, op.outs)]
    kept = [l for l in lits if l is not None]
    return kept if len(kept) == len(lits) else None


def fold_and_merge(scope: Scope) -> None:
    """Constant folding and common-subexpression merging, in one walk over the ops: an op
    whose operands are all literals becomes literals; an op equal to an earlier one (same
    kind, data and operands) is replaced by the earlier one's outputs."""
    table: dict[str, Expr] = {}
    seen: dict[str, Op] = {}
    kept: list[Op] = []
    get = table.get
    for op in scope.ops:
        # one walk over the operands: substituted, their variables' names, and whether any
        # is a literal (then _fold, which wants all of them literals, is tried)
        args, var_names, some_lit = [], [], not op.args
        for a in op.args:
            if type(a) is Var:
                a = get(a.name, a)
            elif type(a) is Splat:
                a = _subst(a, table)
            args.append(a)
            if type(a) is Var:
                var_names.append(a.name)
            elif type(a) is Lit:
                some_lit = True
        op.args = args
        if some_lit:
            lits = _fold(op)
            if lits is not None:
                for (port, _), lit in zip(op.outs, lits):
                    table[op.out(port).name] = lit
                continue
        if op.data or len(var_names) != len(args):
            k = op.key()
        else:  # op.key() of an op of Var operands and no data
            k = f"{op.kind}||{','.join(var_names)}"
        first = seen.get(k)
        if first is not None and first.outs == op.outs:
            for port, _ in op.outs:
                table[op.out(port).name] = first.out(port)
            continue
        seen[k] = op
        kept.append(op)
    scope.ops = kept
    scope.outputs = [(n, t, _subst(e, table)) for n, t, e in scope.outputs]
    # the sockets in place (values only: no new dict of every socket, most of them unchanged)
    sockets = scope.sockets
    for socket, e in sockets.items():
        if type(e) is Var:
            new = get(e.name)
            if new is not None:
                sockets[socket] = new
        elif type(e) is Splat:
            sockets[socket] = _subst(e, table)


def optimise(scope: Scope) -> None:
    fold_and_merge(scope)
    remove_unused(scope)
