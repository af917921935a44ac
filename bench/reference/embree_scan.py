#!/usr/bin/env python3
"""Reference for the `xbandsim bench` rows "scan-pattern rays, paper scene (closest hit)" and
"scan-pattern rays, paper scene + sea plane (closest hit)": Embree ray casting, through
Mitsuba 3 (which bundles Embree) on its LLVM (CPU) back end.

What is measured: closest-hit queries (`Scene.ray_intersect_preliminary`, then the hit
distance t and the hit mask evaluated and the thread synchronised) of the paper's radar scan
pattern, 3.6 M rays from the radar at (0, 0, 4):
  360 beams 1 deg apart x 100 azimuth sub-rays across each beam = 36 000 azimuths at
  (i + 0.5) / 36 000 * 360 deg, x 100 elevations at the centres of 100 equal cells over
  -12.5..+12.5 deg; nautical azimuth (0 = +y north, clockwise), so a ray's direction is
  (sin az cos el, cos az cos el, sin el).
Scene: the paper scene (scenes/paper.toml) as triangle meshes in metres, z up: trihedrals of
edge 0.5 m and 0.3 m, an 8 m x 3 m plate, a sphere of radius 1.5 m (UV sphere) and a capped
cylinder (r 0.3 m, h 1.5 m); `--sea` adds a 20 km x 20 km sea plane at z = 0 (2 triangles).
Not timed: the scene build (Embree BVH), the ray generation and the kernel compilation (one
warm-up run). Printed: median and best rays/s over --repeats timed runs.

    python3 embree_scan.py [--sea] [--threads 2] [--repeats 5] [--json]
"""

import argparse
import json
import math
import statistics
import time

import drjit as dr
import mitsuba as mi
import numpy as np

RADAR = (0.0, 0.0, 4.0)
N_AZ, N_EL, EL_BW_DEG = 36_000, 100, 25.0


# ---------------------------------------------------------------- scene (metres, z up)

def yaw(deg):
    """Object-to-world rotation R = Rz(-yaw): positive yaw turns the object's +y toward +x."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def trihedral(corner, edge, yaw_deg):
    """Three right-triangle faces sharing the corner vertex; the three unit edge directions
    sum to the symmetry axis (+y in the object frame), one edge in the y-z plane, pointing up."""
    s2, s3, s6 = math.sqrt(2), math.sqrt(3), math.sqrt(6)
    axes = np.array([[-1 / s2, 1 / s3, -1 / s6], [1 / s2, 1 / s3, -1 / s6], [0, 1 / s3, math.sqrt(2 / 3)]])
    v = np.vstack([corner, corner + edge * axes @ yaw(yaw_deg).T])
    return v, [[0, 1, 2], [0, 2, 3], [0, 3, 1]]


def plate(centre, width, height, yaw_deg):
    """Vertical rectangle, normal +y in the object frame (width along x, height along z)."""
    w, h = width / 2, height / 2
    local = np.array([[-w, 0, -h], [w, 0, -h], [w, 0, h], [-w, 0, h]])
    return centre + local @ yaw(yaw_deg).T, [[0, 1, 2], [0, 2, 3]]


def uv_sphere(centre, radius, rings=32, segments=64):
    """UV sphere: 2 * segments * (rings - 1) triangles (3968 with the defaults)."""
    th = np.linspace(0, math.pi, rings + 1)[1:-1]          # polar angles of the inner rings
    ph = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    v = centre + radius * np.vstack([ring, [[0, 0, 1]], [[0, 0, -1]]])
    top, bottom = len(ring), len(ring) + 1
    f = []
    for i in range(rings - 1):
        for j in range(segments):
            a, b = i * segments + j, i * segments + (j + 1) % segments
            if i + 1 < rings - 1:                            # quad between ring i and i + 1
                f += [[a, a + segments, b], [b, a + segments, b + segments]]
            if i == 0:
                f.append([top, a, b])
            if i == rings - 2:
                f.append([bottom, b, a])
    return v, f


def cylinder(centre, radius, height, segments=64):
    """Vertical capped cylinder: side quads and two fans."""
    ph = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    ring = np.stack([radius * np.cos(ph), radius * np.sin(ph), np.zeros(segments)], -1)
    lo, hi = centre - [0, 0, height / 2], centre + [0, 0, height / 2]
    v = np.vstack([lo + ring, hi + ring, [lo, hi]])
    n, f = segments, []
    for j in range(n):
        k = (j + 1) % n
        f += [[j, k, n + k], [j, n + k, n + j], [2 * n, k, j], [2 * n + 1, n + j, n + k]]
    return v, f


def paper_scene(sea):
    """The five targets of scenes/paper.toml (and the sea plane) as (vertices, faces) pairs."""
    meshes = [
        trihedral(np.array([300.0, 400.0, 2.0]), 0.5, 216.87),
        trihedral(np.array([-600.0, 300.0, 2.0]), 0.3, 116.57),
        plate(np.array([-200.0, -700.0, 2.5]), 8.0, 3.0, 20.0),
        uv_sphere(np.array([700.0, -300.0, 3.0]), 1.5),
        cylinder(np.array([-150.0, 250.0, 0.75]), 0.3, 1.5),
    ]
    if sea:
        h = 10_000.0
        meshes.append((np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]]), [[0, 1, 2], [0, 2, 3]]))
    return meshes


def build_scene(meshes):
    """A Mitsuba scene (Embree BVH on the LLVM variants) of the given triangle meshes."""
    desc = {"type": "scene"}
    for i, (v, f) in enumerate(meshes):
        f = np.asarray(f, np.uint32)
        mesh = mi.Mesh(f"mesh{i}", vertex_count=len(v), face_count=len(f),
                       has_vertex_normals=False, has_vertex_texcoords=False)
        params = mi.traverse(mesh)
        params["vertex_positions"] = mi.Float(np.asarray(v, np.float32).ravel())
        params["faces"] = mi.UInt32(f.ravel())
        params.update()
        desc[f"mesh{i}"] = mesh
    return mi.load_dict(desc)


# ---------------------------------------------------------------- rays

def scan_rays():
    """The paper's scan grid, azimuth-major (ray = ia * N_EL + ie), as one Ray3f batch."""
    az = np.radians((np.arange(N_AZ) + 0.5) * 360.0 / N_AZ)
    el = np.radians(-EL_BW_DEG / 2 + EL_BW_DEG * (np.arange(N_EL) + 0.5) / N_EL)
    a, e = (x.ravel() for x in np.meshgrid(az, el, indexing="ij"))
    d = [np.sin(a) * np.cos(e), np.cos(a) * np.cos(e), np.sin(e)]
    o = [np.full(a.size, c) for c in RADAR]
    ray = mi.Ray3f(o=mi.Point3f(*[mi.Float(x.astype(np.float32)) for x in o]),
                   d=mi.Vector3f(*[mi.Float(x.astype(np.float32)) for x in d]))
    dr.eval(ray)
    return ray, a.size


def main():
    ap = argparse.ArgumentParser(description="Embree (Mitsuba 3) closest-hit throughput, paper scan pattern")
    ap.add_argument("--sea", action="store_true", help="add a 20 km x 20 km sea plane at z = 0")
    ap.add_argument("--threads", type=int, default=2, help="Dr.Jit worker threads (default 2)")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs after one warm-up (default 5)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    a = ap.parse_args()

    variant = next(v for v in ("llvm_ad_rgb", "llvm_rgb") if v in mi.variants())
    mi.set_variant(variant)
    dr.set_thread_count(a.threads)

    meshes = paper_scene(a.sea)
    scene = build_scene(meshes)
    ray, n = scan_rays()

    def cast():
        pi = scene.ray_intersect_preliminary(ray)
        hit = pi.is_valid()
        dr.eval(pi.t, hit)
        dr.sync_thread()
        return pi.t, hit

    _, hit = cast()                                  # warm-up: traces and compiles the kernel
    hits = int(np.count_nonzero(np.asarray(hit)))
    times = []
    for _ in range(max(1, a.repeats)):
        t0 = time.perf_counter()
        cast()
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)

    out = {
        "reference": "embree-mitsuba",
        "scene": "paper",
        "sea": a.sea,
        "rays": n,
        "threads": a.threads,
        "hits": hits,
        "median_s": med,
        "rays_per_s_median": n / med,
        "rays_per_s_best": n / min(times),
        "triangles": sum(len(f) for _, f in meshes),
        "variant": variant,
        "mitsuba": mi.__version__,
        "repeats": len(times),
    }
    if a.json:
        print(json.dumps(out))
    else:
        print(f"Embree via Mitsuba {mi.__version__} ({variant}), paper scene{' + sea' if a.sea else ''}, "
              f"{out['triangles']} triangles, {n} rays, {a.threads} threads: "
              f"{out['rays_per_s_median'] / 1e6:.1f} M rays/s median, "
              f"{out['rays_per_s_best'] / 1e6:.1f} best, {hits} hits")


if __name__ == "__main__":
    main()
