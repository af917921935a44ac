"""The paper's 5-target scene (scenes/paper.toml) as triangle meshes and analytic shapes,
shared by the reference programs. Metres, ENU (x east, y north, z up), radar at (0, 0, 4).

Each object faces the radar as in the scene file: trihedrals open toward it, the plate 4°
off broadside. The same geometry conventions as docs/formats.md (a trihedral's corner at
its position, faces spanned by the edges along its three axes)."""

import math

import numpy as np

RADAR = np.array([0.0, 0.0, 4.0])


def yaw_matrix(yaw_deg):
    """Object-to-world rotation for a yaw (turns +y toward +x), as R = Rz(-yaw)."""
    a = math.radians(yaw_deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def trihedral(position, edge, yaw_deg):
    """Three right-triangle faces sharing the corner; symmetry axis +y in the object frame."""
    # Unit axes whose sum points along +y (the opening), one edge in the y-z plane, up.
    ay = np.array([0.0, 1.0, 0.0])
    up = np.array([0.0, 0.0, 1.0])
    e1 = ay / math.sqrt(3.0) + math.sqrt(2.0 / 3.0) * up
    rest = [
        ay / math.sqrt(3.0)
        + math.sqrt(2.0 / 3.0) * (math.cos(t) * up + math.sin(t) * np.array([1.0, 0.0, 0.0]))
        for t in (2 * math.pi / 3, 4 * math.pi / 3)
    ]
    axes = [e1] + rest
    r = yaw_matrix(yaw_deg)
    p = np.asarray(position, float)
    v = np.array([p] + [p + edge * (r @ a) for a in axes])
    f = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1]])
    return v, f


def plate(position, width, height, yaw_deg):
    """Vertical plate, normal +y in the object frame, width along x, height along z."""
    r = yaw_matrix(yaw_deg)
    p = np.asarray(position, float)
    hw, hh = width / 2, height / 2
    local = [(-hw, 0, -hh), (hw, 0, -hh), (hw, 0, hh), (-hw, 0, hh)]
    v = np.array([p + r @ np.array(c, float) for c in local])
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def sphere_mesh(centre, radius, rings=48, segments=96):
    """UV sphere (2·segments·(rings−1) triangles)."""
    th = np.linspace(0, math.pi, rings + 1)[1:-1]
    ph = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1) * radius
    v = np.concatenate([ring.reshape(-1, 3), [[0, 0, radius]], [[0, 0, -radius]]]) + centre
    faces = []
    n = segments
    for i in range(rings - 2):
        for j in range(n):
            a, b = i * n + j, i * n + (j + 1) % n
            c, d = a + n, b + n
            faces += [[a, c, b], [b, c, d]]
    top, bot = (rings - 1) * n, (rings - 1) * n + 1
    for j in range(n):
        faces.append([top, (j + 1) % n, j])
        last = (rings - 2) * n
        faces.append([bot, last + j, last + (j + 1) % n])
    return v, np.array(faces)


def cylinder_mesh(centre, radius, height, segments=128):
    """Capped vertical cylinder."""
    ph = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    ring = np.stack([radius * np.cos(ph), radius * np.sin(ph), np.zeros_like(ph)], -1)
    lo = ring + np.asarray(centre) - [0, 0, height / 2]
    hi = ring + np.asarray(centre) + [0, 0, height / 2]
    c_lo = np.asarray(centre) - [0, 0, height / 2]
    c_hi = np.asarray(centre) + [0, 0, height / 2]
    v = np.concatenate([lo, hi, [c_lo, c_hi]])
    n = segments
    faces = []
    for j in range(n):
        k = (j + 1) % n
        faces += [[j, k, n + k], [j, n + k, n + j], [2 * n, k, j], [2 * n + 1, n + j, n + k]]
    return v, np.array(faces)


def paper_meshes(sea=False):
    """The five targets (and optionally a 20 km sea plane at z = 0) as (vertices, faces)."""
    meshes = [
        trihedral([300.0, 400.0, 2.0], 0.5, 216.87),
        trihedral([-600.0, 300.0, 2.0], 0.3, 116.57),
        plate([-200.0, -700.0, 2.5], 8.0, 3.0, 20.0),
        sphere_mesh(np.array([700.0, -300.0, 3.0]), 1.5),
        cylinder_mesh(np.array([-150.0, 250.0, 0.75]), 0.3, 1.5),
    ]
    if sea:
        h = 10_000.0
        meshes.append(
            (np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], float),
             np.array([[0, 1, 2], [0, 2, 3]]))
        )
    return meshes


def scan_directions(n_az=36_000, n_el=100, el_beamwidth_deg=25.0, dtype=np.float32):
    """The paper's uniform scan grid, azimuth-major: azimuths (i+½)/n_az·360°, elevations
    over ±beamwidth/2 at cell centres; nautical azimuth (0 = +y, clockwise)."""
    az = np.radians((np.arange(n_az) + 0.5) * 360.0 / n_az)
    el = np.radians(-el_beamwidth_deg / 2 + el_beamwidth_deg * (np.arange(n_el) + 0.5) / n_el)
    a, e = np.meshgrid(az, el, indexing="ij")
    d = np.stack([np.sin(a) * np.cos(e), np.cos(a) * np.cos(e), np.sin(e)], -1)
    return d.reshape(-1, 3).astype(dtype), a.ravel(), e.ravel()
