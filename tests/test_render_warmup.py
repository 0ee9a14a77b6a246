"""The warm-up child process (matedit.render.warmup.WarmupClient): it links and draws exactly the
variant the viewport will draw (the structure hash it reports equals the one computed here, from
the compiler, independently of the child), in another process, and a dead child is replaced.
Whether Mesa's shader cache then hits is measured by benchmarks/bench_ui_block.py, not here."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from matedit.compiler import compile_document
from matedit.compiler.emit import PREVIEW_DEFINES, Entry
from matedit.io.document import load
from matedit.render.deferred import SPLIT_SUM_ONLY
from matedit.render.paths import wants_forward
from matedit.render.warmup import ViewportState, WarmupClient
from matedit.resources import graphs_dir

MATERIALS = graphs_dir() / "materials"


def _compiled(name: str):
    return compile_document(load(MATERIALS / f"{name}.json"), None, "glsl330")


@pytest.fixture(scope="module")
def client():
    c = WarmupClient(timeout_s=300)
    c.start()
    assert c.wait_ready(300)
    yield c
    c.close()


def _expected(cm, deferred: bool = True) -> str:
    if deferred and not wants_forward(cm):
        return cm.variant(Entry.GBUFFER, PREVIEW_DEFINES).structure_hash
    return cm.variant(Entry.FORWARD, (SPLIT_SUM_ONLY, *PREVIEW_DEFINES)).structure_hash


def test_the_child_draws_the_viewports_variant_in_another_process(client):
    a, b = _compiled("rusty_painted_metal"), _compiled("brushed_gold")
    ra = client.warm(a, ViewportState())
    assert ra.ok, ra.error
    assert ra.pid not in (0, os.getpid())
    assert ra.program == _expected(a)
    rb = client.warm(b, ViewportState())
    assert rb.ok, rb.error
    assert rb.pid == ra.pid  # one child, kept for the next edits
    assert rb.program == _expected(b) != ra.program


def test_forward_viewports_get_the_forward_variant(client):
    cm = _compiled("worn_painted_steel")  # the talk's fields only: deferred by default
    r = client.warm(cm, ViewportState(deferred=False))
    assert r.ok, r.error
    assert r.program == _expected(cm, deferred=False) != _expected(cm)


def test_a_dead_child_is_replaced(client):
    cm = _compiled("brushed_gold")
    first = client.warm(cm, ViewportState())
    assert first.ok, first.error
    client._proc.kill()
    client._proc.wait()
    client.start()
    assert client.wait_ready(300)
    again = client.warm(cm, ViewportState())
    assert again.ok, again.error
    assert again.pid != first.pid


def test_until_the_child_is_ready_a_warm_up_returns_at_once_untried():
    c = WarmupClient(timeout_s=300)
    try:
        r = c.warm(_compiled("brushed_gold"), ViewportState())  # the child was just started
        assert r.starting and not r.ok and r.program == ""
        assert c.pid is not None  # and it keeps starting: a later edit is warmed
        assert c.wait_ready(300)
        assert c.warm(_compiled("brushed_gold"), ViewportState()).ok
    finally:
        c.close()
    assert c.pid is None


def test_a_frozen_bundle_serves_the_warm_up_from_its_entry_point(tmp_path, monkeypatch):
    """In the PyInstaller bundle sys.executable is the bundle's `matedit`: the client starts it
    with MATEDIT_WARMUP_SERVER=1, and packaging/matedit_entry.py serves instead of the CLI.
    Here a script standing in for the bundle runs that entry point."""
    root = Path(__file__).resolve().parent.parent
    bundle = tmp_path / "matedit"
    bundle.write_text(f"#!/bin/sh\nPYTHONPATH='{root}' exec '{sys.executable}' "
                      f"'{root / 'packaging' / 'matedit_entry.py'}' \"$@\"\n")
    bundle.chmod(0o755)
    monkeypatch.setattr(sys, "frozen", True, raising=False)
    monkeypatch.setattr(sys, "executable", str(bundle))
    c = WarmupClient(timeout_s=300)
    try:
        c.start()
        assert c.wait_ready(300)
        cm = _compiled("brushed_gold")
        r = c.warm(cm, ViewportState())
        assert r.ok, r.error
        assert r.program == _expected(cm)
    finally:
        c.close()


def test_a_child_that_cannot_start_is_given_up(tmp_path, monkeypatch):
    bundle = tmp_path / "matedit"
    bundle.write_text("#!/bin/sh\nexit 3\n")  # a bundle whose child dies at once
    bundle.chmod(0o755)
    monkeypatch.setattr(sys, "frozen", True, raising=False)
    monkeypatch.setattr(sys, "executable", str(bundle))
    from matedit.render.warmup import MAX_STARTS

    c = WarmupClient(timeout_s=30)
    cm = _compiled("brushed_gold")
    try:
        for _ in range(3 * MAX_STARTS):
            c.start()
            assert not c.wait_ready(30)
            r = c.warm(cm, ViewportState())
            assert r.starting and not r.ok
        assert c.starts == MAX_STARTS
    finally:
        c.close()
