#!/usr/bin/env bash
# matedit developer entry point: sets everything up, then runs the editor or the tests.
#   ./dev.sh run [FILE]   set up and open the editor (no FILE: the built-in sample material)
#   ./dev.sh test [ARGS]  set up and run lint and the whole test suite (pytest ARGS pass through)
#   ./dev.sh setup        only set up
set -euo pipefail
cd "$(dirname "$0")"

APT_PACKAGES=(
  python3 python3-venv python3-pip
  xvfb xauth
  libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 libglx-mesa0
  libxcb-cursor0 libxcb-icccm4 libxcb-image0 libxcb-keysyms1 libxcb-randr0
  libxcb-render-util0 libxcb-shape0 libxcb-xinerama0 libxcb-xkb1 libxkbcommon-x11-0
  libxkbcommon0 libfontconfig1 libdbus-1-3
  glslang-tools
  desktop-file-utils appstream shared-mime-info dpkg-dev binutils libglib2.0-bin
  spirv-cross spirv-tools
)

setup_system() {
  local missing=()
  for p in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if ((${#missing[@]})); then
    local SUDO=""
    [[ $(id -u) -ne 0 ]] && SUDO="sudo"
    echo "dev.sh: installing Debian packages: ${missing[*]}"
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
  fi
}

setup_python() {
  if [[ ! -x .venv/bin/python ]]; then
    python3 -m venv .venv
  fi
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -e ".[test]"
}

cmd="${1:-run}"
shift || true
case "$cmd" in
  setup)
    setup_system
    setup_python
    ;;
  test)
    setup_system
    setup_python
    .venv/bin/ruff check matedit tests benchmarks
    .venv/bin/mypy  # the pure layers, as [tool.mypy] in pyproject.toml says
    .venv/bin/vulture  # dead code ([tool.vulture]; framework names: tools/vulture_whitelist.py)
    # pytest-xvfb starts a virtual X server for the GUI tests; GL tests use EGL.
    .venv/bin/python -m pytest "$@"
    ;;
  run)
    setup_system
    setup_python
    exec .venv/bin/matedit "$@"
    ;;
  *)
    echo "usage: ./dev.sh run [FILE] | test [PYTEST ARGS] | setup" >&2
    exit 2
    ;;
esac
