//! Triangle meshes from OBJ, STL (ASCII and binary) and glTF 2.0 (`.gltf` with embedded or
//! external buffers, `.glb`), scaled to metres, and a procedurally generated vessel.
//!
//! Axes: OBJ and STL coordinates are taken as the object frame as they are (x, y, z with z
//! up and the front toward +y). glTF is +Y up with the front toward +Z (glTF 2.0
//! specification, §3.4), so its points are mapped `(x, y, z) → (−x, z, y)`, a rotation that
//! keeps handedness. glTF node transforms of the default scene are applied.

use super::{Primitive, PrimitiveKind, ShapeGeometry};
use crate::error::{Error, Result};
use glam::{DMat3, DMat4, DVec3};
use std::path::{Path, PathBuf};

/// An indexed triangle mesh in metres, in the object's own frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriangleMesh {
    /// Vertex positions, m.
    pub vertices_m: Vec<DVec3>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
}

/// Length unit of a mesh file's coordinates (`mesh_units`).
#[derive(
    Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
pub enum MeshUnit {
    /// Metres.
    #[serde(rename = "m")]
    Metre,
    /// Centimetres.
    #[serde(rename = "cm")]
    Centimetre,
    /// Millimetres.
    #[serde(rename = "mm")]
    Millimetre,
    /// International feet (0.3048 m).
    #[serde(rename = "ft")]
    Foot,
    /// Inches (0.0254 m).
    #[serde(rename = "in")]
    Inch,
}

impl MeshUnit {
    /// Parses "m", "cm", "mm", "ft" or "in".
    pub fn parse(text: &str) -> Option<MeshUnit> {
        Some(match text {
            "m" => MeshUnit::Metre,
            "cm" => MeshUnit::Centimetre,
            "mm" => MeshUnit::Millimetre,
            "ft" => MeshUnit::Foot,
            "in" => MeshUnit::Inch,
            _ => return None,
        })
    }

    /// Metres per unit.
    pub fn metres(&self) -> f64 {
        match self {
            MeshUnit::Metre => 1.0,
            MeshUnit::Centimetre => 0.01,
            MeshUnit::Millimetre => 0.001,
            MeshUnit::Foot => 0.3048,
            MeshUnit::Inch => 0.0254,
        }
    }
}

fn mesh_err(path: &Path, message: impl Into<String>) -> Error {
    Error::Mesh {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

impl TriangleMesh {
    /// Triangle `t` placed at `position_m` with `rotation`, tagged `object`: its first vertex
    /// and two edges in the world frame (the edges are differences of placed vertices).
    #[inline]
    pub fn placed_triangle(
        &self,
        t: usize,
        position_m: DVec3,
        rotation: glam::DMat3,
        object: u32,
    ) -> Primitive {
        let [a, b, c] = self.triangles[t];
        let to_world = |v: u32| position_m + rotation * self.vertices_m[v as usize];
        let v0 = to_world(a);
        Primitive {
            kind: PrimitiveKind::Triangle {
                v0,
                e1: to_world(b) - v0,
                e2: to_world(c) - v0,
            },
            object,
        }
    }

    /// Loads a mesh file by extension (`.obj`, `.stl`, `.gltf`, `.glb`), multiplying every
    /// coordinate by `scale_m` (metres per file unit).
    pub fn load(path: &Path, scale_m: f64) -> Result<TriangleMesh> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .unwrap_or_default();
        match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(mesh_err(path, "no such file"))
            }
            Err(e) => return Err(mesh_err(path, format!("cannot be read: {e}"))),
            Ok(m) if m.is_dir() => return Err(mesh_err(path, "is a directory, not a mesh file")),
            Ok(_) => {}
        }
        let mut mesh = match ext.as_str() {
            "obj" => load_obj(path)?,
            "stl" => load_stl(path)?,
            "gltf" | "glb" => load_gltf(path)?,
            other => {
                return Err(mesh_err(
                    path,
                    format!("unknown mesh format \".{other}\"; expected .obj, .stl, .gltf or .glb"),
                ))
            }
        };
        for v in &mut mesh.vertices_m {
            *v *= scale_m;
        }
        mesh.validate(path)?;
        Ok(mesh)
    }

    fn validate(&self, path: &Path) -> Result<()> {
        if self.triangles.is_empty() {
            return Err(mesh_err(path, "the mesh has no triangles"));
        }
        if let Some(v) = self.vertices_m.iter().find(|v| !v.is_finite()) {
            return Err(mesh_err(path, format!("vertex {v} is not finite")));
        }
        let n = self.vertices_m.len() as u32;
        if let Some(t) = self.triangles.iter().find(|t| t.iter().any(|&i| i >= n)) {
            return Err(mesh_err(
                path,
                format!("triangle {t:?} refers to a vertex beyond the {n} vertices"),
            ));
        }
        if self.area_m2() <= 0.0 {
            return Err(mesh_err(
                path,
                format!(
                    "the mesh has zero surface area (all {} triangles are degenerate: their corners lie on a line or coincide)",
                    self.triangles.len()
                ),
            ));
        }
        Ok(())
    }

    /// Centre of the vertices' bounding box, m.
    pub fn bounds_centre_m(&self) -> DVec3 {
        let (lo, hi) = self.vertices_m.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        );
        (lo + hi) * 0.5
    }

    /// Largest distance of a vertex from [`Self::bounds_centre_m`], m.
    pub fn bounding_radius_m(&self) -> f64 {
        let c = self.bounds_centre_m();
        self.vertices_m
            .iter()
            .map(|v| (*v - c).length())
            .fold(0.0, f64::max)
    }

    /// Total surface area, m².
    pub fn area_m2(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let (a, b, c) = (
                    self.vertices_m[t[0] as usize],
                    self.vertices_m[t[1] as usize],
                    self.vertices_m[t[2] as usize],
                );
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Wavefront OBJ text of this mesh.
    pub fn to_obj(&self, comment: &str) -> String {
        let mut s = String::with_capacity(self.vertices_m.len() * 40 + self.triangles.len() * 24);
        for line in comment.lines() {
            s.push_str("# ");
            s.push_str(line);
            s.push('\n');
        }
        for v in &self.vertices_m {
            s.push_str(&format!("v {:.6} {:.6} {:.6}\n", v.x, v.y, v.z));
        }
        for t in &self.triangles {
            s.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
        }
        s
    }
}

fn load_obj(path: &Path) -> Result<TriangleMesh> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) =
        tobj::load_obj(path, &opts).map_err(|e| mesh_err(path, format!("OBJ: {e}")))?;
    let mut mesh = TriangleMesh {
        vertices_m: Vec::new(),
        triangles: Vec::new(),
    };
    for m in models {
        let base = mesh.vertices_m.len() as u32;
        mesh.vertices_m.extend(
            m.mesh
                .positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)),
        );
        mesh.triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    Ok(mesh)
}

/// Checks an STL file's layout before parsing, so that a truncated or foreign file gets a
/// message saying so: a binary STL is an 80-byte header, a u32 triangle count N and N
/// 50-byte records (84 + 50·N bytes); an ASCII STL starts with `solid` and holds `facet`s.
fn check_stl_layout(path: &Path, bytes: &[u8]) -> Result<()> {
    let ascii = bytes.starts_with(b"solid")
        && std::str::from_utf8(&bytes[..bytes.len().min(4096)])
            .map(|t| t.contains("facet") || bytes.len() < 4096)
            .unwrap_or(false);
    if ascii {
        return Ok(());
    }
    if bytes.len() < 84 {
        return Err(mesh_err(
            path,
            format!(
                "not an STL file: {} bytes, shorter than a binary STL's 84-byte header, and not ASCII STL (which starts with \"solid\")",
                bytes.len()
            ),
        ));
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    let needed = 84 + 50 * n;
    if (bytes.len() as u64) < needed {
        return Err(mesh_err(
            path,
            format!(
                "truncated or not a binary STL: its header declares {n} triangles ({needed} bytes), the file has {} bytes",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

fn load_stl(path: &Path) -> Result<TriangleMesh> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    check_stl_layout(path, &bytes)?;
    let stl = stl_io::read_stl(&mut std::io::Cursor::new(&bytes))
        .map_err(|e| mesh_err(path, format!("STL could not be parsed: {e}")))?;
    Ok(TriangleMesh {
        vertices_m: stl
            .vertices
            .iter()
            .map(|v| DVec3::new(v.0[0] as f64, v.0[1] as f64, v.0[2] as f64))
            .collect(),
        triangles: stl
            .faces
            .iter()
            .map(|f| {
                [
                    f.vertices[0] as u32,
                    f.vertices[1] as u32,
                    f.vertices[2] as u32,
                ]
            })
            .collect(),
    })
}

fn load_gltf(path: &Path) -> Result<TriangleMesh> {
    use base64::Engine as _;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let is_glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if is_glb && !bytes.starts_with(b"glTF") {
        return Err(mesh_err(
            path,
            "not a binary glTF (.glb) file: it does not start with the magic bytes \"glTF\"",
        ));
    }
    let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| {
        mesh_err(
            path,
            format!(
                "not a valid glTF {} file: {e}",
                if is_glb { "binary" } else { "JSON" }
            ),
        )
    })?;
    let dir = path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for b in gltf.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| mesh_err(path, "glTF: the binary chunk is missing"))?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let b64 = rest.split_once(";base64,").map(|x| x.1).ok_or_else(|| {
                        mesh_err(path, "glTF: only base64 data URIs are supported")
                    })?;
                    base64::engine::general_purpose::STANDARD
                        .decode(b64)
                        .map_err(|e| mesh_err(path, format!("glTF: bad base64 buffer: {e}")))?
                } else {
                    let p = dir.join(uri);
                    std::fs::read(&p).map_err(|e| Error::io(p, e))?
                }
            }
        };
        if data.len() < b.length() {
            return Err(mesh_err(
                path,
                format!(
                    "glTF buffer {} holds {} bytes but the file declares {} (truncated buffer?)",
                    b.index(),
                    data.len(),
                    b.length()
                ),
            ));
        }
        buffers.push(data);
    }
    let mut mesh = TriangleMesh {
        vertices_m: Vec::new(),
        triangles: Vec::new(),
    };
    let scene = gltf
        .default_scene()
        .or_else(|| gltf.scenes().next())
        .ok_or_else(|| mesh_err(path, "glTF: no scene"))?;
    let mut stack: Vec<(gltf::Node, DMat4)> = scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let m = node.transform().matrix();
        let local = DMat4::from_cols_array_2d(&m.map(|c| c.map(|x| x as f64)));
        let world = parent * local;
        if let Some(gm) = node.mesh() {
            for prim in gm.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    continue;
                }
                let reader = prim.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
                let base = mesh.vertices_m.len() as u32;
                if prim.get(&gltf::Semantic::Positions).is_none() {
                    return Err(mesh_err(
                        path,
                        format!("glTF mesh {}: a primitive has no POSITION", gm.index()),
                    ));
                }
                let positions = reader.read_positions().ok_or_else(|| {
                    mesh_err(
                        path,
                        format!(
                            "glTF mesh {}: the POSITION data lies outside its buffer (accessor or buffer view beyond the buffer's end)",
                            gm.index()
                        ),
                    )
                })?;
                for p in positions {
                    let v =
                        world.transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
                    mesh.vertices_m.push(DVec3::new(-v.x, v.z, v.y));
                }
                let count = mesh.vertices_m.len() as u32 - base;
                match reader.read_indices() {
                    Some(ix) => {
                        let ix: Vec<u32> = ix.into_u32().collect();
                        mesh.triangles.extend(
                            ix.chunks_exact(3)
                                .map(|t| [base + t[0], base + t[1], base + t[2]]),
                        );
                    }
                    None => mesh.triangles.extend(
                        (0..count / 3).map(|i| [base + 3 * i, base + 3 * i + 1, base + 3 * i + 2]),
                    ),
                }
            }
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    Ok(mesh)
}

/// A simple vessel, generated: a hull with a pointed bow, flared sides and a transom stern
/// from the waterline (z = 0) to the deck, a bridge house, a funnel and a mast. Bow toward
/// +y. `segments` sets the resolution along the hull (triangles grow as segments²/2; 128
/// gives about 10 800). `make-vessel` writes it; the scene shape `vessel`
/// ([`super::procedural::VesselParams`]) builds its hulls with the same [`hull_mesh`].
pub fn vessel(length_m: f64, segments: usize) -> TriangleMesh {
    let n = segments.max(8);
    let beam = length_m * 0.25;
    let freeboard = length_m * 0.1;
    // Superstructure boxes (centre, size): bridge, funnel, mast.
    let boxes = [
        (
            DVec3::new(0.0, -0.15 * length_m, freeboard + 0.075 * length_m),
            DVec3::new(0.7 * beam, 0.22 * length_m, 0.15 * length_m),
        ),
        (
            DVec3::new(0.0, -0.33 * length_m, freeboard + 0.1 * length_m),
            DVec3::new(0.25 * beam, 0.08 * length_m, 0.2 * length_m),
        ),
        (
            DVec3::new(0.0, -0.1 * length_m, freeboard + 0.25 * length_m),
            DVec3::new(0.04 * beam, 0.02 * length_m, 0.2 * length_m),
        ),
    ];
    hull_mesh(length_m, beam, freeboard, n, (n / 8).max(2), &boxes)
}

/// A hull of `length_m` with deck width `beam_m` (its parallel body aft of 0.1·L forward of
/// amidships, a pointed bow ahead of it: half-width `B/2·√(1 − ((u − 0.2)/0.8)²)` at
/// `u = 2y/L > 0.2`), sides flaring from 85 % of the deck width at the waterline (z = 0) to
/// the deck at `freeboard_m`, a flat transom, `n` segments along the length, `rows` up the
/// sides and 4 across the deck; then `boxes` (centre, size) standing on it, each face but the
/// bottom split into 4 × 4 quads. Bow toward +y.
pub fn hull_mesh(
    length_m: f64,
    beam_m: f64,
    freeboard_m: f64,
    n: usize,
    rows: usize,
    boxes: &[(DVec3, DVec3)],
) -> TriangleMesh {
    let beam = beam_m;
    let freeboard = freeboard_m;
    let mut mesh = TriangleMesh {
        vertices_m: Vec::new(),
        triangles: Vec::new(),
    };
    // Half-width at the deck as a function of y (stern −L/2 to bow +L/2).
    let half_width = |y: f64| -> f64 {
        let u = (y / (length_m / 2.0)).clamp(-1.0, 1.0);
        if u <= 0.2 {
            beam / 2.0
        } else {
            beam / 2.0 * (1.0 - ((u - 0.2) / 0.8).powi(2)).max(0.0).sqrt()
        }
    };
    let cols = 4usize; // across the deck
    let ys_owned: Vec<f64> = (0..=n)
        .map(|i| -length_m / 2.0 + length_m * i as f64 / n as f64)
        .collect();
    let ys = &ys_owned;
    let grid = |mesh: &mut TriangleMesh,
                pts: &dyn Fn(usize, usize) -> DVec3,
                nu: usize,
                nv: usize,
                flip: bool| {
        let base = mesh.vertices_m.len() as u32;
        for i in 0..=nu {
            for j in 0..=nv {
                mesh.vertices_m.push(pts(i, j));
            }
        }
        let idx = |i: usize, j: usize| base + (i * (nv + 1) + j) as u32;
        for i in 0..nu {
            for j in 0..nv {
                let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
                if flip {
                    mesh.triangles.push([a, c, b]);
                    mesh.triangles.push([a, d, c]);
                } else {
                    mesh.triangles.push([a, b, c]);
                    mesh.triangles.push([a, c, d]);
                }
            }
        }
    };
    // Sides: flare from 85 % of the deck width at the waterline.
    for side in [-1.0f64, 1.0] {
        let f = move |i: usize, j: usize| {
            let y = ys[i];
            let t = j as f64 / rows as f64;
            let w = half_width(y) * (0.85 + 0.15 * t);
            DVec3::new(side * w, y, freeboard * t)
        };
        grid(&mut mesh, &f, n, rows, side < 0.0);
    }
    // Deck and waterline bottom.
    for (z, flip) in [(freeboard, false), (0.0, true)] {
        let f = move |i: usize, j: usize| {
            let y = ys[i];
            let w = half_width(y) * if z > 0.0 { 1.0 } else { 0.85 };
            DVec3::new(-w + 2.0 * w * j as f64 / cols as f64, y, z)
        };
        grid(&mut mesh, &f, n, cols, flip);
    }
    // Transom.
    let hw = half_width(-length_m / 2.0);
    let f = move |i: usize, j: usize| {
        let t = j as f64 / rows as f64;
        let w = hw * (0.85 + 0.15 * t);
        DVec3::new(
            -w + 2.0 * w * i as f64 / cols as f64,
            -length_m / 2.0,
            freeboard * t,
        )
    };
    grid(&mut mesh, &f, cols, rows, false);
    // Their faces as the box primitive builds them, without the bottom (it rests on the
    // deck), each split into 4 × 4 quads.
    for &(c, s) in boxes {
        for p in (ShapeGeometry::Box { size_m: s }).primitives(c, DMat3::IDENTITY, 0) {
            if let PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } = p.kind
            {
                if edge_u.cross(edge_v).z < 0.0 {
                    continue;
                }
                let f = move |i: usize, j: usize| {
                    corner + edge_u * (i as f64 / 4.0) + edge_v * (j as f64 / 4.0)
                };
                grid(&mut mesh, &f, 4, 4, false);
            }
        }
    }
    mesh
}
