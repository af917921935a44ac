#!/usr/bin/env bash
# Builds xbandsim, sets up the reference programs' Python environment (PyPI: mitsuba, which
# bundles Embree, and numpy) and prints xbandsim's bench figures beside the references,
# measured in the same run. Usage: bash bench/run.sh [--repeats N]
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/cpu-level.sh
cargo build --release -p xbandsim-cli
venv="${XBANDSIM_BENCH_VENV:-target/bench-venv}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet -r bench/reference/requirements.txt
fi
"$venv/bin/python" bench/compare.py --xbandsim target/release/xbandsim "$@"
