#!/usr/bin/env python3
"""Turn real coastline data into land for an xbandsim scene (docs/coastlines.md).

Two sources, one output: GeoJSON files in lon/lat (WGS84) for a scene's `[[land]]` tables
(coast, breakwaters) and `[[structure]]` tables (piers, buildings) with `crs = "wgs84"`, and
a scene file that uses them.

  gshhg  a lon/lat box of the GSHHG shorelines through GMT (Debian: `gmt` and
         `gmt-gshhg-full`): `gmt coast -R... -Df -M -W` dumps the shorelines clipped to the
         box; the land polygons are closed along the box's edges.
  osm    a GeoJSON export from OpenStreetMap or QGIS: `natural=coastline` lines (land on
         their left, as OpenStreetMap draws them) merged and closed along the box, land
         polygons (`natural=land`, `place=island|islet`), `man_made=breakwater|groyne` as
         land and `man_made=pier` as structures (lines become a strip per segment, polygons
         stay), and buildings with `height` or `building:levels` as structures.

Only the standard library; every coordinate stays in lon/lat (xbandsim places it about the
scene's `[geo]` origin).
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

# Metres of height per building level when a building gives levels but no height.
LEVEL_HEIGHT_M = 3.0


class CoastError(Exception):
    """Input this script cannot use; the message says what and where."""


# --- geometry in lon/lat ---------------------------------------------------------------


def dedupe(ring):
    """The positions without consecutive repeats (and without the closing repeat)."""
    out = []
    for p in ring:
        if not out or (abs(p[0] - out[-1][0]) > 1e-12 or abs(p[1] - out[-1][1]) > 1e-12):
            out.append(p)
    while len(out) > 1 and out[0] == out[-1]:
        out.pop()
    return out


def signed_area(ring):
    n = len(ring)
    return 0.5 * sum(ring[i][0] * ring[(i + 1) % n][1] - ring[(i + 1) % n][0] * ring[i][1] for i in range(n))


class Box:
    """A lon/lat box, its perimeter walked counter-clockwise from the south-west corner."""

    def __init__(self, west, east, south, north):
        if not (west < east and south < north):
            raise CoastError(f"region {west}/{east}/{south}/{north}: need west < east and south < north")
        self.w, self.e, self.s, self.n = west, east, south, north
        self.eps = 1e-9 * max(east - west, north - south)

    def on_edge(self, p):
        x, y = p
        e = self.eps
        return (abs(y - self.s) <= e or abs(y - self.n) <= e or abs(x - self.w) <= e or abs(x - self.e) <= e)

    def perimeter_t(self, p):
        """Where p lies on the perimeter: 0..1 south edge west to east, 1..2 east edge, 2..3
        north edge east to west, 3..4 west edge north to south."""
        x, y = p
        e = self.eps
        if abs(y - self.s) <= e and x < self.e - e:
            return (x - self.w) / (self.e - self.w)
        if abs(x - self.e) <= e and y < self.n - e:
            return 1.0 + (y - self.s) / (self.n - self.s)
        if abs(y - self.n) <= e and x > self.w + e:
            return 2.0 + (self.e - x) / (self.e - self.w)
        return 3.0 + (self.n - y) / (self.n - self.s)

    def corner(self, k):
        return [(self.w, self.s), (self.e, self.s), (self.e, self.n), (self.w, self.n)][k % 4]

    def clip_chain(self, chain):
        """The pieces of a polyline inside the box (Liang-Barsky per segment)."""
        pieces, cur = [], []
        for a, b in zip(chain, chain[1:]):
            seg = self._clip_segment(a, b)
            if seg is None:
                if cur:
                    pieces.append(cur)
                    cur = []
                continue
            p, q = seg
            if cur and (abs(cur[-1][0] - p[0]) > self.eps or abs(cur[-1][1] - p[1]) > self.eps):
                pieces.append(cur)
                cur = []
            if not cur:
                cur = [p]
            cur.append(q)
            if q != b:  # left the box
                pieces.append(cur)
                cur = []
        if cur:
            pieces.append(cur)
        return [dedupe(p) if p[0] != p[-1] else p for p in pieces if len(p) >= 2]

    def _clip_segment(self, a, b):
        t0, t1 = 0.0, 1.0
        dx, dy = b[0] - a[0], b[1] - a[1]
        for p, q in ((-dx, a[0] - self.w), (dx, self.e - a[0]), (-dy, a[1] - self.s), (dy, self.n - a[1])):
            if p == 0:
                if q < 0:
                    return None
                continue
            r = q / p
            if p < 0:
                t0 = max(t0, r)
            else:
                t1 = min(t1, r)
            if t0 > t1:
                return None
        pa = a if t0 == 0.0 else (a[0] + t0 * dx, a[1] + t0 * dy)
        pb = b if t1 == 1.0 else (a[0] + t1 * dx, a[1] + t1 * dy)
        return pa, pb


def close_along_box(chains, box):
    """Land polygons from coast chains with land on their left: closed chains are rings;
    open ones must start and end on the box's edge, and each is joined to the next chain
    met walking the box's edge counter-clockwise from its end (land on the left)."""
    rings, open_chains = [], []
    for c in chains:
        if len(c) >= 4 and c[0] == c[-1]:
            rings.append(dedupe(c))
        elif len(c) >= 2:
            if not (box.on_edge(c[0]) and box.on_edge(c[-1])):
                raise CoastError(
                    f"a coastline ends inside the box at {c[0]} or {c[-1]}: the data does not cover the region, or lines are not joined"
                )
            open_chains.append(c)
    starts = [(box.perimeter_t(c[0]), i) for i, c in enumerate(open_chains)]
    used = [False] * len(open_chains)
    for first in range(len(open_chains)):
        if used[first]:
            continue
        ring, i = [], first
        for _ in range(len(open_chains) + 1):
            used[i] = True
            ring.extend(open_chains[i])
            t_end = box.perimeter_t(open_chains[i][-1])
            # The next start counter-clockwise from this end (itself when it is the only one).
            nxt = min(starts, key=lambda s: ((s[0] - t_end) % 4.0, s[1]))
            t_next = nxt[0]
            # Box corners passed on the way.
            k = math.floor(t_end)
            steps = 0
            while True:
                corner_t = float(k + 1)
                if (corner_t - t_end) % 4.0 >= (t_next - t_end) % 4.0 or steps > 4:
                    break
                ring.append(box.corner(k + 1))
                k += 1
                steps += 1
            i = nxt[1]
            if i == first:
                break
            if used[i]:
                raise CoastError("coastline chains cross each other along the box edge")
        rings.append(dedupe(ring))
    return [r for r in rings if len(r) >= 3 and signed_area(r) > 0]


# --- GSHHG through GMT -----------------------------------------------------------------


def parse_gmt_dump(text):
    """Segments of a `gmt coast -M -W` dump with their GSHHG levels: [(level, [(lon, lat)])]."""
    segs = []
    for line in text.splitlines():
        line = line.strip()
        if not line:
            continue
        if line.startswith(">"):
            level = 1
            if "Level" in line:
                try:
                    level = int(line.rsplit("Level", 1)[1].split()[0].strip(","))
                except ValueError:
                    level = 1
            segs.append((level, []))
            continue
        if not segs:
            segs.append((1, []))
        parts = line.split()
        try:
            segs[-1][1].append((float(parts[0]), float(parts[1])))
        except (ValueError, IndexError):
            raise CoastError(f"gmt output line {line!r} is not 'lon lat'")
    return [(lv, pts) for lv, pts in segs if len(pts) >= 2]


def same_box_side(a, b, box):
    """Whether the edge a-b runs along one side of the box."""
    e = box.eps
    return any(
        abs(a[i] - v) <= e and abs(b[i] - v) <= e
        for i, v in ((1, box.s), (1, box.n), (0, box.w), (0, box.e))
    )


def coast_runs(ring, box):
    """A polygon GMT clipped to the box, as its coast: the runs between its stretches along
    the box's sides (a ring that never touches them is returned closed)."""
    explicitly_closed = ring[0] == ring[-1]
    pts = dedupe(ring)
    n = len(pts)
    on_box = [same_box_side(pts[i], pts[(i + 1) % n], box) for i in range(n)]
    # GMT leaves a clipped polygon open between two points on the box's edge: it closes
    # along the edge, whichever sides that takes.
    if not explicitly_closed and box.on_edge(pts[-1]) and box.on_edge(pts[0]):
        on_box[n - 1] = True
    if not any(on_box):
        return [pts + [pts[0]]]
    start = (on_box.index(True) + 1) % n
    runs, cur = [], [pts[start]]
    for k in range(n):
        i = (start + k) % n
        if on_box[i]:
            if len(cur) >= 2:
                runs.append(cur)
            cur = [pts[(i + 1) % n]]
        else:
            cur.append(pts[(i + 1) % n])
    if len(cur) >= 2:
        runs.append(cur)
    return runs


def gshhg_polygons(dump_text, box):
    """Land polygons of a GMT dump: its level-1 shorelines (the sea's coasts; lakes and the
    land in them, levels 2-4, are left out). GMT gives each land polygon clipped to the box,
    with stretches along the box's sides; those are dropped and the coast runs, land on
    their left, are closed again along the box ([close_along_box])."""
    chains = []
    for level, pts in parse_gmt_dump(dump_text):
        if level == 1:
            chains.extend(coast_runs(pts, box))
    return close_along_box(chains, box)


def run_gmt(box, resolution):
    gmt = shutil.which("gmt")
    if gmt is None:
        raise CoastError("`gmt` is not installed: on Debian or Ubuntu, apt-get install gmt gmt-gshhg-full")
    region = f"{box.w}/{box.e}/{box.s}/{box.n}"
    # GMT leaves a gmt.history in its working folder: a temporary one.
    with tempfile.TemporaryDirectory() as scratch:
        proc = subprocess.run(
            [gmt, "coast", f"-R{region}", f"-D{resolution}", "-M", "-W"],
            capture_output=True, text=True, check=False, cwd=scratch,
        )
    if proc.returncode != 0:
        raise CoastError(f"gmt coast failed: {proc.stderr.strip()}")
    return proc.stdout


# --- OpenStreetMap / QGIS GeoJSON --------------------------------------------------------


def merge_lines(lines):
    """Joins lines that share end points (an end to a start) into chains."""
    lines = [list(map(tuple, l)) for l in lines if len(l) >= 2]
    by_start = {}
    for i, l in enumerate(lines):
        by_start.setdefault(l[0], []).append(i)
    used = [False] * len(lines)
    chains = []
    # Start from lines no other line ends into, then close the loops that are left.
    ends = {l[-1] for l in lines}
    order = [i for i, l in enumerate(lines) if l[0] not in ends] + list(range(len(lines)))
    for i in order:
        if used[i]:
            continue
        used[i] = True
        chain = list(lines[i])
        while chain[-1] != chain[0]:
            nxt = [j for j in by_start.get(chain[-1], []) if not used[j]]
            if not nxt:
                break
            used[nxt[0]] = True
            chain.extend(lines[nxt[0]][1:])
        chains.append(chain)
    return chains


def strip_polygons(line, width_m):
    """A rectangle `width_m` wide around each segment of a lon/lat line."""
    out = []
    for a, b in zip(line, line[1:]):
        lat = math.radians(0.5 * (a[1] + b[1]))
        mx = 111_320.0 * math.cos(lat)  # metres per degree east
        my = 110_574.0  # metres per degree north
        dx, dy = (b[0] - a[0]) * mx, (b[1] - a[1]) * my
        length = math.hypot(dx, dy)
        if length == 0:
            continue
        nx, ny = -dy / length * width_m / 2, dx / length * width_m / 2
        off = (nx / mx, ny / my)
        out.append([
            (a[0] - off[0], a[1] - off[1]), (b[0] - off[0], b[1] - off[1]),
            (b[0] + off[0], b[1] + off[1]), (a[0] + off[0], a[1] + off[1]),
        ])
    return out


def building_height_m(props, default_m):
    for key in ("height", "building:height"):
        v = props.get(key)
        if v is not None:
            try:
                return float(str(v).split()[0].rstrip("m"))
            except ValueError:
                pass
    levels = props.get("building:levels")
    if levels is not None:
        try:
            return float(levels) * LEVEL_HEIGHT_M
        except ValueError:
            pass
    return default_m


def osm_layers(geojson, box, breakwater_width_m, breakwater_height_m, building_height_default_m):
    """(coast polygons, breakwater polygons, pier polygons, building polygons; each but the
    coast with its height and name)."""
    if geojson.get("type") != "FeatureCollection":
        raise CoastError("the OpenStreetMap/QGIS export must be a GeoJSON FeatureCollection")
    coast_lines, land, moles, piers, buildings = [], [], [], [], []
    for k, f in enumerate(geojson.get("features", [])):
        props = f.get("properties") or {}
        geom = f.get("geometry") or {}
        kind, coords = geom.get("type"), geom.get("coordinates")
        if coords is None:
            continue
        polys = [coords] if kind == "Polygon" else coords if kind == "MultiPolygon" else []
        if props.get("natural") == "coastline":
            if kind == "LineString":
                coast_lines.append([tuple(p[:2]) for p in coords])
            elif kind == "MultiLineString":
                coast_lines.extend([tuple(p[:2]) for p in l] for l in coords)
            else:
                raise CoastError(f"feature {k}: natural=coastline should be a line, is a {kind}")
        elif props.get("man_made") in ("breakwater", "pier", "groyne"):
            h = building_height_m(props, breakwater_height_m)
            into = piers if props.get("man_made") == "pier" else moles
            if kind == "LineString":
                into.extend((r, h, props.get("name")) for r in strip_polygons(coords, breakwater_width_m))
            for p in polys:
                into.append((dedupe([tuple(q[:2]) for q in p[0]]), h, props.get("name")))
        elif "building" in props:
            for p in polys:
                buildings.append((dedupe([tuple(q[:2]) for q in p[0]]), building_height_m(props, building_height_default_m), props.get("name")))
        elif props.get("natural") == "land" or props.get("place") in ("island", "islet"):
            for p in polys:
                land.append(dedupe([tuple(q[:2]) for q in p[0]]))
    pieces = []
    for chain in merge_lines(coast_lines):
        if chain[0] == chain[-1]:
            pieces.append(chain)
        else:
            pieces.extend(box.clip_chain(chain))
    coast = close_along_box(pieces, box) + [r if signed_area(r) > 0 else r[::-1] for r in land]
    return coast, moles, piers, buildings


# --- output ------------------------------------------------------------------------------


def inside(p, ring):
    """Even-odd point in polygon."""
    x, y = p
    hit = False
    n = len(ring)
    for i in range(n):
        (ax, ay), (bx, by) = ring[i], ring[(i + 1) % n]
        if (ay > y) != (by > y) and x < ax + (y - ay) / (by - ay) * (bx - ax):
            hit = not hit
    return hit


def check_origin_on_water(origin, polygons):
    for k, ring in enumerate(polygons):
        if inside(origin, ring):
            raise CoastError(
                f"the origin {origin[0]}, {origin[1]} (where the radar stands) is on land (polygon {k}): give --origin LON,LAT on the water"
            )


def feature(ring, name=None, height_m=None):
    ring = list(ring)
    if signed_area(ring) < 0:
        ring.reverse()
    closed = [list(map(lambda v: round(v, 7), p)) for p in ring] + [[round(ring[0][0], 7), round(ring[0][1], 7)]]
    props = {}
    if name:
        props["name"] = name
    if height_m is not None:
        props["height_m"] = round(height_m, 2)
    return {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [closed]}}


def write_collection(path, features, note):
    data = {"type": "FeatureCollection", "xbandsim_note": note, "features": features}
    Path(path).write_text(json.dumps(data, indent=None, separators=(",", ":")) + "\n")


def scene_text(origin, layers, max_range_m, structures=()):
    lines = [
        "# Made by scripts/coastline.py; add objects below.",
        "[radar]",
        'preset = "drs4d-nxt"',
        "position_m = [0.0, 0.0, 10.0]",
        f"max_range_m = {max_range_m:.1f}",
        "",
        "[environment]",
        "sea_state = 2.0",
        "clutter = true",
        "",
        "[display]",
        f"range_ring_spacing_m = {max(500.0, round(max_range_m / 6.0, -2)):.1f}",
        "",
        "[geo]",
        f"origin_lon_deg = {origin[0]}",
        f"origin_lat_deg = {origin[1]}",
    ]
    for file, table in layers:
        lines += ["", "[[land]]", f'geojson = "{file}"', 'crs = "wgs84"'] + table
    for file, kind in structures:
        lines += ["", "[[structure]]", f'geojson = "{file}"', 'crs = "wgs84"', f'kind = "{kind}"']
    return "\n".join(lines) + "\n"


def parse_region(text):
    try:
        w, e, s, n = (float(v) for v in text.split("/"))
    except ValueError:
        raise CoastError(f"--region {text!r}: expected WEST/EAST/SOUTH/NORTH in degrees")
    return Box(w, e, s, n)


def parse_origin(text, box):
    if text is None:
        return (round(0.5 * (box.w + box.e), 6), round(0.5 * (box.s + box.n), 6))
    try:
        lon, lat = (float(v) for v in text.split(","))
    except ValueError:
        raise CoastError(f"--origin {text!r}: expected LON,LAT in degrees")
    return (lon, lat)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="source", required=True)
    for name in ("gshhg", "osm"):
        p = sub.add_parser(name)
        p.add_argument("--region", required=True, help="WEST/EAST/SOUTH/NORTH, degrees")
        p.add_argument("--out", required=True, help="output folder (GeoJSON files and scene.toml)")
        p.add_argument("--origin", help="LON,LAT of the scene's origin (default the box's centre)")
        p.add_argument("--height-m", type=float, default=15.0, help="height of the coast's land, m (default 15)")
        p.add_argument("--terrain", default="rock", choices=["rock", "sand", "grass", "forest", "urban"])
        p.add_argument("--beach-width-m", type=float, help="rise to the height over this width inland (default: a cliff at the shore)")
        p.add_argument("--max-range-m", type=float, default=6000.0)
    sub.choices["gshhg"].add_argument("--resolution", default="f", choices=list("fhilc"), help="GSHHG resolution (default f, full)")
    sub.choices["gshhg"].add_argument("--dump", help="read a saved `gmt coast -M -W` dump instead of running gmt")
    osm = sub.choices["osm"]
    osm.add_argument("geojson", help="the GeoJSON export")
    osm.add_argument("--breakwater-width-m", type=float, default=12.0)
    osm.add_argument("--breakwater-height-m", type=float, default=4.0)
    osm.add_argument("--building-height-m", type=float, default=10.0, help="height of buildings that give none")
    args = ap.parse_args(argv)
    try:
        box = parse_region(args.region)
        origin = parse_origin(args.origin, box)
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        table = [f"height_m = {args.height_m}", f'terrain = "{args.terrain}"']
        if args.beach_width_m is not None:
            table += ['edge = "beach"', f"beach_width_m = {args.beach_width_m}"]
        if args.source == "gshhg":
            try:
                dump = Path(args.dump).read_text() if args.dump else run_gmt(box, args.resolution)
            except OSError as e:
                raise CoastError(f"{args.dump or 'gmt'}: {e.strerror or e}")
            coast = gshhg_polygons(dump, box)
            check_origin_on_water(origin, coast)
            note = "GSHHG shorelines (Wessel & Smith), LGPL-3.0; via GMT `gmt coast -M -W`"
            write_collection(out / "coast.geojson", [feature(r, f"coast-{i}") for i, r in enumerate(coast)], note)
            layers = [("coast.geojson", table)]
            structures = []
            counts = {"coast": len(coast)}
        else:
            try:
                data = json.loads(Path(args.geojson).read_text())
            except (OSError, json.JSONDecodeError) as e:
                raise CoastError(f"{args.geojson}: {e}")
            coast, moles, piers, buildings = osm_layers(data, box, args.breakwater_width_m, args.breakwater_height_m, args.building_height_m)
            check_origin_on_water(origin, coast + [r for r, _, _ in moles + piers + buildings])
            note = "OpenStreetMap contributors, ODbL 1.0"
            write_collection(out / "coast.geojson", [feature(r, f"coast-{i}") for i, r in enumerate(coast)], note)
            layers = [("coast.geojson", table)]
            structures = []
            if moles:
                write_collection(out / "breakwaters.geojson", [feature(r, n, h) for r, h, n in moles], note)
                layers.append(("breakwaters.geojson", ['terrain = "rock"']))
            if piers:
                write_collection(out / "piers.geojson", [feature(r, n, h) for r, h, n in piers], note)
                structures.append(("piers.geojson", "pier"))
            if buildings:
                write_collection(out / "buildings.geojson", [feature(r, n, h) for r, h, n in buildings], note)
                structures.append(("buildings.geojson", "building"))
            counts = {"coast": len(coast), "breakwaters": len(moles), "piers": len(piers), "buildings": len(buildings)}
        (out / "scene.toml").write_text(scene_text(origin, layers, args.max_range_m, structures))
    except CoastError as e:
        print(f"coastline.py: {e}", file=sys.stderr)
        return 2
    print(f"wrote {out}: " + ", ".join(f"{v} {k} polygons" for k, v in counts.items()) + f"; origin {origin[0]}, {origin[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
