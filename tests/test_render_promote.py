"""A deferred material drawn forward once the viewport is idle (Renderer.promote_forward, the
render server's FORWARD_WHEN_IDLE_S): the same image as the forward path, split-sum frames
only, back to the deferred path at the next structural edit."""

from __future__ import annotations

import time

import moderngl
import numpy as np
from graphs_util import link, material, node

from matedit.compiler import compile_document

SIZE = (64, 48)  # the render server's viewport

def _material(roughness=0.4, extra=False):
    d = material()
    node(d, "r", "scalar_parameter", {"name": "rough"}, {"value": roughness})
    node(d, "make", "make_attributes", values={"baseColor": [0.8, 0.4, 0.2], "metallic": 0.3})
    node(d, "out", "material_output")
    link(d, "r", "value", "make", "roughness")
    if extra:
        node(d, "m", "scalar_parameter", {"name": "metal"}, {"value": 0.5})
        link(d, "m", "value", "make", "metallic")
    link(d, "make", "attributes", "out", "attributes")
    return d


def _image(r, mode="splitsum"):
    r.mode = mode
    r.render_converged()
    return r.read_linear().copy()


def test_promoted_material_draws_the_forward_image_until_the_next_structural_edit(render_pair):
    r, f = render_pair["deferred"], render_pair["forward"]
    cm = compile_document(_material())
    r.set_material(cm)
    f.set_material(cm)
    deferred_image = _image(r)
    reference = _image(r, "reference")
    r.mode = "splitsum"
    assert not r.is_forward and r.can_promote and not r.promoted
    links = r.link_count
    assert r.promote_forward()
    assert r.is_forward and r.promoted and not r.can_promote and r.link_count == links + 1
    assert np.array_equal(_image(r), _image(f))  # the forward path's program and image
    assert not np.array_equal(_image(r), deferred_image)  # (the paths differ a little)
    # a value edit keeps the path; reference mode draws the deferred program, linked already
    r.set_uniforms({"p_rough": 0.6})
    assert r.is_forward
    r.set_uniforms({"p_rough": 0.4})
    assert np.array_equal(_image(r, "reference"), reference) and r.link_count == links + 1
    r.mode = "splitsum"
    # the same program again stays forward; a new one is drawn deferred (its link is quick)
    r.set_material(compile_document(_material()))
    assert r.is_forward
    r.set_material(compile_document(_material(extra=True)))
    assert not r.is_forward and not r.promoted and r.can_promote


def test_promotion_waits_for_the_lit_split_sum_view_and_a_link_failure_is_not_retried(
        render_pair, monkeypatch):
    r = render_pair["deferred"]
    r.set_material(compile_document(_material(roughness=0.2)))
    r.mode = "reference"
    assert not r.can_promote and not r.promote_forward()
    r.mode = "splitsum"
    r.set_view("coat")
    assert not r.can_promote
    r.set_view("lit")
    assert r.can_promote

    def refuse(*_args, **_kw):
        raise moderngl.Error("refused")

    monkeypatch.setattr(r.programs, "material", refuse)
    assert not r.promote_forward() and not r.is_forward
    assert not r.can_promote  # not tried again for this material


def test_the_render_server_promotes_once_idle_and_only_when_asked():
    from matedit.app.render_client import RenderProcess

    cm = compile_document(_material(roughness=0.3))
    for idle in (0.05, None):
        frames: list = []
        proc = RenderProcess(on_frame=lambda *a, seen=frames: seen.append(a))
        proc.start({"size": SIZE, "forward_when_idle_s": idle, "warm_up": False})
        try:
            proc.post("call", "set_material", (cm,), {}).result(120)
            proc.sync(120)
            end = time.monotonic() + 60
            while idle is not None and not proc.call("get", "promoted") and \
                    time.monotonic() < end:
                time.sleep(0.3)  # asking is a message: the server must be left idle a while
            if idle is None:
                time.sleep(0.5)
            promoted = proc.call("get", "promoted")
            assert promoted == (idle is not None)
            assert proc.call("get", "is_forward") == promoted
            if promoted:  # the promoted path's frame was sent without being asked for
                end = time.monotonic() + 30
                while len(frames) < 2 and time.monotonic() < end:
                    time.sleep(0.05)
                assert len(frames) >= 2
        finally:
            proc.stop()
