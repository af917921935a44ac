#!/usr/bin/env python3
"""Checks a dataset made by `xbandsim dataset` with a real COCO client (docs/formats.md,
"Dataset labels"): annotations.json loads in pycocotools; every mask decodes to its `area`
and its box is the mask's tight box; COCOeval of the annotations scored against
themselves gives AP = 1.0 for boxes and masks; the YOLO detect lines are the COCO boxes.
A dataset in WebDataset shards is read with the webdataset package: every sample of
every shard, with its files under one key.

Usage: check_labels.py DATASET_DIR   (exit status 1 on any failure)
"""
import contextlib
import io
import os
import sys

import glob
import json

import numpy as np
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval


def main(root):
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO(os.path.join(root, "annotations.json"))
    anns = gt.loadAnns(gt.getAnnIds())
    if not anns:
        raise SystemExit("no annotations: nothing to check")
    for a in anns:
        m = gt.annToMask(a)
        assert int(m.sum()) == a["area"], (a["id"], int(m.sum()), a["area"])
        ys, xs = np.nonzero(m)
        x, y, w, h = a["bbox"]
        # The box is the mask's tight box (pixel edges).
        assert [xs.min(), ys.min(), xs.max() + 1, ys.max() + 1] == [x, y, x + w, y + h], a["id"]
    results = []
    for kind in ("bbox", "segm"):
        dets = [
            dict(image_id=a["image_id"], category_id=a["category_id"], bbox=a["bbox"],
                 segmentation=a["segmentation"], score=1.0)
            for a in anns
        ]
        with contextlib.redirect_stdout(io.StringIO()):
            e = COCOeval(gt, gt.loadRes(dets), kind)
            e.evaluate()
            e.accumulate()
            e.summarize()
        ap = float(e.stats[0])
        assert ap == 1.0, f"{kind} AP {ap}"
        results.append(f"{kind} AP {ap:.3f}")
    # WebDataset shards through the webdataset reader: samples keyed by index.
    shards = sorted(glob.glob(os.path.join(root, "shards", "*.tar")))
    members = {}
    if shards:
        import webdataset as wds

        for sample in wds.WebDataset(shards, shardshuffle=False):
            for ext, value in sample.items():
                if not ext.startswith("__"):
                    members[f"{sample['__key__']}.{ext}"] = value
        record = json.load(open(os.path.join(root, "dataset.json")))
        keys = {m.split(".")[0] for m in members}
        assert len(keys) == record["count"], (len(keys), record["count"])
        results.append(f"{len(shards)} shards read by webdataset")
    # YOLO detect lines are the COCO boxes, normalised.
    n_yolo = 0
    for img in gt.loadImgs(gt.getImgIds()):
        if "shard" in img:
            name = img["file_name"].replace("ppi_gray.png", "yolo.txt").replace("ppi.png", "yolo.txt")
            assert img["file_name"] in members, img["file_name"]
            text = members[name].decode()
        else:
            text = open(os.path.join(root, os.path.dirname(img["file_name"]), "yolo.txt")).read()
        lines = [l.split() for l in text.splitlines()]
        boxes = [a["bbox"] for a in gt.loadAnns(gt.getAnnIds(imgIds=[img["id"]]))]
        assert len(lines) == len(boxes), img["file_name"]
        for l, (x, y, w, h) in zip(lines, boxes):
            s = img["width"]
            got = [float(v) for v in l[1:]]
            want = [(x + w / 2) / s, (y + h / 2) / s, w / s, h / s]
            assert max(abs(g - t) for g, t in zip(got, want)) < 2e-6, (l, want)
            n_yolo += 1
    print(f"{root}: {len(gt.getImgIds())} images, {len(anns)} annotations; "
          f"{', '.join(results)}; {n_yolo} YOLO lines match the COCO boxes")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    main(sys.argv[1])
