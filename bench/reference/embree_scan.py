#!/usr/bin/env python3
"""Reference for `xbandsim bench`'s "scan-pattern rays, paper scene (closest hit)" rows:
Embree (through Mitsuba 3, which bundles it) casting the same 3.6 M rays of the paper's
scan grid from the radar at (0, 0, 4) against the same five targets as triangle meshes
(`--sea` adds a 20 km sea plane, like the bench's second row). Closest-hit queries
(`Scene.ray_intersect_preliminary`, Embree's packet intersection); the scene build, the ray
generation and the kernel compilation (a warm-up run) are not timed.

    python3 embree_scan.py [--sea] [--threads 2] [--repeats 5] [--json]
"""

import argparse
import json
import statistics
import time

import drjit as dr
import mitsuba as mi
import numpy as np

from scene import RADAR, paper_meshes, scan_directions


def build_scene(sea):
    objects = {"type": "scene"}
    for i, (v, f) in enumerate(paper_meshes(sea)):
        mesh = mi.Mesh(f"m{i}", vertex_count=len(v), face_count=len(f),
                       has_vertex_normals=False, has_vertex_texcoords=False)
        params = mi.traverse(mesh)
        params["vertex_positions"] = mi.Float(v.astype(np.float32).ravel())
        params["faces"] = mi.UInt32(f.astype(np.uint32).ravel())
        params.update()
        objects[f"m{i}"] = mesh
    return mi.load_dict(objects)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sea", action="store_true", help="add a 20 km sea plane at z = 0")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    variants = mi.variants()
    mi.set_variant("llvm_ad_rgb" if "llvm_ad_rgb" in variants else "llvm_rgb")
    dr.set_thread_count(a.threads)
    scene = build_scene(a.sea)
    d, _, _ = scan_directions()
    n = len(d)
    o = np.broadcast_to(RADAR.astype(np.float32), d.shape)
    rays = mi.Ray3f(o=mi.Point3f(*[mi.Float(np.ascontiguousarray(o[:, k])) for k in range(3)]),
                    d=mi.Vector3f(*[mi.Float(np.ascontiguousarray(d[:, k])) for k in range(3)]))
    dr.eval(rays)

    def cast():
        pi = scene.ray_intersect_preliminary(rays)
        hit = pi.is_valid()
        dr.eval(pi.t, hit)
        dr.sync_thread()
        return hit

    hits = int(dr.count(cast())[0]) if hasattr(dr.count(cast()), "__getitem__") else int(dr.count(cast()))
    times = []
    for _ in range(a.repeats):
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
    }
    if a.json:
        print(json.dumps(out))
    else:
        print(f"Embree (Mitsuba {mi.__version__}), {n} rays, sea {a.sea}, {a.threads} threads: "
              f"{out['rays_per_s_median'] / 1e6:.1f} M rays/s median, {hits} hits")


if __name__ == "__main__":
    main()
