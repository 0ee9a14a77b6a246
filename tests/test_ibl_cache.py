"""The bake cache: a second bake does no GPU work; writes are atomic; bad entries rebake."""

from __future__ import annotations

import numpy as np
import pytest

from matedit.ibl import BakeSettings, Environment, bake, bake_brdf_lut
from matedit.ibl import cache as ibl_cache
from matedit.ibl.gpu import Baker

SMALL = BakeSettings(size=16, samples=16, lut_size=16, lut_samples=256)


@pytest.fixture
def gpu_calls(monkeypatch):
    """Counts every GPU pass the Baker runs."""
    calls = []
    for name in ("equirect_to_cube", "resample_cube", "prefilter", "brdf_lut"):
        original = getattr(Baker, name)

        def counting(self, *args, _original=original, _name=name, **kwargs):
            calls.append(_name)
            return _original(self, *args, **kwargs)

        monkeypatch.setattr(Baker, name, counting)
    return calls


def small_env() -> Environment:
    rng = np.random.default_rng(5)
    return Environment(name="test", equirect=(rng.random((32, 64, 3)) * 4).astype(np.float32))


def test_second_bake_is_a_cache_hit_without_gpu_work(ctx, tmp_path, gpu_calls):
    first = bake(small_env(), SMALL, ctx=ctx, cache_dir=tmp_path)
    assert not first.from_cache
    assert sorted(gpu_calls) == ["brdf_lut", "equirect_to_cube", "prefilter"]
    gpu_calls.clear()
    second = bake(small_env(), SMALL, ctx=ctx, cache_dir=tmp_path)
    assert second.from_cache and gpu_calls == []
    assert second.key == first.key
    for a, b in zip(first.mips, second.mips):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(first.lut, second.lut)
    np.testing.assert_array_equal(first.sh, second.sh)
    assert not list(tmp_path.glob("*.tmp")) and not list(tmp_path.glob(".*"))


def test_changed_settings_or_content_miss_the_cache(ctx, tmp_path, gpu_calls):
    bake(small_env(), SMALL, ctx=ctx, cache_dir=tmp_path)
    other = BakeSettings(size=16, samples=32, lut_size=16, lut_samples=256)
    assert not bake(small_env(), other, ctx=ctx, cache_dir=tmp_path).from_cache
    env = small_env()
    env.equirect[0, 0, 0] += 1.0
    assert not bake(env, SMALL, ctx=ctx, cache_dir=tmp_path).from_cache
    # The LUT depends on neither, so it was computed once.
    assert gpu_calls.count("brdf_lut") == 1


def test_corrupt_cache_entry_is_baked_again(ctx, tmp_path, gpu_calls):
    first = bake(small_env(), SMALL, ctx=ctx, cache_dir=tmp_path)
    entry = tmp_path / f"ibl-{first.key}.npz"
    entry.write_bytes(entry.read_bytes()[:100])
    gpu_calls.clear()
    again = bake(small_env(), SMALL, ctx=ctx, cache_dir=tmp_path)
    assert not again.from_cache and "prefilter" in gpu_calls
    assert bake(small_env(), SMALL, ctx=ctx, cache_dir=tmp_path).from_cache


def test_lut_cache(ctx, tmp_path, gpu_calls):
    with Baker(ctx) as baker:
        a = bake_brdf_lut(8, 256, baker=baker, cache_dir=tmp_path)
        b = bake_brdf_lut(8, 256, baker=baker, cache_dir=tmp_path)
    assert gpu_calls == ["brdf_lut"]
    np.testing.assert_array_equal(a, b)


def test_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("MATEDIT_CACHE_DIR", str(tmp_path / "mine"))
    assert ibl_cache.ibl_cache_dir() == tmp_path / "mine" / "ibl"
    monkeypatch.delenv("MATEDIT_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert ibl_cache.ibl_cache_dir() == tmp_path / "xdg" / "matedit" / "ibl"


def test_atomic_save_leaves_no_partial_file(tmp_path, monkeypatch):
    target = tmp_path / "entry.npz"

    def explode(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(np, "savez", explode)
    with pytest.raises(OSError):
        ibl_cache.save(target, {"a": np.zeros(3)})
    assert list(tmp_path.iterdir()) == []
