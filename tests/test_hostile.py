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
from hypothesis import HealthCheck, given, settings
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
                                                             tmp_path / "r.png"]]
    if kind != "folder":  # validate FOLDER checks every *.json in it: none here is fine
        commands.append(["validate", target])
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
    labels = {n.label for win in [w, *w.extra_windows]
              for n in win.controller.document.graph.nodes.values()}
    assert {"first crash", "second crash"} <= labels
    for other in w.extra_windows:
        qtbot.addWidget(other)
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


def _set(a, value):
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
    "a NaN": _mutate_arrays(lambda a, tmp: _set(a, np.nan)),
    "an infinity": _mutate_arrays(lambda a, tmp: _set(a, np.inf)),
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
