#!/usr/bin/env bash
# Runs the reference programs alone (no xbandsim build) and prints one JSON object per line:
# Embree without and with the sea plane, then the NumPy frame. bench/run.sh (via
# bench/compare.py) runs the same programs beside `xbandsim bench` and prints the ratios.
# Usage: bash bench/reference/run.sh [--repeats N] [--threads N]
# The virtual environment is $XBANDSIM_BENCH_VENV (default target/bench-venv), made if missing.
set -euo pipefail
cd "$(dirname "$0")"
repeats=5 threads=2
while [ $# -gt 0 ]; do
  case "$1" in
    --repeats) repeats="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    *) echo "usage: $0 [--repeats N] [--threads N]" >&2; exit 2 ;;
  esac
done
venv="${XBANDSIM_BENCH_VENV:-../../target/bench-venv}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet -r requirements.txt
fi
py="$venv/bin/python"
"$py" embree_scan.py --json --threads "$threads" --repeats "$repeats"
"$py" embree_scan.py --json --threads "$threads" --repeats "$repeats" --sea
"$py" numpy_frame.py --json --repeats "$repeats"
