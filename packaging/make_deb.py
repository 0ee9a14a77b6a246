"""Stage and build dist/matedit_VERSION_amd64.deb around the PyInstaller bundle.

    python packaging/make_deb.py BUNDLE_DIR VERSION OUT.deb STAGE_DIR

Layout of the package: the bundle in /opt/matedit, /usr/bin/matedit (a link to it), the
desktop entry, hicolor icons (48, 128, 256 rasterised here from the SVG with Qt, and the
SVG itself), AppStream metainfo and the shared-mime-info types. `Depends` is computed:
the shared libraries that the bundle's ELF files need and that the bundle does not carry,
mapped to the Debian packages that hold them on this machine, plus libc6 at the highest
GLIBC symbol version any file asks for, plus fontconfig's configuration (data the bundled
libfontconfig reads).
"""

from __future__ import annotations

import datetime
import os
import re
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from matedit.io.atomic import atomic_write_bytes, atomic_write_text  # noqa: E402

APP_ID = "org.matedit.matedit"
ICON_SIZES = (48, 128, 256)
# Loaded with dlopen (moderngl's glcontext: EGL headless, GLX in the editor), so no ELF
# file names them; they are NEEDED by Qt too, but say so in one place.
DLOPENED = ("libEGL.so.1", "libGL.so.1")
# Data the bundled libraries read from the system: fontconfig's configuration (and through
# it a font), without which Qt draws no text.
DATA_DEPENDS = ("fontconfig-config",)


def is_elf(path: Path) -> bool:
    try:
        with open(path, "rb") as f:
            return f.read(4) == b"\x7fELF"
    except OSError:
        return False


def elf_files(bundle: Path) -> list[Path]:
    return sorted(p for p in bundle.rglob("*") if p.is_file() and not p.is_symlink()
                  and is_elf(p))


def needed_and_glibc(path: Path) -> tuple[list[str], list[tuple[int, ...]]]:
    dyn = subprocess.run(["readelf", "-dW", str(path)], capture_output=True, text=True,
                         check=True).stdout
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", dyn)
    ver = subprocess.run(["readelf", "-VW", str(path)], capture_output=True, text=True,
                         check=True).stdout
    glibc = [tuple(int(x) for x in m.split(".")) for m in re.findall(r"GLIBC_(\d+(?:\.\d+)+)",
                                                                      ver)]
    return needed, glibc


def system_libraries() -> dict[str, str]:
    """soname -> path, for the x86-64 libraries the dynamic loader knows."""
    out = subprocess.run(["/sbin/ldconfig", "-p"], capture_output=True, text=True,
                         check=True).stdout
    libs: dict[str, str] = {}
    for line in out.splitlines():
        m = re.match(r"\s*(\S+) \(([^)]*)\) => (\S+)", line)
        if m and "x86-64" in m.group(2):
            libs.setdefault(m.group(1), m.group(3))
    return libs


def package_of(path: str) -> str:
    candidates = {path, os.path.realpath(path)}
    for p in list(candidates):  # merged /usr: dpkg may know either spelling
        if p.startswith("/usr/lib/"):
            candidates.add(p[len("/usr"):])
        elif p.startswith("/lib/"):
            candidates.add("/usr" + p)
    for p in sorted(candidates):
        r = subprocess.run(["dpkg-query", "-S", p], capture_output=True, text=True)
        if r.returncode == 0:
            return r.stdout.split(":", 1)[0].strip()
    raise SystemExit(f"make_deb: no Debian package holds {path}; cannot write Depends")


def compute_depends(bundle: Path) -> tuple[str, list[str]]:
    carried = {p.name for p in bundle.rglob("*")}
    needed: set[str] = set(DLOPENED)
    glibc: list[tuple[int, ...]] = []
    for f in elf_files(bundle):
        n, g = needed_and_glibc(f)
        needed.update(n)
        glibc.extend(g)
    system = sorted(needed - carried)
    known = system_libraries()
    packages: set[str] = set()
    for lib in system:
        if lib not in known:
            raise SystemExit(f"make_deb: the bundle needs {lib}, which this machine lacks")
        packages.add(package_of(known[lib]))
    packages.update(DATA_DEPENDS)
    libc = max(glibc) if glibc else (2, 17)
    deps = []
    for pkg in sorted(packages):
        deps.append(f"{pkg} (>= {'.'.join(map(str, libc))})" if pkg == "libc6" else pkg)
    return ", ".join(deps), system


def rasterise(svg: Path, size: int) -> bytes:
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PySide6.QtCore import QBuffer, QByteArray, QIODevice, Qt
    from PySide6.QtGui import QGuiApplication, QImage, QPainter
    from PySide6.QtSvg import QSvgRenderer

    _app = QGuiApplication.instance() or QGuiApplication([])
    renderer = QSvgRenderer(str(svg))
    if not renderer.isValid():
        raise SystemExit(f"make_deb: cannot read {svg}")
    img = QImage(size, size, QImage.Format.Format_ARGB32_Premultiplied)
    img.fill(Qt.GlobalColor.transparent)
    p = QPainter(img)
    p.setRenderHint(QPainter.RenderHint.Antialiasing)
    p.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform)
    renderer.render(p)
    p.end()
    data = QByteArray()
    buf = QBuffer(data)
    buf.open(QIODevice.OpenModeFlag.WriteOnly)
    img.save(buf, "PNG")
    buf.close()
    return bytes(data)


def installed_size_kib(root: Path) -> int:
    total = 0
    for p in root.rglob("*"):
        if p.is_file() and not p.is_symlink() and "DEBIAN" not in p.relative_to(root).parts:
            total += (p.stat().st_size + 1023) // 1024
    return total


def main(argv: list[str]) -> int:
    bundle, version, out, stage = Path(argv[0]), argv[1], Path(argv[2]), Path(argv[3])
    if not (bundle / "matedit").is_file():
        raise SystemExit(f"make_deb: {bundle}/matedit is missing; build the bundle first")
    if stage.exists():
        subprocess.run(["rm", "-rf", "--", str(stage)], check=True)
    share = stage / "usr" / "share"
    (stage / "opt").mkdir(parents=True)
    subprocess.run(["cp", "-a", "--", str(bundle), str(stage / "opt" / "matedit")], check=True)
    (stage / "usr" / "bin").mkdir(parents=True)
    os.symlink("/opt/matedit/matedit", stage / "usr" / "bin" / "matedit")

    linux = HERE / "linux"
    atomic_write_text(share / "applications" / f"{APP_ID}.desktop",
                      (linux / f"{APP_ID}.desktop").read_text())
    date = datetime.datetime.fromtimestamp(
        int(os.environ.get("SOURCE_DATE_EPOCH", "0")) or datetime.datetime.now().timestamp(),
        tz=datetime.timezone.utc).date().isoformat()
    meta = (linux / f"{APP_ID}.metainfo.xml.in").read_text()
    meta = meta.replace("@VERSION@", version).replace("@DATE@", date)
    atomic_write_text(share / "metainfo" / f"{APP_ID}.metainfo.xml", meta)
    atomic_write_text(share / "mime" / "packages" / "matedit.xml",
                      (linux / "matedit-mime.xml").read_text())
    svg = linux / f"{APP_ID}.svg"
    icons = share / "icons" / "hicolor"
    atomic_write_bytes(icons / "scalable" / "apps" / f"{APP_ID}.svg", svg.read_bytes())
    for size in ICON_SIZES:
        atomic_write_bytes(icons / f"{size}x{size}" / "apps" / f"{APP_ID}.png",
                           rasterise(svg, size))
    atomic_write_text(share / "doc" / "matedit" / "copyright",
                      "matedit\n\nLicense: MIT\n\nThe bundle in /opt/matedit also carries "
                      "Python, Qt (PySide6, LGPL-3.0), NumPy, OpenImageIO, moderngl,\n"
                      "networkx, jsonschema and platformdirs under their own licenses.\n")

    depends, system = compute_depends(stage / "opt" / "matedit")
    control = (
        "Package: matedit\n"
        f"Version: {version}\n"
        "Architecture: amd64\n"
        "Maintainer: The matedit developers <matedit@localhost>\n"
        f"Installed-Size: {installed_size_kib(stage)}\n"
        f"Depends: {depends}\n"
        "Section: graphics\n"
        "Priority: optional\n"
        "Description: node-based editor for layered physically based materials\n"
        " matedit builds real-time materials from nodes and layers, previews them with\n"
        " image-based lighting on the shading model of Karis (Real Shading in Unreal\n"
        " Engine 4), and exports GLSL for OpenGL, Vulkan and WebGL 2. The package\n"
        " carries its own Python, Qt and libraries in /opt/matedit.\n"
    )
    atomic_write_text(stage / "DEBIAN" / "control", control)
    for p in [stage, *stage.rglob("*")]:  # dpkg-deb wants sane modes on everything
        if p.is_dir() and not p.is_symlink():
            p.chmod(0o755)
    out.parent.mkdir(parents=True, exist_ok=True)
    subprocess.run(["dpkg-deb", "--root-owner-group", "-Zxz", "-z6", "--build", str(stage),
                    str(out)], check=True, stdout=subprocess.DEVNULL)
    print(f"make_deb: {out} (Depends: {depends}; system libraries: {' '.join(system)})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
