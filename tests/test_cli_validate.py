"""`matedit validate` per the command-line contract."""

from __future__ import annotations

import subprocess
import sys

from matedit.resources import graphs_dir


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True, cwd=cwd)


def test_all_samples_validate():
    files = sorted(str(p) for p in graphs_dir().rglob("*.json"))
    r = run("validate", *files)
    assert r.returncode == 0, r.stderr
    assert "error" not in r.stderr


def test_malformed_files_exit_2_with_one_line_each(tmp_path):
    (tmp_path / "a.json").write_text("{")
    (tmp_path / "b.json").write_text('{"format": "matedit.material", "version": 99}')
    (tmp_path / "c.json").write_text(
        '{"format": "matedit.material", "version": 2, "nodes": [{"id": "x", "kind": "nope"}]}')
    r = run("validate", str(tmp_path / "a.json"), str(tmp_path / "b.json"),
            str(tmp_path / "c.json"), str(tmp_path / "missing.json"))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert all(l.startswith("error: ") for l in lines), r.stderr
    assert "Traceback" not in r.stderr
    assert any("a.json" in l and "JSON" in l for l in lines)
    assert any("b.json" in l and "newer" in l for l in lines)
    assert any("c.json" in l and "node x" in l and "nope" in l for l in lines)
    assert any("missing.json" in l and "not found" in l for l in lines)
    per_file = [l.split(":")[1].strip() for l in lines]
    assert per_file.count(str(tmp_path / "a.json")) == 1


def test_bad_option_exits_2():
    r = run("validate")
    assert r.returncode == 2 and r.stderr.startswith("error: ")
    r = run("frobnicate")
    assert r.returncode == 2 and r.stderr.startswith("error: ")


def test_validate_reads_light_rigs(tmp_path):
    """Rig documents are checked like the others: fine exits 0, a bad field names it."""
    import json

    good = tmp_path / "rig.json"
    good.write_text(json.dumps({"format": "matedit.lightrig", "version": 1, "lights": [
        {"type": "point", "position": [0, 1, 0], "intensity": 2.0}]}))
    assert run("validate", str(good)).returncode == 0
    bad = tmp_path / "bad_rig.json"
    bad.write_text(json.dumps({"format": "matedit.lightrig", "version": 1, "lights": [
        {"type": "sphere", "radius": -1}]}))
    r = run("validate", str(bad))
    assert r.returncode == 2 and r.stderr.startswith("error: ") and "radius" in r.stderr


def test_the_valid_path_orders_the_graph_without_importing_networkx():
    """networkx's import (with its backend scan) was the largest part of `matedit validate`;
    a valid file is ordered by validate.stable_order, and networkx loads only to name a cycle."""
    sample = graphs_dir() / "materials" / "rusty_painted_metal.json"
    probe = ("import sys\nfrom matedit.cli import main\n"
             "try:\n    main(['validate', sys.argv[1]])\nexcept SystemExit as e:\n"
             "    assert not e.code, e.code\n"
             "print('networkx' in sys.modules)\n")
    r = subprocess.run([sys.executable, "-c", probe, str(sample)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[-1] == "False"

