"""Generate a small labelled dataset and draw its boxes and masks over the images.

    python examples/dataset_boxes.py                     # 8 samples of datasets/detection.toml
    python examples/dataset_boxes.py --spec datasets/clutter.toml --count 16 --out out/clutter

Writes the dataset (xbandsim.dataset.generate, the same bytes as `xbandsim dataset`), reads it
back with xbandsim.data.RadarDataset (torchvision's detection convention) and saves a sheet of
the first samples with their boxes (red) and masks (tinted) to OUT/boxes.png.
"""

from __future__ import annotations

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

import xbandsim
from xbandsim.data import RadarDataset


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spec", default="datasets/detection.toml")
    parser.add_argument("--count", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="out/example-dataset")
    args = parser.parse_args(argv)

    summary = xbandsim.dataset.generate(args.spec, args.out, count=args.count, seed=args.seed)
    print(f"dataset in {args.out}: {summary}")
    ds = RadarDataset(args.out, tensors=False)
    shown = min(len(ds), 8)
    cols = 4
    rows = (shown + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 4 * rows), squeeze=False)
    boxes_drawn = 0
    for i, ax in enumerate(axes.flat):
        ax.set_axis_off()
        if i >= shown:
            continue
        image, target = ds[i]
        gray = image[0]
        ax.imshow(gray, cmap="gray", vmin=0, vmax=1)
        if len(target["masks"]):
            union = np.any(target["masks"].astype(bool), axis=0)
            ax.imshow(np.ma.masked_where(~union, union), cmap="autumn", alpha=0.35)
        for (x0, y0, x1, y1), label in zip(target["boxes"], target["labels"]):
            ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, color="red", lw=1))
            boxes_drawn += 1
        ax.set_title(f"sample {target['sample']}: {len(target['boxes'])} boxes", fontsize=9)
    fig.tight_layout()
    path = os.path.join(args.out, "boxes.png")
    fig.savefig(path, dpi=80)
    print(f"wrote {path}: {shown} samples, {boxes_drawn} boxes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
