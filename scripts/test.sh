#!/usr/bin/env bash
# The README's test command (and CI's): every Rust test — the physics against closed forms,
# the labels, the CLI, `xbandsim validate`'s checks, the golden hashes —, then a dataset's
# label files through a real COCO client (pycocotools in a virtual environment under target/,
# installed from PyPI on first use; scripts/check_labels.py), then the Python package
# (crates/xbandsim-py, built by pip with maturin into the same environment, with Ray,
# Stable-Baselines3 and torch from PyPI for its tests), a check that it writes the CLI's
# bytes for the same dataset, and its pytest suite.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/cpu-level.sh

cargo test --workspace

echo "== labels through pycocotools (scripts/check_labels.py)"
venv=target/check-venv
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r scripts/requirements-check.txt
cargo build --release --quiet -p xbandsim-cli
rm -rf target/check-labels
target/release/xbandsim dataset datasets/detection.toml --out target/check-labels --count 24 --seed 7
"$venv/bin/python" scripts/check_labels.py target/check-labels
rm -rf target/check-shards
target/release/xbandsim dataset datasets/detection.toml --out target/check-shards --count 12 --seed 7 --format webdataset --shard-samples 5
"$venv/bin/python" scripts/check_labels.py target/check-shards
target/release/xbandsim dataset schema > target/dataset-spec.schema.json
"$venv/bin/python" scripts/check_schema.py target/dataset-spec.schema.json datasets/*.toml

echo "== the baseline tracker scored with py-motmetrics and TrackEval (scripts/score_tracks.py)"
target/release/xbandsim track scenes/crossing.toml --frames 40 --out target/check-tracks.json
"$venv/bin/python" scripts/score_tracks.py --check target/check-tracks.json
echo "== the scenario's NMEA 0183 and AIS read by pynmea2 and pyais (scripts/check_nmea.py)"
target/release/xbandsim nmea scenes/crossing.toml --duration-s 400 --out target/check.nmea --truth target/check-nmea-truth.jsonl
"$venv/bin/python" scripts/check_nmea.py target/check.nmea target/check-nmea-truth.jsonl -4.14 50.33
echo "== the live radar as chart-plotter software sees it (scripts/check_serve.py)"
"$venv/bin/python" scripts/check_serve.py target/release/xbandsim scenes/crossing.toml --soak 30
echo "== the spoke stream decoded by protobufjs, as mayara's web client decodes it (scripts/check_protobufjs.js)"
# Node.js and npm from the machine; protobufjs and ws from the npm registry into target/.
if command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1; then
  npm install --prefix target/check-node --no-save --no-audit --no-fund --silent protobufjs@7.6.6 ws@8.23.1
  node scripts/check_protobufjs.js target/release/xbandsim scenes/crossing.toml
else
  echo "skipped: Node.js and npm are not installed (Debian: apt-get install nodejs npm)"
fi
echo "== the live radar's page in headless Chromium (scripts/check_page.py)"
# Debian's chromium and chromium-driver, installed with apt-get where this user may; where
# not, check_page.py says why and skips.
if ! command -v chromedriver >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1; then
  as_root=""
  if [ "$(id -u)" != 0 ] && command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then as_root="sudo -n"; fi
  if [ "$(id -u)" = 0 ] || [ -n "$as_root" ]; then
    { $as_root apt-get update -qq && DEBIAN_FRONTEND=noninteractive $as_root apt-get install -y -qq --no-install-recommends chromium chromium-driver; } >target/apt-chromium.log 2>&1 \
      || echo "xbandsim: installing chromium and chromium-driver with apt-get failed (target/apt-chromium.log)" >&2
  fi
fi
"$venv/bin/python" scripts/check_page.py target/release/xbandsim scenes/harbour-departure.toml
echo "== the same plots tracked by a Stone Soup peer, scored side by side (scripts/peer_stonesoup.py)"
"$venv/bin/python" scripts/peer_stonesoup.py --xbandsim target/release/xbandsim --check scenes/crossing.toml

echo "== the Python package (pip install ./crates/xbandsim-py, then pytest)"
# Optional extras with wheels for fewer platforms and Pythons than the rest: Ray (for
# xbandsim.distributed) and Stable-Baselines3 with torch (the environments through SB3,
# RadarDataset's torch tensors). Where PyPI has no wheel for this one, their tests are
# skipped with that reason; any other failure to install (PyPI unreachable, which pip also
# reports as "no matching distribution", or a broken wheel) fails the run, and once
# installed the tests must import them. Sets XBANDSIM_<NAME>_REQUIRED or _UNAVAILABLE.
install_optional() {
  local name=$1 requirements=$2 what=$3 log="target/pip-$1.log"
  local upper
  upper=$(echo "$name" | tr '[:lower:]' '[:upper:]')
  if "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements" >"$log" 2>&1; then
    export "XBANDSIM_${upper}_REQUIRED=1"
  elif grep -q "No matching distribution found" "$log" \
      && ! grep -qiE "Retrying|NewConnectionError|ProxyError|Could not fetch URL|Temporary failure in name resolution|Network is unreachable|timed out" "$log"; then
    echo "xbandsim: PyPI has no $what wheel for this platform or Python; its tests will be skipped" >&2
    export "XBANDSIM_${upper}_UNAVAILABLE=PyPI has no wheel of $requirements for this platform"
  else
    cat "$log" >&2
    echo "xbandsim: installing $requirements failed (pip's output above; free disk: $(df -h . | awk 'NR==2 {print $4}'))" >&2
    exit 1
  fi
}
install_optional ray scripts/requirements-ray.txt Ray
install_optional sb3 scripts/requirements-sb3.txt torch
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps ./crates/xbandsim-py
# The package is a second build of the same library (a Python extension, with other
# dependencies): it must write the CLI's bytes, so that shards made by Ray workers and by
# the CLI merge into one dataset (docs/architecture.md, "Determinism and the golden hashes").
echo "== the Python package writes the CLI's bytes (the detection set above, made again)"
rm -rf target/check-labels-py
"$venv/bin/python" -c "import xbandsim.dataset as d; d.generate('datasets/detection.toml', 'target/check-labels-py', 24, 7)"
diff -r target/check-labels target/check-labels-py
# The suite runs in a network namespace of its own with only the loopback interface (as root,
# or as a user where user namespaces are allowed): nothing in it reaches the network, and the
# local Ray cluster of test_distributed.py listens on 127.0.0.1 alone (outside one, Ray's
# servers listen on every interface of the machine).
lo_up='ip link set lo up 2>/dev/null || ifconfig lo up 2>/dev/null'
netns=""
for how in "unshare --net" "unshare --user --map-root-user --net"; do
  if $how sh -c "$lo_up" 2>/dev/null; then netns=$how; break; fi
done
if [ -n "$netns" ]; then
  XBANDSIM_LOOPBACK_ONLY=1 $netns sh -c "$lo_up"' && exec "$@"' sh \
    "$venv/bin/python" -m pytest -q -rs crates/xbandsim-py/tests
else
  echo "xbandsim: no network namespace with a loopback interface here; the Python tests run on the machine's network" >&2
  "$venv/bin/python" -m pytest -q -rs crates/xbandsim-py/tests
fi
