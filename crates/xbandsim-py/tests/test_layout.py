"""The Python package takes a dataset folder's layout from Rust (the dataset crate's
``layout``, through the binding): sample folders, shard and member names, which samples a
shard holds, the label members' byte ranges and the manifests' sha256 checks are the
generator's own, checked here against what the generator wrote."""

import json
import os
import shutil
import tarfile
from pathlib import Path

import pytest

import xbandsim
from xbandsim import _xbandsim, data, distributed
from xbandsim.errors import XbandsimIOError

ROOT = Path(__file__).resolve().parents[3]
DETECTION = ROOT / "datasets" / "detection.toml"
TRACKING = ROOT / "datasets" / "tracking.toml"  # sequences of 8 frames


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """Detection in folders and in tar shards of 2 (5 samples: shards of 2, 2 and 1),
    tracking sequences in tar shards of 1."""
    root = tmp_path_factory.mktemp("layout")
    xbandsim.dataset.generate(DETECTION, root / "dir", 3, seed=2, jobs=1)
    xbandsim.dataset.generate(DETECTION, root / "wds", 5, seed=2, jobs=1, shard_samples=2)
    xbandsim.dataset.generate(TRACKING, root / "seq", 2, seed=2, jobs=1, shard_samples=1)
    return root


def test_the_names_are_where_the_generator_writes(made):
    assert _xbandsim.sample_dir(42) == "samples/000000/000000042"
    assert _xbandsim.sample_dir(1234) == "samples/000001/000001234"
    assert _xbandsim.sample_indices(str(made / "dir")) == [0, 1, 2]
    for i in range(3):
        assert (made / "dir" / _xbandsim.sample_dir(i) / "files.sha256").is_file()
    for name, count, per in (("wds", 5, 2), ("seq", 2, 1)):
        folder = made / name
        shards = _xbandsim.shard_count(count, per)
        expected = {f"shards/{f}" for f in os.listdir(folder / "shards")}
        assert expected == {
            f(t) for t in range(shards) for f in (_xbandsim.shard_file, _xbandsim.shard_manifest_file)
        }
        record = json.loads((folder / _xbandsim.RECORD_FILE).read_text())
        assert _xbandsim.read_record(str(folder)) == {
            "count": record["count"],
            "frames": record["frames_per_sample"],
            "seed": record["seed"],
            "shard_samples": record["samples_per_shard"],
            "cli_args": f" --format webdataset --shard-samples {per}",
        }
        for t in range(shards):
            tar_name = _xbandsim.shard_file(t)
            assert _xbandsim.parse_shard_file_name(os.path.basename(tar_name)) == t
            first, end = _xbandsim.shard_samples(t, per, count)
            with tarfile.open(folder / tar_name) as tar:
                for m in tar.getmembers():
                    index, rel = _xbandsim.parse_member_name(m.name)
                    assert first <= index < end
                    assert _xbandsim.member_name(index, rel) == m.name
                    assert m.name == f"{_xbandsim.sample_key(index)}.{_xbandsim.member_extension(rel)}"
                    if record["frames_per_sample"] > 1 and rel not in ("scene.toml", "baseline.json"):
                        frame = _xbandsim.frame_of(rel)
                        assert rel == _xbandsim.frame_file(8, frame, rel.split("/", 1)[1])
    assert _xbandsim.read_record(str(made / "dir"))["shard_samples"] is None
    assert _xbandsim.index_files() == [
        "annotations.json", "targets.jsonl", "baseline.jsonl", "yolo/data.yaml",
        "yolo_obb/data.yaml", "README.md",
    ]
    assert _xbandsim.index_files(2)[-1] == _xbandsim.CARD_FILE == "README.md"
    assert _xbandsim.parse_member_name("README.md") is None
    assert _xbandsim.coco_image_id(1, 8, 3) == 12
    with pytest.raises(XbandsimIOError):
        _xbandsim.read_record(str(made / "nowhere"))


def test_label_ranges_and_member_checks_are_the_manifests(made, tmp_path):
    folder = made / "seq"
    manifest = str(folder / _xbandsim.shard_manifest_file(1))
    ranges = _xbandsim.shard_label_ranges(manifest)
    with tarfile.open(folder / _xbandsim.shard_file(1)) as tar:
        labels = [m for m in tar.getmembers()
                  if m.name.endswith((".coco.json", ".targets.jsonl", ".baseline.json"))]
        assert ranges == [(m.name, m.offset_data, m.offset_data + m.size) for m in labels]
        assert len(ranges) == 17  # 8 frames, two label files each, and the sample's baseline
    blob = (folder / _xbandsim.shard_file(1)).read_bytes()
    read = [(name, blob[start:end]) for name, start, end in ranges]
    assert _xbandsim.check_shard_members(manifest, read) is None
    name, data_ = read[3]
    flipped = bytes([data_[0] ^ 1]) + data_[1:]
    assert _xbandsim.check_shard_members(manifest, [(name, flipped)]) == (
        f"{name}: differs from the manifest"
    )
    assert _xbandsim.check_shard_members(manifest, [("000000099.coco.json", b"")]) == (
        "000000099.coco.json: not in the manifest"
    )
    broken = tmp_path / "broken.manifest.json"
    broken.write_text("{")
    with pytest.raises(XbandsimIOError):
        _xbandsim.shard_label_ranges(str(broken))


def test_python_readers_and_the_ray_helpers_ask_rust(made, monkeypatch):
    """What data.py and distributed.py produce equals the Rust functions' results, and comes
    from them: a binding function replaced shows in what the Python side does."""
    assert distributed._shard_sizes(5, 2) == [2, 2, 1]
    assert distributed._shard_sizes(4, 2) == [2, 2]
    row = distributed._webdataset_row({"index": 42, "files": {"frame_0003/ppi.png": b"x"}})
    assert row == {"__key__": "000000042", "frame_0003.ppi.png": b"x"}
    assert f"{row['__key__']}.frame_0003.ppi.png" == _xbandsim.member_name(42, "frame_0003/ppi.png")

    asked = []
    for name in ("parse_member_name", "parse_shard_file_name", "sample_indices", "read_record"):
        real = getattr(_xbandsim, name)
        monkeypatch.setattr(
            _xbandsim, name, lambda *a, _real=real, _name=name: (asked.append(_name), _real(*a))[1]
        )
    shards = data.RadarDataset(made / "wds", tensors=False, masks=False)
    folders = data.RadarDataset(made / "dir", tensors=False, masks=False)
    assert len(shards) == 5 and len(folders) == 3
    assert set(asked) == {"parse_member_name", "parse_shard_file_name", "sample_indices", "read_record"}

    # A sequence's items: frame folders and image ids as Rust names and numbers them.
    seq = data.RadarDataset(made / "seq", tensors=False, masks=False)
    assert len(seq) == 2 * 8
    _, target = seq[8 + 5]
    assert (target["sample"], target["frame"]) == (1, 5)
    assert target["image_id"] == _xbandsim.coco_image_id(1, 8, 5)


def test_the_url_assembly_reads_label_members_where_rust_says(made, tmp_path):
    """The driver's assembly for a URL (``_assemble_at_url``, with fsspec's local file
    system): the index files are a single run's, and a label member that differs from its
    manifest is refused with the manifest check's words."""
    fsspec = pytest.importorskip("fsspec")
    shards = tmp_path / "shards-only"
    xbandsim.dataset.generate(DETECTION, shards, 5, seed=2, jobs=1, shard_samples=2, assemble=False)
    assert not (shards / "annotations.json").exists()
    url = f"file://{shards}"
    fs, root = fsspec.core.url_to_fs(url)
    assert distributed._assemble_at_url(fs, root, url, str(DETECTION), 5, 2, 2) == 0
    for f in _xbandsim.index_files(2):
        assert (shards / f).read_bytes() == (made / "wds" / f).read_bytes(), f

    corrupt = tmp_path / "corrupt"
    shutil.copytree(shards, corrupt)
    tar = corrupt / _xbandsim.shard_file(2)
    name, start, _ = _xbandsim.shard_label_ranges(str(corrupt / _xbandsim.shard_manifest_file(2)))[0]
    blob = bytearray(tar.read_bytes())
    blob[start] ^= 1
    tar.write_bytes(bytes(blob))
    url = f"file://{corrupt}"
    fs, root = fsspec.core.url_to_fs(url)
    with pytest.raises(XbandsimIOError, match=f"{name}: differs from the manifest"):
        distributed._assemble_at_url(fs, root, url, str(DETECTION), 5, 2, 2)
