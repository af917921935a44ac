#!/usr/bin/env python3
"""Reference for `xbandsim bench`'s "paper-equivalent frame" rows: the seed paper's frame in
NumPy, vectorised the way a careful NumPy user would write it. The paper's 3.6 M-ray scan
grid from the radar at (0, 0, 4), a bounding-sphere prefilter per object, exact intersections
(Möller–Trumbore on the reflectors', plate's and buoy's triangles, the quadratic on the dome), the paper's amplitude law
A = 1/(1 + l²/1000), the two-way sinc² pattern (3.9° × 25° beam) for each of 360 beams, echo
impulse responses on the 100 MHz sample grid, LFM chirp (B = 50 MHz, T µs), thermal noise,
FFT matched filter batched over the beams, dB over noise, and a 512 × 512 PPI (nearest spoke,
linear in range) out to 1000 m. Each pulse width's time is the whole frame, ray cast
included.

    python3 numpy_frame.py [--T 1 20 50] [--repeats 3] [--json]
"""

import argparse
import json
import statistics
import time

import numpy as np

from scene import RADAR, paper_meshes, scan_directions

C = 299_792_458.0
F0, B, FS = 9.41e9, 50e6, 100e6
LAMBDA = C / F0
AZ_BW, EL_BW = np.radians(3.9), np.radians(25.0)
MAX_RANGE = 1000.0
V_REF = 1e-3  # volts of a unit-amplitude ray (paper_reference_voltage_uv = 1000)
NOISE_RMS = np.sqrt(1.380649e-23 * 290.0 * 10 ** 0.5 * FS)  # k·T0·F·fs, F = 5 dB


def pattern(off_rad, bw):
    """One-way normalised power pattern sinc²: −3 dB at ±bw/2."""
    return np.sinc(0.8859 * off_rad / bw) ** 2


def cast(dirs, triangles, spheres):
    """Closest hit distance per ray (inf where none): prefilter by each object's bounding
    sphere, then the exact intersection on the candidate rays (Möller–Trumbore for
    triangles, the quadratic for the sphere, which xbandsim also treats analytically)."""
    t_best = np.full(len(dirs), np.inf)
    for centre, radius in spheres:
        rel = centre - RADAR
        dist = np.linalg.norm(rel)
        cand = np.nonzero(dirs @ (rel / dist) >= np.cos(np.arcsin(min(1.0, radius / dist))))[0]
        d = dirs[cand]
        bq = d @ rel
        disc = bq * bq - (rel @ rel - radius * radius)
        ok = disc >= 0
        t = bq - np.sqrt(np.where(ok, disc, 0.0))
        hit = ok & (t > 1e-9)
        idx = cand[hit]
        t_best[idx] = np.minimum(t_best[idx], t[hit])
    for v, f in triangles:
        centre = v.mean(axis=0)
        radius = np.linalg.norm(v - centre, axis=1).max()
        rel = centre - RADAR
        dist = np.linalg.norm(rel)
        cos_lim = np.cos(np.arcsin(min(1.0, radius / dist)))
        cand = np.nonzero(dirs @ (rel / dist) >= cos_lim)[0]
        if len(cand) == 0:
            continue
        d = dirs[cand].astype(np.float64)
        for tri in f:
            v0, v1, v2 = v[tri[0]], v[tri[1]], v[tri[2]]
            e1, e2 = v1 - v0, v2 - v0
            p = np.cross(d, e2)
            det = p @ e1
            ok = np.abs(det) > 1e-12
            inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
            s = RADAR - v0
            u = (p @ s) * inv
            q = np.cross(s, e1)
            w = (d @ q) * inv
            t = (q @ e2) * inv
            hit = ok & (u >= 0) & (w >= 0) & (u + w <= 1) & (t > 1e-9)
            idx = cand[hit]
            t_best[idx] = np.minimum(t_best[idx], t[hit])
    return t_best


def frame(pulse_us, dirs, az, el, triangles, spheres, rng):
    n_t = int(round(pulse_us * 1e-6 * FS))
    bins = int(MAX_RANGE * 2 * FS / C) + 1
    n_fft = 1 << int(np.ceil(np.log2(bins + 2 * n_t)))
    t = cast(dirs, triangles, spheres)
    hit = np.isfinite(t)
    l, a_hit, e_hit = t[hit], az[hit], el[hit]
    amp = V_REF / (1 + l * l / 1000) * np.exp(-4j * np.pi * l / LAMBDA) / NOISE_RMS
    amp = amp * pattern(e_hit, EL_BW)
    delay = np.rint(2 * l / C * FS).astype(int)
    beams = np.radians(np.arange(360.0))
    ir = np.zeros((360, n_fft), complex)
    for k, b in enumerate(beams):
        off = np.angle(np.exp(1j * (a_hit - b)))
        g = pattern(off, AZ_BW)
        near = g > 1e-6
        np.add.at(ir[k], delay[near], amp[near] * g[near])
    tt = np.arange(n_t) / FS
    chirp = np.exp(1j * np.pi * (B / (n_t / FS)) * (tt - n_t / FS / 2) ** 2)
    s = np.fft.fft(chirp, n_fft)
    ref = np.conj(s) / np.sqrt(n_t)
    noise = (rng.standard_normal((360, n_fft)) + 1j * rng.standard_normal((360, n_fft))) / np.sqrt(2)
    noise[:, bins + n_t:] = 0
    y = np.fft.ifft((np.fft.fft(ir, axis=1) * s + np.fft.fft(noise, axis=1)) * ref, axis=1)
    polar = 10 * np.log10(np.abs(y[:, :bins]) ** 2 + 1e-30)
    # PPI: nearest spoke, linear interpolation in range.
    size = 512
    xs = (np.arange(size) + 0.5 - size / 2) * 2 * MAX_RANGE / size
    x, yv = np.meshgrid(xs, -xs)
    r = np.hypot(x, yv) * 2 * FS / C
    spoke = np.rint(np.degrees(np.arctan2(x, yv)) % 360).astype(int) % 360
    j = np.clip(np.floor(r).astype(int), 0, bins - 2)
    fr = r - j
    ppi = polar[spoke, j] * (1 - fr) + polar[spoke, j + 1] * fr
    ppi[r > bins - 1] = np.nan
    return ppi


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--T", type=float, nargs="+", default=[1.0, 20.0, 50.0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    dirs, az, el = scan_directions(dtype=np.float64)
    meshes = paper_meshes(sea=False)
    # The dome (index 3) is a sphere: intersected analytically, as xbandsim does.
    triangles = [m for i, m in enumerate(meshes) if i != 3]
    spheres = [(np.array([700.0, -300.0, 3.0]), 1.5)]
    rng = np.random.default_rng(1)
    out = {"reference": "numpy-paper-frame", "numpy": np.__version__, "frames": {}}
    for pulse in a.T:
        frame(pulse, dirs, az, el, triangles, spheres, rng)  # warm-up
        times = []
        for _ in range(a.repeats):
            t0 = time.perf_counter()
            frame(pulse, dirs, az, el, triangles, spheres, rng)
            times.append(time.perf_counter() - t0)
        out["frames"][f"{pulse:g}"] = statistics.median(times)
        if not a.json:
            print(f"NumPy paper frame, {pulse:g} us: {statistics.median(times) * 1e3:.0f} ms")
    if a.json:
        print(json.dumps(out))


if __name__ == "__main__":
    main()
