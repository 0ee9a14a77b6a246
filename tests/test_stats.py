"""`matedit stats` (issue 28): instruction counts per target, node and layer; permutations;
--measure; the JSON report and its schema.

The module totals are checked against an independent count made here from the SPIR-V binary
(opcode numbers of the SPIR-V specification, section 3.32), not from the disassembly text the
command parses."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.commands import stats
from matedit.compiler.api import compile_all
from matedit.io.document import FileResolver, load, save
from matedit.resources import graphs_dir

TOOLS = ("glslangValidator", "spirv-opt", "spirv-dis")
pytestmark = pytest.mark.skipif(not all(shutil.which(t) for t in TOOLS),
                                reason="glslang-tools and spirv-tools are not installed")
ROOT = Path(__file__).resolve().parents[1]
SCHEMA = json.loads((ROOT / "matedit" / "schemas" / "stats.schema.json").read_text())
SAMPLES = sorted((graphs_dir() / "materials").glob("*.json"))
ALL_TARGET_SAMPLES = ("mossy_stone", "worn_painted_steel", "red_brick")  # layers, a switch
SUM_TOLERANCE = 0.05  # the issue's: per-node figures sum to the total within 5 %


def _sum(t: dict) -> float:
    return sum(r["instructions"] for r in t["nodes"]) + t["shading"]["instructions"]


# --- an independent count from the binary -------------------------------------------------------
# SPIR-V 1.6 opcodes (spec section 3.32) that are structure or declarations, not work
_NOT_WORK = {1, 8, 54, 55, 56, 59, 245, 246, 247, 248, 255, 317}  # Undef, Line, Function...,
# Variable, Phi, LoopMerge, SelectionMerge, Label, Unreachable, NoLine
_SAMPLES = set(range(87, 99)) - {86}  # ImageSample* (87-94), Fetch, Gather, DrefGather, Read


def _binary_counts(spv: bytes) -> tuple[int, int]:
    """(executed instructions, texture samples) of a SPIR-V module's function bodies."""
    words = struct.unpack(f"<{len(spv) // 4}I", spv)
    debug_sets = set()
    i, inside, n, samples = 5, False, 0, 0
    while i < len(words):
        count, op = words[i] >> 16, words[i] & 0xFFFF
        if op == 11:  # OpExtInstImport result name
            name = struct.pack(f"<{count - 2}I", *words[i + 2:i + count]).split(b"\0")[0]
            if name.startswith(b"NonSemantic."):
                debug_sets.add(words[i + 1])
        if op == 54:
            inside = True
        if inside and op not in _NOT_WORK and not (op == 12 and words[i + 3] in debug_sets):
            n += 1
            samples += op in _SAMPLES
        if op == 56:
            inside = False
        i += count
    return n, samples


def _optimised(glsl: str, tmp: Path, vulkan: bool) -> bytes:
    src, raw, opt = tmp / "m.frag", tmp / "m.spv", tmp / "o.spv"
    src.write_text(glsl.replace("#version 300 es", "#version 310 es", 1))
    args = ["glslangValidator", "-V"] if vulkan else ["glslangValidator", "-G", "--aml",
                                                      "--amb"]
    subprocess.run([*args, "-S", "frag", "-o", str(raw), str(src)], check=True,
                   capture_output=True)
    subprocess.run(["spirv-opt", "-O", str(raw), "-o", str(opt)], check=True)
    return opt.read_bytes()


@pytest.fixture(scope="module")
def reports():
    """glsl450 figures of every sample; every GLSL target of three."""
    r = FileResolver()
    out = {}
    for p in SAMPLES:
        targets = list(stats.TARGETS) if p.stem in ALL_TARGET_SAMPLES else ["glsl450"]
        out[p.stem] = stats.material_stats(load(p), r, targets)
    return out


def test_node_figures_sum_to_the_total(reports):
    assert len(reports) == len(SAMPLES) >= 20
    for name, per_target in reports.items():
        for target, t in per_target.items():
            total = t["instructions"]
            assert total > 500, (name, target)
            assert abs(_sum(t) - total) <= SUM_TOLERANCE * total, (name, target, _sum(t))
            # the shading code is a row of its own, and every sample has some node cost
            assert 0 < t["shading"]["instructions"] < total
            assert sum(r["instructions"] for r in t["nodes"]) > 0, name
            samples = sum(r["samples"] for r in t["nodes"]) + t["shading"]["samples"]
            assert abs(samples - t["samples"]) <= max(0.5, SUM_TOLERANCE * t["samples"])


def test_layers_sum_to_their_stack(reports):
    seen = 0
    for per_target in reports.values():
        t = per_target["glsl450"]
        rows = {r["id"]: r for r in t["nodes"]}
        stacks = {layer["stack"] for layer in t["layers"]}
        for s in stacks:
            layers = [layer for layer in t["layers"] if layer["stack"] == s]
            total = sum(layer["instructions"] for layer in layers)
            assert total == pytest.approx(rows[s]["instructions"], abs=0.1 * len(layers) + 0.1)
            for layer in layers:
                inner = sum(n["instructions"] for n in layer["nodes"])
                assert inner + layer["blend_cost"]["instructions"] <= \
                    layer["instructions"] + 0.1 * (len(layer["nodes"]) + 1)
                assert layer["blend_cost"]["instructions"] <= layer["instructions"] + 0.1
            seen += 1
    assert seen >= 5  # the layered samples


@pytest.mark.parametrize("name", ALL_TARGET_SAMPLES)
def test_totals_match_an_independent_count_of_the_binary(name, tmp_path, reports):
    doc = load(graphs_dir() / "materials" / f"{name}.json")
    compiled = compile_all(doc, FileResolver(), list(stats.TARGETS))
    rep = reports[name]
    for target, cm in compiled.items():
        n, samples = _binary_counts(_optimised(cm.fragment_text, tmp_path,
                                               stats.TARGETS[target].vulkan))
        st = rep[target]["static"]
        assert st["instructions"] == n, target
        assert st["samples"] == samples, target
        assert st["alu"] + st["texture"] + st["memory"] + st["control"] == n
        # dynamic counts see each loop as often as it runs: never fewer than the module's
        assert rep[target]["instructions"] >= n
        assert rep[target]["alu"] + rep[target]["texture"] + rep[target]["memory"] + \
            rep[target]["control"] == rep[target]["instructions"]


def _noise_material(noise_branches: int = 1, octaves: float = 4.0,
                    dead: bool = False, folded: bool = False):
    """uv -> fbm -> roughness (and a second, unshared fbm -> metallic); optionally an
    unconnected fbm and a constant expression folded into the cavity input."""
    d = material()
    node(d, "uv", "texcoord")
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "make", "attributes", "out", "attributes")
    for i, port in enumerate(("roughness", "metallic")[:noise_branches]):
        node(d, f"n{i}", "fbm", values={"octaves": octaves, "seed": 3.0 + i,
                                        "scale": 4.0 + i})
        link(d, "uv", "uv", f"n{i}", "uv")
        link(d, f"n{i}", "value", "make", port)
    if dead:
        node(d, "dead", "fbm", values={"octaves": 8.0})
        link(d, "uv", "uv", "dead", "uv")
    if folded:
        node(d, "c1", "constant", {"type": "float", "value": 0.5})
        node(d, "c2", "constant", {"type": "float", "value": 0.8})
        node(d, "k", "multiply")
        link(d, "c1", "value", "k", "a")
        link(d, "c2", "value", "k", "b")
        link(d, "k", "result", "make", "cavity")
    return d


def _glsl450(doc) -> dict:
    return stats.material_stats(doc, FileResolver(), ["glsl450"])["glsl450"]


def _row(t: dict, nid: str) -> dict:
    return next(r for r in t["nodes"] if r["id"] == nid)


def test_dead_node_and_folded_constant_cost_nothing():
    base = _glsl450(_noise_material())
    with_dead = _glsl450(_noise_material(dead=True))
    assert _row(with_dead, "dead")["instructions"] == 0
    assert with_dead["instructions"] == base["instructions"]
    folded = _glsl450(_noise_material(folded=True))
    for nid in ("k", "c1", "c2"):
        assert _row(folded, nid)["instructions"] == 0
    # the folded 0.4 reaches the shading as a literal: the module may change a little there,
    # but the node itself owns nothing and the fbm keeps its figure
    assert _row(folded, "n0")["instructions"] == pytest.approx(
        _row(base, "n0")["instructions"], rel=0.02)


def test_duplicated_noise_branch_doubles_its_cost():
    one = _glsl450(_noise_material(1))
    two = _glsl450(_noise_material(2))
    single = _row(one, "n0")["instructions"]
    pair = _row(two, "n0")["instructions"] + _row(two, "n1")["instructions"]
    assert single > 50
    assert pair == pytest.approx(2 * single, rel=0.20)  # the 20 %


OCTAVE_RATIO = (3.0, 4.0)  # the counted 8-octave / 2-octave ratio of the fBm node


def test_fbm_octaves_counted_and_measured():
    """Counted: the fBm loop runs to NODE_FBM_MAX_OCTAVES (8) with an early exit on the
    node's octave count; dynamic counting runs it with the node's value, so the node costs a
    fixed part (scale, seed, the loop's set-up and exit, the normalisation) plus one loop body
    per octave. Independent of how the counter works, the figure must then be linear in the
    octave count: c(8) - c(2) = 6 (c(2) - c(1)), to 1 %. With a body of about 230
    instructions and a fixed part of about 30, 8 octaves count 3.8 times 2 (read: 1875.5 /
    492.0 = 3.81); the test asks for 3 to 4. Statically (each instruction once) the counts are the
    same. Measured: 8 octaves evaluate four times the gradient noises of 2, on top of the
    fixed cost; on llvmpipe at 128 x 128 the measured ratio of four fBm nodes' subtree read
    1.7, 3.6 and 5.7 in three tries on a shared machine, so the test asks for at least 1.3:
    more, clearly, not how much more."""
    reps = {o: _glsl450(_noise_material(octaves=o)) for o in (1.0, 2.0, 8.0)}
    c1, c2, c8 = (_row(reps[o], "n0")["instructions"] for o in (1.0, 2.0, 8.0))
    assert c8 - c2 == pytest.approx(6 * (c2 - c1), rel=0.01), (c1, c2, c8)
    assert OCTAVE_RATIO[0] <= c8 / c2 <= OCTAVE_RATIO[1], (c2, c8, c8 / c2)
    assert reps[8.0]["static"]["instructions"] == reps[2.0]["static"]["instructions"]
    # the material's total grows by the same instructions as the node
    assert reps[8.0]["instructions"] - reps[2.0]["instructions"] == pytest.approx(
        c8 - c2, rel=0.05)
    from matedit.commands.stats_measure import measure_costs

    def measured(octaves: float) -> float:
        d = _fbm_stack(octaves)
        t = stats.material_stats(d, FileResolver(), ["glsl450"])
        m = measure_costs(d, FileResolver(), t, size=128, runs=7, only=["q"])
        (row,) = m["rows"]
        return row["cost_ms"]["median"]

    m2, m8 = measured(2.0), measured(8.0)
    assert m2 > 0
    assert m8 / m2 >= 1.3, (m2, m8)


def _fbm_stack(octaves: float):
    """Four fBm nodes summed and scaled (`q`) into roughness: q's subtree is all four."""
    d = material()
    node(d, "uv", "texcoord")
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "make", "attributes", "out", "attributes")
    for i in range(4):
        node(d, f"f{i}", "fbm", values={"octaves": octaves, "seed": float(i + 1)})
        link(d, "uv", "uv", f"f{i}", "uv")
    node(d, "sum1", "add")
    node(d, "sum2", "add")
    node(d, "sum3", "add")
    link(d, "f0", "value", "sum1", "a")
    link(d, "f1", "value", "sum1", "b")
    link(d, "f2", "value", "sum2", "a")
    link(d, "f3", "value", "sum2", "b")
    link(d, "sum1", "result", "sum3", "a")
    link(d, "sum2", "result", "sum3", "b")
    node(d, "q", "multiply", values={"b": 0.25})
    link(d, "sum3", "result", "q", "a")
    link(d, "q", "result", "make", "roughness")
    return d


def _heavy_and_light():
    """An 8-octave domain-warped fBm into base colour, and a constant multiply into metallic."""
    d = material()
    node(d, "uv", "texcoord")
    node(d, "warp", "domain_warp", values={"octaves": 8.0, "strength": 0.2})
    node(d, "heavy", "fbm", values={"octaves": 8.0})
    node(d, "light", "multiply", values={"a": 0.3, "b": 0.9})
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "uv", "uv", "warp", "uv")
    link(d, "warp", "uv", "heavy", "uv")
    link(d, "heavy", "value", "make", "roughness")
    node(d, "s", "scalar_parameter", {"name": "metal"}, {"value": 0.5})
    link(d, "s", "value", "light", "a")
    link(d, "light", "result", "make", "metallic")
    link(d, "make", "attributes", "out", "attributes")
    return d


def test_measure_ranks_heavy_above_light_in_every_run():
    from matedit.commands.stats_measure import measure_costs

    d = _heavy_and_light()
    t = stats.material_stats(d, FileResolver(), ["glsl450"])
    assert _row(t["glsl450"], "heavy")["instructions"] > \
        50 * max(1.0, _row(t["glsl450"], "light")["instructions"])
    # 256 px: the heavy node costs ~7 ms a frame there, twice what a loaded machine has
    # added to a round's fastest frame in trials (at 128 px its ~3.5 ms flipped a round)
    m = measure_costs(d, FileResolver(), t, size=256, runs=10)
    rows = {r["id"]: r for r in m["rows"]}
    heavy, light = rows["heavy"], rows["light"]
    assert len(heavy["runs_ms"]) == len(light["runs_ms"]) == 10
    wins = sum(h > lt for h, lt in zip(heavy["runs_ms"], light["runs_ms"]))
    assert wins == 10, (heavy["runs_ms"], light["runs_ms"])
    for r in m["rows"]:
        assert all(v >= 0 for v in r["cost_ms"].values())
        assert r["cost_ms"]["iqr"] >= 0
        # a figure reads 0 where the difference was negative, and the row says so
        assert r["clamped"] == bool(np.percentile(r["runs_ms"], 25) < 0)
    assert m["frame_ms"]["median"] > 0


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "matedit", "stats", *args],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)


def test_json_report_validates_against_the_schema(tmp_path):
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    path = graphs_dir() / "materials" / "worn_painted_steel.json"
    r = _cli(str(path), "--json")
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    jsonschema.validate(rep, SCHEMA)
    assert set(rep["targets"]) == {"glsl330", "glsl450", "essl300", "hlsl", "msl"}
    # the one switch makes two permutations; switching the rust layer off costs less
    p = rep["permutations"]
    assert p["count"] == 2 and len(p["variants"]) == 2
    on = next(v for v in p["variants"] if v["values"]["rust_on"])
    off = next(v for v in p["variants"] if not v["values"]["rust_on"])
    assert on["instructions"] > off["instructions"]
    assert on["instructions"] == rep["targets"]["glsl450"]["instructions"]
    # an instance of it: the same command
    inst = tmp_path / "inst.json"
    inst.write_text(json.dumps({"format": "matedit.instance", "version": 2,
                                "parent": str(path), "parameters": {}}))
    r = _cli(str(inst), "--json", "--target", "glsl450")
    assert r.returncode == 0, r.stderr
    jsonschema.validate(json.loads(r.stdout), SCHEMA)


def test_measure_json_validates(tmp_path):
    p = tmp_path / "m.json"
    save(_heavy_and_light(), p)
    r = _cli(str(p), "--json", "--target", "glsl450", "--measure", "--size", "32",
             "--runs", "3")
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    jsonschema.validate(rep, SCHEMA)
    assert rep["measure"]["rows"]


def test_budget_flags_warn_and_set_the_status(tmp_path):
    """Over a budget: the report, then one `warning:` line per budget passed, status 3; within
    it, status 0 and no warning."""
    path = graphs_dir() / "materials" / "worn_painted_steel.json"
    r = _cli(str(path), "--json", "--target", "essl300")
    assert r.returncode == 0, r.stderr
    n = json.loads(r.stdout)["targets"]["essl300"]["samplers"]
    assert n >= 2
    r = _cli(str(path), "--target", "essl300", "--budget-samplers", str(n - 1))
    assert r.returncode == 3, r.stderr
    assert "essl300:" in r.stdout  # the report is printed all the same
    (line,) = r.stderr.strip().splitlines()
    assert line == (f"warning: worn_painted_steel.json: {n} texture samplers on essl300: over "
                    f"the budget of {n - 1}")
    r = _cli(str(path), "--target", "essl300", "--budget-samplers", str(n))
    assert r.returncode == 0 and r.stderr == ""
    r = _cli(str(path), "--target", "glsl450", "--budget-instructions", "100")
    assert r.returncode == 3 and "over the budget of 100" in r.stderr


@pytest.mark.parametrize("args,needle", [
    (["missing.json"], "missing.json"),
    (["{bad}", "--size", "2"], "--size"),
])
def test_bad_input_is_one_error_line(tmp_path, args, needle):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    args = [str(bad) if a == "{bad}" else str(tmp_path / a) if a.endswith(".json") else a
            for a in args]
    r = _cli(*args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], lines
    r = _cli(str(bad))
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "bad.json" in r.stderr


# --- the attribution rule on a module written by hand ------------------------------------------
_HAND = """
%1 = OpExtInstImport "NonSemantic.Shader.DebugInfo.100"
%u = OpConstant %int 0
%l1 = OpConstant %int 3300001
%l2 = OpConstant %int 3300002
%l3 = OpConstant %int 3300003
%l9 = OpConstant %int 1600009
%l50 = OpConstant %int 3300050
%in = OpExtInst %void %1 DebugInlinedAt %l1 %s
%main = OpFunction %void None %f
%lab = OpLabel
%d1 = OpExtInst %void %1 DebugLine %src %l1 %l1 %u %u
%a = OpFMul %float %x %x
%b = OpFAdd %float %a %x
%d2 = OpExtInst %void %1 DebugLine %src %l2 %l2 %u %u
%c = OpFMul %float %a %y
%d3 = OpExtInst %void %1 DebugLine %src %l3 %l3 %u %u
%e = OpFSub %float %b %c
%sc = OpExtInst %void %1 DebugScope %s %in
%d9 = OpExtInst %void %1 DebugLine %src %l9 %l9 %u %u
%g = OpImageSampleImplicitLod %v4float %si %b
%s0 = OpExtInst %void %1 DebugScope %s
%d0 = OpExtInst %void %1 DebugLine %src %l50 %l50 %u %u
OpReturn
OpFunctionEnd
"""


# --- trip counts on a module written by hand --------------------------------------------------
_LOOP = """
%float = OpTypeFloat 32
%int = OpTypeInt 32 1
%bool = OpTypeBool
%i0 = OpConstant %int 0
%i1 = OpConstant %int 1
%i8 = OpConstant %int 8
%f0 = OpConstant %float 0
%f1 = OpConstant %float 1
OpMemberName %Block 0 "u_n_octaves"
%Block = OpTypeStruct %float
%pBlock = OpTypePointer Uniform %Block
%pf = OpTypePointer Uniform %float
%ub = OpVariable %pBlock Uniform
%main = OpFunction %void None %f
%entry = OpLabel
%ac = OpAccessChain %pf %ub %i0
%oct = OpLoad %float %ac
OpBranch %head
%head = OpLabel
%k = OpPhi %int %i0 %entry %k1 %cont
%lt = OpSLessThan %bool %k %i8
OpLoopMerge %merge %cont None
OpBranchConditional %lt %body %merge
%body = OpLabel
%kf = OpConvertSToF %float %k
%rest = OpFSub %float %oct %kf
%stop = OpFOrdLessThanEqual %bool %rest %f0
OpSelectionMerge %go None
OpBranchConditional %stop %brk %go
%brk = OpLabel
OpBranch %merge
%go = OpLabel
%w1 = OpFMul %float %rest %rest
%w2 = OpFAdd %float %w1 %f1
%w3 = OpExtInst %float %x %y
OpBranch %cont
%cont = OpLabel
%k1 = OpIAdd %int %k %i1
OpBranch %head
%merge = OpLabel
OpReturn
OpFunctionEnd
"""


@pytest.mark.parametrize("octaves,expected", [
    # entry: AccessChain, Load, Branch (3); per header run: SLessThan, BranchConditional (2);
    # per body run: ConvertSToF, FSub, FOrdLessThanEqual, BranchConditional (4); per full
    # octave: FMul, FAdd, ExtInst, Branch (go) + IAdd, Branch (cont) (6); a break: Branch (1);
    # the merge: Return (1). n octaves (1 <= n < 8): n + 1 header runs, n + 1 body runs, n
    # full octaves, one break.
    (1.0, 3 + 2 * 2 + 4 * 2 + 6 * 1 + 1 + 1),
    (3.0, 3 + 2 * 4 + 4 * 4 + 6 * 3 + 1 + 1),
    # 8 and more: the bound ends it; 9 header runs, 8 bodies, no break
    (8.0, 3 + 2 * 9 + 4 * 8 + 6 * 8 + 1),
    (20.0, 3 + 2 * 9 + 4 * 8 + 6 * 8 + 1),
])
def test_loop_trip_counts_on_a_hand_written_module(octaves, expected):
    from matedit.compiler import cost, trips

    m = cost.parse(_LOOP)
    t = trips.weights(m.body, m.globals, {"u_n_octaves": octaves})
    assert cost.count(m, t.weights).figures.instructions == expected
    assert cost.count(m).figures.instructions == 3 + 2 + 4 + 1 + 6 + 1  # static: each once


def test_a_loop_on_an_unknown_value_counts_at_its_bound_and_without_one_once():
    from matedit.compiler import cost, trips

    m = cost.parse(_LOOP)
    # the octave count unknown (not given): the break is unknown, the bound of 8 ends it
    t = trips.weights(m.body, m.globals, {})
    assert cost.count(m, t.weights).figures.instructions == \
        3 + 2 * 9 + 4 * 8 + 6 * 8 + 1 * 8 + 1
    # no bound either (the comparison against a loaded value): counted once
    unbounded = _LOOP.replace("%lt = OpSLessThan %bool %k %i8",
                              "%lt = OpFOrdLessThan %bool %oct %f1")
    m = cost.parse(unbounded)
    t = trips.weights(m.body, m.globals, {})
    assert cost.count(m, t.weights).figures.instructions == cost.count(m).figures.instructions
    assert [n for _, n in t.loops] == [None]


def test_attribution_rule_on_a_hand_written_module():
    """Lines 1, 2, 3 of the material (source 33) are nodes A, B, C; C is fed by A and B, B is
    not fed by A. %a (A's) is used by A's own %b and by B's %c: B shares it, so %a is split
    A 1/2, B 1/2; %b is A's alone (C's use of it is C's input). The sample at a library line
    (source 16) inlined at line 1 is A's. OpReturn, at line 50 (the entry point's, no node),
    is the shading's."""
    from matedit.compiler import cost

    m = cost.parse(_HAND)
    names = {1: "A", 2: "B", 3: "C"}

    def owner(chain):
        for line in reversed(chain):
            src, n = divmod(line, 100_000)
            if src == 33 and n in names:
                return f"{names[n]}:0"
        return None

    fed_by = {"A": set(), "B": set(), "C": {"A", "B"}}
    split = cost.attribute(m, owner, lambda a, b: a[0] != b[0] and a[0] not in fed_by[b[0]])
    got = {k: cost.instructions(f) for k, f in split.items()}
    assert got == {"A:0": 2.5, "B:0": 1.5, "C:0": 1.0, None: 1.0}
    assert split["A:0"]["samples"] == 1.0 and split["A:0"]["texture"] == 1.0
    whole = cost.attribute(m, owner)  # without the rule: each instruction to its line
    assert {k: cost.instructions(f) for k, f in whole.items()} == \
        {"A:0": 3.0, "B:0": 1.0, "C:0": 1.0, None: 1.0}
    t = cost.count(m)
    assert t.figures.instructions == 6 and t.figures.samples == 1
