"""Hostile input: injection payloads in every string field, device files, FIFOs, symbolic
links, deep call chains and dead-node floods, by hand and generated with hypothesis, through
`validate`, `compile --target all` (checked with glslangValidator) and the loader.

Every case ends in exit 0 with valid GLSL free of the file's text, or exit 2 with `error:`
lines; never a traceback, an internal error or a hang (20 s per case; see hostile.py).
The number of generated examples per property is HOSTILE_EXAMPLES (default 60).
"""

from __future__ import annotations

import copy
import json
import os
import threading
from datetime import timedelta

import pytest
from hostile import (
    MARK,
    PAYLOADS,
    assert_clean_failure,
    base_material,
    check_compile,
    cli,
    function_doc,
    write,
)
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from matedit.graph.names import GLSL_KEYWORDS, identifier_problem
from matedit.io.document import FormatError, load, loads

pytestmark = pytest.mark.timeout(20, method="signal")
EXAMPLES = int(os.environ.get("HOSTILE_EXAMPLES", "60"))
# Generated cases: each example within 20 s (hypothesis' deadline), the whole property
# within the sum (pytest-timeout, which also ends a hang).
HSET = settings(max_examples=EXAMPLES, deadline=timedelta(seconds=20), derandomize=True,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])
HTIMEOUT = pytest.mark.timeout(20 * EXAMPLES + 60, method="signal")

# --- every string field of a material, one payload at a time --------------------------------

STRING_FIELDS = {
    "name": lambda d, v: d.__setitem__("name", v),
    "description": lambda d, v: d.__setitem__("description", v),
    "node id": lambda d, v: _rename_node(d, "m", v),
    "node label": lambda d, v: d["nodes"][2].__setitem__("label", v),
    "parameter name": lambda d, v: d["nodes"][1]["settings"].__setitem__("name", v),
    "colour parameter name": lambda d, v: d["nodes"][0]["settings"].__setitem__("name", v),
    "node kind": lambda d, v: d["nodes"][2].__setitem__("kind", v),
    "link port": lambda d, v: d["links"][1]["to"].__setitem__(1, v),
    "value key": lambda d, v: d["nodes"][2]["values"].__setitem__(v, 0.25),
    "setting key": lambda d, v: d["nodes"][1]["settings"].__setitem__(v, 1),
    "comment text": lambda d, v: d["comments"][0].__setitem__("text", v),
    "comment id": lambda d, v: d["comments"][0].__setitem__("id", v),
    "preview mesh": lambda d, v: d.setdefault("preview", {}).__setitem__("mesh", v),
    "preview environment": lambda d, v: d.setdefault("preview", {}).__setitem__(
        "environment", v),
    "unknown top-level field": lambda d, v: d.__setitem__("x_future", v),
    "unknown node field": lambda d, v: d["nodes"][0].__setitem__("x_future", v),
    "texture path": lambda d, v: _add_texture(d, v),
    "texture parameter name": lambda d, v: _add_texture(d, "t.png", v),
    "component mask channels": lambda d, v: _add_mask(d, v),
}


def _rename_node(d, old, new):
    for n in d["nodes"]:
        if n["id"] == old:
            n["id"] = new
    for l in d["links"]:
        for end in ("from", "to"):
            if l[end][0] == old:
                l[end][0] = new


def _add_texture(d, path, name="albedo"):
    d["nodes"] += [
        {"id": "tex", "kind": "texture_parameter", "position": [0, 300],
         "settings": {"name": name, "path": path}},
        {"id": "samp", "kind": "texture_sample", "position": [200, 300]},
    ]
    d["links"] = [l for l in d["links"] if l["to"] != ["make", "baseColor"]]
    d["links"] += [{"from": ["tex", "texture"], "to": ["samp", "texture"]},
                   {"from": ["samp", "rgb"], "to": ["make", "baseColor"]}]


def _add_mask(d, channels):
    d["nodes"].append({"id": "mask", "kind": "component_mask", "position": [200, 0],
                       "settings": {"channels": channels}})
    d["links"] = [l for l in d["links"] if l["to"] != ["make", "baseColor"]]
    d["links"] += [{"from": ["col", "color"], "to": ["mask", "value"]},
                   {"from": ["mask", "result"], "to": ["make", "metallic"]}]


@pytest.mark.parametrize("field", sorted(STRING_FIELDS))
@pytest.mark.parametrize("payload", range(len(PAYLOADS)))
def test_payload_in_every_string_field(tmp_path, field, payload):
    raw = base_material()
    STRING_FIELDS[field](raw, PAYLOADS[payload])
    doc = write(tmp_path / "m.json", raw)
    check_compile(doc, tmp_path / "out", [MARK])


def test_samples_of_texture_sample_output_names_exist():
    """The builders above use real port names (else the payload cases prove nothing)."""
    from matedit.graph import nodes

    assert {o.name for o in nodes.REGISTRY["texture_sample"].outputs} >= {"rgb"}
    assert {i.name for i in nodes.REGISTRY["texture_sample"].inputs} >= {"texture"}
    assert {o.name for o in nodes.REGISTRY["component_mask"].outputs} >= {"result"} \
        if "component_mask" in nodes.REGISTRY else True


# --- function and layer files whose names or ports carry code --------------------------------

FILE_NAMES = [f"evil\n#error {MARK}\n", "trail\\", f"sp ace {MARK}", f"p\u00f6wer{MARK}",
              f"x ; {MARK}() ;", f"{MARK}" + "y" * 180]


@pytest.mark.parametrize("fname", range(len(FILE_NAMES)))
def test_function_file_name_never_reaches_glsl(tmp_path, fname):
    stem = FILE_NAMES[fname]
    fn = write(tmp_path / f"{stem}.json", function_doc())
    raw = base_material()
    raw["nodes"].append({"id": "call", "kind": "function_call", "position": [200, 0],
                         "settings": {"function": fn.name}})
    raw["links"] = [l for l in raw["links"] if l["to"] != ["m", "a"]]
    raw["links"] += [{"from": ["r", "value"], "to": ["call", "a"]},
                     {"from": ["call", "result"], "to": ["m", "a"]}]
    doc = write(tmp_path / "m.json", raw)
    rc = check_compile(doc, tmp_path / "out", ["#error", "trail\\", " */", "sp ace"])
    assert rc == 0  # a strange file name is no reason to refuse the material
    frag = (tmp_path / "out" / "m.glsl330.frag").read_text()
    assert "// material function fn_" in frag
    # the file's name survives only inside the function's checked identifier
    import re

    for line in frag.splitlines():
        rest = re.sub(r"\bfn_[A-Za-z0-9_]+", "", line)
        assert MARK not in rest and "evil" not in rest, line
        assert all(len(w) <= 64 for w in re.findall(r"fn_[A-Za-z0-9_]+", line))


@pytest.mark.parametrize("port", ["p\u00f6wer", f"a\n#error {MARK}", "gl_x", "a__b", "in",
                                  "x" * 65, ""])
def test_function_port_names_are_checked_where_they_are_used(tmp_path, port):
    fn = write(tmp_path / "f.json", function_doc(inputs=((port, "float"),)))
    raw = base_material()
    raw["nodes"].append({"id": "call", "kind": "function_call", "position": [200, 0],
                         "settings": {"function": "f.json"}})
    raw["links"] += [{"from": ["call", "result"], "to": ["make", "metallic"]}]
    doc = write(tmp_path / "m.json", raw)
    assert check_compile(doc, tmp_path / "out", [MARK]) == 2
    rc, _, err = cli("validate", fn)
    assert_clean_failure(rc, err)
    assert "node i0" in err and "field name" in err


def test_layer_file_name_and_layer_ids(tmp_path):
    layer = function_doc(inputs=(), outputs=(("attributes", "MaterialAttributes"),), body=[])
    layer["nodes"].append({"id": "mk", "kind": "make_attributes", "position": [100, 0]})
    layer["links"] = [{"from": ["mk", "attributes"], "to": ["o0", "value"]}]
    write(tmp_path / f"lay\n#error {MARK}.json", layer)
    raw = base_material()
    raw["nodes"].append({"id": "stack", "kind": "layer_stack", "position": [300, 0],
                         "settings": {"layers": [
                             {"id": "base", "function": f"lay\n#error {MARK}.json"},
                             {"id": "top", "function": f"lay\n#error {MARK}.json",
                              "blend": "alpha"}]}})
    raw["links"] = [l for l in raw["links"] if l["to"] != ["out", "attributes"]]
    raw["links"].append({"from": ["stack", "attributes"], "to": ["out", "attributes"]})
    doc = write(tmp_path / "m.json", raw)
    assert check_compile(doc, tmp_path / "out", [MARK]) == 0
    raw["nodes"][-1]["settings"]["layers"][1]["id"] = f"t\u00f6p{MARK}"
    write(doc, raw)
    assert check_compile(doc, tmp_path / "out2", [MARK]) == 2


# --- generated names: collisions, keywords, reserved words, non-ASCII -----------------------

ident_chars = st.sampled_from("abcxyz_019ABZ")
names = st.one_of(
    st.text(ident_chars, min_size=1, max_size=12),
    st.sampled_from(sorted(GLSL_KEYWORDS)),
    st.sampled_from(["gl_Position", "gl_x", "a__b", "p_rough", "u_m_b", "fn_rotate", "l_m_a",
                     "in_a", "out_result", "t_albedo", "main", "evaluateMaterial",
                     "shadeSurface", "g_surface", "uFrame", "fragColor", "v_uv",
                     "defaultMaterialAttributes", "MaterialAttributes"]),
    st.text(min_size=0, max_size=8),  # any unicode
    st.text(ident_chars, min_size=60, max_size=70),
)


@HTIMEOUT
@HSET
@given(node_id=names, param=names, param2=names)
def test_generated_names_never_collide(tmp_path_factory, node_id, param, param2):
    """A node named like a generated local next to parameters named like generated uniforms
    (the `p_rough` + `rough_x` miscompile) either compiles to valid GLSL for every target or
    is refused cleanly."""
    tmp = tmp_path_factory.mktemp("names")
    raw = base_material()
    _rename_node(raw, "m", node_id)
    raw["nodes"][1]["settings"]["name"] = param
    raw["nodes"][0]["settings"]["name"] = param2
    doc = write(tmp / "m.json", raw)
    rc = check_compile(doc, tmp / "out", [MARK])
    if rc == 0:
        refl = json.loads((tmp / "out" / "m.reflection.json").read_text())
        uniforms = [u["name"] for u in refl["uniforms"]]
        assert len(uniforms) == len(set(uniforms))
        assert identifier_problem(param) is None and identifier_problem(param2) is None


def test_the_reported_collisions_compile_apart(tmp_path):
    """Node `p_rough` (input x) beside parameter `rough_x`; node `fn_rotate`; nodes `a_b`
    and `a` whose unconnected inputs would both make `u_a_b_c`-like names."""
    raw = base_material()
    raw["nodes"][1]["settings"]["name"] = "rough_x"
    raw["nodes"] += [
        {"id": "p_rough", "kind": "multiply", "position": [0, 0], "values": {"b": 0.3}},
        {"id": "fn_rotate", "kind": "add", "position": [0, 0]},
    ]
    raw["links"] = [l for l in raw["links"] if l["to"] != ["make", "roughness"]]
    raw["links"] += [{"from": ["r", "value"], "to": ["p_rough", "a"]},
                     {"from": ["p_rough", "result"], "to": ["fn_rotate", "a"]},
                     {"from": ["fn_rotate", "result"], "to": ["make", "roughness"]},
                     {"from": ["m", "result"], "to": ["make", "metallic"]}]
    doc = write(tmp_path / "m.json", raw)
    assert check_compile(doc, tmp_path / "out", []) == 0
    refl = json.loads((tmp_path / "out" / "m.reflection.json").read_text())
    names = [u["name"] for u in refl["uniforms"]]
    assert "p_rough_x" in names and len(names) == len(set(names))
    # the CPU evaluator and the GPU agree that the parameter still drives roughness:
    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver

    cm = compile_document(load(doc), FileResolver())
    assert any(u.name == "p_rough_x" for u in cm.ir.uniforms)
    assert "l_p_rough_result" in cm.fragment_text and "float p_rough_x;" in cm.fragment_text


# --- numbers -----------------------------------------------------------------------------------

numbers = st.one_of(st.floats(allow_nan=False, allow_infinity=False, width=64),
                    st.integers(min_value=-(10**320), max_value=10**320),
                    st.sampled_from(["1e400", "-1e999", "1e-400", "123456789012345678901234567"
                                     "890", "0.1e309"]))


@HTIMEOUT
@HSET
@given(value=numbers, where=st.sampled_from(["value", "position", "constant", "default"]))
def test_numbers_either_work_or_name_their_field(tmp_path_factory, value, where):
    tmp = tmp_path_factory.mktemp("num")
    raw = base_material()
    token = str(value)
    if where == "value":
        raw["nodes"][1]["values"]["value"] = "@N@"
    elif where == "position":
        raw["nodes"][1]["position"] = ["@N@", 0]
    elif where == "constant":
        raw["nodes"].append({"id": "k", "kind": "constant", "position": [0, 0],
                             "settings": {"value": "@N@"}})
        raw["links"].append({"from": ["k", "value"], "to": ["make", "metallic"]})
    else:
        raw["nodes"][2]["values"]["b"] = "@N@"
    text = json.dumps(raw).replace('"@N@"', token)
    doc = write(tmp / "m.json", text)
    rc = check_compile(doc, tmp / "out", [MARK])
    if rc == 2:
        _, _, err = cli("validate", doc)
        assert "m.json" in err


def test_overflowing_number_names_node_and_field(tmp_path):
    raw = json.dumps(base_material()).replace('"value": 0.4', '"value": 1e400')
    rc, _, err = cli("validate", write(tmp_path / "m.json", raw))
    assert_clean_failure(rc, err)
    assert "node r" in err and "field values.value" in err and "64-bit float" in err


# --- files that are not files ------------------------------------------------------------------

def _fifo(tmp_path):
    p = tmp_path / "fifo.json"
    os.mkfifo(p)
    return p


SPECIAL = {
    "/dev/zero": lambda tmp: "/dev/zero",
    "/dev/null": lambda tmp: "/dev/null",
    "fifo": _fifo,
    "folder": lambda tmp: str(tmp),
    "missing": lambda tmp: str(tmp / "nope.json"),
    "dangling link": lambda tmp: (os.symlink(tmp / "gone", tmp / "link.json"),
                                  str(tmp / "link.json"))[1],
    "link loop": lambda tmp: (os.symlink(tmp / "l2.json", tmp / "l1.json"),
                              os.symlink(tmp / "l1.json", tmp / "l2.json"),
                              str(tmp / "l1.json"))[2],
}


def _no_writer_left(path):
    """Open and close the FIFO's write end so a reader that blocked would return."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
        os.close(fd)
    except OSError:
        pass


@pytest.mark.parametrize("kind", sorted(SPECIAL))
def test_special_files_as_document(tmp_path, kind):
    target = SPECIAL[kind](tmp_path)
    commands = [["compile", target, "-o", tmp_path / "o"], ["render", target, "-o",
                                                             tmp_path / "r.png"],
                ["validate", target]]  # a folder with no *.json in it is an error too
    for command in commands:
        rc, _, err = cli(*command)
        assert_clean_failure(rc, err)
    with pytest.raises(FormatError):
        load(target)


@pytest.mark.parametrize("kind", sorted(SPECIAL))
def test_special_files_as_function_reference(tmp_path, kind):
    target = SPECIAL[kind](tmp_path)
    raw = base_material()
    raw["nodes"].append({"id": "call", "kind": "function_call", "position": [0, 0],
                         "settings": {"function": os.path.relpath(target, tmp_path)}})
    doc = write(tmp_path / "m.json", raw)
    assert check_compile(doc, tmp_path / "out", [MARK]) == 2


@pytest.mark.gl
@pytest.mark.parametrize("kind", ["/dev/zero", "fifo", "folder", "missing"])
@pytest.mark.parametrize("where", ["--mesh", "preview.mesh", "--env", "texture"])
def test_special_files_as_mesh_environment_and_texture(tmp_path, kind, where):
    target = SPECIAL[kind](tmp_path)
    raw = base_material()
    args = []
    if where == "--mesh":
        args = ["--mesh", target]
    elif where == "--env":
        args = ["--env", target]
    elif where == "preview.mesh":
        raw["preview"] = {"mesh": os.path.relpath(target, tmp_path)}
    else:
        _add_texture(raw, os.path.relpath(target, tmp_path))
    doc = write(tmp_path / "m.json", raw)
    timer = threading.Timer(5, _no_writer_left, [target]) if kind == "fifo" else None
    if timer:
        timer.start()
    try:
        rc, _, err = cli("render", doc, "-o", tmp_path / "r.png", "--size", "32x32", *args)
    finally:
        if timer:
            timer.cancel()
    if where == "texture":
        # a texture that cannot be read is a warning and shows as a checker: the render works
        assert rc == 0, err
        assert (tmp_path / "r.png").is_file()
    else:
        assert_clean_failure(rc, err)


# --- deep call chains and dead-node floods -----------------------------------------------------

def _chain(tmp_path, depth: int):
    for k in range(depth):
        body = None
        f = function_doc()
        if k + 1 < depth:
            f["nodes"].append({"id": "c", "kind": "function_call", "position": [100, 0],
                               "settings": {"function": f"f{k + 1}.json"}})
            f["links"] = [{"from": ["i0", "value"], "to": ["c", "a"]},
                          {"from": ["c", "result"], "to": ["o0", "value"]}]
        del body
        write(tmp_path / f"f{k}.json", f)
    raw = base_material()
    raw["nodes"].append({"id": "call", "kind": "function_call", "position": [200, 0],
                         "settings": {"function": "f0.json"}})
    raw["links"] += [{"from": ["call", "result"], "to": ["make", "metallic"]}]
    return write(tmp_path / "m.json", raw)


def test_call_chain_at_the_limit_compiles(tmp_path):
    from matedit.graph.validate import MAX_CALL_DEPTH

    doc = _chain(tmp_path, MAX_CALL_DEPTH)
    assert check_compile(doc, tmp_path / "out", [MARK], targets=("glsl330",)) == 0


@pytest.mark.parametrize("depth", [65, 300, 1200])
def test_deep_call_chains_are_refused_quickly(tmp_path, depth):
    doc = _chain(tmp_path, depth)
    for command in (["validate", doc], ["compile", doc, "-o", tmp_path / "o"]):
        rc, _, err = cli(*command)
        assert_clean_failure(rc, err)
        assert "nest" in err and "node call" in err


def test_recursive_calls_are_refused(tmp_path):
    a = function_doc()
    a["nodes"].append({"id": "c", "kind": "function_call", "position": [0, 0],
                       "settings": {"function": "b.json"}})
    b = copy.deepcopy(a)
    b["nodes"][-1]["settings"]["function"] = "a.json"
    write(tmp_path / "a.json", a)
    write(tmp_path / "b.json", b)
    raw = base_material()
    raw["nodes"].append({"id": "call", "kind": "function_call", "position": [0, 0],
                         "settings": {"function": "a.json"}})
    doc = write(tmp_path / "m.json", raw)
    assert check_compile(doc, tmp_path / "out", []) == 2


def test_nine_thousand_dead_nodes_cost_no_uniforms(tmp_path):
    raw = base_material()
    for k in range(9000):
        raw["nodes"].append({"id": f"dead{k}", "kind": "multiply", "position": [k, 0],
                             "values": {"a": 0.5, "b": 0.25}})
    doc = write(tmp_path / "m.json", raw)
    assert check_compile(doc, tmp_path / "out", [], targets=("glsl330",)) == 0
    refl = json.loads((tmp_path / "out" / "m.reflection.json").read_text())
    assert {u["node"] for u in refl["uniforms"]} == {"col", "r", "m", "make"}
    assert refl["uniform_block"]["size"] <= 256


@pytest.mark.gl
def test_dead_node_flood_links_on_llvmpipe(tmp_path):
    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver
    from matedit.render.context import headless_context

    raw = base_material()
    for k in range(9000):
        raw["nodes"].append({"id": f"dead{k}", "kind": "multiply", "position": [k, 0]})
    cm = compile_document(loads(json.dumps(raw), "m.json", tmp_path / "m.json"),
                          FileResolver())
    ctx = headless_context()
    try:
        prog = ctx.program(vertex_shader=cm.vertex_text, fragment_shader=cm.fragment_text)
        prog.release()
    finally:
        ctx.release()


# --- the loader alone, on generated garbage ----------------------------------------------------

json_values = st.recursive(
    st.none() | st.booleans() | st.floats(allow_nan=False, allow_infinity=False)
    | st.integers() | st.text(max_size=20),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.text(max_size=8), children, max_size=4),
    max_leaves=20,
)


@HTIMEOUT
@HSET
@given(mutation=st.lists(st.tuples(st.sampled_from(["top", "node", "link", "settings"]),
                                   st.text(max_size=10), json_values), min_size=1, max_size=4))
def test_loader_never_raises_anything_but_format_errors(mutation):
    raw = base_material()
    for where, key, value in mutation:
        target = {"top": raw, "node": raw["nodes"][1], "link": raw["links"][0],
                  "settings": raw["nodes"][1]["settings"]}[where]
        target[key] = value
    try:
        doc = loads(json.dumps(raw), "m.json")
    except FormatError as exc:
        assert str(exc).startswith("m.json")
        return
    from matedit.io.document import dumps

    again = loads(dumps(doc), "m.json")  # a file that loads also saves, and loads again
    assert dumps(again) == dumps(doc)


# === Numbers, names and streams (issue 22): streams, non-UTF-8 names, synthetic image ======
# === readers, OBJ bounds, degenerate meshes, contact sheets, glTF URIs, empty folders ======
#
# Helpers of this section only. Subprocess cases run `python -m matedit` with the matedit
# this test imported (so the same tree is under test), argv given as bytes where a name is
# not UTF-8.

STREAM_COMMANDS = {"nodes --json": ["nodes", "--json"], "nodes": ["nodes"],
                   "--version": ["--version"], "--help": ["--help"]}


def _matedit_argv(*args) -> list[bytes]:
    import sys

    return [os.fsencode(sys.executable), b"-m", b"matedit",
            *[a if isinstance(a, bytes) else os.fsencode(str(a)) for a in args]]


def _matedit_env() -> dict:
    import matedit

    root = os.path.dirname(os.path.dirname(os.path.abspath(matedit.__file__)))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([root, env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env.pop("MATEDIT_DEBUG", None)
    return env


def _run_matedit(*args, cwd=None, timeout=18, **kw):
    import subprocess

    return subprocess.run(_matedit_argv(*args), env=_matedit_env(), cwd=cwd, timeout=timeout,
                          **kw)


def _close_fd(fd: int):
    return lambda: os.close(fd)


def _error_lines(err: bytes) -> list[str]:
    return [l for l in err.decode("utf-8", "backslashreplace").splitlines() if l.strip()]


@pytest.mark.parametrize("how", ["stdout closed", "stdout full", "broken pipe"])
@pytest.mark.parametrize("command", sorted(STREAM_COMMANDS))
def test_stdout_closed_full_or_broken(tmp_path, how, command):
    """Output that cannot be written is one `error:` line and status 2; a reader that went
    away (`| head -1`) ends it quietly with 141. Never an internal error or a traceback."""
    import subprocess

    args = STREAM_COMMANDS[command]
    if how == "broken pipe":
        # The reader has gone before the first write (as `head` may have, whatever the
        # pipe's buffer holds): every write meets EPIPE.
        read_end, write_end = os.pipe()
        os.close(read_end)
        try:
            r = _run_matedit(*args, stdout=write_end, stderr=subprocess.PIPE)
        finally:
            os.close(write_end)
        assert r.stderr == b"", r.stderr
        assert r.returncode == 141
        return
    if how == "stdout full":
        with open("/dev/full", "wb") as full:
            r = _run_matedit(*args, stdout=full, stderr=subprocess.PIPE)
    else:
        r = _run_matedit(*args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         preexec_fn=_close_fd(1))
    lines = _error_lines(r.stderr)
    assert r.returncode == 2, r.stderr
    assert len(lines) == 1 and lines[0].startswith("error: cannot write to standard output: "), \
        lines


@pytest.mark.parametrize("how", ["stderr closed", "stderr full"])
@pytest.mark.parametrize("case", ["error", "success"])
def test_stderr_closed_or_full_changes_only_what_is_seen(tmp_path, how, case):
    """With stderr gone the status still tells, and nothing meant for stderr lands on
    stdout."""
    import subprocess

    args = ["validate", tmp_path / "missing.json"] if case == "error" else \
        ["nodes", "--category", "Math"]
    if how == "stderr full":
        with open("/dev/full", "wb") as full:
            r = _run_matedit(*args, stdout=subprocess.PIPE, stderr=full)
    else:
        r = _run_matedit(*args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                         preexec_fn=_close_fd(2))
    if case == "error":
        assert r.returncode == 2
        assert r.stdout == b""
    else:
        assert r.returncode == 0
        assert b"node kinds" in r.stdout and b"error" not in r.stdout


BAD = b"\xff\xfe"  # not UTF-8: Python shows these bytes as surrogate escapes


def _bytes_exists(path: bytes) -> bool:
    return os.path.lexists(path) and os.path.getsize(path) > 0


def _non_utf8_fixture(tmp: bytes) -> dict[str, bytes]:
    """Files with non-UTF-8 names: an environment, a texture, a mesh, and a material
    (itself so named) that reads the texture."""
    import numpy as np

    from matedit.io.images import write_image

    env = tmp + b"/env" + BAD + b".exr"
    tex = tmp + b"/tex" + BAD + b".png"
    obj = tmp + b"/tri" + BAD + b".obj"
    doc = tmp + b"/m" + BAD + b".json"
    write_image(os.fsdecode(env), np.full((8, 16, 3), 0.5, np.float32))
    write_image(os.fsdecode(tex), np.full((4, 4, 3), 0.25, np.float32))
    with open(obj, "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    raw = base_material()
    _add_texture(raw, os.fsdecode(b"tex" + BAD + b".png"))
    with open(doc, "w", encoding="utf-8") as f:
        f.write(json.dumps(raw))  # the name is written as a \udcff escape, which JSON allows
    os.mkdir(tmp + b"/dir" + BAD)
    return {"env": env, "tex": tex, "obj": obj, "doc": doc, "dir": tmp + b"/dir" + BAD}


# name -> (argv with {placeholders}, the files that must exist afterwards)
NON_UTF8_CASES = {
    "render -o": (["render", "doc", "-o", b"OUT.png", "--size", "16x16"], [b"OUT.png"]),
    "render -o in a folder": (["render", "doc", "-o", b"dir/r.exr", "--size", "16x16"],
                              [b"dir/r.exr"]),
    "render --env": (["render", "doc", "-o", b"r.png", "--size", "16x16", "--env", "env"],
                     [b"r.png"]),
    "render --mesh": (["render", "doc", "-o", b"r.png", "--size", "16x16", "--mesh", "obj"],
                      [b"r.png"]),
    "brdf-lut -o": (["brdf-lut", "-o", b"OUT.exr", "--size", "8", "--samples", "64",
                     "--no-cache"], [b"OUT.exr"]),
    "bake -o": (["bake", "doc", "-o", b"dir", "--size", "8"], [b"dir/m" + BAD + b"_orm.png"]),
    "bake-ibl ENV -o": (["bake-ibl", "env", "-o", b"OUT", "--size", "8", "--samples", "8",
                         "--no-cache"], [b"OUT/brdf_lut.exr", b"OUT/prefiltered_mip0.exr"]),
    "export .gltf": (["export", "doc", "-o", b"OUT.gltf", "--size", "8", "--mesh", "obj"],
                     [b"OUT.gltf", b"OUT.bin"]),
    "export .glb": (["export", "doc", "-o", b"OUT.glb", "--size", "8"], [b"OUT.glb"]),
    "export .usda": (["export", "doc", "-o", b"OUT.usda", "--size", "8", "--mesh", "obj"],
                     [b"OUT.usda", b"out___orm.png"]),
    "export .usdz": (["export", "doc", "-o", b"OUT.usdz", "--size", "8"], [b"OUT.usdz"]),
    "export --check": (["export", "doc", "-o", b"OUT.gltf", "--size", "8", "--check",
                        "--check-size", "16", "--check-image", b"dir/chk.png"],
                       [b"OUT.gltf", b"OUT.bin", b"dir/chk.png"]),
    # the side folder and the texture's copy: their names as text MaterialX can hold
    "export .mtlx": (["export", "doc", "-o", b"OUT.mtlx", "--size", "8"],
                     [b"OUT.mtlx", b"out___textures/tex__.png"]),
    "export .mtlx --zip": (["export", "doc", "-o", b"OUT.mtlx", "--size", "8", "--zip"],
                           [b"OUT.zip"]),
    "contact-sheet": (["contact-sheet", "doc", "-o", b"OUT.png", "--size", "16"],
                      [b"OUT.png"]),
}


def _expand(arg, fixture: dict[str, bytes], tmp: bytes):
    if isinstance(arg, str):
        return fixture.get(arg, arg)
    return tmp + b"/" + arg.replace(b"OUT", b"out" + BAD).replace(b"dir", b"dir" + BAD)


@pytest.mark.gl
@pytest.mark.parametrize("case", sorted(NON_UTF8_CASES))
def test_non_utf8_file_names(tmp_path, case):
    """Names with bytes that are not UTF-8 (valid on Linux) work as inputs and outputs;
    a texture so named is read (no warning), and the glTF's .bin URI names those bytes."""
    import subprocess
    import urllib.parse

    tmp = os.fsencode(tmp_path)
    fixture = _non_utf8_fixture(tmp)
    args, outputs = NON_UTF8_CASES[case]
    r = _run_matedit(*[_expand(a, fixture, tmp) for a in args], stdout=subprocess.PIPE,
                     stderr=subprocess.PIPE, cwd=tmp)
    err = r.stderr.decode("utf-8", "backslashreplace")
    assert r.returncode == 0, err
    assert "warning" not in err and "error" not in err, err  # the texture was read
    for out in outputs:
        assert _bytes_exists(_expand(out, fixture, tmp)), (out, os.listdir(tmp))
    if case == "export .gltf":
        gltf = json.loads(open(_expand(b"OUT.gltf", fixture, tmp), "rb").read())
        uri = gltf["buffers"][0]["uri"]
        assert uri.isascii()
        assert urllib.parse.unquote_to_bytes(uri) == b"out" + BAD + b".bin"
    if case == "bake-ibl ENV -o":  # the paths it prints are the bytes the shell gave
        assert tmp + b"/out" + BAD + b"/ibl.json" in r.stdout.splitlines()


@pytest.mark.parametrize("where", ["render --env", "render --mesh", "validate",
                                   "bake-ibl ENV"])
def test_non_utf8_names_in_error_messages(tmp_path, where):
    """A missing file with a non-UTF-8 name is one `error:` line showing the byte as \\xNN."""
    import subprocess

    tmp = os.fsencode(tmp_path)
    doc = write(tmp_path / "m.json", base_material())
    missing = tmp + b"/gone" + BAD
    args = {"render --env": ["render", doc, "-o", tmp + b"/r.png", "--env", missing + b".exr"],
            "render --mesh": ["render", doc, "-o", tmp + b"/r.png", "--mesh",
                              missing + b".obj"],
            "validate": ["validate", missing + b".json"],
            "bake-ibl ENV": ["bake-ibl", missing + b".exr", "-o", tmp + b"/o"]}[where]
    r = _run_matedit(*args, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    lines = _error_lines(r.stderr)
    assert r.returncode == 2, lines
    assert len(lines) == 1 and lines[0].startswith("error: "), lines
    assert "gone\\xff\\xfe" in lines[0], lines


# OpenImageIO's `null` reader makes up an image (1024x1024, or whatever `?RES=` asks) for a
# name ending in .null; it allocates only when the pixels are read.
SYNTHETIC_NAMES = ["x.null", "x.null?RES=16384x8192.png", "x.null?RES=16384x8192",
                   "x.nul", "x.term"]


@pytest.mark.gl
@pytest.mark.parametrize("where", ["--env", "texture"])
@pytest.mark.parametrize("name", SYNTHETIC_NAMES)
def test_synthetic_image_readers_are_refused_before_allocating(tmp_path, name, where):
    """A 2-byte file that selects a synthetic reader is refused, as an error (--env) or as a
    texture that cannot be read (drawn as a checker), and memory stays small."""
    import subprocess

    (tmp_path / name).write_bytes(b"ab")
    raw = base_material()
    args = []
    if where == "--env":
        args = ["--env", tmp_path / name]
    else:
        _add_texture(raw, name)
    doc = write(tmp_path / "m.json", raw)
    # The peak is VmHWM, this process's own: Linux carries the parent's ru_maxrss across
    # fork and exec, so after a long pytest run getrusage would report pytest's peak.
    script = ("import sys\nfrom matedit.cli import main\n"
              "rc = main(sys.argv[1:])\n"
              "hwm = [l for l in open('/proc/self/status') if l.startswith('VmHWM:')][0]\n"
              "print(int(hwm.split()[1]) // 1024)\n"
              "raise SystemExit(rc)\n")
    import sys

    r = subprocess.run([sys.executable, "-c", script, "render", str(doc), "-o",
                        str(tmp_path / "r.png"), "--size", "16x16", *map(str, args)],
                       env=_matedit_env(), capture_output=True, text=True, timeout=18)
    peak_mb = int(r.stdout.split()[-1])
    assert peak_mb < 600, f"{peak_mb} MB"
    lines = [l for l in r.stderr.splitlines() if l.strip()]
    if where == "--env":
        assert_clean_failure(r.returncode, r.stderr)
        assert len(lines) == 1 and name.split("?")[0] in lines[0], lines
    else:
        assert r.returncode == 0, r.stderr  # the texture shows as a checker
        assert not any(l.startswith("error") for l in lines), lines


def test_images_are_read_only_by_real_formats_readers(tmp_path):
    """The reader alone: a synthetic format is refused whatever its name says, and a real
    image whose extension names another real format is still read."""
    import numpy as np

    from matedit.io.images import ImageError, read_image, write_image

    (tmp_path / "x.null?RES=16384x8192.png").write_bytes(b"ab")
    with pytest.raises(ImageError, match="null"):
        read_image(tmp_path / "x.null?RES=16384x8192.png")
    write_image(tmp_path / "real.exr", np.ones((2, 4, 3)))
    os.rename(tmp_path / "real.exr", tmp_path / "really_exr.tif")
    img = read_image(tmp_path / "really_exr.tif")
    assert img.format_name == "openexr" and img.pixels.shape == (2, 4, 3)


def _obj_limit_case(tmp_path, monkeypatch, case):
    """(OBJ path, the words the error must hold) for one way past the limits; small limits
    are patched in where the real ones would take seconds to reach."""
    import matedit.render.mesh as mesh

    tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    if case == "one huge polygon":  # the real limit: a fan of 2,000,001 triangles
        n = mesh.MAX_OBJ_TRIANGLES + 3 if hasattr(mesh, "MAX_OBJ_TRIANGLES") else 2_000_003
        text = tri + "f" + " 1 2 3" * (n // 3 + 1) + "\n"
        return write(tmp_path / "fan.obj", text), ["fan.obj:4:", "triangles"]
    monkeypatch.setattr(mesh, "MAX_OBJ_VERTICES", 100, raising=False)
    monkeypatch.setattr(mesh, "MAX_OBJ_TRIANGLES", 100, raising=False)
    if case == "vertices":
        text = "v 0 0 0\n" * 101 + "f 1 2 3\n"
        return write(tmp_path / "v.obj", text), ["v.obj:101:", "more than 100 vertices"]
    if case == "texture coordinates":
        text = tri + "vt 0 0\n" * 101 + "f 1/1 2/2 3/3\n"
        return write(tmp_path / "vt.obj", text), ["vt.obj:104:", "texture coordinates"]
    if case == "normals":
        text = tri + "vn 0 0 1\n" * 101 + "f 1//1 2//1 3//1\n"
        return write(tmp_path / "vn.obj", text), ["vn.obj:104:", "normals"]
    if case == "triangles":
        text = tri + "f 1 2 3\n" * 101
        return write(tmp_path / "f.obj", text), ["f.obj:104:", "more than 100 triangles"]
    # distinct corners: 40 triangles of 60 positions and 3 UVs, 120 different pairs
    text = "v 0 0 0\n" * 60 + "vt 0 0\nvt 1 0\nvt 0 1\n" + "".join(
        "f " + " ".join(f"{c % 60 + 1}/{c // 60 + 1}" for c in range(3 * k, 3 * k + 3)) + "\n"
        for k in range(40))
    return write(tmp_path / "c.obj", text), ["c.obj:", "distinct vertices"]


OBJ_LIMIT_CASES = ["one huge polygon", "vertices", "texture coordinates", "normals",
                   "triangles", "distinct corners"]


@pytest.mark.parametrize("case", OBJ_LIMIT_CASES)
def test_obj_beyond_the_stated_limits_is_refused_while_parsing(tmp_path, monkeypatch, case):
    import time

    from matedit.render.mesh import MeshError, load_obj

    path, words = _obj_limit_case(tmp_path, monkeypatch, case)
    start = time.monotonic()
    with pytest.raises(MeshError) as info:
        load_obj(path)
    assert time.monotonic() - start < 5
    assert all(w in str(info.value) for w in words), str(info.value)
    assert "the limit for a preview mesh" in str(info.value) or case == "distinct corners"


@pytest.mark.gl
def test_obj_beyond_the_limits_through_render(tmp_path, monkeypatch):
    path, words = _obj_limit_case(tmp_path, monkeypatch, "one huge polygon")
    doc = write(tmp_path / "m.json", base_material())
    rc, _, err = cli("render", doc, "-o", tmp_path / "r.png", "--size", "16x16", "--mesh", path)
    assert_clean_failure(rc, err)
    assert len(err.splitlines()) == 1 and "triangles" in err


DEGENERATE_OBJS = {
    "zero-area triangle": "v 0 0 0\nv 0 0 0\nv 0 0 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                          "f 1/1 2/2 3/3\n",
    "coincident UVs": "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.5\nf 1/1 2/1 3/1\n",
    "collinear points": "v 0 0 0\nv 1 0 0\nv 2 0 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                        "f 1/1 2/2 3/3\n",
    "collinear UVs": "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 1\nvt 2 2\nf 1/1 2/2 3/3\n",
    "zero normals": "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n",
    "mixed with a good face": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nvt 0 0\nvt 1 0\n"
                              "vt 0 1\nf 1/1 2/2 3/3\nf 4/1 4/2 4/3\n",
}


@pytest.mark.parametrize("case", sorted(DEGENERATE_OBJS))
def test_degenerate_obj_gets_finite_unit_frames(tmp_path, case):
    import warnings

    import numpy as np

    from matedit.render.mesh import load_obj

    path = write(tmp_path / "d.obj", DEGENERATE_OBJS[case])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy warning fails the case
        mesh = load_obj(path)
    for name, v in (("normals", mesh.normals), ("tangents", mesh.tangents[:, :3])):
        assert np.all(np.isfinite(v)), name
        assert np.allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-5), (name, v)
    assert np.allclose(np.sum(mesh.normals * mesh.tangents[:, :3], axis=1), 0.0, atol=1e-5)
    assert set(np.unique(mesh.tangents[:, 3])) <= {-1.0, 1.0}


@pytest.mark.gl
@pytest.mark.parametrize("case", ["zero-area triangle", "coincident UVs", "zero normals"])
def test_degenerate_obj_exports_finite_gltf_tangents(tmp_path, case):
    import warnings

    import numpy as np
    import pygltflib

    path = write(tmp_path / "d.obj", DEGENERATE_OBJS[case])
    doc = write(tmp_path / "m.json", base_material())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rc, _, err = cli("export", doc, "-o", tmp_path / "d.glb", "--size", "4", "--mesh", path)
    assert rc == 0, err
    # nothing but the bake's own note (no UV layout to bake on: the plane), never a warning
    assert all(line.startswith("note: ") and "on a plane" in line
               for line in err.splitlines()), err
    g = pygltflib.GLTF2().load(str(tmp_path / "d.glb"))
    blob = g.binary_blob()
    attrs = g.meshes[0].primitives[0].attributes
    for index, width in ((attrs.NORMAL, 3), (attrs.TANGENT, 4)):
        view = g.bufferViews[g.accessors[index].bufferView]
        v = np.frombuffer(blob[view.byteOffset:view.byteOffset + view.byteLength],
                          np.float32).reshape(-1, width)
        assert np.all(np.isfinite(v))
        assert np.allclose(np.linalg.norm(v[:, :3], axis=1), 1.0, atol=1e-5)


def _sheet_case(tmp_path, case):
    raw = base_material()
    if case == "missing preview mesh":
        raw["preview"] = {"mesh": "gone.obj"}
    elif case == "missing preview environment":
        raw["preview"] = {"environment": "gone.hdr"}
    elif case == "unreadable preview mesh":
        raw["preview"] = {"mesh": "bad.obj"}
        write(tmp_path / "bad.obj", "v 0 0 0\nf 1 2 3\n")
    elif case == "unreadable preview environment":
        raw["preview"] = {"environment": "bad.hdr"}
        (tmp_path / "bad.hdr").write_bytes(b"#?RADIANCE\nnot really\n")
    return write(tmp_path / "m.json", raw)


@pytest.mark.gl
@pytest.mark.parametrize("size", [16, 24, 32, 63, 64])
def test_contact_sheet_small_tiles(tmp_path, size):
    from matedit.io.images import read_image

    doc = _sheet_case(tmp_path, "plain")
    rc, _, err = cli("contact-sheet", doc, doc, "-o", tmp_path / "s.png", "--size", size)
    assert rc == 0, err
    assert read_image(tmp_path / "s.png").pixels.shape == (size, 2 * size, 3)


@pytest.mark.gl
@pytest.mark.parametrize("case", ["missing preview mesh", "missing preview environment",
                                  "unreadable preview mesh", "unreadable preview environment",
                                  "size below the minimum"])
def test_contact_sheet_bad_previews_name_material_and_field(tmp_path, case):
    doc = _sheet_case(tmp_path, case)
    size = "8" if case == "size below the minimum" else "16"
    rc, _, err = cli("contact-sheet", doc, "-o", tmp_path / "s.png", "--size", size)
    assert_clean_failure(rc, err)
    lines = err.splitlines()
    assert len(lines) == 1, lines
    if case == "size below the minimum":
        assert "16..2048" in lines[0]
    else:
        field = "preview.mesh" if "mesh" in case else "preview.environment"
        assert lines[0].startswith(f"error: {doc}: {field}: "), lines
    assert not (tmp_path / "s.png").exists()


@pytest.mark.gl
@pytest.mark.parametrize("stem", ["odd name #1 %41", "caf\u00e9 & co", "a?b;c=d", "plain"])
def test_gltf_buffer_uri_is_percent_encoded(tmp_path, stem):
    import urllib.parse

    import pygltflib

    doc = write(tmp_path / "m.json", base_material())
    out = tmp_path / f"{stem}.gltf"
    rc, _, err = cli("export", doc, "-o", out, "--size", "4")
    assert rc == 0, err
    uri = json.loads(out.read_text(encoding="utf-8"))["buffers"][0]["uri"]
    assert uri == urllib.parse.quote(f"{stem}.bin", safe="")
    assert uri.isascii() and not set(" #?") & set(uri)
    bin_path = tmp_path / urllib.parse.unquote(uri)
    assert bin_path == tmp_path / f"{stem}.bin" and bin_path.is_file()
    g = pygltflib.GLTF2().load(str(out))
    assert g.buffers[0].byteLength == bin_path.stat().st_size


@pytest.mark.parametrize("layout", ["empty", "other files only", "empty subfolders",
                                    "beside a good file"])
def test_validate_on_a_folder_without_documents(tmp_path, layout):
    folder = tmp_path / "docs"
    folder.mkdir()
    args = [folder]
    if layout == "other files only":
        (folder / "notes.txt").write_text("x")
        (folder / "m.json.bak").write_text("{}")
    elif layout == "empty subfolders":
        (folder / "a" / "b").mkdir(parents=True)
    elif layout == "beside a good file":
        args = [write(tmp_path / "m.json", base_material()), folder]
    rc, out, err = cli("validate", *args)
    assert_clean_failure(rc, err)
    assert err.splitlines() == [
        f"error: {folder}: no material, function or instance files (*.json)"]
# === Numbers, nesting and MaterialX values (issue 22): float32 at every entry point of a number,
# huge integers, duplicate keys in rigs, --exposure, malformed MaterialX numbers, deeply nested
# JSON per reader, the default exposure, and generated rig and instance files ==================
#
# The rule: a number the renderer would receive is finite and within float32 (one function,
# matedit.graph.numbers.gpu_number_problem, asked by every format); JSON text goes through one
# bounded-depth parser (matedit.io.jsontext.parse_json). Refusals are exit 2 with `error:` lines
# naming the file, the node (parameter, light) and the field.

N22 = '"@N@"'  # where a raw JSON token goes into a file written as JSON text


def _rig22() -> dict:
    """A valid rig: a sphere light, then a tube light (light 1)."""
    return {"format": "matedit.lightrig", "version": 1, "lights": [
        {"type": "sphere", "position": [2.4, 2.8, 3.0], "radius": 0.3,
         "color": [1.0, 0.96, 0.9], "intensity": 18.0, "influence_radius": 25.0},
        {"type": "tube", "position": [-2.8, 1.6, -2.4], "direction": [0, 1, 0],
         "radius": 0.04, "length": 1.6, "color": [0.75, 0.85, 1.0], "intensity": 10.0}]}


def _text22(raw: dict, token: str) -> str:
    return json.dumps(raw).replace(N22, token)


def _material22(tmp, token="0.4", where=None) -> object:
    """base_material as m.json, with `token` as raw JSON at `where` (a function of the dict)."""
    raw = base_material()
    if where is not None:
        where(raw)
    return write(tmp / "m.json", _text22(raw, token))


def _instance22(tmp, parameters: str) -> object:
    """i.json: an instance of a valid m.json with `parameters` (JSON text) as its overrides."""
    _material22(tmp)
    return write(tmp / "i.json", '{"format": "matedit.instance", "version": 2, "name": "i", '
                 f'"parent": "m.json", "parameters": {parameters}}}')


def _rig_file22(tmp, field, token, light=1) -> object:
    raw = _rig22()
    if isinstance(field, tuple):  # (list field, index)
        raw["lights"][light][field[0]][field[1]] = "@N@"
    else:
        raw["lights"][light][field] = "@N@"
    return write(tmp / "rig.json", _text22(raw, token))


def _add_constant22(raw):
    raw["nodes"].append({"id": "k", "kind": "constant", "position": [0, 0],
                         "settings": {"type": "float", "value": "@N@"}})
    raw["links"].append({"from": ["k", "value"], "to": ["make", "metallic"]})


def _function22(tmp, token):
    fn = function_doc()
    fn["nodes"][0]["settings"]["default"] = "@N@"
    write(tmp / "f.json", _text22(fn, token))
    raw = base_material()
    raw["nodes"].append({"id": "call", "kind": "function_call", "position": [200, 0],
                         "settings": {"function": "f.json"}})
    raw["links"] += [{"from": ["call", "result"], "to": ["make", "metallic"]}]
    return write(tmp / "m.json", raw)


def _set(path, value="@N@"):
    """A mutation of base_material's dict: raw[path...] = value."""
    def apply(raw):
        target = raw
        for p in path[:-1]:
            target = target[p]
        target[path[-1]] = value
    return apply


def _float32_rig(field):
    name = field if isinstance(field, str) else field[0]
    return lambda t, v: ("rig", _rig_file22(t, field, v), ["rig.json", "light 1", f"field {name}"])


# entry -> (what kind of file, the file, what every message must name)
FLOAT32_ENTRIES = {
    "material value": lambda t, v: ("material", _material22(
        t, v, _set(["nodes", 1, "values", "value"])), ["m.json", "node r", "field value"]),
    "input value": lambda t, v: ("material", _material22(
        t, v, _set(["nodes", 2, "values", "b"])), ["m.json", "node m", "field b"]),
    "colour component": lambda t, v: ("material", _material22(
        t, v, _set(["nodes", 0, "values", "value"], [0.5, "@N@", 0.5])),
        ["m.json", "node col", "field value"]),
    "constant setting": lambda t, v: ("material", _material22(t, v, _add_constant22),
                                      ["m.json", "node k", "field value"]),
    "parameter range": lambda t, v: ("material", _material22(
        t, v, _set(["nodes", 1, "settings", "ui_max"])), ["m.json", "node r", "field ui_max"]),
    "function input default": lambda t, v: ("function", _function22(t, v),
                                            ["m.json", "node call", "field a"]),
    "instance scalar override": lambda t, v: ("instance", _instance22(t, f'{{"rough": {v}}}'),
                                              ["i.json", "parameter rough"]),
    "instance colour override": lambda t, v: ("instance", _instance22(
        t, f'{{"tint": [0.1, {v}, 0.1]}}'), ["i.json", "parameter tint"]),
    **{f"rig {f if isinstance(f, str) else f[0]}": _float32_rig(f)
       for f in ["intensity", ("color", 0), ("position", 2), "length", "radius",
                 ("direction", 1), "influence_radius"]},
}
FLOAT32_VALUES = ["3.5e38", "1e308", "-1e39", str(10**39)]


@pytest.mark.parametrize("value", FLOAT32_VALUES)
@pytest.mark.parametrize("entry", [*sorted(FLOAT32_ENTRIES), "render --exposure"])
def test_float32_overflow_is_refused_where_the_number_enters(tmp_path, entry, value):
    """validate refuses what a float32 uniform cannot hold, naming file, node and field; the
    commands that would pack it (compile, render, bake) refuse it the same way, never with
    "float too large to pack"."""
    if entry == "render --exposure":
        doc = _material22(tmp_path)
        rc, _, err = cli("render", doc, "-o", tmp_path / "x.png", "--size", "8x8",
                         f"--exposure={value}")
        assert_clean_failure(rc, err)
        assert "--exposure" in err and "pack" not in err
        return
    kind, path, needles = FLOAT32_ENTRIES[entry](tmp_path, value)
    png = ("-o", tmp_path / "x.png", "--size", "8x8")
    good = write(tmp_path / "good.json", base_material())
    runs = {"rig": [("validate", path), ("render", good, *png, "--lights", path)],
            "instance": [("validate", path), ("render", path, *png),
                         ("compile", path, "-o", tmp_path / "out")],
            "material": [("validate", path), ("render", path, *png),
                         ("compile", path, "-o", tmp_path / "out"),
                         ("bake", path, "-o", tmp_path / "bake", "--size", "8")]}
    runs["function"] = runs["material"]
    for args in runs[kind]:
        rc, _, err = cli(*args)
        assert_clean_failure(rc, err)
        assert all(n in err for n in needles) and "float32" in err, (args[0], err)
        assert "pack" not in err, err
    if kind == "function":  # the function file itself names its input node
        rc, _, err = cli("validate", tmp_path / "f.json")
        assert_clean_failure(rc, err)
        assert "f.json" in err and "node i0" in err and "field default" in err, err
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("digits", [400, 5000])
@pytest.mark.parametrize("where", ["rig intensity", "rig position", "rig version",
                                   "instance override", "material value"])
def test_huge_integers_are_clean_errors(tmp_path, where, digits):
    """A 400-digit (or 5000-digit, past Python's conversion limit) integer is an `error:`
    line from validate and render, never an internal OverflowError."""
    token = "9" * digits
    if where.startswith("rig"):
        raw = _rig22()
        if where == "rig version":
            raw["version"] = "@N@"
        elif where == "rig position":
            raw["lights"][1]["position"][0] = "@N@"
        else:
            raw["lights"][1]["intensity"] = "@N@"
        rig = write(tmp_path / "rig.json", _text22(raw, token))
        checks = [("validate", rig), ("render", _material22(tmp_path), "-o",
                                      tmp_path / "x.png", "--size", "8x8", "--lights", rig)]
        name = "rig.json"
    elif where == "instance override":
        inst = _instance22(tmp_path, f'{{"rough": {token}}}')
        checks = [("validate", inst), ("render", inst, "-o", tmp_path / "x.png", "--size",
                                       "8x8")]
        name = "i.json"
    else:
        doc = _material22(tmp_path, token, _set(["nodes", 1, "values", "value"]))
        checks = [("validate", doc), ("render", doc, "-o", tmp_path / "x.png", "--size", "8x8")]
        name = "m.json"
    for args in checks:
        rc, _, err = cli(*args)
        assert_clean_failure(rc, err)
        assert name in err and "Overflow" not in err and token not in err, err


@pytest.mark.parametrize("case", ["format twice", "lights twice", "intensity twice",
                                  "type twice", "name twice"])
def test_rig_duplicate_keys_are_refused(tmp_path, case):
    """Rigs refuse a key twice in one object, as documents do (the same parser)."""
    text = json.dumps(_rig22())
    if case == "format twice":
        text = text.replace('{"format"', '{"format": "matedit.lightrig", "format"', 1)
    elif case == "lights twice":
        text = text.replace('"lights": [', '"lights": [], "lights": [', 1)
    elif case == "intensity twice":
        text = text.replace('"intensity": 10.0', '"intensity": 10.0, "intensity": 1e3', 1)
    elif case == "type twice":
        text = text.replace('{"type": "tube"', '{"type": "point", "type": "tube"', 1)
    else:
        text = text.replace('{"type": "tube"', '{"name": "a", "name": "b", "type": "tube"', 1)
    key = case.split()[0]
    rig = write(tmp_path / "rig.json", text)
    from matedit.io.rig import RigError
    from matedit.io.rig import loads as rig_loads

    with pytest.raises(RigError, match=f"key '{key}' appears twice"):
        rig_loads(text, "rig.json")
    for args in [("validate", rig), ("render", _material22(tmp_path), "-o", tmp_path / "x.png",
                                     "--size", "8x8", "--lights", rig)]:
        rc, _, err = cli(*args)
        assert_clean_failure(rc, err)
        assert "rig.json" in err and f"'{key}' appears twice" in err, err


@pytest.mark.parametrize("value, ok", [
    ("nan", False), ("NaN", False), ("inf", False), ("-inf", False), ("1e308", False),
    ("1e400", False), ("30.5", False), ("-31", False), ("abc", False),
    pytest.param("30", True, marks=pytest.mark.gl), pytest.param("-30", True,
                                                                  marks=pytest.mark.gl),
])
def test_exposure_option_is_a_finite_number_of_stops_within_30(tmp_path, value, ok):
    """`render --exposure` takes -30..30 EV; NaN, infinities and 2**EV overflows are one
    `error:` line naming the option (exit 2); the extremes render."""
    out = tmp_path / "x.png"
    rc, _, err = cli("render", _material22(tmp_path), "-o", out, "--size", "8x8",
                     f"--exposure={value}")
    if ok:
        assert rc == 0 and out.is_file(), err
        return
    assert_clean_failure(rc, err)
    assert len(err.strip().splitlines()) == 1 and "--exposure" in err, err
    assert not out.exists()


# MaterialX documents, written by hand: each holds one malformed number
def _mx22(body: str) -> str:
    return ('<?xml version="1.0"?>\n<materialx version="1.39">\n' + body +
            '<surfacematerial name="M" type="material"><input name="surfaceshader" '
            'type="surfaceshader" nodename="S"/></surfacematerial>\n</materialx>\n')


def _mx_extract22(index: str) -> str:
    return _mx22('<nodegraph name="NG"><constant name="c" type="color3"><input name="value" '
                 'type="color3" value="0.2,0.4,0.6"/></constant><extract name="ex" '
                 'type="float"><input name="in" type="color3" nodename="c"/><input '
                 f'name="index" type="integer" value="{index}"/></extract><output name="o" '
                 'type="float" nodename="ex"/></nodegraph><standard_surface name="S" '
                 'type="surfaceshader"><input name="metalness" type="float" nodegraph="NG" '
                 'output="o"/></standard_surface>')


def _mx_normalmap22(scale: str, value: str | None = None) -> str:
    source = (f'<input name="in" type="vector3" value="{value}"/>' if value is not None else
              '<input name="in" type="vector3" nodename="img"/>')
    return _mx22('<nodegraph name="NG"><image name="img" type="vector3"><input name="file" '
                 'type="filename" value="n.png"/></image><normalmap name="nm" '
                 f'type="vector3">{source}<input name="scale" type="float" value="{scale}"/>'
                 '</normalmap><output name="o" type="vector3" nodename="nm"/></nodegraph>'
                 '<standard_surface name="S" type="surfaceshader"><input name="normal" '
                 'type="vector3" nodegraph="NG" output="o"/></standard_surface>')


def _mx_surface22(name: str, type_: str, value: str, more: str = "") -> str:
    return _mx22(f'<standard_surface name="S" type="surfaceshader"><input name="{name}" '
                 f'type="{type_}" value="{value}"/>{more}</standard_surface>')


def _mx_graph22(value: str) -> str:
    return _mx22('<nodegraph name="NG"><multiply name="mul" type="color3"><input name="in1" '
                 'type="color3" value="0.5,0.5,0.5"/><input name="in2" type="color3" '
                 f'value="{value}"/></multiply><output name="o" type="color3" '
                 'nodename="mul"/></nodegraph><standard_surface name="S" '
                 'type="surfaceshader"><input name="base_color" type="color3" nodegraph="NG" '
                 'output="o"/></standard_surface>')


def _mx_interface22(value: str) -> str:
    return _mx22(f'<nodegraph name="NG"><input name="amt" type="float" value="{value}"/>'
                 '<multiply name="mul" type="float"><input name="in1" type="float" '
                 'interfacename="amt"/><input name="in2" type="float" value="0.5"/></multiply>'
                 '<output name="o" type="float" nodename="mul"/></nodegraph><standard_surface '
                 'name="S" type="surfaceshader"><input name="metalness" type="float" '
                 'nodegraph="NG" output="o"/></standard_surface>')


# case -> (document, the node and the input its error names)
MTLX_MALFORMED = {
    "extract index empty": (_mx_extract22(""), "NG/ex", "input index"),
    "extract index text": (_mx_extract22("abc"), "NG/ex", "input index"),
    "extract index NaN": (_mx_extract22("nan"), "NG/ex", "input index"),
    "extract index 1.5": (_mx_extract22("1.5"), "NG/ex", "input index"),
    "extract index 1e308": (_mx_extract22("1e308"), "NG/ex", "input index"),
    "normalmap scale abc": (_mx_normalmap22("abc"), "NG/nm", "input scale"),
    "normalmap scale NaN": (_mx_normalmap22("nan"), "NG/nm", "input scale"),
    "normalmap scale 1e308": (_mx_normalmap22("1e308"), "NG/nm", "input scale"),
    "normalmap value overflows when decoded": (_mx_normalmap22("1", "3e38,0.5,1"), "NG/nm",
                                               "input in"),
    "colour 1e308": (_mx_surface22("base_color", "color3", "1e308,0,0"), "node S",
                     "input base_color"),
    "colour text": (_mx_surface22("base_color", "color3", "red"), "node S",
                    "input base_color"),
    "float 1e308": (_mx_surface22("metalness", "float", "1e308"), "node S", "input metalness"),
    "float inf": (_mx_surface22("metalness", "float", "inf"), "node S", "input metalness"),
    "float -1e39": (_mx_surface22("metalness", "float", "-1e39"), "node S",
                    "input metalness"),
    "vector 1e39 in a nodegraph": (_mx_graph22("1e39,1,1"), "NG/mul", "input in2"),
    "interface input 1e308": (_mx_interface22("1e308"), "node NG", "input amt"),
    "colour times weight overflows": (
        _mx_surface22("emission_color", "color3", "3e38,3e38,3e38",
                      '<input name="emission" type="float" value="3e38"/>'),
        "node S", "emission_color"),
}


@pytest.mark.parametrize("case", sorted(MTLX_MALFORMED))
def test_mtlx_import_of_malformed_numbers_is_a_clean_error(tmp_path, case):
    """Empty, textual, NaN, infinite and beyond-float32 numbers in any numeric MaterialX input
    are `error:` lines naming the .mtlx file, the node and the input; nothing is written."""
    text, node, inp = MTLX_MALFORMED[case]
    src = write(tmp_path / "in.mtlx", text)
    out = tmp_path / "out.json"
    rc, _, err = cli("import", src, "-o", out)
    assert_clean_failure(rc, err)
    assert "in.mtlx" in err and node in err and inp in err, err
    assert not out.exists()


def _nested22(shape: str) -> str:
    """JSON text of a nesting `shape`: 100,000 arrays, 100,000 objects, or arrays for a field
    of the top-level object so that the file nests "N levels" (the top object is one)."""
    if shape == "100000 arrays":
        return "[" * 100_000 + "]" * 100_000
    if shape == "100000 objects":
        return '{"a": ' * 100_000 + "1" + "}" * 100_000
    depth = int(shape.split()[0]) - 1
    return "[" * depth + "]" * depth


def _deep_material22(tmp, shape, name="m.json"):
    """A material whose whole text (the 100,000 shapes) or an unknown field is `shape`."""
    if shape.startswith("100000"):
        return write(tmp / name, _nested22(shape))
    return write(tmp / name, _text22({**base_material(), "x_deep": "@N@"}, _nested22(shape)))


def _nested_reader22(tmp, reader, shape):
    """(command line, or a callable raising the format's error) for `reader` on `shape`."""
    if reader in ("validate", "compile", "render"):
        doc = _deep_material22(tmp, shape)
        return {"validate": ("validate", doc), "compile": ("compile", doc, "-o", tmp / "out"),
                "render": ("render", doc, "-o", tmp / "x.png", "--size", "8x8")}[reader]
    if reader.startswith("rig"):
        text = (_nested22(shape) if shape.startswith("100000") else
                _text22({**_rig22(), "lights": "@N@"}, _nested22(shape)))
        rig = write(tmp / "rig.json", text)
        if reader == "rig (validate)":
            return ("validate", rig)
        return ("render", _material22(tmp), "-o", tmp / "x.png", "--size", "8x8", "--lights",
                rig)
    if reader == "instance":
        inst = (write(tmp / "i.json", _nested22(shape)) if shape.startswith("100000") else
                _instance22(tmp, f'{{"rough": 0.5, "x": {_nested22(shape)}}}'))
        return ("render", inst, "-o", tmp / "x.png", "--size", "8x8")
    if reader == "instance parent":
        _deep_material22(tmp, shape, "p.json")
        inst = write(tmp / "i.json", '{"format": "matedit.instance", "version": 2, '
                     '"parent": "p.json", "parameters": {}}')
        return ("validate", inst)
    assert reader == "recovery file"  # the editor reads it with matedit.io.document.loads
    rec = _deep_material22(tmp, shape, "rec.json")
    return lambda: loads(rec.read_text(encoding="utf-8"), str(rec), tmp / "m.json")


NESTED_READERS = ["validate", "compile", "render", "rig (validate)", "rig (render --lights)",
                  "instance", "instance parent", "recovery file"]


@pytest.mark.parametrize("shape", ["100000 arrays", "100000 objects", "65 levels",
                                   "900 levels"])
@pytest.mark.parametrize("reader", NESTED_READERS)
def test_deeply_nested_json_is_one_error_per_reader(tmp_path, reader, shape):
    """Every JSON reader refuses nesting beyond 64 levels with an `error:` line (exit 2) or its
    format's error; never a RecursionError. 64 levels (the limit) still load."""
    job = _nested_reader22(tmp_path, reader, shape)
    if callable(job):
        with pytest.raises(FormatError, match="nest more than 64 deep"):
            job()
    else:
        rc, _, err = cli(*job)
        assert_clean_failure(rc, err)
        assert "nest more than 64 deep" in err and "Recursion" not in err, err
    if reader == "validate" and shape == "65 levels":  # the limit itself is fine
        rc, _, err = cli("validate", _deep_material22(tmp_path, "64 levels"))
        assert rc == 0, err


@pytest.mark.gl
def test_default_exposure_is_the_documented_0_ev(tmp_path):
    """0 EV: the renderer's default, what `render` applies without --exposure, what the
    editor's viewport starts at and what docs/cli.md states (no hidden -0.5 EV look)."""
    from pathlib import Path

    from matedit.render.settings import DEFAULT_EXPOSURE_EV, PreviewSettings

    assert DEFAULT_EXPOSURE_EV == 0.0 and PreviewSettings().exposure == 0.0
    docs = (Path(__file__).resolve().parent.parent / "docs" / "cli.md").read_text("utf-8")
    row = next(l for l in docs.splitlines() if l.startswith("| `--exposure EV`"))
    assert row.split("|")[2].strip() == "0", row
    doc = _material22(tmp_path)
    outs = {}
    for name, extra in {"default": [], "0": ["--exposure=0"], "-0.5": ["--exposure=-0.5"]}.items():
        outs[name] = tmp_path / f"{name}.png"
        rc, _, err = cli("render", doc, "-o", outs[name], "--size", "16x16", *extra)
        assert rc == 0, err
    assert outs["default"].read_bytes() == outs["0"].read_bytes()
    assert outs["default"].read_bytes() != outs["-0.5"].read_bytes()


# --- generated rig and instance files --------------------------------------------------------

# The formats' loaders are quick: three times the documents' generated cases each.
HSET22 = settings(HSET, max_examples=3 * EXAMPLES)


class _Raw22(str):
    """A JSON token written as it is (NaN, 1e400, a 400-digit integer, deep nesting)."""


class _Pairs22(list):
    """A JSON object as (key, value) pairs, so that a key may appear twice."""


def _json22(v) -> str:
    if isinstance(v, _Raw22):
        return str(v)
    if isinstance(v, dict):
        v = _Pairs22(v.items())
    if isinstance(v, _Pairs22):
        return "{" + ", ".join(f"{json.dumps(k)}: {_json22(x)}" for k, x in v) + "}"
    if isinstance(v, list):
        return "[" + ", ".join(_json22(x) for x in v) + "]"
    return json.dumps(v)  # floats: NaN and Infinity come out as those (invalid) tokens


def _pairs22(v):
    """`v` with every dict as _Pairs22 (the generated mutations edit pairs)."""
    if isinstance(v, dict):
        return _Pairs22((k, _pairs22(x)) for k, x in v.items())
    if isinstance(v, list):
        return [_pairs22(x) for x in v]
    return v


RAW_TOKENS22 = ["1e400", "-1e999", "NaN", "Infinity", "-Infinity", "3.5e38", "-3.4028236e38",
                "3.4028234e38", "1e39", "1e308", "1e-400", "1e-40", "9" * 400, "-" + "9" * 400,
                "9" * 5000, "1e12", "1e6", "1e-7", "-0.0", "0", "1", "true", "null",
                "[" * 70 + "]" * 70, '{"a": ' * 70 + "1" + "}" * 70,
                "[" * 100_000 + "]" * 100_000]
hostile_values22 = st.one_of(
    json_values, st.sampled_from(RAW_TOKENS22).map(_Raw22), st.floats(), st.text(max_size=12),
    st.lists(st.one_of(st.floats(), st.integers(), st.sampled_from(RAW_TOKENS22[:16])
                       .map(_Raw22)), max_size=4))


def _mutate22(top: _Pairs22, ops, objects: dict) -> str:
    """Apply (operation, object, key, value) edits to the pairs of `top` and its objects
    (found by `objects[name](top)`, None when an earlier edit removed them); the JSON text."""
    for op, where, key, value in ops:
        obj = objects[where](top)
        if obj is None:
            continue
        if op == "element":
            if type(obj) is list and obj:  # an array, not an object's pairs
                at = key if isinstance(key, int) else sum(map(ord, str(key)))
                obj[at % len(obj)] = value  # deterministic (str hashes are salted)
            continue
        if not isinstance(obj, _Pairs22):
            continue
        i = next((n for n, (k, _) in enumerate(obj) if k == key), None)
        if op == "delete":
            if i is not None:
                del obj[i]
        elif op == "duplicate" or i is None:
            obj.append((key, value))
        else:
            obj[i] = (key, value)
    return _json22(top)


def _member22(obj, key):
    if isinstance(obj, _Pairs22):
        return next((v for k, v in obj if k == key), None)
    if type(obj) is list and isinstance(key, int) and key < len(obj):
        return obj[key]
    return None


RIG_OBJECTS22 = {
    "top": lambda t: t,
    "light 0": lambda t: _member22(_member22(t, "lights"), 0),
    "light 1": lambda t: _member22(_member22(t, "lights"), 1),
    "light 1 position": lambda t: _member22(_member22(_member22(t, "lights"), 1), "position"),
    "light 1 color": lambda t: _member22(_member22(_member22(t, "lights"), 1), "color"),
    "light 0 direction": lambda t: _member22(_member22(_member22(t, "lights"), 0), "direction"),
}
RIG_KEYS22 = ["format", "version", "lights", "type", "position", "direction", "radius", "length",
              "color", "intensity", "influence_radius", "name"]


def _edits22(objects, keys):
    """1 to 4 edits, mostly of the format's own keys (an unknown key is refused at once)."""
    known = st.sampled_from(keys)
    return st.lists(st.tuples(st.sampled_from(["set", "set", "delete", "duplicate", "element"]),
                              st.sampled_from(sorted(objects)),
                              st.one_of(known, known, known, st.text(max_size=6)),
                              hostile_values22), min_size=1, max_size=4)


def _light_context22():
    """Shading points on the unit sphere seen from the camera, rough to near-mirror."""
    import numpy as np

    from matedit.shading.lights import makeShadingContext

    d = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, -1],
                  [0.6, 0.0, 0.8], [0.0, -0.6, 0.8]], float)
    v = np.array([0.0, 0.0, 4.0]) - d
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    n = len(d)
    return makeShadingContext(d, d, v, np.full((n, 3), 0.8), np.full((n, 3), 0.04),
                              np.linspace(0.0, 1.0, n))


def _assert_lights_finite22(lights) -> None:
    """What the renderer does with a rig, without GL: the LightsBlock packs with no numpy
    warning and holds finite float32s, and each light's radiance (the shading twin) stays
    far inside float32 at points on the preview sphere."""
    import warnings

    import numpy as np

    from matedit.shading.lights import evaluateLight
    from matedit.shading.lights_block import pack_lights

    s = _light_context22()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an overflow in a cast fails the case
        block = np.frombuffer(pack_lights(lights), "<f4")
        assert np.isfinite(block).all()
        for light in lights:
            radiance = evaluateLight(s, light)
            assert np.isfinite(radiance).all() and np.abs(radiance).max() < 1e30, light


@HTIMEOUT
@HSET22
@given(edits=_edits22(RIG_OBJECTS22, RIG_KEYS22))
@example(edits=[("set", "light 1", "intensity", _Raw22("1e39"))])
@example(edits=[("element", "light 1 color", 0, _Raw22("3.4e38"))])
@example(edits=[("element", "light 1 position", 1, _Raw22("9" * 400))])
@example(edits=[("set", "light 0", "radius", _Raw22("1e308"))])
@example(edits=[("duplicate", "light 1", "intensity", 5.0)])
@example(edits=[("element", "light 1 position", 0, _Raw22("1e-7"))])  # L = -V behind a point
def test_generated_rigs_load_cleanly_or_light_finitely(edits):
    """Mutated rigs (wrong types, huge, NaN and infinite numbers, 400-digit integers, deep
    nesting, duplicate and missing keys, unknown fields, unicode): the loader raises RigError
    naming the file, or the lights pack and shine finitely. 3 x HOSTILE_EXAMPLES cases."""
    from matedit.io.rig import RigError
    from matedit.io.rig import loads as rig_loads

    text = _mutate22(_pairs22(_rig22()), edits, RIG_OBJECTS22)
    try:
        lights = rig_loads(text, "rig.json")
    except RigError as exc:
        assert str(exc).startswith("rig.json: "), exc
        event("refused")
        return
    event("loaded")
    _assert_lights_finite22(lights)


INSTANCE_OBJECTS22 = {
    "top": lambda t: t,
    "parameters": lambda t: _member22(t, "parameters"),
    "tint": lambda t: _member22(_member22(t, "parameters"), "tint"),
    "preview": lambda t: _member22(t, "preview"),
}
INSTANCE_KEYS22 = ["format", "version", "name", "description", "parent", "parameters",
                   "parent_parameters", "preview", "rough", "tint", "mesh", "environment"]


@HTIMEOUT
@HSET22
@given(edits=_edits22(INSTANCE_OBJECTS22, INSTANCE_KEYS22))
@example(edits=[("set", "parameters", "rough", _Raw22("3.5e38"))])
@example(edits=[("element", "tint", 2, _Raw22("1e308"))])
@example(edits=[("set", "parameters", "rough", _Raw22("[" * 100_000 + "]" * 100_000))])
def test_generated_instances_load_cleanly_or_compile_finite(tmp_path_factory, edits):
    """Mutated instances of a valid material: loading and resolving raise FormatError or
    InstanceError naming the instance (or report its parameter errors), or the effective
    material compiles and its uniform block packs finite float32s with no numpy warning.
    3 x HOSTILE_EXAMPLES cases."""
    import struct
    import warnings

    import numpy as np

    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver
    from matedit.io.instance import InstanceError, load_instance, resolve

    tmp = tmp_path_factory.mktemp("inst")
    write(tmp / "m.json", base_material())
    base = {"format": "matedit.instance", "version": 2, "name": "i", "parent": "m.json",
            "parameters": {"rough": 0.3, "tint": [0.5, 0.2, 0.1]}, "preview": {"mesh": "cube"}}
    path = write(tmp / "i.json", _mutate22(_pairs22(base), edits, INSTANCE_OBJECTS22))
    try:
        r = resolve(load_instance(path))
    except (FormatError, InstanceError) as exc:
        assert str(exc).startswith(str(path)), exc
        event("refused")
        return
    if r.errors:
        assert all(p.file == str(path) for p in r.errors), r.errors
        event("parameter errors")
        return
    event("compiled")
    compiled = compile_document(r.document, FileResolver())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        data = compiled.pack_uniforms()
        floats = np.frombuffer(data, "<f4")
        assert np.isfinite(floats).all() and struct.calcsize(f"<{len(floats)}f") == len(data)


@pytest.mark.gl
@pytest.mark.parametrize("case", ["rig at the limits", "rig at the limits, reference",
                                  "rig far away", "instance at float32's edge",
                                  "rig colour times intensity beyond the limit"])
def test_a_handful_of_extreme_files_render_finite_pixels(tmp_path, case):
    """The few renders behind the generated cases: rigs at the stated limits render finite
    linear pixels with nothing on stderr (no numpy warning), in split sum and reference;
    an instance at float32's edge renders; a rig past the limit is refused, not rendered."""
    import warnings

    import numpy as np

    from matedit.io.images import read_image

    good = write(tmp_path / "m.json", base_material())
    near = {"format": "matedit.lightrig", "version": 1, "lights": [
        {"type": "sphere", "position": [2, 2, 3], "radius": 1e6, "color": [1, 1, 1],
         "intensity": 1e12, "influence_radius": 1e6},
        {"type": "tube", "position": [-1.5, 0, 0], "direction": [0, 1, 0], "radius": 0.04,
         "length": 1e6, "color": [1e6, 1e6, 1e6], "intensity": 1e6, "influence_radius": 1e6},
        {"type": "point", "position": [0, 0, 1.001], "intensity": 1e12,
         "influence_radius": 1e6},
        {"type": "point", "position": [0, 0, 1.5], "intensity": 1e12,
         "influence_radius": 1e-6},
        {"type": "directional", "direction": [0, 0, -1], "color": [1e12, 0, 1],
         "intensity": 1}]}
    far = {"format": "matedit.lightrig", "version": 1, "lights": [
        {"type": "tube", "position": [1e6, -1e6, 1e6], "direction": [1, 1, 0], "radius": 1e6,
         "length": 1e6, "intensity": 1e12, "influence_radius": 1e6},
        {"type": "sphere", "position": [-1e6, 1e6, -1e6], "radius": 1e6, "intensity": 1e12,
         "influence_radius": 1e6}]}
    beyond = {"format": "matedit.lightrig", "version": 1, "lights": [
        {"type": "point", "position": [0, 0, 3], "color": [1e7, 1, 1], "intensity": 1e6}]}
    args: list = ["render", good]
    if case.startswith("instance"):
        inst = write(tmp_path / "i.json", {"format": "matedit.instance", "version": 2,
                                           "parent": "m.json", "parameters": {
                                               "rough": 3.4e38, "tint": [1e30, 0.5, 0.0]}})
        args = ["render", inst]
    else:
        rig = {"rig far away": far, "rig colour times intensity beyond the limit": beyond
               }.get(case, near)
        args += ["--lights", write(tmp_path / "rig.json", rig)]
    if case.endswith("reference"):
        args += ["--ibl", "reference", "--samples", "4"]
    for out in ("x.exr", "x.png"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a numpy warning would be an internal error
            rc, _, err = cli(*args, "-o", tmp_path / out, "--size", "16x16")
        if "beyond" in case:
            assert_clean_failure(rc, err)
            assert "light 0, field intensity" in err and "1e+12" in err, err
            return
        assert rc == 0 and err == "", err
    pixels = read_image(tmp_path / "x.exr").pixels
    if case.startswith("rig"):
        assert np.isfinite(pixels).all()
    else:  # a material's own arithmetic may overflow; never to NaN
        assert not np.isnan(pixels).any()
# === State the app keeps: recovery entries and IBL cache entries (issue 22) ====================
# Both are files the editor finds on disk at launch, so both are untrusted input: each hostile
# class below must be skipped or discarded with a message, never crash, hang (pytest-timeout
# ends one) or execute anything, and the good entries beside it must still be used.

import math  # noqa: E402
import shutil  # noqa: E402
import stat  # noqa: E402

import numpy as np  # noqa: E402
from test_app_support import app_env  # noqa: E402, F401 - the GUI tests' fixture

GUI_TIMEOUT = pytest.mark.timeout(180, method="signal")  # a few editor windows each


def _recovery_meta(pid=1, when=1.7e9, name="good", document=None, kind="material") -> str:
    return json.dumps({"pid": pid, "time": when, "name": name, "document": document,
                       "kind": kind})


def _plant_recovery(folder, name: str, kind: str) -> None:
    """A recovery entry `name` of one hostile class `kind` in `folder`."""
    rec, meta = folder / f"{name}.json", folder / f"{name}.meta"
    rec.write_text(json.dumps(base_material()))
    text = {
        "pid 2**40": _recovery_meta(pid=2**40),
        "negative pid": _recovery_meta(pid=-5),
        "pid true": _recovery_meta(pid=True),
        "pid string": _recovery_meta(pid="4242"),
        "pid 400 digits": '{"pid": ' + "9" * 400 + "}",
        "time 1e309": '{"pid": 1, "time": 1e309}',
        "time NaN": '{"pid": 1, "time": NaN}',
        "time -inf": '{"pid": 1, "time": -Infinity}',
        "time -1e300": _recovery_meta(when=-1e300),
        "time string": _recovery_meta(when="yesterday"),
        "name a list": _recovery_meta(name=["x"]),
        "document a number": _recovery_meta(document=7),
        "document with NUL": _recovery_meta(document="a\u0000b.json"),
        "kind unknown": _recovery_meta(kind="shader"),
        "meta a list": "[1, 2, 3]",
        "meta deeply nested": "[" * 50000 + "]" * 50000,
    }.get(kind)
    if text is not None:
        meta.write_text(text)
    elif kind == "meta invalid UTF-8":
        meta.write_bytes(b'{"pid": 1, "name": "\xff\xfe"}')
    elif kind == "meta huge":  # over the 64 KiB a metadata file may have
        _sparse(meta, 1 << 20)
    elif kind == "meta FIFO":
        os.mkfifo(meta)
    elif kind == "meta link to /dev/zero":
        os.symlink("/dev/zero", meta)
    elif kind == "recovery file FIFO":
        rec.unlink()
        os.mkfifo(rec)
        meta.write_text(_recovery_meta())
    elif kind == "recovery file link to /dev/zero":
        rec.unlink()
        os.symlink("/dev/zero", rec)
        meta.write_text(_recovery_meta())
    elif kind == "recovery file link elsewhere":
        rec.unlink()
        elsewhere = folder.parent / "elsewhere.json"
        elsewhere.write_text(json.dumps(base_material()))
        os.symlink(elsewhere, rec)
        meta.write_text(_recovery_meta())
    elif kind == "recovery file huge":  # over the 64 MiB a document may have
        _sparse(rec, 65 << 20)
        meta.write_text(_recovery_meta())
    else:
        raise AssertionError(kind)


HOSTILE_RECOVERY = [
    "pid 2**40", "negative pid", "pid true", "pid string", "pid 400 digits", "time 1e309",
    "time NaN", "time -inf", "time -1e300", "time string", "name a list", "document a number",
    "document with NUL", "kind unknown", "meta a list", "meta deeply nested",
    "meta invalid UTF-8", "meta huge", "meta FIFO", "meta link to /dev/zero",
    "recovery file FIFO", "recovery file link to /dev/zero", "recovery file link elsewhere",
    "recovery file huge",
]


@pytest.fixture
def recovery_folder(tmp_path, monkeypatch):
    folder = tmp_path / "recovery"
    folder.mkdir()
    monkeypatch.setenv("MATEDIT_RECOVERY_DIR", str(folder))
    (folder / "good.json").write_text(json.dumps(base_material()))
    (folder / "good.meta").write_text(_recovery_meta(pid=2**31 - 1))  # no such process
    return folder


@pytest.mark.parametrize("kind", HOSTILE_RECOVERY)
def test_hostile_recovery_entry_is_skipped_and_set_aside(recovery_folder, kind):
    pytest.importorskip("PySide6")
    from matedit.app import recovery

    _plant_recovery(recovery_folder, "bad", kind)
    entries = recovery.find_recoveries()  # never raises, never blocks
    assert [e.rec.name for e in entries] == ["good.json"]  # the good one is still offered
    assert all(e.describe() for e in entries)
    # the scan that found it set it aside: kept for a person, never offered or named again
    assert not os.path.lexists(recovery_folder / "bad.json")
    assert os.path.lexists(recovery_folder / "bad.json.unreadable")
    again, problems = recovery.scan_recoveries()
    assert [e.rec.name for e in again] == ["good.json"] and problems == []
    if kind == "recovery file link to /dev/zero":
        assert stat.S_ISCHR(os.stat("/dev/zero").st_mode)


def test_hostile_recovery_entry_is_named_in_one_message(recovery_folder):
    pytest.importorskip("PySide6")
    from matedit.app import recovery

    for i, kind in enumerate(HOSTILE_RECOVERY):
        _plant_recovery(recovery_folder, f"bad{i:02d}", kind)
    entries, problems = recovery.scan_recoveries()
    assert [e.rec.name for e in entries] == ["good.json"]
    assert len(problems) == len(HOSTILE_RECOVERY)
    assert all(p.startswith(f"bad{i:02d}.json: ") for i, p in enumerate(problems))
    line = recovery.skipped_message(problems)
    assert line == (f"skipped {len(HOSTILE_RECOVERY)} damaged recovery files: {problems[0]}; "
                    f"{problems[1]}; and {len(HOSTILE_RECOVERY) - 2} more")


def test_the_liveness_check_takes_any_pid():
    pytest.importorskip("PySide6")
    from matedit.app.recovery import _alive

    for pid in (2**40, -(2**40), 2**64, -1, 0, os.getpid()):
        assert _alive(pid) is False
    assert _alive(os.getppid()) is True


@GUI_TIMEOUT
@pytest.mark.gui
@pytest.mark.usefixtures("app_env")
def test_launch_with_hostile_recovery_entries_offers_the_good_ones(qtbot, capfd):
    """The real editor window at launch: every hostile class at once beside two crashed
    editors' real autosaves; the launch neither fails nor hangs, the damaged entries are
    named once in the status bar and on stderr, and the good work is recovered."""
    import shiboken6
    import test_app_support
    from PySide6.QtCore import QPointF

    from matedit.app.recovery import recovery_dir
    from matedit.graph.commands import SetLabel

    keep = {"recover_all": lambda entries: {e.rec: "keep" for e in entries}}
    for label in ("first crash", "second crash"):
        w = test_app_support.make_window(qtbot, track=False, answers=keep)
        nid = w.tabs.material.canvas.add_node_at("material_output", QPointF(0, 0))
        assert w.controller.push(SetLabel(nid, label))
        assert w.actions.autosave() is not None
        shiboken6.delete(w)  # the editor dies: the autosave stays
    folder = recovery_dir()
    for i, kind in enumerate(HOSTILE_RECOVERY):
        _plant_recovery(folder, f"bad{i:02d}", kind)

    seen: list = []

    def recover_all(entries):
        seen.extend(entries)
        return {e.rec: "recover" for e in entries}

    w = test_app_support.make_window(qtbot, answers={"recover_all": recover_all})
    assert len(seen) == 2 and all(e.document is None for e in seen)
    labels = set()
    for i in range(w.documents.count()):  # each recovered material in a tab of its own
        w.documents.activate(i)
        labels |= {n.label for n in w.controller.document.graph.nodes.values()}
    assert {"first crash", "second crash"} <= labels
    assert len(w.actions.skipped_recoveries) == len(HOSTILE_RECOVERY)
    qtbot.waitUntil(lambda: "damaged recovery file" in w.statusBar().currentMessage(),
                    timeout=5000)
    err = capfd.readouterr().err
    assert all(f"bad{i:02d}.json: " in err for i in range(len(HOSTILE_RECOVERY)))
    assert w.shown_errors == []  # a status line, not a modal box
    # shown once: the next launch finds nothing to complain about
    w2 = test_app_support.make_window(qtbot, answers={"recover_all": lambda es: {}})
    assert w2.actions.skipped_recoveries == []


# --- IBL cache entries ----------------------------------------------------------------------

_SMALL_BAKE = dict(size=16, samples=16, lut_size=16, lut_samples=256)


def _small_env():
    from matedit.ibl import Environment

    rng = np.random.default_rng(22)
    return Environment(name="hostile", equirect=(rng.random((32, 64, 3)) * 4).astype("f4"))


class _Unpickled:
    """An object whose unpickling makes a folder: proof that loading ran code from a file."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        return (os.mkdir, (self.marker,))


def _npz_arrays(path):
    with np.load(path, allow_pickle=False) as data:
        return {name: data[name] for name in data.files}


def _write_npz(path, arrays):
    path.unlink()
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _mutate_arrays(change):
    def mutate(path, target, tmp):
        arrays = _npz_arrays(path)
        arrays[target] = change(arrays[target], tmp)
        _write_npz(path, arrays)
    return mutate


def _replace_file(make):
    def mutate(path, target, tmp):
        path.unlink()
        make(path, tmp)
    return mutate


def _flip_middle(path, target, tmp):
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x55
    path.write_bytes(bytes(data))


def _scaled_keeping_checksum(path, target, tmp):
    arrays = _npz_arrays(path)
    arrays[target] = (arrays[target] * np.float32(1.25)).astype(arrays[target].dtype)
    _write_npz(path, arrays)  # the stored checksum no longer matches


def _older_format(path, target, tmp):
    from matedit.ibl import cache

    arrays = _npz_arrays(path)
    arrays[cache.VERSION_NAME] = np.array(cache.CACHE_FORMAT - 1, dtype="<i8")
    _write_npz(path, arrays)  # checksum still right: only the version is wrong


def _link_to_copy(path, target, tmp):
    decoy = tmp / "decoy.npz"
    shutil.copyfile(path, decoy)
    path.unlink()
    os.symlink(decoy, path)


def _sparse(path, size):
    with open(path, "wb") as f:  # no disk space taken
        f.truncate(size)


def _set_element(a, value):
    a = a.copy()
    a.flat[len(a.flat) // 2] = value
    return a


HOSTILE_CACHE = {
    "FIFO": _replace_file(lambda p, tmp: os.mkfifo(p)),
    "link to /dev/zero": _replace_file(lambda p, tmp: os.symlink("/dev/zero", p)),
    "link to a valid entry elsewhere": _link_to_copy,
    "a folder": _replace_file(lambda p, tmp: p.mkdir()),
    "huge sparse file": _replace_file(lambda p, tmp: _sparse(p, 64 << 20)),
    "not a zip": _replace_file(lambda p, tmp: p.write_bytes(os.urandom(4096))),
    "a pickle": _replace_file(lambda p, tmp: p.write_bytes(
        __import__("pickle").dumps(_Unpickled(tmp / "ran")))),
    "truncated": lambda p, target, tmp: p.write_bytes(p.read_bytes()[: p.stat().st_size // 2]),
    "a byte flipped": _flip_middle,
    "string array": _mutate_arrays(lambda a, tmp: np.full(a.shape, "0.5")),
    "object array": _mutate_arrays(lambda a, tmp: np.array(
        [_Unpickled(tmp / "ran")] * a.size, dtype=object).reshape(a.shape)),
    "wrong shape": _mutate_arrays(lambda a, tmp: a[..., :1].copy()),
    "wrong dtype": _mutate_arrays(lambda a, tmp: a.astype(np.float16)),
    "a NaN": _mutate_arrays(lambda a, tmp: _set_element(a, np.nan)),
    "an infinity": _mutate_arrays(lambda a, tmp: _set_element(a, np.inf)),
    "values changed, checksum kept": _scaled_keeping_checksum,
    "an older format version": _older_format,
}


@pytest.fixture(scope="module")
def clean_bake(gl_ctx, tmp_path_factory):
    """One bake into a fresh cache: the result every rebuilt entry must equal, and its
    files (an `ibl-` entry and an `lut-` entry)."""
    from matedit.ibl import BakeSettings, bake

    folder = tmp_path_factory.mktemp("clean-cache")
    result = bake(_small_env(), BakeSettings(**_SMALL_BAKE), ctx=gl_ctx, cache_dir=folder)
    assert not result.from_cache and not result.warnings
    files = {p.name.split("-")[0]: p for p in folder.glob("*.npz")}
    assert sorted(files) == ["ibl", "lut"]
    return result, files


@pytest.mark.gl
@pytest.mark.parametrize("entry", ["ibl", "lut"])
@pytest.mark.parametrize("kind", sorted(HOSTILE_CACHE))
def test_hostile_cache_entry_is_discarded_and_rebuilt(ctx, tmp_path, clean_bake, entry, kind):
    from matedit.ibl import BakeSettings, bake

    clean, files = clean_bake
    cache_dir = tmp_path / "cache"
    cache_dir.mkdir()
    for name, src in files.items():
        if entry == "ibl" or name == "lut":  # a bad LUT entry is read when the bake is not
            shutil.copyfile(src, cache_dir / src.name)
    path = cache_dir / files[entry].name
    HOSTILE_CACHE[kind](path, "mip1" if entry == "ibl" else "lut", tmp_path)

    again = bake(_small_env(), BakeSettings(**_SMALL_BAKE), ctx=ctx, cache_dir=cache_dir)
    assert not again.from_cache
    assert any("discarded a damaged IBL cache entry" in w and path.name in w
               for w in again.warnings), again.warnings
    for a, b in zip(clean.mips, again.mips, strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(clean.lut, again.lut)
    np.testing.assert_array_equal(clean.sh, again.sh)
    assert not (tmp_path / "ran").exists()  # nothing in the file was executed
    # rebuilt in place as a regular file of our own: the next bake reads it
    st = os.lstat(path)
    assert stat.S_ISREG(st.st_mode)
    assert bake(_small_env(), BakeSettings(**_SMALL_BAKE), ctx=ctx,
                cache_dir=cache_dir).from_cache
    assert stat.S_ISCHR(os.stat("/dev/zero").st_mode)
    if kind == "link to a valid entry elsewhere":  # what the link pointed to is untouched
        assert (tmp_path / "decoy.npz").read_bytes() == files[entry].read_bytes()


@GUI_TIMEOUT
@pytest.mark.gui
@pytest.mark.usefixtures("app_env")
def test_launch_with_hostile_ibl_cache_entries_rebakes(qtbot, tmp_path, monkeypatch):
    """The real editor window bakes its studio environment at launch; with its cache entry a
    FIFO and its LUT entry a link to /dev/zero it neither hangs nor fails, and both entries
    are rebuilt as regular files."""
    import test_app_support

    from matedit.ibl import BakeSettings, load_environment
    from matedit.ibl.bake import cache_paths

    monkeypatch.setenv("MATEDIT_CACHE_DIR", str(tmp_path / "cache"))
    settings = BakeSettings()
    paths = cache_paths(load_environment("studio", settings.resolved().size), settings)
    paths["ibl"].parent.mkdir(parents=True)
    os.mkfifo(paths["ibl"])
    os.symlink("/dev/zero", paths["lut"])
    w = test_app_support.make_window(qtbot, show=True)
    renderer = test_app_support.wait_for_renderer(qtbot, w)
    assert renderer.environment_warnings and all(
        "discarded a damaged IBL cache entry" in m for m in renderer.environment_warnings)
    for p in paths.values():
        assert stat.S_ISREG(os.lstat(p).st_mode)
    assert stat.S_ISCHR(os.stat("/dev/zero").st_mode)
    assert math.isfinite(float(np.asarray(renderer.read_image()).sum()))
