"""Render one frame of an example scene and plot it with matplotlib: the PPI in dB with each
object's label box, and the polar (B-scope) record.

    python examples/render_frame.py                         # scenes/paper.toml -> out/render_frame.png
    python examples/render_frame.py scenes/sea-state-4-rain.toml --out out/rain.png --show
"""

from __future__ import annotations

import argparse
import os
import sys

import matplotlib

if "--show" not in sys.argv:
    matplotlib.use("Agg")  # headless: write the figure only
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

import xbandsim


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="scenes/paper.toml")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="out/render_frame.png")
    parser.add_argument("--show", action="store_true", help="open a window as well")
    args = parser.parse_args(argv)

    sim = xbandsim.Simulation(args.scene)
    frame = sim.render(seed=args.seed)
    truth = frame.truth

    fig, (ax_ppi, ax_polar) = plt.subplots(1, 2, figsize=(13, 6))
    im = ax_ppi.imshow(frame.ppi_db, cmap="viridis", vmin=0, vmax=60)
    for obj in frame.objects:
        box = obj.get("ppi_box_px")
        if box is None:  # nothing to see: the object keeps its flag, not a box
            continue
        x0, y0, x1, y1 = box
        ax_ppi.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, color="red", lw=1))
        ax_ppi.text(x0, y0 - 3, f"{obj['name']} ({obj['visibility']})", color="red", fontsize=7)
    ax_ppi.set_title(f"PPI, dB over noise ({os.path.basename(args.scene)})")
    ax_ppi.set_axis_off()
    fig.colorbar(im, ax=ax_ppi, fraction=0.046)

    spokes, bins = frame.polar_db.shape
    extent = [0, bins * truth["range_bin_m"], 360, 0]
    ax_polar.imshow(frame.polar_db, aspect="auto", cmap="viridis", vmin=0, vmax=60, extent=extent)
    ax_polar.set_xlabel("range, m")
    ax_polar.set_ylabel("azimuth, deg")
    ax_polar.set_title(f"polar record: {spokes} spokes x {bins} bins")

    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"wrote {args.out}: {len(frame.objects)} objects, "
          f"peak {np.nanmax(frame.ppi_db):.1f} dB over noise")
    if args.show:
        plt.show()
    return 0


if __name__ == "__main__":
    sys.exit(main())
