#!/usr/bin/env bash
# Runs every benchmark and writes benchmarks/RESULTS.md and benchmarks/results.json (keys: benchmarks/README.md).
#   benchmarks/run.sh            the full run (about 6 minutes on 2 cores with llvmpipe)
#   benchmarks/run.sh --quick    fewer repetitions and a smaller IBL bake, to try it out
# Benchmark-only dependencies are set up here and nowhere else: MaterialX, pyinstrument and
# py-spy go into .venv; Filament's cmgen (libfilament-tools) and Xvfb come from apt.
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ ! -x .venv/bin/python ]]; then
  ./dev.sh setup  # a fresh checkout: the project and its test tools first
fi

if ! .venv/bin/python -c "import MaterialX, pyinstrument" 2>/dev/null \
   || [[ ! -x .venv/bin/py-spy ]]; then
  echo "benchmarks/run.sh: installing materialx, pyinstrument, py-spy into .venv"
  .venv/bin/python -m pip install -q materialx pyinstrument py-spy
fi

apt_missing=()
command -v cmgen >/dev/null || apt_missing+=(libfilament-tools)
command -v xvfb-run >/dev/null || apt_missing+=(xvfb xauth)
if ((${#apt_missing[@]})); then
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  echo "benchmarks/run.sh: installing Debian packages: ${apt_missing[*]}"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${apt_missing[@]}"
fi

export MESA_SHADER_CACHE_DISABLE=true
export MATEDIT_BENCH_COMMAND="benchmarks/run.sh${*:+ $*}"
exec .venv/bin/python benchmarks/run_all.py "$@"
