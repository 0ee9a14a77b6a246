#!/usr/bin/env bash
# Builds matedit's release artefacts into dist/:
#   dist/matedit-VERSION-py3-none-any.whl, dist/matedit-VERSION.tar.gz   (python -m build)
#   dist/matedit-VERSION-linux-x86_64/      one-folder PyInstaller bundle; its `matedit`
#                                           runs the editor and every command, no Python needed
#   dist/matedit_VERSION_amd64.deb          the bundle in /opt/matedit, /usr/bin/matedit,
#                                           desktop entry, icons, AppStream, MIME type
# Usage: packaging/build.sh            (sets up .venv with ./dev.sh setup when it is missing)
# PYTHON=... picks another interpreter that has the project and its test extra installed.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)

PY=${PYTHON:-.venv/bin/python}
if [[ ! -x $PY ]]; then
  ./dev.sh setup
fi
if ! "$PY" -c "import PyInstaller, build" 2>/dev/null; then
  "$PY" -m pip install -q "pyinstaller>=6.3" "build>=1.0"
fi
for tool in dpkg-deb readelf strip desktop-file-validate appstreamcli update-mime-database; do
  command -v "$tool" >/dev/null || { echo "build.sh: $tool is missing; run ./dev.sh setup" >&2; exit 2; }
done

VERSION=$("$PY" -c "import matedit; print(matedit.__version__)")
BUNDLE="matedit-$VERSION-linux-x86_64"
DEB="matedit_${VERSION}_amd64.deb"
mkdir -p dist build
rm -rf "dist/$BUNDLE" "dist/$DEB" "dist/matedit-$VERSION.tar.gz" \
  "dist/matedit-$VERSION-py3-none-any.whl"

echo "build.sh: [1/4] wheel and sdist"
"$PY" -m build --no-isolation --outdir dist . >build/python-build.log 2>&1 \
  || { tail -30 build/python-build.log >&2; exit 1; }

echo "build.sh: [2/4] PyInstaller bundle"
MATEDIT_VERSION="$VERSION" "$PY" -m PyInstaller packaging/matedit.spec --noconfirm \
  --distpath dist --workpath build/pyinstaller >build/pyinstaller.log 2>&1 \
  || { tail -30 build/pyinstaller.log >&2; exit 1; }
# The interpreter's shared library carries its symbol tables (17 MB of 23); nothing needs
# them at run time. Only this one is stripped: auditwheel-patched libraries (numpy's
# OpenBLAS) no longer load once strip has rewritten them.
strip --strip-unneeded dist/"$BUNDLE"/_internal/libpython3*.so*
"dist/$BUNDLE/matedit" --version >/dev/null

echo "build.sh: [3/4] desktop entry and AppStream metainfo"
desktop-file-validate packaging/linux/org.matedit.matedit.desktop

echo "build.sh: [4/4] Debian package"
"$PY" packaging/make_deb.py "dist/$BUNDLE" "$VERSION" "dist/$DEB" build/deb
appstreamcli validate --no-net build/deb/usr/share/metainfo/org.matedit.matedit.metainfo.xml \
  >/dev/null

echo "build.sh: done in $(( $(date +%s) - start )) s"
du -sh "dist/$BUNDLE" | sed 's/^/  bundle  /'
du -h "dist/$DEB" "dist/matedit-$VERSION-py3-none-any.whl" "dist/matedit-$VERSION.tar.gz" \
  | sed 's/^/  file    /'
