"""RadarDataset against the dataset's own index files: its image ids are annotations.json's
(perfect predictions score AP 1.0 in pycocotools' COCOeval: single frames and sequences,
folders and tar shards, a count= subset and on the fly); an unfinished dataset is said to
be one; the tar shards read with the webdataset library as docs/python.md shows."""

import contextlib
import glob
import io
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import xbandsim
from xbandsim.data import RadarDataset

ROOT = Path(__file__).resolve().parents[3]
DETECTION = ROOT / "datasets" / "detection.toml"
TRACKING = ROOT / "datasets" / "tracking.toml"  # sequences of 8 frames
REAL_RADAR = ROOT / "datasets" / "real-radar.toml"  # artefacts labelled beside the targets


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """Small datasets: detection in folders and in tar shards, tracking sequences (8 frames a
    sample) in folders and in tar shards."""
    root = tmp_path_factory.mktemp("data")
    runs = {
        "detection": (DETECTION, 5, {}),
        "detection-shards": (DETECTION, 5, {"shard_samples": 2}),
        "tracking": (TRACKING, 3, {}),
        "tracking-shards": (TRACKING, 3, {"shard_samples": 2}),
    }
    for name, (spec, count, kw) in runs.items():
        xbandsim.dataset.generate(spec, root / name, count, seed=4, **kw)
    return root


def _ap(annotations, ds, kind):
    """COCOeval's AP of ``ds``'s ground truth, given as predictions with score 1, against
    ``annotations`` (annotations.json), over the images ``ds`` holds."""
    from pycocotools import mask as mask_utils
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO(str(annotations))
    predictions, ids = [], []
    for i in range(len(ds)):
        _, target = ds[i]
        ids.append(target["image_id"])
        for box, label, mask in zip(target["boxes"], target["labels"], target["masks"]):
            x0, y0, x1, y1 = (float(v) for v in box)
            rle = mask_utils.encode(np.asfortranarray(np.asarray(mask, dtype=np.uint8)))
            rle["counts"] = rle["counts"].decode()
            predictions.append(
                dict(image_id=int(target["image_id"]), category_id=int(label),
                     bbox=[x0, y0, x1 - x0, y1 - y0], segmentation=rle, score=1.0)
            )
    assert predictions, "no labelled object to score"
    with contextlib.redirect_stdout(io.StringIO()):
        e = COCOeval(gt, gt.loadRes(predictions), kind)
        e.params.imgIds = sorted(ids)
        e.evaluate()
        e.accumulate()
        e.summarize()
    return float(e.stats[0]), ids


@pytest.mark.parametrize("name", ["detection", "detection-shards", "tracking", "tracking-shards"])
def test_ground_truth_through_radar_dataset_scores_ap_1_against_annotations_json(made, name):
    folder = made / name
    ds = RadarDataset(folder, tensors=False)
    coco = json.loads((folder / "annotations.json").read_text())
    assert len(ds) == len(coco["images"])
    for kind in ("bbox", "segm"):
        ap, ids = _ap(folder / "annotations.json", ds, kind)
        assert ap == pytest.approx(1.0, abs=1e-9), (name, kind, ap)
    # Every item names the COCO image of its own sample and frame.
    images = {im["id"]: im for im in coco["images"]}
    for i in (0, len(ds) - 1):
        _, target = ds[i]
        image = images[target["image_id"]]
        assert (image["sample"], image["frame"]) == (target["sample"], target["frame"])


def test_artefact_labels_come_through_radar_dataset_marked_and_without_tracks(tmp_path):
    """datasets/real-radar.toml labels its artefacts: RadarDataset gives them with
    ``artefacts`` True and ``track_ids`` -1 (COCO's null), in the artefact categories, their
    masks decoded; the ground truth, artefacts included, scores AP 1.0 for boxes and masks."""
    folder = tmp_path / "real-radar"
    xbandsim.dataset.generate(REAL_RADAR, folder, 3, seed=4)
    coco = json.loads((folder / "annotations.json").read_text())
    names = {c["id"]: c["name"] for c in coco["categories"]}
    ds = RadarDataset(folder, tensors=False)
    seen = 0
    for i in range(len(ds)):
        _, target = ds[i]
        for label, track, artefact, mask in zip(
            target["labels"], target["track_ids"], target["artefacts"], target["masks"]
        ):
            assert names[int(label)].startswith("artefact_") == bool(artefact)
            assert (track == -1) == bool(artefact)
            assert mask.any()
            seen += bool(artefact)
    assert seen > 0
    for kind in ("bbox", "segm"):
        ap, _ = _ap(folder / "annotations.json", ds, kind)
        assert ap == pytest.approx(1.0, abs=1e-9), (kind, ap)


def test_a_count_subset_and_on_the_fly_items_keep_the_datasets_image_ids(made):
    for name, spec, count in (("detection", DETECTION, 5), ("tracking", TRACKING, 2)):
        annotations = made / name / "annotations.json"
        subset = RadarDataset(made / name, count=2, tensors=False)
        ap, ids = _ap(annotations, subset, "bbox")
        assert ap == pytest.approx(1.0, abs=1e-9), (name, ap)
        live = RadarDataset(spec, count=count, seed=4, tensors=False)
        ap, live_ids = _ap(annotations, live, "bbox")
        assert ap == pytest.approx(1.0, abs=1e-9), (name, ap)
        stored = RadarDataset(made / name, tensors=False)
        assert live_ids == [stored[i][1]["image_id"] for i in range(len(live))]
    # The numbering: sample index x frames per sample + frame + 1, as the assembler's.
    _, target = RadarDataset(made / "tracking", tensors=False)[8 + 3]
    assert (target["sample"], target["frame"], target["image_id"]) == (1, 3, 1 * 8 + 3 + 1)


def _no_warning(source):
    with warnings.catch_warnings():
        warnings.simplefilter("error", xbandsim.IncompleteDatasetWarning)
        return RadarDataset(source, tensors=False)


def test_an_unfinished_dataset_is_said_to_be_one(tmp_path):
    """Shard 0 of 2 alone (samples 0 and 2 of 4, no index files), then the whole run: the
    dataset class warns, naming the folder, what is missing and how to finish it, until
    the dataset is complete."""
    out = tmp_path / "half"
    xbandsim.dataset.generate(DETECTION, out, 4, seed=1, shard="0/2")
    with pytest.warns(xbandsim.IncompleteDatasetWarning) as caught:
        ds = RadarDataset(out, tensors=False)
    message = str(caught[0].message)
    assert str(out) in message
    assert "2 of its 4 samples are missing" in message
    assert "annotations.json" in message and "README.md" in message
    assert f"xbandsim dataset SPEC --out {out} --count 4 --seed 1" in message
    assert "again" in message
    assert caught[0].filename == __file__  # pointed at the caller's line
    assert len(ds) == 2  # what is there is read
    xbandsim.dataset.generate(DETECTION, out, 4, seed=1)
    assert len(_no_warning(out)) == 4

    # Every sample, but the index files left to a later run.
    out = tmp_path / "unassembled"
    xbandsim.dataset.generate(DETECTION, out, 2, seed=1, assemble=False)
    with pytest.warns(xbandsim.IncompleteDatasetWarning, match="index files are not written"):
        RadarDataset(out, tensors=False)

    # Tar shards: one shard of three made.
    out = tmp_path / "shards"
    xbandsim.dataset.generate(DETECTION, out, 5, seed=1, shard_samples=2, shard="0/3")
    with pytest.warns(xbandsim.IncompleteDatasetWarning) as caught:
        RadarDataset(out, tensors=False)
    message = str(caught[0].message)
    assert "3 of its 5 samples are missing" in message
    assert "--format webdataset --shard-samples 2" in message
    xbandsim.dataset.generate(DETECTION, out, 5, seed=1, shard_samples=2)
    assert len(_no_warning(out)) == 5


def test_the_data_extra_installs_what_the_shard_reader_needs():
    from test_examples import _extras

    _, extras = _extras()
    assert {"webdataset", "pillow", "pycocotools"} <= extras["data"]


def test_tar_shards_read_with_webdataset_as_the_docs_show(made):
    """The reading loop of docs/python.md ("Reading the tar shards with webdataset"): every
    sample under its key, the PNG decoded (by Pillow) to the pixels RadarDataset reads, the
    labels as dicts, the polar record as an array."""
    import webdataset as wds

    folder = made / "detection-shards"
    shards = sorted(glob.glob(str(folder / "shards" / "shard-*.tar")))
    assert len(shards) == 3
    reference = RadarDataset(folder, tensors=False, masks=False)
    seen = 0
    for sample in wds.WebDataset(shards, shardshuffle=False).decode("l8"):
        image = sample["ppi_gray.png"]           # uint8 (512, 512), decoded by Pillow
        coco = sample["coco.json"]               # the sample's COCO fragment, a dict
        polar = sample["polar.npy"]              # float32 (spokes, range bins)
        index = int(sample["__key__"])
        pixels, target = reference[index]
        assert image.dtype == np.uint8 and image.shape == (512, 512)
        assert np.array_equal(image.astype(np.float32) / 255.0, pixels[0])
        assert len(coco["annotations"]) == len(target["boxes"])
        assert polar.dtype == np.float32 and polar.ndim == 2
        seen += 1
    assert seen == 5


def test_tensors_without_torch_say_how_to_install_it(monkeypatch):
    """tensors=True where torch cannot be imported names the extra that installs it."""
    import sys

    from xbandsim.data import RadarDataset

    monkeypatch.setitem(sys.modules, "torch", None)  # `import torch` raises ImportError
    with pytest.raises(ImportError, match=r"xbandsim-py\[torch\]"):
        RadarDataset(ROOT / "datasets" / "detection.toml", count=1, tensors=True)
    assert RadarDataset(ROOT / "datasets" / "detection.toml", count=1).tensors is False
