#!/usr/bin/env bash
# The README's first command: sets up everything on a fresh machine and runs the main job on
# an example. Needs Rust >= 1.89 (rustup) and python3 with venv; crates come from crates.io and
# Python packages from PyPI.
#   1. builds the `xbandsim` command line and renders the paper's 5-target scene into out/
#      (ppi.png, ppi_gray.png, polar.npy, truth.json);
#   2. installs the Python package with its Gymnasium environments, what the scripts in
#      examples/ need (matplotlib) and the dataset readers (webdataset, Pillow, pycocotools)
#      into .venv (pip builds the Rust extension with maturin; the extras gym, examples and
#      data of crates/xbandsim-py/pyproject.toml) and takes one step of
#      xbandsim/Detection-v0 to show it works. Ray (xbandsim.distributed) is the [ray] extra,
#      not installed here: pip install "./crates/xbandsim-py[ray]".
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/cpu-level.sh

echo "== building xbandsim and rendering scenes/paper.toml into out/"
cargo build --release -p xbandsim-cli
target/release/xbandsim render scenes/paper.toml --out out/

echo "== installing the Python package (xbandsim[gym,examples,data]) into .venv"
venv="${XBANDSIM_VENV:-.venv}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "./crates/xbandsim-py[gym,examples,data]"
"$venv/bin/python" - <<'PY'
import gymnasium as gym
import xbandsim

frame = xbandsim.Simulation("scenes/paper.toml").render(seed=0)
print(f"xbandsim {xbandsim.__version__}: paper scene {frame.polar_db.shape[0]} spokes x "
      f"{frame.polar_db.shape[1]} bins, {len(frame.objects)} objects")
env = gym.make("xbandsim/Detection-v0")
obs, info = env.reset(seed=0)
obs, reward, terminated, truncated, info = env.step(xbandsim.envs.action_vector())
print(f"xbandsim/Detection-v0: observation {obs.shape} {obs.dtype}, reward {reward:.2f}, "
      f"{info['targets_detected']} of {info['targets_observed']} targets detected")
PY
echo "done: out/ holds the rendered frame; activate the Python package with: source $venv/bin/activate"
