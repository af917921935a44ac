#!/usr/bin/env python3
"""Reference for the `xbandsim bench` rows "paper-equivalent frame (3.6 M-ray grid,
bounding-sphere prefilter, 512^2 PPI), {1, 20, 50} us": one radar frame of the seed paper's
pipeline in NumPy, vectorised the way a careful NumPy user would write it.

What one timed frame does (the ray cast included every time):
  1. Ray cast of the paper's scan grid, 3.6 M rays from the radar at (0, 0, 4): 36 000
     azimuths at (i + 0.5) / 36 000 * 360 deg (360 beams x 100 sub-rays) x 100 elevations at
     the centres of 100 cells over -12.5..+12.5 deg, nautical azimuth (0 = +y, clockwise).
     Per object a bounding-sphere prefilter (the azimuth columns and elevation rows the
     sphere can touch, then the exact cone test; `--prefilter rays`: the cone test on all
     3.6 M rays) picks candidate rays, which are intersected exactly: Moller-Trumbore on
     the trihedrals' 3 and the plate's 2 triangles, the quadratic on the sphere, the side
     quadratic and the two cap planes on the cylinder. Closest hit.
  2. Echoes: amplitude A = 1/(1 + l^2/1000) (l one-way distance, m) with carrier phase
     exp(-j 4 pi l / lambda), lambda = c / 9.41 GHz; for each of 360 beams (k deg) weighted by
     the two-way pattern Gn_az * Gn_el, Gn(d) = sinc^2(0.8859 d / bw) (-3 dB at bw/2; 3.9 deg
     azimuth, 25 deg elevation), added at the nearest 100 MHz sample of the delay 2 l / c.
  3. LFM chirp (B = 50 MHz, T us, 100 MHz samples), complex white Gaussian noise (k T0 F fs,
     F = 5 dB), FFT matched filter batched over the 360 beams, power in dB over the noise,
     range out to 1000 m.
  4. Scan conversion to a 512 x 512 PPI (nearest spoke, linear interpolation in range).
Not timed (set up once, as `xbandsim bench` builds its simulation and scan converter outside
its timing): the grid's direction table, the chirp spectrum and the PPI lookup table.
Printed: the median whole-frame time per pulse width after one warm-up frame.

    python3 numpy_frame.py [--T 1 20 50] [--repeats 3] [--prefilter grid|rays] [--json]
                           [--save-ppi PREFIX]
"""

import argparse
import json
import math
import statistics
import time

import numpy as np

C = 299_792_458.0
F0, B, FS = 9.41e9, 50e6, 100e6        # carrier, chirp bandwidth, complex sample rate (Hz)
LAMBDA = C / F0
RADAR = np.array([0.0, 0.0, 4.0])
N_BEAMS, N_AZ, N_EL = 360, 36_000, 100
AZ_BW, EL_BW = math.radians(3.9), math.radians(25.0)
MAX_RANGE = 1000.0
BIN_M = C / (2 * FS)                     # range per sample, 1.499 m
N_BINS = int(MAX_RANGE / BIN_M) + 1
PPI_SIZE = 512
V_REF = 1e-3                             # volts of a ray with A = 1 (xbandsim's paper default)
NOISE_RMS = math.sqrt(1.380649e-23 * 290.0 * 10 ** 0.5 * FS)   # k T0 F fs, volts rms

D_AZ = 2 * math.pi / N_AZ
D_EL = EL_BW / N_EL
GRID_AZ = (np.arange(N_AZ) + 0.5) * D_AZ
GRID_EL = -EL_BW / 2 + (np.arange(N_EL) + 0.5) * D_EL


def scan_directions():
    """Unit directions of the grid, azimuth-major: ray index = ia * N_EL + ie."""
    a, e = np.meshgrid(GRID_AZ, GRID_EL, indexing="ij")
    return np.stack([np.sin(a) * np.cos(e), np.cos(a) * np.cos(e), np.sin(e)], -1).reshape(-1, 3)


# ---------------------------------------------------------------- scene (metres, z up)

def yaw(deg):
    """Object-to-world rotation R = Rz(-yaw): positive yaw turns the object's +y toward +x."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def trihedral(corner, edge, yaw_deg):
    """3 triangles (v0, v1, v2) sharing the corner; symmetry axis +y in the object frame."""
    s2, s3, s6 = math.sqrt(2), math.sqrt(3), math.sqrt(6)
    axes = np.array([[-1 / s2, 1 / s3, -1 / s6], [1 / s2, 1 / s3, -1 / s6], [0, 1 / s3, math.sqrt(2 / 3)]])
    p = corner + edge * axes @ yaw(yaw_deg).T
    return np.array([[corner, p[0], p[1]], [corner, p[1], p[2]], [corner, p[2], p[0]]])


def plate(centre, width, height, yaw_deg):
    """2 triangles of a vertical rectangle, normal +y in the object frame."""
    w, h = width / 2, height / 2
    q = centre + np.array([[-w, 0, -h], [w, 0, -h], [w, 0, h], [-w, 0, h]]) @ yaw(yaw_deg).T
    return np.array([[q[0], q[1], q[2]], [q[0], q[2], q[3]]])


def bounding_sphere(points):
    c = points.mean(axis=0)
    return c, float(np.linalg.norm(points - c, axis=1).max())


def paper_objects():
    """The five targets of scenes/paper.toml: (kind, parameters, bounding centre, radius)."""
    objs = []
    for tris in (trihedral(np.array([300.0, 400.0, 2.0]), 0.5, 216.87),
                 trihedral(np.array([-600.0, 300.0, 2.0]), 0.3, 116.57),
                 plate(np.array([-200.0, -700.0, 2.5]), 8.0, 3.0, 20.0)):
        objs.append(("triangles", tris, *bounding_sphere(tris.reshape(-1, 3))))
    centre = np.array([700.0, -300.0, 3.0])
    objs.append(("sphere", (centre, 1.5), centre, 1.5))
    centre, r, h = np.array([-150.0, 250.0, 0.75]), 0.3, 1.5
    objs.append(("cylinder", (centre, r, h), centre, math.hypot(r, h / 2)))
    return objs


# ---------------------------------------------------------------- 1. ray cast

def candidates(dirs, centre, radius, prefilter="grid"):
    """Indices of the rays that pass through the bounding sphere (centre, radius).
    "grid": angular box on the scan grid, then the cone test on the rays inside it;
    "rays": the cone test on every one of the 3.6 M rays (no use of the grid's structure)."""
    rel = centre - RADAR
    dist, ground = np.linalg.norm(rel), math.hypot(rel[0], rel[1])
    if ground <= radius:                                     # sphere over the radar: all rays
        return np.arange(len(dirs))
    cos_max = math.sqrt(1 - (radius / dist) ** 2)
    if prefilter == "rays":
        return np.nonzero(dirs @ (rel / dist) >= cos_max)[0]
    # Angular box first: azimuth columns and elevation rows the sphere can touch (+1 cell).
    az_c, half_az = math.atan2(rel[0], rel[1]), math.asin(radius / ground) + D_AZ
    cols = np.arange(math.floor((az_c - half_az) / D_AZ), math.ceil((az_c + half_az) / D_AZ) + 1) % N_AZ
    el_c, half_el = math.atan2(rel[2], ground), math.asin(radius / dist) + D_EL
    lo = max(0, math.floor((el_c - half_el + EL_BW / 2) / D_EL))
    hi = min(N_EL, math.ceil((el_c + half_el + EL_BW / 2) / D_EL) + 1)
    if lo >= hi:
        return np.empty(0, np.int64)
    idx = (cols[:, None] * N_EL + np.arange(lo, hi)[None, :]).ravel()
    # Then the exact cone test: angle to the centre <= asin(radius / dist).
    keep = dirs[idx] @ (rel / dist) >= cos_max
    return idx[keep]


def hit_triangles(d, tris):
    """Closest positive t per ray over the triangles (Moller-Trumbore), inf where none."""
    t_best = np.full(len(d), np.inf)
    for v0, v1, v2 in tris:
        e1, e2, s = v1 - v0, v2 - v0, RADAR - v0
        p = np.cross(d, e2)
        det = p @ e1
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            u = (p @ s) * inv
            q = np.cross(s, e1)                               # one vector: the origin is shared
            v = (d @ q) * inv
            t = (q @ e2) * inv
        ok = (np.abs(det) > 1e-12) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6)
        t_best = np.where(ok, np.minimum(t_best, t), t_best)
    return t_best


def hit_sphere(d, centre, r):
    oc = RADAR - centre
    b = d @ oc
    disc = b * b - (oc @ oc - r * r)
    with np.errstate(invalid="ignore"):
        t = -b - np.sqrt(disc)                                # the radar is outside: near root
    return np.where((disc >= 0) & (t > 1e-6), t, np.inf)


def hit_cylinder(d, centre, r, h):
    """Vertical capped cylinder: side (quadratic in x, y) and the two cap disks."""
    px, py = RADAR[0] - centre[0], RADAR[1] - centre[1]
    z0, z1 = centre[2] - h / 2, centre[2] + h / 2
    dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
    a = dx * dx + dy * dy
    b = px * dx + py * dy
    disc = b * b - a * (px * px + py * py - r * r)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (-b - np.sqrt(disc)) / a
        z = RADAR[2] + t * dz
        best = np.where((disc >= 0) & (t > 1e-6) & (z >= z0) & (z <= z1), t, np.inf)
        for zc in (z0, z1):
            tc = (zc - RADAR[2]) / dz
            inside = (px + tc * dx) ** 2 + (py + tc * dy) ** 2 <= r * r
            best = np.where(inside & (tc > 1e-6), np.minimum(best, tc), best)
    return best


def ray_cast(dirs, objects, prefilter="grid"):
    """(ray index, one-way distance) of every ray's closest hit."""
    all_idx, all_t = [], []
    for kind, params, centre, radius in objects:
        idx = candidates(dirs, centre, radius, prefilter)
        d = dirs[idx]
        if kind == "triangles":
            t = hit_triangles(d, params)
        elif kind == "sphere":
            t = hit_sphere(d, *params)
        else:
            t = hit_cylinder(d, *params)
        hit = np.isfinite(t)
        all_idx.append(idx[hit])
        all_t.append(t[hit])
    idx, t = np.concatenate(all_idx), np.concatenate(all_t)
    order = np.lexsort((t, idx))                              # by ray, nearest first
    idx, t = idx[order], t[order]
    first = np.r_[True, idx[1:] != idx[:-1]]
    return idx[first], t[first]


# ---------------------------------------------------------------- 2.-4. echoes, filter, PPI

def gn(off, bw):
    """One-way normalised power pattern sinc^2 (np.sinc(x) = sin(pi x)/(pi x)), 0.5 at bw/2."""
    return np.sinc(0.8859 * off / bw) ** 2


class FrameSetup:
    """Per pulse width, built once: FFT length, chirp spectrum, noise scale, PPI lookup."""

    def __init__(self, pulse_us):
        self.n_t = max(1, round(pulse_us * 1e-6 * FS))
        # Outputs 0..N_BINS-1 of the correlation need n_fft >= N_BINS + n_t - 1 (no wrap).
        self.n_fft = 1 << math.ceil(math.log2(N_BINS + self.n_t - 1))
        tau = np.arange(self.n_t) / FS
        T = self.n_t / FS
        chirp = np.exp(1j * math.pi * (B / T) * (tau - T / 2) ** 2)
        s = np.fft.fft(chirp, self.n_fft)
        norm = math.sqrt(self.n_t)                            # unit-energy filter: noise at 0 dB
        self.echo_filter = np.abs(s) ** 2 / norm              # transmit chirp x matched filter
        self.noise_filter = np.conj(s) / norm                 # matched filter alone
        # PPI: pixel centres -> nearest spoke and fractional range bin (north up, east right).
        xs = (np.arange(PPI_SIZE) + 0.5 - PPI_SIZE / 2) * (2 * MAX_RANGE / PPI_SIZE)
        x, y = np.meshgrid(xs, -xs)
        rbin = np.hypot(x, y) / BIN_M
        spoke = np.rint(np.degrees(np.arctan2(x, y)) % 360).astype(np.int64) % N_BEAMS
        j = np.minimum(rbin.astype(np.int64), N_BINS - 2)
        self.ppi_index = spoke * N_BINS + j
        self.ppi_frac = rbin - j
        self.ppi_outside = rbin > N_BINS - 1


def frame(dirs, objects, setup, rng, prefilter="grid"):
    """One whole frame: ray cast, echoes, chirp + noise, matched filter, PPI (dB)."""
    idx, l = ray_cast(dirs, objects, prefilter)
    az, el = GRID_AZ[idx // N_EL], GRID_EL[idx % N_EL]
    # Echo of every hit in noise-rms units, with the elevation pattern (beam at 0 deg tilt).
    amp = (V_REF / NOISE_RMS) / (1 + l * l / 1000) * np.exp(-4j * math.pi * l / LAMBDA) * gn(el, EL_BW)
    delay = np.rint(2 * l / C * FS).astype(np.int64)
    # Impulse responses of the 360 beams: two-way azimuth pattern of beam k for every hit.
    beams = np.radians(np.arange(N_BEAMS))
    off = (az[None, :] - beams[:, None] + math.pi) % (2 * math.pi) - math.pi
    ir = np.zeros((N_BEAMS, setup.n_fft), complex)
    np.add.at(ir, (np.arange(N_BEAMS)[:, None], delay[None, :]), gn(off, AZ_BW) * amp[None, :])
    # Chirp, noise and matched filter in the frequency domain, batched over the beams. White
    # noise is white in either domain: drawn directly as its spectrum (variance n_fft per bin).
    noise = rng.standard_normal((N_BEAMS, 2 * setup.n_fft)).view(complex) * math.sqrt(setup.n_fft / 2)
    spec = np.fft.fft(ir, axis=1) * setup.echo_filter + noise * setup.noise_filter
    y = np.fft.ifft(spec, axis=1)[:, :N_BINS]
    polar_db = 10 * np.log10(y.real ** 2 + y.imag ** 2 + 1e-30)
    # PPI: nearest spoke, linear in range; NaN outside the range.
    flat = polar_db.ravel()
    ppi = flat[setup.ppi_index] * (1 - setup.ppi_frac) + flat[setup.ppi_index + 1] * setup.ppi_frac
    ppi[setup.ppi_outside] = np.nan
    return ppi, len(idx)


def main():
    ap = argparse.ArgumentParser(description="NumPy paper-equivalent frame time")
    ap.add_argument("--T", type=float, nargs="+", default=[1.0, 20.0, 50.0], help="pulse widths, us")
    ap.add_argument("--repeats", type=int, default=3, help="timed frames per pulse width (default 3)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--prefilter", choices=("grid", "rays"), default="grid",
                    help="bounding-sphere prefilter: on the scan grid's azimuth columns and elevation "
                         "rows, then per ray (default; like xbandsim's column culling), or per ray "
                         "over all 3.6 M rays")
    ap.add_argument("--save-ppi", metavar="PREFIX", help="save each pulse width's last PPI as PREFIX_<T>us.npy")
    a = ap.parse_args()

    dirs = scan_directions()
    objects = paper_objects()
    rng = np.random.default_rng(1)
    out = {"reference": "numpy-paper-frame", "numpy": np.__version__, "rays": len(dirs),
           "repeats": max(1, a.repeats), "prefilter": a.prefilter, "frames": {}, "raycast_s": None, "hits": None}
    for pulse in a.T:
        setup = FrameSetup(pulse)
        frame(dirs, objects, setup, rng, a.prefilter)        # warm-up
        times = []
        for _ in range(max(1, a.repeats)):
            t0 = time.perf_counter()
            ppi, hits = frame(dirs, objects, setup, rng, a.prefilter)
            times.append(time.perf_counter() - t0)
        out["frames"][f"{pulse:g}"] = statistics.median(times)
        out["hits"] = hits
        if a.save_ppi:
            np.save(f"{a.save_ppi}_{pulse:g}us.npy", ppi)
        if not a.json:
            print(f"NumPy paper frame, {pulse:g} us (n_fft {setup.n_fft}): "
                  f"{statistics.median(times) * 1e3:.1f} ms median, {min(times) * 1e3:.1f} best, {hits} hits")
    # The ray cast alone, for context (it is inside every frame time above).
    times = []
    for _ in range(max(1, a.repeats)):
        t0 = time.perf_counter()
        ray_cast(dirs, objects, a.prefilter)
        times.append(time.perf_counter() - t0)
    out["raycast_s"] = statistics.median(times)
    if a.json:
        print(json.dumps(out))
    else:
        print(f"of which the ray cast: {out['raycast_s'] * 1e3:.1f} ms median")


if __name__ == "__main__":
    main()
