"""The Python API over the Rust core: shapes, dtypes, determinism, scene sources, settings,
exceptions, the GIL released while rendering, and the dataset generator."""

import json
import threading
from pathlib import Path

import numpy as np
import pytest

import xbandsim

ROOT = Path(__file__).resolve().parents[3]
PAPER = ROOT / "scenes" / "paper.toml"

SMALL = """
[radar]
spokes = 90
max_range_m = 1500.0

[environment]
clutter = false

[[object]]
name = "buoy"
shape = "point"
rcs_m2 = 10.0
position_m = [0.0, 800.0, 2.0]
"""


def test_render_paper_scene_shapes_and_dtypes():
    sim = xbandsim.Simulation(PAPER)
    frame = sim.render(seed=0)
    assert frame.polar_db.dtype == np.float32
    assert frame.polar_db.shape == sim.polar_shape
    size = sim.image_size_px
    assert frame.ppi_db.shape == (size, size) and frame.ppi_db.dtype == np.float32
    assert frame.ppi_gray.shape == (size, size) and frame.ppi_gray.dtype == np.uint8
    assert frame.ppi_rgb.shape == (size, size, 3) and frame.ppi_rgb.dtype == np.uint8
    assert np.isnan(frame.ppi_db[0, 0]) and np.isfinite(frame.ppi_db[size // 2, size // 2])
    assert [o["name"] for o in frame.objects] == [o["name"] for o in frame.truth["objects"]]
    assert len(frame.objects) == 5
    assert frame.truth["spokes"] == frame.polar_db.shape[0]
    assert frame.iq is None and frame.doppler_cube_db is None


def test_same_seed_same_arrays_other_seed_other_noise():
    sim = xbandsim.Simulation(PAPER)
    a, b, c = sim.render(seed=3), sim.render(seed=3), sim.render(seed=4)
    assert np.array_equal(a.polar_db, b.polar_db)
    assert np.array_equal(a.ppi_rgb, b.ppi_rgb)
    assert a.truth == b.truth
    assert not np.array_equal(a.polar_db, c.polar_db)


def test_toml_text_dict_and_file_give_the_same_frame(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    from_file = xbandsim.Simulation(path).render(seed=1)
    from_text = xbandsim.Scene.from_toml(SMALL).simulation().render(seed=1)
    scene = {
        "radar": {"spokes": 90, "max_range_m": 1500.0},
        "environment": {"clutter": False},
        "object": [
            {"name": "buoy", "shape": "point", "rcs_m2": 10.0, "position_m": [0.0, 800.0, 2.0]}
        ],
    }
    from_dict = xbandsim.Scene.from_dict(scene).simulation().render(seed=1)
    assert np.array_equal(from_file.polar_db, from_text.polar_db)
    assert np.array_equal(from_file.polar_db, from_dict.polar_db)
    # The point target's echo (north, spoke 0) peaks at its slant range, far above the noise.
    sim = xbandsim.Simulation(path)
    truth = from_file.objects[0]
    spoke0 = from_file.polar_db[0]
    assert spoke0.max() > 20.0
    assert abs(np.argmax(spoke0) * sim.range_bin_m - truth["range_m"]) < 2 * sim.range_bin_m


def test_settings_change_the_scene():
    scene = xbandsim.Scene.from_toml(SMALL)
    changed = scene.with_settings({"radar.spokes": 45, "display.image_size_px": np.int64(128)})
    sim = changed.simulation()
    frame = sim.render()
    assert frame.polar_db.shape[0] == 45
    assert frame.ppi_gray.shape == (128, 128)
    # The original is untouched.
    assert scene.simulation().render().polar_db.shape[0] == 90


def test_iq_output():
    sim = xbandsim.Scene.from_toml(SMALL).simulation()
    frame = sim.render(iq=True, images=False)
    assert frame.ppi_gray is None and frame.ppi_rgb is None
    assert frame.iq.dtype == np.complex64 and frame.iq.shape[0] == 90
    assert frame.iq_pulses["spoke"].shape == (90,)
    assert frame.truth["iq"]["shape"] == list(frame.iq.shape)


def test_errors_name_the_field_and_the_file(tmp_path):
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        xbandsim.Scene.from_toml(SMALL).with_settings({"radar.pulse_width_us": -1.0}).simulation()
    assert e.value.field == "radar.pulse_width_us" and e.value.problem == "out of range"
    assert str(e.value).startswith("settings: ") and "-1" in str(e.value)
    assert isinstance(e.value, ValueError) and isinstance(e.value, xbandsim.XbandsimError)

    bad = tmp_path / "bad.toml"
    bad.write_text("[radar]\nspokes = \n")
    with pytest.raises(xbandsim.SceneSyntaxError) as e:
        xbandsim.Scene.from_file(bad)
    assert "bad.toml" in str(e.value)

    with pytest.raises(xbandsim.SceneSyntaxError) as e:
        xbandsim.Scene.from_toml(SMALL.replace('"point"', '"pyramid"'), name="mine.toml")
    assert "mine.toml" in str(e.value) and "pyramid" in str(e.value)

    with pytest.raises(xbandsim.XbandsimIOError):
        xbandsim.Simulation(tmp_path / "missing.toml")
    with pytest.raises(OSError):
        xbandsim.Scene.from_file(tmp_path / "missing.toml")

    with pytest.raises(xbandsim.SceneSyntaxError):
        xbandsim.Scene.from_dict({"radar": {"spokes": None}})
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        xbandsim.Simulation(PAPER).render(seed=-1)
    assert e.value.field == "seed" and e.value.problem == "out of range"


def test_threads_render_concurrently_with_the_gil_released():
    sim = xbandsim.Simulation(PAPER)
    want = sim.render(seed=5).polar_db
    results = {}

    def work(k):
        results[k] = sim.render(seed=5).polar_db

    threads = [threading.Thread(target=work, args=(k,)) for k in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(results[k], want) for k in range(3))


def test_dataset_generate(tmp_path):
    out = tmp_path / "ds"
    summary = xbandsim.dataset.generate(ROOT / "datasets" / "detection.toml", out, count=3, seed=2)
    assert summary == {"in_shard": 3, "skipped": 0, "made": 3, "missing": 0, "assembled": True}
    coco = json.loads((out / "annotations.json").read_text())
    assert len(coco["images"]) == 3
    again = xbandsim.dataset.generate(ROOT / "datasets" / "detection.toml", out, count=3, seed=2)
    assert again["skipped"] == 3 and again["made"] == 0
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        xbandsim.dataset.generate(ROOT / "datasets" / "detection.toml", tmp_path / "x", count=0)
    assert e.value.field == "count"
    with pytest.raises(xbandsim.DatasetMismatchError):
        xbandsim.dataset.generate(ROOT / "datasets" / "detection.toml", out, count=3, seed=9)


def test_version():
    assert xbandsim.__version__.count(".") == 2


def _items(ds):
    return [ds[i] for i in range(len(ds))]


def test_radar_dataset_folders_shards_and_on_the_fly_agree(tmp_path):
    spec = ROOT / "datasets" / "detection.toml"
    xbandsim.dataset.generate(spec, tmp_path / "dir", count=4, seed=5)
    xbandsim.dataset.generate(spec, tmp_path / "wds", count=4, seed=5, shard_samples=3)
    folders = xbandsim.data.RadarDataset(tmp_path / "dir", tensors=False)
    shards = xbandsim.data.RadarDataset(tmp_path / "wds", tensors=False)
    live = xbandsim.data.RadarDataset(spec, count=4, seed=5, tensors=False)
    assert len(folders) == len(shards) == len(live) == 4
    coco = json.loads((tmp_path / "dir" / "annotations.json").read_text())
    labelled = 0
    for (ia, ta), (ib, tb), (ic, tc) in zip(_items(folders), _items(shards), _items(live)):
        assert ia.dtype == np.float32 and ia.shape == (1, 512, 512)
        assert 0.0 <= ia.min() and ia.max() <= 1.0
        assert np.array_equal(ia, ib) and np.array_equal(ia, ic)
        for key in ("boxes", "labels", "area", "track_ids", "masks"):
            assert np.array_equal(ta[key], tb[key]) and np.array_equal(ta[key], tc[key]), key
        # The boxes are the dataset's COCO boxes (x, y, w, h -> x0, y0, x1, y1).
        image = next(im for im in coco["images"] if im["sample"] == ta["sample"])
        want = [a for a in coco["annotations"] if a["image_id"] == image["id"]]
        assert len(want) == len(ta["boxes"])
        for a, box, mask, area in zip(want, ta["boxes"], ta["masks"], ta["area"]):
            x, y, w, h = a["bbox"]
            assert list(box) == [x, y, x + w, y + h]
            # Each mask is the box's tight mask and holds `area` pixels.
            ys, xs = np.nonzero(mask)
            assert mask.sum() == area == a["area"]
            assert [xs.min(), ys.min(), xs.max() + 1, ys.max() + 1] == list(box)
            labelled += 1
    assert labelled > 0


def _render_in_child(index):
    spec = ROOT / "datasets" / "detection.toml"
    item = xbandsim.data.RadarDataset(spec, count=4, seed=5, tensors=False)[index]
    frame = xbandsim.Simulation(ROOT / "scenes" / "paper.toml").render(seed=1)
    return item[0].sum(), frame.polar_db.sum()


@pytest.mark.skipif(
    "fork" not in __import__("multiprocessing").get_all_start_methods(),
    reason="no fork() on this platform",
)
def test_rendering_in_a_process_forked_after_rendering():
    """A torch DataLoader worker is a fork of a process that has usually rendered already:
    the library's threads are not in the child, and rendering there must not wait for them
    (it did, forever, on rayon's global pool)."""
    import multiprocessing

    here = _render_in_child(1)  # the parent renders first, as a DataLoader's parent does
    ctx = multiprocessing.get_context("fork")
    with ctx.Pool(2) as pool:
        results = [pool.apply_async(_render_in_child, (1,)) for _ in range(2)]
        for r in results:
            assert r.get(timeout=120) == here


def test_radar_dataset_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        xbandsim.data.RadarDataset(tmp_path)
    with pytest.raises(xbandsim.InvalidArgumentError):
        xbandsim.data.RadarDataset(ROOT / "datasets" / "detection.toml")
    with pytest.raises(xbandsim.InvalidArgumentError):
        xbandsim.data.RadarDataset(tmp_path, image="infrared")
    ds = xbandsim.data.RadarDataset(ROOT / "datasets" / "detection.toml", count=1, tensors=False)
    with pytest.raises(IndexError):
        ds[1]
    with pytest.raises(ValueError):
        xbandsim._xbandsim.decode_rle("a b", 2, 2)


def test_radar_dataset_through_torch_dataloader_workers(tmp_path):
    """With torch installed, items are tensors and torch's DataLoader with worker processes
    (forked after the parent rendered) gives the NumPy path's arrays, from folders, tar shards
    and on the fly. Skipped without torch: scripts/test.sh does not install it (torch from
    PyPI brings several GB of CUDA libraries; docs/python.md says how it was checked)."""
    torch = pytest.importorskip("torch", reason="torch is not installed (docs/python.md)")
    from torch.utils.data import DataLoader

    spec = ROOT / "datasets" / "detection.toml"
    xbandsim.dataset.generate(spec, tmp_path / "dir", count=4, seed=5)
    xbandsim.dataset.generate(spec, tmp_path / "wds", count=4, seed=5, shard_samples=3)
    for source in (dict(source=tmp_path / "dir"), dict(source=tmp_path / "wds"),
                   dict(source=spec, count=4, seed=5)):
        want = _items(xbandsim.data.RadarDataset(tensors=False, **source))
        loader = DataLoader(
            xbandsim.data.RadarDataset(**source),
            batch_size=2,
            num_workers=2,
            collate_fn=lambda batch: tuple(zip(*batch)),
            timeout=120,
        )
        got = [item for images, targets in loader for item in zip(images, targets)]
        assert len(got) == len(want)
        for (image, target), (want_image, want_target) in zip(got, want):
            assert isinstance(image, torch.Tensor) and image.dtype == torch.float32
            assert np.array_equal(image.numpy(), want_image)
            for key in ("boxes", "labels", "masks", "area", "iscrowd", "track_ids"):
                assert isinstance(target[key], torch.Tensor), key
                assert np.array_equal(target[key].numpy(), want_target[key]), key


RECEIVER = SMALL.replace(
    "[[object]]",
    '[receiver]\nvideo_spokes = 256\nvideo_samples = 128\nstc = "auto"\n\n[[object]]',
)


def test_receiver_video_and_spoke_stream(tmp_path):
    """Frame.video is the receiver's video; the CLI's spokes.bin (bytes and packed) reads
    back with read_spokes as the same levels, one record a spoke, angles from north."""
    import subprocess

    path = tmp_path / "receiver.toml"
    path.write_text(RECEIVER)
    frame = xbandsim.Simulation(path).render(seed=2)
    assert frame.video.dtype == np.uint8 and frame.video.shape == (256, 128)
    assert frame.video.max() <= 15 and frame.truth["video"]["bits"] == 4
    assert xbandsim.render(tmp_path / "receiver.toml", seed=2).video is not None
    assert xbandsim.Simulation(PAPER).render().video is None
    cli = ROOT / "target" / "release" / "xbandsim"
    if not cli.exists():
        pytest.skip("the CLI is not built (scripts/test.sh builds it)")
    for packing in ["bytes", "packed"]:
        out = tmp_path / packing
        subprocess.run(
            [str(cli), "render", str(path), "--out", str(out), "--seed", "2",
             "--spoke-format", packing],
            check=True, capture_output=True,
        )
        video = np.load(out / "video.npy")
        assert np.array_equal(video, frame.video)
        stream = xbandsim.read_spokes(out / "spokes.bin")
        assert stream["spokes_per_revolution"] == 256
        assert np.array_equal(stream["levels"], video)
        assert np.allclose(stream["angle_deg"], np.arange(256) * 360.0 / 256)
        assert stream["heading_deg"] is None
        assert set(stream["bits"]) == {4}
        assert np.allclose(stream["range_m"], 1500.0)
    with pytest.raises(xbandsim.XbandsimError):
        xbandsim.read_spokes(out / "video.npy")
