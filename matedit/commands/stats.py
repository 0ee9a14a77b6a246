"""`matedit stats FILE [--target T] [--json] [--measure]`: what a material costs, per target,
per node and per layer (docs/cli.md). The figures come from `matedit.interop.stats`; the
timings of `--measure` from `matedit.commands.stats_measure`.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from matedit.cli_support import UsageError, report
from matedit.interop.stats import (
    ALL_TARGETS,
    ATTRIBUTION,
    COUNTING,
    DEFAULT_BUDGET,
    SCHEMA_VERSION,
    TARGETS,
    ToolError,
    material_stats,
    over_budget,
    permutations,
)
from matedit.io.input_kinds import declare_inputs

OVER_BUDGET = 3  # the exit status of a material over a --budget-* budget (docs/cli.md)

__all__ = ["TARGETS", "build_report", "material_stats", "register", "run", "text_report"]


def register(sub) -> None:
    p = sub.add_parser("stats", help="what a material costs, per target, node and layer",
                       description="Instruction counts (after spirv-opt -O), texture samples, "
                       "samplers, uniform bytes and varyings per target; the instructions "
                       "each node and layer accounts for; static-switch permutations; "
                       "--measure: timed renders with each costly subtree replaced by a "
                       "constant.")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--target", default="all", choices=[*ALL_TARGETS, "all"],
                   help="one target, or all (default)")
    p.add_argument("--json", action="store_true", help="the report as JSON "
                   "(matedit/schemas/stats.schema.json)")
    p.add_argument("--measure", action="store_true", help="time renders (EGL) with each "
                   "layer and each of the 10 costliest nodes replaced by its mean value")
    p.add_argument("--size", type=int, default=256, metavar="N",
                   help="--measure: render N x N pixels (default 256)")
    p.add_argument("--runs", type=int, default=9, metavar="K",
                   help="--measure: timed repetitions per variant (default 9)")
    p.add_argument("--budget-samplers", type=int, default=None, metavar="N",
                   help="warn and exit 3 above N texture samplers on essl300 (WebGL2 "
                   f"guarantees {DEFAULT_BUDGET['samplers']})")
    p.add_argument("--budget-instructions", type=int, default=None, metavar="N",
                   help="warn and exit 3 above N dynamic glsl450 instructions")
    declare_inputs(p, file="document")
    p.set_defaults(run=run)


def build_report(path: Path, targets: list[str], measure: dict | None = None) -> dict:
    from matedit.compiler import CompileError
    from matedit.io.document import FileResolver, FormatError
    from matedit.io.instance import InstanceError, load_effective

    try:
        doc, notes = load_effective(path)
    except (FormatError, InstanceError) as exc:
        raise UsageError(str(exc)) from None
    for note in notes:
        report("warning", note.format())
    if doc.is_function:
        raise UsageError(f"{path}: is a material function; give a material that calls it")
    resolver = FileResolver()
    try:
        per_target = material_stats(doc, resolver, targets)
        perms = permutations(doc, resolver)
    except ToolError as exc:
        raise UsageError(f"{path}: {exc}") from None
    except CompileError as exc:
        first = exc.diagnostics[0] if exc.diagnostics else None
        raise UsageError(f"{first.file or path}: {first.format()}" if first else
                         f"{path}: {exc}") from None
    out: dict[str, Any] = {"format": "matedit.stats", "version": SCHEMA_VERSION,
                           "source": path.name, "attribution": ATTRIBUTION,
                           "counting": COUNTING,
                           "targets": per_target, "permutations": perms}
    if measure is not None:
        from matedit.commands.stats_measure import measure_costs

        out["measure"] = measure_costs(doc, resolver, per_target, **measure)
    return out


def run(args) -> int:
    path = Path(args.file)
    targets = list(ALL_TARGETS) if args.target == "all" else [args.target]
    if args.size < 8 or args.size > 4096:
        raise UsageError(f"--size {args.size}: expected 8 to 4096")
    if args.runs < 3 or args.runs > 101:
        raise UsageError(f"--runs {args.runs}: expected 3 to 101")
    for flag, v in (("--budget-samplers", args.budget_samplers),
                    ("--budget-instructions", args.budget_instructions)):
        if v is not None and v < 0:
            raise UsageError(f"{flag} {v}: expected 0 or more")
    measure = {"size": args.size, "runs": args.runs} if args.measure else None
    rep = build_report(path, targets, measure)
    if args.json:
        sys.stdout.write(json.dumps(rep, indent=2, sort_keys=True) + "\n")
    else:
        sys.stdout.write(text_report(rep))
    sys.stdout.flush()
    over = over_budget(rep["targets"], args.budget_samplers, args.budget_instructions)
    for text in over:
        report("warning", f"{path.name}: {text}")
    return OVER_BUDGET if over else 0


def text_report(rep: dict, top: int = 10) -> str:
    lines = [f"{rep['source']}", "counting: dynamic (loops by their trip counts with the "
             "current values; static: each instruction once)"]
    for t, f in rep["targets"].items():
        lines.append(f"\n{t}: {f['instructions']} dynamic instructions ({f['alu']} ALU, "
                     f"{f['texture']} texture, {f['memory']} memory, {f['control']} control), "
                     f"{f['samples']} samples, {f['samplers']} samplers, "
                     f"{f['uniform_bytes']} uniform bytes, {f['varyings']} varyings  "
                     f"[{f['module']}]")
        lines.append(f"  static: {f['static']['instructions']} instructions in the module, "
                     f"{f['static']['samples']} samples; {f['loops']['count']} loops, "
                     f"{f['loops']['counted_once']} counted once (no known bound)")
        rows = [r for r in f["nodes"] if r["instructions"] > 0][:top]
        for r in rows:
            lines.append(f"  {r['id']:<24} {r['kind']:<22} {r['instructions']:>8.1f} instr "
                         f"{r['samples']:>5.1f} samples")
        zero = sum(1 for r in f["nodes"] if r["instructions"] == 0)
        more = sum(1 for r in f["nodes"] if r["instructions"] > 0) - len(rows)
        if more > 0:
            lines.append(f"  ... {more} more nodes")
        if zero:
            lines.append(f"  ({zero} nodes cost 0: folded, dead or parameters)")
        lines.append(f"  {'shading':<47} {f['shading']['instructions']:>8.1f} instr "
                     f"{f['shading']['samples']:>5.1f} samples")
        for layer in f["layers"]:
            lines.append(f"  layer {layer['name']:<18} ({layer['blend']}) "
                         f"{layer['instructions']:>8.1f} instr, blend "
                         f"{layer['blend_cost']['instructions']:.1f}")
    p = rep["permutations"]
    if p["switches"]:
        lines.append(f"\nstatic switches: {len(p['switches'])}, {p['count']} permutations")
        for v in p["variants"]:
            vals = ", ".join(f"{k}={'on' if b else 'off'}" for k, b in v["values"].items())
            lines.append(f"  {vals}: {v['instructions']} instructions (glsl450), "
                         f"{v['samples']} samples{'  (current)' if v['current'] else ''}")
    if "measure" in rep:
        m = rep["measure"]
        lines.append(f"\nmeasured ({m['size']}x{m['size']}, {m['runs']} runs, {m['renderer']}):"
                     f" frame {m['frame_ms']['median']:.3f} ms median")
        for r in m["rows"]:
            c = r["cost_ms"]
            note = "" if not r["clamped"] else "  (clamped at 0)" if c["median"] == 0 else \
                "  (lower quartile clamped at 0)"
            lines.append(f"  {r['what']:<6} {r['id']:<24} {r['cost_ms']['median']:>8.3f} ms "
                         f"(IQR {r['cost_ms']['iqr']:.3f}), counted "
                         f"{r['counted_instructions']} instr{note}")
        rc = m["rank_correlation"]
        lines.append("  rank correlation, measured vs counted (Spearman): " +
                     ("n/a" if rc is None else f"{rc:.2f}"))
    return "\n".join(lines) + "\n"
