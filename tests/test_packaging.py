"""Packaging: `matedit --version`, the user folders, the desktop integration files, and
(marked slow) the artefacts of packaging/build.sh: the PyInstaller bundle run from a clean
environment, the editor started from it under Xvfb, and the Debian package.

The slow tests build once per session (module fixture, about a minute or two on 2 cores).
They are skipped only when PyInstaller cannot be installed, and the skip says why.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import matedit
from matedit import dirs

ROOT = Path(__file__).resolve().parent.parent
LINUX = ROOT / "packaging" / "linux"
APP_ID = "org.matedit.matedit"
VERSION = matedit.__version__
SAMPLE = "graphs/materials/rusty_painted_metal.json"


def run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def need(tool: str) -> str:
    path = shutil.which(tool)
    if path is None:
        pytest.fail(f"{tool} is missing: ./dev.sh setup installs it")
    return path


# --- version and folders ---------------------------------------------------------------------

def test_version_flag_prints_the_package_version():
    r = run([sys.executable, "-m", "matedit", "--version"])
    assert (r.returncode, r.stdout, r.stderr) == (0, f"matedit {VERSION}\n", "")


def test_version_agrees_with_pyproject():
    text = (ROOT / "pyproject.toml").read_text()
    assert re.search(r'^version = "([^"]+)"$', text, re.M).group(1) == VERSION
    assert re.fullmatch(r"\d+\.\d+\.\d+", VERSION)


def test_cache_override_and_xdg(monkeypatch, tmp_path):
    monkeypatch.setenv("MATEDIT_CACHE_DIR", str(tmp_path / "mine"))
    assert dirs.cache_dir() == tmp_path / "mine"
    monkeypatch.delenv("MATEDIT_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    assert dirs.cache_dir() == tmp_path / "cache" / "matedit"
    assert dirs.config_dir() == tmp_path / "config" / "matedit"
    assert dirs.recovery_dir() == tmp_path / "data" / "matedit" / "recovery"
    from matedit.ibl import cache

    assert cache.ibl_cache_dir() == tmp_path / "cache" / "matedit" / "ibl"
    assert not (tmp_path / "cache").exists()  # asking creates nothing


def test_folders_without_xdg_variables(monkeypatch, tmp_path):
    for var in ("MATEDIT_CACHE_DIR", "XDG_CACHE_HOME", "XDG_CONFIG_HOME", "XDG_DATA_HOME"):
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    assert dirs.cache_dir() == tmp_path / ".cache" / "matedit"
    assert dirs.config_dir() == tmp_path / ".config" / "matedit"
    assert dirs.recovery_dir() == tmp_path / ".local" / "share" / "matedit" / "recovery"


# --- desktop integration files (source form) -------------------------------------------------

def test_desktop_entry_validates():
    r = run([need("desktop-file-validate"), str(LINUX / f"{APP_ID}.desktop")])
    assert r.returncode == 0 and r.stdout == "", r.stdout + r.stderr
    text = (LINUX / f"{APP_ID}.desktop").read_text()
    assert f"Icon={APP_ID}\n" in text and "Exec=matedit %f\n" in text
    assert "MimeType=application/x-matedit-material;\n" in text


def filled_metainfo(tmp_path: Path) -> Path:
    text = (LINUX / f"{APP_ID}.metainfo.xml.in").read_text()
    out = tmp_path / f"{APP_ID}.metainfo.xml"
    out.write_text(text.replace("@VERSION@", VERSION).replace("@DATE@", "2026-01-01"))
    return out


def test_metainfo_validates(tmp_path):
    path = filled_metainfo(tmp_path)
    r = run([need("appstreamcli"), "validate", "--no-net", "--pedantic", str(path)])
    assert r.returncode == 0, r.stdout + r.stderr
    assert "W:" not in r.stdout and "E:" not in r.stdout, r.stdout


def mime_types_of(share: Path, files: list[Path]) -> list[str]:
    """Content types as GIO sees them with `share` first in XDG_DATA_DIRS."""
    gio = shutil.which("gio")
    if gio is None:
        pytest.skip("gio (libglib2.0-bin) is not installed: cannot query MIME types")
    env = dict(os.environ, XDG_DATA_DIRS=f"{share}:/usr/share",
               XDG_DATA_HOME=str(share.parent / "no-user-data"))
    r = run([gio, "info", "-a", "standard::content-type", *map(str, files)], env=env)
    assert r.returncode == 0, r.stderr
    return re.findall(r"standard::content-type: (\S+)", r.stdout)


def check_mime_package(share: Path, tmp_path: Path) -> None:
    r = run([need("update-mime-database"), "-V", str(share / "mime")])
    assert r.returncode == 0 and "error" not in r.stderr.lower(), r.stderr
    plain = tmp_path / "plain.json"
    plain.write_text('{"format": "something.else", "nodes": []}\n')
    compact = tmp_path / "compact.json"
    compact.write_text(json.dumps(json.loads((ROOT / SAMPLE).read_text()),
                                  separators=(",", ":")))
    renamed = tmp_path / "no_extension"  # content decides, not the name
    renamed.write_text((ROOT / SAMPLE).read_text())
    files = [ROOT / SAMPLE, ROOT / "graphs/functions/edge_wear.json",
             ROOT / "graphs/layers/rust.json", compact, renamed, plain]
    assert mime_types_of(share, files) == [
        "application/x-matedit-material", "application/x-matedit-function",
        "application/x-matedit-function", "application/x-matedit-material",
        "application/x-matedit-material", "application/json"]


def test_mime_types_match_documents_by_content_and_not_all_json(tmp_path):
    share = tmp_path / "share"
    (share / "mime" / "packages").mkdir(parents=True)
    shutil.copy(LINUX / "matedit-mime.xml", share / "mime" / "packages" / "matedit.xml")
    check_mime_package(share, tmp_path)


def test_icon_svg_is_our_own_and_square():
    svg = (LINUX / f"{APP_ID}.svg").read_text()
    assert 'viewBox="0 0 256 256"' in svg and "Drawn for matedit" in svg


# --- the built artefacts (slow) --------------------------------------------------------------

def _ensure_pyinstaller() -> None:
    if importlib.util.find_spec("PyInstaller") is not None:
        return
    r = run([sys.executable, "-m", "pip", "install", "-q", "pyinstaller>=6.3"])
    if r.returncode != 0 or importlib.util.find_spec("PyInstaller") is None:
        tail = (r.stderr or r.stdout).strip().splitlines()[-1:] or ["no output"]
        pytest.skip(f"PyInstaller cannot be installed into {sys.prefix}: {tail[0]}")


@pytest.fixture(scope="module")
def built():
    """Runs packaging/build.sh once; returns the paths of what it made."""
    _ensure_pyinstaller()
    env = dict(os.environ, PYTHON=sys.executable)
    r = run([str(ROOT / "packaging" / "build.sh")], cwd=ROOT, env=env, timeout=1500)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    print(r.stdout)
    dist = ROOT / "dist"
    return {
        "bundle": dist / f"matedit-{VERSION}-linux-x86_64",
        "deb": dist / f"matedit_{VERSION}_amd64.deb",
        "wheel": dist / f"matedit-{VERSION}-py3-none-any.whl",
        "sdist": dist / f"matedit-{VERSION}.tar.gz",
        "log": r.stdout,
    }


def clean_env(home: Path, **extra) -> dict[str, str]:
    """No virtual environment, no PYTHONPATH, nothing of this process but a plain PATH."""
    env = {"PATH": "/usr/bin:/bin", "HOME": str(home), "LANG": "C.UTF-8",
           "MATEDIT_CACHE_DIR": str(home / "cache")}
    env.update(extra)
    return env


@pytest.fixture
def workdir(tmp_path):
    shutil.copytree(ROOT / "graphs", tmp_path / "graphs")
    return tmp_path


def bundle_run(built, args, cwd, timeout=300, **extra):
    exe = built["bundle"] / "matedit"
    return run([str(exe), *args], cwd=cwd, env=clean_env(cwd, **extra), timeout=timeout)


@pytest.mark.slow
def test_build_reports_sizes_and_makes_all_artefacts(built):
    for key in ("bundle", "deb", "wheel", "sdist"):
        assert built[key].exists(), key
    assert "bundle" in built["log"] and "done in" in built["log"]
    assert (built["bundle"] / "matedit").stat().st_mode & 0o111


@pytest.mark.slow
def test_wheel_carries_package_data(built):
    names = set(zipfile.ZipFile(built["wheel"]).namelist())
    for must in ("matedit/shaders/common.glsl", "matedit/ui/style.qss",
                 "matedit/graphs/materials/rusty_painted_metal.json",
                 "matedit/schemas/material.schema.json", "matedit/schemas/document.schema.json"):
        assert must in names, must


@pytest.mark.slow
def test_bundle_is_lean_and_self_contained(built):
    internal = built["bundle"] / "_internal"
    names = {p.name for p in internal.rglob("*")}
    # no Qt OpenGL widget either: the editor's viewport draws in its render process
    for unused in ("libQt6Quick.so.6", "libQt6Qml.so.6", "libQt6Network.so.6", "libqgtk3.so",
                   "libgtk-3.so.0", "libQt6Pdf.so.6", "libQt6OpenGLWidgets.so.6"):
        assert unused not in names, unused
    for used in ("libqxcb.so", "libqsvg.so"):
        assert used in names, used
    for kind in ("shaders", "graphs", "ui", "schemas"):
        assert (internal / "matedit" / kind).is_dir(), kind
    assert not any(p.suffix == ".py" and p.parent.name == "matedit" for p in internal.rglob("*"))


@pytest.mark.slow
def test_bundle_runs_the_commands_with_no_python(built, workdir):
    r = bundle_run(built, ["--version"], workdir)
    assert (r.returncode, r.stdout.strip()) == (0, f"matedit {VERSION}")
    r = bundle_run(built, ["validate", "graphs"], workdir)
    assert r.returncode == 0, r.stderr
    broken = workdir / "broken.json"
    broken.write_text('{"format": "matedit.material", "version": 2, "nodes": [{"id": 3}]}')
    r = bundle_run(built, ["validate", "broken.json"], workdir)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.startswith("error: broken.json") and len(r.stderr.splitlines()) == 1

    r = bundle_run(built, ["compile", SAMPLE, "-o", "out", "--target", "all"], workdir)
    assert r.returncode == 0, r.stderr
    # Same output as the installed package's own compiler, file for file.
    ref = workdir / "ref"
    r2 = run([sys.executable, "-m", "matedit", "compile", SAMPLE, "-o", str(ref), "--target",
              "all"], cwd=workdir)
    assert r2.returncode == 0, r2.stderr
    names = sorted(p.name for p in (workdir / "out").iterdir())
    assert names == sorted(p.name for p in ref.iterdir())
    # GLSL: STEM.TARGET.frag; HLSL and MSL: STEM.frag.hlsl and STEM.frag.metal
    assert {n.split(".")[1] for n in names if n.endswith(".frag")} == {
        "glsl330", "glsl450", "essl300"}
    cross = {"hlsl", "metal"} if shutil.which("spirv-cross") else set()
    assert {n.rsplit(".", 1)[1] for n in names if ".frag." in n} == cross
    for n in names:
        assert (workdir / "out" / n).read_bytes() == (ref / n).read_bytes(), n


@pytest.mark.slow
def test_bundle_renders_like_the_package(built, workdir):
    import OpenImageIO as oiio

    args = ["render", SAMPLE, "--size", "96x96", "--env", "sky"]
    r = bundle_run(built, [*args, "-o", "bundle.png"], workdir, timeout=600)
    assert r.returncode == 0, r.stderr
    r2 = run([sys.executable, "-m", "matedit", *args, "-o", "venv.png"], cwd=workdir,
             env=dict(os.environ, MATEDIT_CACHE_DIR=str(workdir / "cache2")), timeout=600)
    assert r2.returncode == 0, r2.stderr
    a = oiio.ImageBuf(str(workdir / "bundle.png")).get_pixels(oiio.FLOAT)
    b = oiio.ImageBuf(str(workdir / "venv.png")).get_pixels(oiio.FLOAT)
    assert a.shape[:2] == (96, 96)
    assert a[..., :3].std() > 0.05  # a lit sphere, not a flat colour
    # Same code, same GL driver: identical up to rounding (1/255 mean).
    assert float(np.abs(a - b).mean()) < 1 / 255


@pytest.mark.slow
def test_bundle_bakes_ibl_and_lut(built, workdir):
    r = bundle_run(built, ["brdf-lut", "-o", "lut.exr", "--size", "16", "--samples", "64"],
                   workdir)
    assert r.returncode == 0, r.stderr
    r = bundle_run(built, ["bake-ibl", "sky", "-o", "ibl", "--size", "16", "--samples", "16"],
                   workdir)
    assert r.returncode == 0, r.stderr
    assert (workdir / "lut.exr").stat().st_size > 0
    assert any(p.suffix == ".exr" for p in (workdir / "ibl").iterdir())


@pytest.mark.slow
def test_editor_starts_from_the_bundle_and_draws(built, workdir):
    xvfb = need("xvfb-run")
    exe = built["bundle"] / "matedit"
    env = clean_env(workdir, QT_QPA_PLATFORM="xcb", MATEDIT_QUIT_AFTER_FIRST_FRAME="240")
    r = run([xvfb, "-a", "-s", "-screen 0 1280x800x24", str(exe), SAMPLE], cwd=workdir,
            env=env, timeout=400)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "viewport frame drawn" in r.stderr
    assert "Traceback" not in r.stderr and "could not load the Qt platform plugin" not in \
        r.stderr.lower()


def deb_field(deb: Path, name: str) -> str:
    r = run([need("dpkg-deb"), "-f", str(deb), name])
    assert r.returncode == 0, r.stderr
    return r.stdout.strip()


@pytest.mark.slow
def test_deb_control_fields(built):
    deb = built["deb"]
    assert deb_field(deb, "Package") == "matedit"
    assert deb_field(deb, "Version") == VERSION
    assert deb_field(deb, "Architecture") == "amd64"
    assert int(deb_field(deb, "Installed-Size")) > 50_000  # KiB: the bundle is in it
    depends = [d.split()[0] for d in deb_field(deb, "Depends").split(", ")]
    for lib in ("libc6", "libegl1", "libgl1", "libxcb1", "fontconfig-config"):
        assert lib in depends
    # Nothing the bundle carries: no dependency provides a library the bundle already has.
    carried = {p.name for p in (built["bundle"] / "_internal").rglob("*.so*")}
    for pkg in depends:
        r = run(["dpkg", "-L", pkg])
        assert r.returncode == 0, f"{pkg} is not installed here: {r.stderr}"
        provided = {Path(line).name for line in r.stdout.splitlines()}
        assert not (provided & carried), (pkg, sorted(provided & carried))


@pytest.mark.slow
def test_deb_contents(built):
    r = run([need("dpkg-deb"), "-c", str(built["deb"])])
    assert r.returncode == 0, r.stderr
    listing = r.stdout
    entries = {line.split()[5].lstrip("."): line for line in listing.splitlines()}
    assert "/usr/bin/matedit" in entries
    assert entries["/usr/bin/matedit"].startswith("l") and "-> /opt/matedit/matedit" in \
        entries["/usr/bin/matedit"]
    assert entries["/opt/matedit/matedit"].startswith("-rwx")
    for path in (f"/usr/share/applications/{APP_ID}.desktop",
                 f"/usr/share/metainfo/{APP_ID}.metainfo.xml",
                 "/usr/share/mime/packages/matedit.xml",
                 f"/usr/share/icons/hicolor/scalable/apps/{APP_ID}.svg",
                 *(f"/usr/share/icons/hicolor/{s}x{s}/apps/{APP_ID}.png" for s in (48, 128, 256)),
                 "/opt/matedit/_internal/matedit/shaders/common.glsl"):
        assert path in entries, path
    assert all(" root/root " in line for line in listing.splitlines())


@pytest.fixture(scope="module")
def extracted(built, tmp_path_factory):
    root = tmp_path_factory.mktemp("deb")
    r = run([need("dpkg-deb"), "-x", str(built["deb"]), str(root)])
    assert r.returncode == 0, r.stderr
    return root


@pytest.mark.slow
def test_installed_files_validate(extracted, tmp_path):
    share = extracted / "usr" / "share"
    r = run([need("desktop-file-validate"), str(share / "applications" / f"{APP_ID}.desktop")])
    assert r.returncode == 0 and r.stdout == "", r.stdout
    meta = share / "metainfo" / f"{APP_ID}.metainfo.xml"
    r = run([need("appstreamcli"), "validate", "--no-net", str(meta)])
    assert r.returncode == 0, r.stdout + r.stderr
    assert f'<release version="{VERSION}"' in meta.read_text()
    check_mime_package(share, tmp_path)


@pytest.mark.slow
def test_installed_icons(extracted):
    import OpenImageIO as oiio

    hicolor = extracted / "usr" / "share" / "icons" / "hicolor"
    for size in (48, 128, 256):
        buf = oiio.ImageBuf(str(hicolor / f"{size}x{size}" / "apps" / f"{APP_ID}.png"))
        px = buf.get_pixels(oiio.FLOAT)
        assert px.shape == (size, size, 4)
        alpha = px[..., 3]
        assert alpha[0, 0] == 0 and alpha[size // 2, size // 2] == 1  # transparent corners
        assert px[..., :3].std() > 0.1


@pytest.mark.slow
def test_installed_copy_runs_from_its_own_folder(extracted, workdir):
    exe = extracted / "opt" / "matedit" / "matedit"
    r = run([str(exe), "validate", SAMPLE], cwd=workdir, env=clean_env(workdir))
    assert r.returncode == 0, r.stderr
