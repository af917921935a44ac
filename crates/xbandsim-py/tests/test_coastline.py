"""scripts/coastline.py: real coastline data to land polygons and a scene (docs/coastlines.md),
from a saved GMT dump of the GSHHG shorelines and from an OpenStreetMap-style GeoJSON export;
and the two real example scenes made with it."""

import importlib.util
import json
import subprocess
import sys

import pytest
import xbandsim

from conftest import ROOT

SCRIPT = ROOT / "scripts" / "coastline.py"
DUMP = ROOT / "scripts" / "testdata" / "plymouth-sound-gmt-coast.txt"


def load_script():
    spec = importlib.util.spec_from_file_location("coastline", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(args, cwd):
    return subprocess.run([sys.executable, str(SCRIPT), *args], cwd=cwd, capture_output=True, text=True)


def polygons(path):
    return [f["geometry"]["coordinates"][0] for f in json.loads(path.read_text())["features"]]


def test_gshhg_dump_becomes_land_that_knows_sea_from_land(tmp_path):
    out = tmp_path / "plymouth"
    r = run(["gshhg", "--region=-4.26/-4.04/50.27/50.39", "--origin=-4.15,50.318", "--dump", str(DUMP), "--out", str(out)], tmp_path)
    assert r.returncode == 0, r.stderr
    assert "5 coast polygons" in r.stdout
    coast = load_script()
    rings = polygons(out / "coast.geojson")
    on_land = lambda lon, lat: any(coast.inside((lon, lat), [tuple(p) for p in ring]) for ring in rings)
    # Rame Head and Plymouth Hoe are land; the Channel south of the breakwater, the Sound
    # north of it and the Hamoaze are water; the breakwater itself is an island.
    assert on_land(-4.222, 50.318) and on_land(-4.135, 50.370)
    assert not on_land(-4.15, 50.29) and not on_land(-4.15, 50.345)
    assert on_land(-4.149, 50.3321)
    # Every ring is counter-clockwise (land on the left) and closed.
    for ring in rings:
        assert ring[0] == ring[-1] and coast.signed_area([tuple(p) for p in ring[:-1]]) > 0
    # The scene it wrote loads and shows land.
    frame = xbandsim.Simulation(out / "scene.toml").render(seed=1)
    assert frame.land_mask is not None and frame.land_mask.sum() > 100
    assert len(frame.truth["land"]["polygons"]) == 5
    assert frame.land_mask.shape == frame.polar_db.shape
    assert set(frame.land_polygon[frame.land_mask == 1]) <= set(range(5))


def test_an_origin_on_land_and_bad_regions_are_refused(tmp_path):
    r = run(["gshhg", "--region=-4.26/-4.04/50.27/50.39", "--origin=-4.222,50.318", "--dump", str(DUMP), "--out", str(tmp_path / "o")], tmp_path)
    assert r.returncode == 2 and "is on land" in r.stderr and "--origin" in r.stderr
    r = run(["gshhg", "--region=-4.04/-4.26/50.27/50.39", "--dump", str(DUMP), "--out", str(tmp_path / "o")], tmp_path)
    assert r.returncode == 2 and "west < east" in r.stderr
    missing = tmp_path / "no-such-dump.txt"
    r = run(["gshhg", "--region=-4.26/-4.04/50.27/50.39", "--dump", str(missing), "--out", str(tmp_path / "o")], tmp_path)
    assert r.returncode == 2 and f"{missing}: No such file" in r.stderr and "Traceback" not in r.stderr


OSM = {
    "type": "FeatureCollection",
    "features": [
        # The coast as two ways (land on the left: walking west to east, land to the north).
        {"type": "Feature", "properties": {"natural": "coastline"},
         "geometry": {"type": "LineString", "coordinates": [[9.90, 60.005], [10.0, 60.006]]}},
        {"type": "Feature", "properties": {"natural": "coastline"},
         "geometry": {"type": "LineString", "coordinates": [[10.0, 60.006], [10.1, 60.004]]}},
        {"type": "Feature", "properties": {"man_made": "breakwater", "name": "Mole"},
         "geometry": {"type": "LineString", "coordinates": [[10.0, 60.006], [10.0, 60.0], [10.003, 59.998]]}},
        {"type": "Feature", "properties": {"building": "yes", "building:levels": "4"},
         "geometry": {"type": "Polygon", "coordinates": [[[10.01, 60.008], [10.011, 60.008], [10.011, 60.0085], [10.01, 60.0085], [10.01, 60.008]]]}},
        {"type": "Feature", "properties": {"place": "islet"},
         "geometry": {"type": "Polygon", "coordinates": [[[9.98, 59.99], [9.985, 59.99], [9.985, 59.993], [9.98, 59.99]]]}},
    ],
}


def test_an_openstreetmap_export_becomes_coast_breakwaters_and_buildings(tmp_path):
    src = tmp_path / "export.geojson"
    src.write_text(json.dumps(OSM))
    out = tmp_path / "osm"
    r = run(["osm", str(src), "--region=9.95/10.05/59.97/60.03", "--origin=10.0,59.99", "--out", str(out)], tmp_path)
    assert r.returncode == 0, r.stderr
    assert "2 coast polygons, 2 breakwaters polygons, 0 piers polygons, 1 buildings polygons" in r.stdout
    coast = load_script()
    rings = polygons(out / "coast.geojson")
    on_land = lambda lon, lat: any(coast.inside((lon, lat), [tuple(p) for p in ring]) for ring in rings)
    assert on_land(10.0, 60.02) and not on_land(10.0, 59.995) and on_land(9.983, 59.9905)
    buildings = json.loads((out / "buildings.geojson").read_text())["features"]
    assert buildings[0]["properties"]["height_m"] == 12.0
    moles = json.loads((out / "breakwaters.geojson").read_text())["features"]
    assert all(m["properties"]["name"] == "Mole" and m["properties"]["height_m"] == 4.0 for m in moles)
    frame = xbandsim.Simulation(out / "scene.toml").render(seed=2)
    names = [p["name"] for p in frame.truth["land"]["polygons"]]
    assert "Mole" in names and frame.land_mask.sum() > 0
    # The building is a structure: an object of class "building" listed in land.structures.
    assert "[[structure]]" in (out / "scene.toml").read_text()
    [structure] = frame.truth["land"]["structures"]
    assert frame.truth["objects"][structure["id"]]["class"] == "building"
    assert (frame.structure_mask == structure["id"]).sum() == structure["cells"]


@pytest.mark.parametrize("name", ["drobak-sound", "plymouth-sound"])
def test_the_real_example_scenes_render_with_their_land_and_vessels(name):
    scene = ROOT / "scenes" / "real" / name / "scene.toml"
    frame = xbandsim.Simulation(scene).render(seed=0)
    assert frame.land_mask.sum() > 1000
    objects = frame.objects
    assert len(objects) >= 6
    assert all(o["distance_to_coast_m"] > 0 for o in objects)
    classes = {o["class"] for o in objects}
    assert {"buoy", "ship"} <= classes
    moving = [o for o in objects if o["speed_kn"] > 0.5]
    assert moving, "each example has moving vessels"
    assert (ROOT / "scenes" / "real" / name / "ATTRIBUTION.md").exists()


def test_the_gshhg_command_of_the_docs_runs_as_written(repo_root):
    """docs/coastlines.md's GSHHG command, run from the repository root. Where GMT is not
    installed (the tests install no system packages), the same command reads the saved
    output of the `gmt coast` call it makes for that box (scripts/testdata/)."""
    import shutil
    import shlex

    text = (ROOT / "docs" / "coastlines.md").read_text()
    lines = [l for l in text.splitlines() if l.startswith("python3 scripts/coastline.py gshhg")]
    assert len(lines) == 1, lines
    args = shlex.split(lines[0])[2:]
    if shutil.which("gmt") is None:
        args += ["--dump", str(DUMP)]
    r = run(args, repo_root)
    assert r.returncode == 0, r.stderr
    frame = xbandsim.Simulation(repo_root / "out" / "plymouth" / "scene.toml").render(seed=0)
    assert frame.land_mask.sum() > 100
