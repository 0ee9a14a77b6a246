"""`matedit validate` on a valid file imports neither numpy, jsonschema (with referencing) nor
networkx: a structural check of the start-up work (benchmarks/bench_startup.py times it).

Each case runs the command in a fresh interpreter and reads `sys.modules` after it, so a
module-level `np.` in a node module, a top-level `import numpy` in any subcommand module, or
a schema check that loads the library for a valid file makes it fail.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
HEAVY = ("numpy", "jsonschema", "referencing", "networkx")

PROBE = """
import json, sys
from matedit.cli import main
heavy = sys.argv[1].split(",")
rc = main(sys.argv[2:])
print(json.dumps({"rc": rc, "loaded": sorted(m for m in heavy if m in sys.modules),
                  "commands": sorted(m for m in sys.modules if m.startswith("matedit.commands."))}))
"""


def _probe(*args: str, heavy: str = ",".join(HEAVY)) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONDONTWRITEBYTECODE="1")
    r = subprocess.run([sys.executable, "-c", PROBE, heavy, *args], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=120)
    return json.loads(r.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("sample", ["materials/worn_painted_steel.json",
                                    "materials/car_paint.json",
                                    "instances/worn_paint_red.json",
                                    "functions"])
def test_the_valid_path_imports_no_heavy_module(sample):
    out = _probe("validate", str(ROOT / "graphs" / sample))
    assert out == {"rc": 0, "loaded": [], "commands": ["matedit.commands.validate"]}


def test_an_invalid_file_still_gets_the_librarys_error(tmp_path):
    # the library decides and words the error, so it is loaded on this path (and only here)
    bad = json.loads((ROOT / "graphs" / "materials" / "car_paint.json").read_text())
    bad["nodes"][0]["position"] = [0, "x"]
    f = tmp_path / "bad.json"
    f.write_text(json.dumps(bad))
    out = _probe("validate", str(f))
    assert out["rc"] == 2
    assert "jsonschema" in out["loaded"]


def test_the_node_modules_do_not_read_numpy_at_import():
    # numpy is bound lazily in the catalogue; evaluation still gets the real module
    code = ("import sys, matedit.graph.nodes, matedit.compiler.passes;"
            "assert 'numpy' not in sys.modules;"
            "from matedit.nodes import maths; import numpy;"
            "assert maths.np.sqrt is numpy.sqrt; print('ok')")
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONDONTWRITEBYTECODE="1")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True,
                       text=True, timeout=120)
    assert r.stdout.strip() == "ok", r.stderr


def test_a_material_is_validated_without_the_instance_reader_or_the_writers():
    # nor the file writers (matedit.io.atomic) and the command-input checks (matedit.io.inputs)
    out = _probe("validate", str(ROOT / "graphs" / "materials" / "car_paint.json"),
                 heavy="matedit.io.instance,matedit.io.atomic,matedit.io.inputs")
    assert out["rc"] == 0 and out["loaded"] == []
    out = _probe("validate", str(ROOT / "graphs" / "instances" / "worn_paint_red.json"),
                 heavy="matedit.io.instance")
    assert out["rc"] == 0 and out["loaded"] == ["matedit.io.instance"]


def test_a_command_line_imports_only_its_commands_module():
    # the other subcommands' modules (and what they import) are no part of validate's start
    out = _probe("validate", "--help")
    assert out["commands"] == ["matedit.commands.validate"]
    out = _probe("--help")  # the whole list: every command's module
    from matedit.commands import COMMANDS

    assert set(out["commands"]) >= {f"matedit.commands.{m}" for m in COMMANDS.values()}


def test_the_command_table_is_the_parsers():
    # COMMANDS names each command's module; a parser registered under another name, or a
    # command missing from the table, fails here (and the order is the help's)
    import argparse

    from matedit.cli import build_parser
    from matedit.commands import COMMANDS

    def names(parser):
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        return list(sub.choices)

    assert names(build_parser()) == list(COMMANDS)
    for name in COMMANDS:
        assert names(build_parser(name)) == [name]
