//! Model: the world — the objects with their shapes, sizes and poses, validated from the
//! scene file's `[[object]]` tables (docs/formats.md).

use super::checks::{finite, finite_vec, positive};
use super::motion::{
    heading_of, HeadingRule, Kinematics, Motion, Trajectory, WaveMotion, Waypoint, KNOT_M_PER_S,
};
use crate::error::{Error, Problem, Result};
use crate::geometry::{
    object_frame, Aabb, BuoyParams, MeshUnit, ShapeGeometry, Superstructure, TriangleMesh,
    VesselParams,
};
use crate::scene::{ObjectSpec, ShapeName};
use glam::{DMat3, DVec3};
use std::path::Path;
use std::sync::OnceLock;

/// A shape's box in object coordinates, made on first use. Two are equal whatever they hold:
/// the box follows from the shape, which objects compare.
#[derive(Debug, Clone, Default)]
struct ShapeBox(OnceLock<Aabb>);

impl PartialEq for ShapeBox {
    fn eq(&self, _: &ShapeBox) -> bool {
        true
    }
}

/// A validated scene object.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    /// Unique name.
    name: String,
    /// Class label.
    class: String,
    /// Shape and sizes.
    shape: ShapeGeometry,
    /// The shape's box in object coordinates, made on first use and kept: a mesh's takes a
    /// pass over its triangles, and labels ask for it every frame.
    local_bounds: ShapeBox,
    /// Reference position, ENU m.
    position_m: DVec3,
    /// Object-to-world rotation.
    rotation: DMat3,
    /// How it moves (None: it stays where it is).
    moving: Option<Moving>,
}

/// A moving object's motion and the pose it starts from.
#[derive(Debug, Clone, PartialEq)]
struct Moving {
    motion: Motion,
    /// The steady path's origin at t = 0 (a track keeps only its height), ENU m.
    start_m: DVec3,
    /// Static pitch and roll, applied before the heading.
    tilt: DMat3,
}

impl SceneObject {
    /// An object of `shape` at `position_m` (ENU m) turned by `rotation` (object to world):
    /// the name must not be empty, the position finite, every size of the shape finite and
    /// above zero (a mesh must hold triangles) and the rotation a proper rotation
    /// (`RᵀR = I`, det R = 1, to 1e-9).
    pub fn new(
        name: impl Into<String>,
        class: impl Into<String>,
        shape: ShapeGeometry,
        position_m: DVec3,
        rotation: DMat3,
    ) -> Result<SceneObject> {
        let name = name.into();
        if name.trim().is_empty() {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "object.name",
                "\"\"",
                "must not be empty",
            ));
        }
        let position_m = finite_vec(
            &format!("object \"{name}\".position_m"),
            position_m.to_array(),
        )?;
        let orthonormal = (rotation.transpose() * rotation - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|e| e.abs() < 1e-9);
        if !rotation.is_finite() || !orthonormal || (rotation.determinant() - 1.0).abs() > 1e-9 {
            return Err(Error::invalid(
                Problem::OutOfRange,
                format!("object \"{name}\".rotation"),
                format!("{rotation:?}"),
                "must be a rotation matrix (orthonormal, determinant 1)",
            ));
        }
        let sizes: Vec<f64> = match &shape {
            ShapeGeometry::Point { rcs_m2 } => vec![*rcs_m2],
            ShapeGeometry::Sphere { radius_m } => vec![*radius_m],
            ShapeGeometry::Plate { width_m, height_m }
            | ShapeGeometry::Dihedral { width_m, height_m } => vec![*width_m, *height_m],
            ShapeGeometry::Trihedral { edge_m } => vec![*edge_m],
            ShapeGeometry::Cylinder { radius_m, height_m } => vec![*radius_m, *height_m],
            ShapeGeometry::Box { size_m } => size_m.to_array().to_vec(),
            ShapeGeometry::Mesh { mesh } => vec![mesh.triangles.len() as f64],
            ShapeGeometry::Vessel { params, parts, .. } => vec![
                params.length_m,
                params.beam_m,
                params.freeboard_m,
                parts.mesh.triangles.len() as f64,
            ],
            ShapeGeometry::Buoy { params } => vec![params.radius_m, params.height_m],
        };
        if let Some(bad) = sizes.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                format!("object \"{name}\".shape"),
                bad,
                format!(
                    "every size of a {} must be a finite number above zero (a mesh needs triangles)",
                    shape.name()
                ),
            ));
        }
        Ok(SceneObject {
            name,
            class: class.into(),
            local_bounds: ShapeBox::default(),
            shape,
            position_m,
            rotation,
            moving: None,
        })
    }

    /// The object moving with `motion` from `start_m` (the steady path's origin at t = 0; a
    /// track takes only its height), tilted at rest by `tilt` (static pitch and roll, a
    /// rotation): its position and rotation become those of t = 0.
    pub fn with_motion(mut self, motion: Motion, start_m: DVec3, tilt: DMat3) -> Result<Self> {
        let field = format!("object \"{}\"", self.name);
        let start_m = finite_vec(&format!("{field}.position_m"), start_m.to_array())?;
        let moving = Moving {
            motion,
            start_m,
            tilt,
        };
        let k = moving.motion.kinematics(start_m, tilt, 0.0);
        // The t = 0 pose goes through the same checks as a static object's.
        let checked = SceneObject::new(
            self.name.clone(),
            self.class.clone(),
            self.shape.clone(),
            k.position_m,
            k.rotation,
        )?;
        self.position_m = checked.position_m;
        self.rotation = checked.rotation;
        self.moving = Some(moving);
        Ok(self)
    }

    /// Its motion (None for an object that stays put).
    pub fn motion(&self) -> Option<&Motion> {
        self.moving.as_ref().map(|m| &m.motion)
    }

    /// Position, velocity, heading and rotation at time `t_s` (a still object: where it is,
    /// zero velocity, the heading of its bow, +y).
    pub fn kinematics(&self, t_s: f64) -> Kinematics {
        match &self.moving {
            Some(m) => m.motion.kinematics(m.start_m, m.tilt, t_s),
            None => Kinematics {
                position_m: self.position_m,
                velocity_mps: DVec3::ZERO,
                heading_rad: heading_of(self.rotation).unwrap_or(0.0),
                rotation: self.rotation,
            },
        }
    }

    /// The still object standing where this one is at time `t_s`, shifted by `shift_m`.
    pub fn posed_at(&self, t_s: f64, shift_m: DVec3) -> SceneObject {
        let k = self.kinematics(t_s);
        SceneObject {
            name: self.name.clone(),
            class: self.class.clone(),
            shape: self.shape.clone(),
            local_bounds: self.local_bounds.clone(),
            position_m: k.position_m + shift_m,
            rotation: k.rotation,
            moving: None,
        }
    }

    /// Unique name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Class label.
    pub fn class(&self) -> &str {
        &self.class
    }

    /// Shape name as a scene file writes it.
    pub fn shape_name(&self) -> &'static str {
        self.shape.name()
    }

    /// Shape and sizes.
    pub fn shape(&self) -> &ShapeGeometry {
        &self.shape
    }

    /// Bounding box of the shape's primitives in object coordinates (empty for a point).
    pub fn local_bounds(&self) -> Aabb {
        *self
            .local_bounds
            .0
            .get_or_init(|| self.shape.local_bounds())
    }

    /// Reference position, ENU m.
    pub fn position_m(&self) -> DVec3 {
        self.position_m
    }

    /// Object-to-world rotation.
    pub fn rotation(&self) -> DMat3 {
        self.rotation
    }

    /// The shape's rods placed in the world, ENU m (only a detailed vessel has any).
    pub fn rods_m(&self) -> Vec<crate::geometry::Rod> {
        self.shape
            .rods()
            .iter()
            .map(|r| r.placed(self.position_m, self.rotation))
            .collect()
    }
}

impl SceneObject {
    /// Height of the object's highest point, m (its position for a point object).
    pub fn top_m(&self) -> f64 {
        let prims = self.shape.primitives(self.position_m, self.rotation, 0);
        if prims.is_empty() {
            return self.position_m.z;
        }
        prims
            .iter()
            .map(|p| p.bounds().max.z)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Centre of the object's bounding sphere, ENU m.
    pub fn bounding_centre_m(&self) -> DVec3 {
        self.position_m + self.rotation * self.shape.bounding_centre_local_m()
    }
}

/// The meshes a scene's objects load, by file and metres per file unit: objects that name the
/// same file at the same scale share one mesh (loaded once; the BVH builds its hierarchy
/// once for all of them, `scattering::scene_bvh_of`).
pub(super) type LoadedMeshes =
    std::collections::HashMap<(std::path::PathBuf, u64), std::sync::Arc<TriangleMesh>>;

pub(super) fn build_object(
    i: usize,
    o: &ObjectSpec,
    base_dir: &Path,
    meshes: &mut LoadedMeshes,
) -> Result<SceneObject> {
    let name = o.name.clone().unwrap_or_else(|| format!("object-{i}"));
    if name.trim().is_empty() {
        return Err(Error::invalid(
            Problem::OutOfRange,
            format!("object[{i}].name"),
            "\"\"",
            "must not be empty",
        ));
    }
    let prefix = format!("object \"{name}\"");
    let f = |field: &str| format!("{prefix}.{field}");
    if let Some(mmsi) = o.mmsi {
        if mmsi == 0 || mmsi > 999_999_999 {
            return Err(Error::invalid(
                Problem::OutOfRange,
                f("mmsi"),
                mmsi,
                "an MMSI is 1 to 999999999 (nine digits)",
            ));
        }
    } else if let Some(class) = o.ais_class {
        return Err(Error::invalid(
            Problem::Conflict,
            f("ais_class"),
            format!("{class:?}"),
            "an AIS transponder needs the object's `mmsi`",
        ));
    }
    let shape_kind = o.shape.ok_or_else(|| {
        Error::missing(
            f("shape"),
            format!(
                "every object needs a shape, one of: {}",
                ShapeName::ALL.map(|s| s.as_str()).join(", ")
            ),
        )
    })?;
    let shape_name = shape_kind.as_str().to_string();
    let need = |field: &str, v: Option<f64>| -> Result<f64> {
        let v = v.ok_or_else(|| {
            Error::missing(f(field), format!("shape \"{shape_name}\" needs `{field}`"))
        })?;
        positive(&f(field), v)
    };
    let shape = match shape_kind {
        ShapeName::Point => ShapeGeometry::Point {
            rcs_m2: need("rcs_m2", o.rcs_m2)?,
        },
        ShapeName::Sphere => ShapeGeometry::Sphere {
            radius_m: need("radius_m", o.radius_m)?,
        },
        ShapeName::Plate => ShapeGeometry::Plate {
            width_m: need("width_m", o.width_m)?,
            height_m: need("height_m", o.height_m)?,
        },
        ShapeName::Trihedral => ShapeGeometry::Trihedral {
            edge_m: need("edge_m", o.edge_m)?,
        },
        ShapeName::Dihedral => ShapeGeometry::Dihedral {
            width_m: need("width_m", o.width_m)?,
            height_m: need("height_m", o.height_m)?,
        },
        ShapeName::Cylinder => ShapeGeometry::Cylinder {
            radius_m: need("radius_m", o.radius_m)?,
            height_m: need("height_m", o.height_m)?,
        },
        ShapeName::Box => {
            let s = o.size_m.ok_or_else(|| {
                Error::missing(f("size_m"), "shape \"box\" needs `size_m = [x, y, z]`")
            })?;
            for (k, v) in s.iter().enumerate() {
                if !v.is_finite() || *v <= 0.0 {
                    return Err(Error::invalid(
                        Problem::NotFinite,
                        f("size_m"),
                        format!("{s:?}"),
                        format!("component {k} must be a finite number greater than zero"),
                    ));
                }
            }
            ShapeGeometry::Box {
                size_m: DVec3::from_array(s),
            }
        }
        ShapeName::Mesh => {
            let file = o.mesh_file.as_deref().ok_or_else(|| {
                Error::missing(
                    f("mesh_file"),
                    "shape \"mesh\" needs `mesh_file` (an .obj, .stl, .gltf or .glb file)",
                )
            })?;
            let unit = o.mesh_units.unwrap_or(MeshUnit::Metre);
            let scale = positive(&f("mesh_scale"), o.mesh_scale.unwrap_or(1.0))?;
            let path = base_dir.join(file);
            let scale_m = unit.metres() * scale;
            let key = (path, scale_m.to_bits());
            let mesh = match meshes.get(&key) {
                Some(mesh) => std::sync::Arc::clone(mesh),
                None => {
                    let mesh = TriangleMesh::load(&key.0, scale_m).map_err(|e| {
                        Error::unusable(f("mesh_file"), format!("\"{file}\""), "cannot be used", e)
                    })?;
                    let mesh = std::sync::Arc::new(mesh);
                    meshes.insert(key, std::sync::Arc::clone(&mesh));
                    mesh
                }
            };
            ShapeGeometry::Mesh { mesh }
        }
        ShapeName::Vessel => {
            ShapeGeometry::vessel(vessel_params(o, &f, need("length_m", o.length_m)?)?)
        }
        ShapeName::Buoy => ShapeGeometry::Buoy {
            params: buoy_params(
                o,
                &f,
                need("radius_m", o.radius_m)?,
                need("height_m", o.height_m)?,
            )?,
        },
    };
    // Fields that this shape does not use are reported rather than silently ignored.
    let used: &[&str] = match shape {
        ShapeGeometry::Point { .. } => &["rcs_m2"],
        ShapeGeometry::Sphere { .. } => &["radius_m"],
        ShapeGeometry::Plate { .. } | ShapeGeometry::Dihedral { .. } => &["width_m", "height_m"],
        ShapeGeometry::Trihedral { .. } => &["edge_m"],
        ShapeGeometry::Cylinder { .. } => &["radius_m", "height_m"],
        ShapeGeometry::Box { .. } => &["size_m"],
        ShapeGeometry::Mesh { .. } => &["mesh_file", "mesh_units", "mesh_scale"],
        ShapeGeometry::Vessel { .. } => &[
            "length_m",
            "beam_m",
            "freeboard_m",
            "superstructure",
            "superstructure_height_m",
            "mast_height_m",
            "outfit",
            "outfit_seed",
        ],
        ShapeGeometry::Buoy { .. } => {
            &["radius_m", "height_m", "mast_height_m", "reflector_edge_m"]
        }
    };
    let present = [
        ("rcs_m2", o.rcs_m2.is_some()),
        ("radius_m", o.radius_m.is_some()),
        ("width_m", o.width_m.is_some()),
        ("height_m", o.height_m.is_some()),
        ("edge_m", o.edge_m.is_some()),
        ("size_m", o.size_m.is_some()),
        ("mesh_file", o.mesh_file.is_some()),
        ("mesh_units", o.mesh_units.is_some()),
        ("mesh_scale", o.mesh_scale.is_some()),
        ("length_m", o.length_m.is_some()),
        ("beam_m", o.beam_m.is_some()),
        ("freeboard_m", o.freeboard_m.is_some()),
        ("superstructure", o.superstructure.is_some()),
        (
            "superstructure_height_m",
            o.superstructure_height_m.is_some(),
        ),
        ("mast_height_m", o.mast_height_m.is_some()),
        ("reflector_edge_m", o.reflector_edge_m.is_some()),
        ("outfit", o.outfit.is_some()),
        ("outfit_seed", o.outfit_seed.is_some()),
    ];
    for (field, is_set) in present {
        if is_set && !used.contains(&field) {
            return Err(Error::invalid(
                Problem::Conflict,
                f(field),
                "(set)",
                format!(
                    "shape \"{shape_name}\" does not use `{field}`; it uses {}",
                    used.join(", ")
                ),
            ));
        }
    }
    let yaw = o
        .yaw_deg
        .map(|v| finite(&f("yaw_deg"), v))
        .transpose()?
        .map(f64::to_radians);
    let pitch = finite(&f("pitch_deg"), o.pitch_deg.unwrap_or(0.0))?.to_radians();
    let roll = finite(&f("roll_deg"), o.roll_deg.unwrap_or(0.0))?.to_radians();
    let motion = build_motion(&prefix, o, yaw)?;
    let position_m = match (&motion, o.position_m) {
        (Some(m), given) if matches!(m.path(), Trajectory::Track { .. }) => {
            let k = m.kinematics(DVec3::ZERO, DMat3::IDENTITY, 0.0);
            match given {
                None => DVec3::new(k.position_m.x, k.position_m.y, 0.0),
                Some(p) => {
                    let p = finite_vec(&f("position_m"), p)?;
                    if (p.truncate() - k.position_m.truncate()).length() > 1e-3 {
                        return Err(Error::invalid(
                            Problem::Conflict,
                            f("position_m"),
                            format!("{p:?}"),
                            format!("the track puts the object at east {:.3} m, north {:.3} m at t = 0; with a track, position_m may only repeat that and set the height (or leave it out: height 0)", k.position_m.x, k.position_m.y),
                        ));
                    }
                    p
                }
            }
        }
        (_, Some(p)) => finite_vec(&f("position_m"), p)?,
        (_, None) => {
            return Err(Error::missing(
                f("position_m"),
                "every object needs position_m = [east, north, up] (or a track)",
            ))
        }
    };
    let object = SceneObject {
        class: o.class.clone().unwrap_or_else(|| "object".to_string()),
        name,
        local_bounds: ShapeBox::default(),
        shape,
        position_m,
        rotation: object_frame(yaw.unwrap_or(0.0), pitch, roll),
        moving: None,
    };
    match motion {
        None => Ok(object),
        Some(m) => object.with_motion(m, position_m, object_frame(0.0, pitch, roll)),
    }
}

/// `value` (already finite and positive) within `lo ..= hi`, else an error naming `field`
/// that says `why`.
fn within(field: String, value: f64, lo: f64, hi: f64, why: &str) -> Result<f64> {
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(Error::invalid(
            Problem::OutOfRange,
            field,
            value,
            format!("must be between {lo:.4} and {hi:.4} m ({why})"),
        ))
    }
}

/// The fields of a `vessel` (docs/formats.md): each finite, above zero and in proportion to
/// the length.
fn vessel_params(
    o: &ObjectSpec,
    f: &dyn Fn(&str) -> String,
    length_m: f64,
) -> Result<VesselParams> {
    let l = within(
        f("length_m"),
        length_m,
        1.0,
        500.0,
        "a vessel's length overall",
    )?;
    let mut p = VesselParams::new(l);
    if let Some(b) = o.beam_m {
        let b = positive(&f("beam_m"), b)?;
        p.beam_m = within(
            f("beam_m"),
            b,
            0.05 * l,
            0.6 * l,
            "0.05 to 0.6 times length_m",
        )?;
    }
    if let Some(fb) = o.freeboard_m {
        let fb = positive(&f("freeboard_m"), fb)?;
        p.freeboard_m = within(
            f("freeboard_m"),
            fb,
            0.01 * l,
            0.25 * l,
            "0.01 to 0.25 times length_m",
        )?;
    }
    p.outfit = o.outfit;
    p.outfit_seed = o.outfit_seed.unwrap_or(0);
    if let Some(outfit) = o.outfit {
        let (lo, hi) = outfit.length_range_m();
        within(
            f("length_m"),
            l,
            lo,
            hi,
            &format!("the lengths an outfit \"{}\" is built for", outfit.as_str()),
        )?;
        let unused = match outfit {
            crate::geometry::Outfit::Rib => Some(("mast_height_m", o.mast_height_m.is_some())),
            crate::geometry::Outfit::Kayak => Some((
                "mast_height_m or superstructure_height_m",
                o.mast_height_m.is_some() || o.superstructure_height_m.is_some(),
            )),
            _ => None,
        };
        if let Some((field, true)) = unused {
            return Err(Error::invalid(
                Problem::Conflict,
                f(field.split(' ').next().unwrap_or(field)),
                "(set)",
                format!(
                    "an outfit \"{}\" has no mast or deck house for {field} to set",
                    outfit.as_str()
                ),
            ));
        }
    }
    if let (Some(outfit), Some(s)) = (o.outfit, o.superstructure) {
        return Err(Error::invalid(
            Problem::Conflict,
            f("superstructure"),
            format!("\"{}\"", s.as_str()),
            format!(
                "a detailed vessel (outfit \"{}\") builds its own deck structures; leave superstructure out",
                outfit.as_str()
            ),
        ));
    }
    if o.outfit.is_none() && o.outfit_seed.is_some() {
        return Err(Error::invalid(
            Problem::Conflict,
            f("outfit_seed"),
            "(set)",
            "varies a detailed vessel; it needs an outfit",
        ));
    }
    p.superstructure = o.superstructure.unwrap_or_default();
    match (p.outfit, p.superstructure, o.superstructure_height_m) {
        (None, Superstructure::None, Some(_)) => {
            return Err(Error::invalid(
                Problem::Conflict,
                f("superstructure_height_m"),
                "(set)",
                "needs a superstructure (\"cabin\", \"wheelhouse\", \"bridge-aft\", \"bridge-fore\" or \"decks\") or an outfit",
            ))
        }
        (_, _, Some(h)) => {
            let h = positive(&f("superstructure_height_m"), h)?;
            p.superstructure_height_m = within(
                f("superstructure_height_m"),
                h,
                0.0,
                0.5 * l,
                "at most half of length_m",
            )?;
        }
        (Some(outfit), _, None) => {
            p.superstructure_height_m = outfit.default_house_height_m(p.beam_m)
        }
        (None, s, None) => {
            p.superstructure_height_m = VesselParams::default_superstructure_height_m(s, p.beam_m)
        }
    }
    if let Some(m) = o.mast_height_m {
        let m = positive(&f("mast_height_m"), m)?;
        // The funnels of bridge-aft and decks reach 1.2 times the structures' height.
        let lowest = p.freeboard_m + 1.2 * p.superstructure_height_m;
        if m <= lowest {
            return Err(Error::invalid(
                Problem::OutOfRange,
                f("mast_height_m"),
                m,
                format!("must be above {lowest:.4} m, the deck structures' top (freeboard + 1.2 × superstructure height)"),
            ));
        }
        p.mast_height_m = Some(within(
            f("mast_height_m"),
            m,
            lowest,
            p.freeboard_m + 2.5 * l,
            "above the deck structures (freeboard + 1.2 × superstructure height) and at most freeboard + 2.5 × length_m",
        )?);
    }
    Ok(p)
}

/// The fields of a `buoy` (docs/formats.md).
fn buoy_params(
    o: &ObjectSpec,
    f: &dyn Fn(&str) -> String,
    radius_m: f64,
    height_m: f64,
) -> Result<BuoyParams> {
    let radius_m = within(f("radius_m"), radius_m, 0.0, 10.0, "a buoy's float radius")?;
    let height_m = within(
        f("height_m"),
        height_m,
        0.0,
        30.0,
        "a buoy's float height above the waterline",
    )?;
    let reflector_edge_m = o
        .reflector_edge_m
        .map(|a| {
            let a = positive(&f("reflector_edge_m"), a)?;
            within(
                f("reflector_edge_m"),
                a,
                0.0,
                2.0 * radius_m,
                "at most twice radius_m",
            )
        })
        .transpose()?;
    let mut p = BuoyParams {
        radius_m,
        height_m,
        mast_height_m: None,
        reflector_edge_m,
    };
    if let Some(m) = o.mast_height_m {
        let m = positive(&f("mast_height_m"), m)?;
        let lowest = p.top_m();
        let floor = if reflector_edge_m.is_some() {
            "the float's height plus the reflector's (4/√3 × reflector_edge_m)"
        } else {
            "above the float's height_m"
        };
        if m <= lowest {
            return Err(Error::invalid(
                Problem::OutOfRange,
                f("mast_height_m"),
                m,
                format!("must be above {lowest:.4} m ({floor})"),
            ));
        }
        p.mast_height_m = Some(within(
            f("mast_height_m"),
            m,
            lowest,
            height_m + 30.0,
            "at most 30 m above the float",
        )?);
    }
    Ok(p)
}

/// The motion fields of an `[[object]]` (docs/formats.md, "Motion"); None when it has none.
fn build_motion(prefix: &str, o: &ObjectSpec, yaw_rad: Option<f64>) -> Result<Option<Motion>> {
    let f = |field: &str| format!("{prefix}.{field}");
    let conflict = |field: &str, with: &str| {
        Error::invalid(
            Problem::Conflict,
            f(field),
            "(set)",
            format!("give either `{field}` or `{with}`, not both"),
        )
    };
    let path = if let Some(track) = &o.track {
        for (field, set) in [
            ("speed_kn", o.speed_kn.is_some()),
            ("course_deg", o.course_deg.is_some()),
            ("velocity_mps", o.velocity_mps.is_some()),
            ("turn_rate_deg_per_s", o.turn_rate_deg_per_s.is_some()),
        ] {
            if set {
                return Err(conflict(field, "track"));
            }
        }
        Some(Trajectory::Track {
            points: track
                .iter()
                .map(|p| Waypoint {
                    time_s: p[0],
                    east_m: p[1],
                    north_m: p[2],
                })
                .collect(),
        })
    } else {
        let velocity_mps = match (o.speed_kn, o.course_deg, o.velocity_mps) {
            (Some(_), _, Some(_)) => return Err(conflict("speed_kn", "velocity_mps")),
            (None, Some(_), Some(_)) => return Err(conflict("course_deg", "velocity_mps")),
            (Some(speed), course, None) => {
                let speed = super::motion::check_speed_kn(&f("speed_kn"), speed)?;
                let course = course.ok_or_else(|| {
                    Error::missing(
                        f("course_deg"),
                        "speed_kn needs course_deg (nautical degrees, 0 = north, 90 = east)",
                    )
                })?;
                let c = finite(&f("course_deg"), course)?.to_radians();
                let s = speed * KNOT_M_PER_S;
                Some(DVec3::new(s * c.sin(), s * c.cos(), 0.0))
            }
            (None, Some(_), None) => {
                return Err(Error::missing(f("speed_kn"), "course_deg needs speed_kn"))
            }
            (None, None, Some(v)) => {
                let v = finite_vec(&f("velocity_mps"), v)?;
                let limit_mps = super::motion::MAX_SPEED_KN * KNOT_M_PER_S;
                if v.length() > limit_mps {
                    return Err(Error::invalid(
                            Problem::OutOfRange,
                            f("velocity_mps"),
                            crate::model::checks::fmt_vec(v),
                            format!("its speed {:.1} m/s is above {limit_mps:.1} m/s ({} kn, above the water speed record)", v.length(), super::motion::MAX_SPEED_KN),
                        ));
                }
                Some(v)
            }
            (None, None, None) => None,
        };
        let turn = o
            .turn_rate_deg_per_s
            .map(|w| finite(&f("turn_rate_deg_per_s"), w))
            .transpose()?;
        match (velocity_mps, turn) {
            (None, Some(_)) => {
                return Err(Error::missing(
                    f("speed_kn"),
                    "turn_rate_deg_per_s needs a speed (speed_kn and course_deg, or velocity_mps)",
                ))
            }
            (Some(v), w) => Some(Trajectory::Steady {
                velocity_mps: v,
                turn_rate_rad_per_s: w.unwrap_or(0.0).to_radians(),
            }),
            (None, None) => None,
        }
    };
    let amplitudes = [
        o.heave_amplitude_m,
        o.roll_amplitude_deg,
        o.pitch_amplitude_deg,
    ];
    let wave = if amplitudes.iter().any(Option::is_some) {
        let period_s = o.motion_period_s.ok_or_else(|| {
            Error::missing(
                f("motion_period_s"),
                "wave-induced motion (heave, roll, pitch amplitudes) needs motion_period_s",
            )
        })?;
        Some(WaveMotion {
            heave_amplitude_m: o.heave_amplitude_m.unwrap_or(0.0),
            roll_amplitude_rad: o.roll_amplitude_deg.unwrap_or(0.0).to_radians(),
            pitch_amplitude_rad: o.pitch_amplitude_deg.unwrap_or(0.0).to_radians(),
            period_s,
            phase_rad: o.motion_phase_deg.unwrap_or(0.0).to_radians(),
        })
    } else {
        for (field, set) in [
            ("motion_period_s", o.motion_period_s.is_some()),
            ("motion_phase_deg", o.motion_phase_deg.is_some()),
        ] {
            if set {
                return Err(Error::invalid(
                    Problem::Conflict,
                    f(field),
                    "(set)",
                    "needs a wave-induced motion: heave_amplitude_m, roll_amplitude_deg or pitch_amplitude_deg",
                ));
            }
        }
        None
    };
    if path.is_none() && wave.is_none() {
        return Ok(None);
    }
    let moves = path.is_some();
    let path = path.unwrap_or(Trajectory::Steady {
        velocity_mps: DVec3::ZERO,
        turn_rate_rad_per_s: 0.0,
    });
    let still_with_course = o.speed_kn == Some(0.0) && o.course_deg.is_some();
    let heading = match yaw_rad {
        Some(y) => HeadingRule::Fixed(y),
        // Not moving, but a course given: the bow points along it.
        None if still_with_course => HeadingRule::Fixed(o.course_deg.unwrap_or(0.0).to_radians()),
        None if moves => HeadingRule::AlongCourse,
        None => HeadingRule::Fixed(0.0),
    };
    Motion::new(prefix, path, heading, wave).map(Some)
}

/// The own ship's roll and pitch (`[own_ship]` `roll_amplitude_deg`, `pitch_amplitude_deg`,
/// `motion_period_s`, `motion_phase_deg`): the period is needed with an amplitude and refused
/// without one.
pub(super) fn build_own_ship_wave(
    ship: super::motion::OwnShip,
    s: &crate::scene::OwnShipSpec,
    mast_height_m: f64,
) -> Result<super::motion::OwnShip> {
    if s.roll_amplitude_deg.is_none() && s.pitch_amplitude_deg.is_none() {
        for (field, set) in [
            ("own_ship.motion_period_s", s.motion_period_s.is_some()),
            ("own_ship.motion_phase_deg", s.motion_phase_deg.is_some()),
        ] {
            if set {
                return Err(Error::invalid(
                    Problem::Conflict,
                    field,
                    "(set)",
                    "needs a roll or pitch: roll_amplitude_deg or pitch_amplitude_deg",
                ));
            }
        }
        return Ok(ship);
    }
    let period_s = s.motion_period_s.ok_or_else(|| {
        Error::missing(
            "own_ship.motion_period_s",
            "roll and pitch (roll_amplitude_deg, pitch_amplitude_deg) need motion_period_s",
        )
    })?;
    ship.rolling(
        s.roll_amplitude_deg.unwrap_or(0.0),
        s.pitch_amplitude_deg.unwrap_or(0.0),
        period_s,
        s.motion_phase_deg.unwrap_or(0.0),
        mast_height_m,
    )
}
