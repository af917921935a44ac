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

echo "== the Python package (pip install ./crates/xbandsim-py, then pytest)"
# Ray (for xbandsim.distributed) has wheels for fewer platforms and Pythons than the rest.
# Where PyPI has none for this one, its tests are skipped with that reason; any other failure
# to install it (PyPI unreachable, which pip also reports as "no matching distribution", or a
# broken wheel) fails the run, and once installed the tests must import it.
ray_log=target/pip-ray.log
if "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r scripts/requirements-ray.txt >"$ray_log" 2>&1; then
  export XBANDSIM_RAY_REQUIRED=1
elif grep -q "No matching distribution found" "$ray_log" \
    && ! grep -qiE "Retrying|NewConnectionError|ProxyError|Could not fetch URL|Temporary failure in name resolution|Network is unreachable|timed out" "$ray_log"; then
  echo "xbandsim: PyPI has no Ray wheel for this platform or Python; the Ray tests will be skipped" >&2
  export XBANDSIM_RAY_UNAVAILABLE="PyPI has no wheel of scripts/requirements-ray.txt for this platform"
else
  cat "$ray_log" >&2
  exit 1
fi
# Stable-Baselines3 and torch (the environments through SB3, RadarDataset's torch tensors):
# the same rule as Ray's. Skipped only where PyPI has no torch wheel for this platform or
# Python; any other failure to install fails the run.
sb3_log=target/pip-sb3.log
if "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r scripts/requirements-sb3.txt >"$sb3_log" 2>&1; then
  export XBANDSIM_SB3_REQUIRED=1
elif grep -q "No matching distribution found" "$sb3_log" \
    && ! grep -qiE "Retrying|NewConnectionError|ProxyError|Could not fetch URL|Temporary failure in name resolution|Network is unreachable|timed out" "$sb3_log"; then
  echo "xbandsim: PyPI has no torch wheel for this platform or Python; the Stable-Baselines3 tests will be skipped" >&2
  export XBANDSIM_SB3_UNAVAILABLE="PyPI has no wheel of scripts/requirements-sb3.txt for this platform"
else
  cat "$sb3_log" >&2
  exit 1
fi
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
