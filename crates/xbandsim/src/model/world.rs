//! Model: the world — the objects with their shapes, sizes and poses, validated from the
//! scene file's `[[object]]` tables (docs/formats.md).

use super::checks::{finite, finite_vec, positive};
use crate::error::{Error, Problem, Result};
use crate::geometry::{object_frame, MeshUnit, ShapeGeometry, TriangleMesh};
use crate::scene::{ObjectSpec, ShapeName};
use glam::{DMat3, DVec3};
use std::path::Path;

/// A validated scene object.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    /// Unique name.
    name: String,
    /// Class label.
    class: String,
    /// Shape and sizes.
    shape: ShapeGeometry,
    /// Reference position, ENU m.
    position_m: DVec3,
    /// Object-to-world rotation.
    rotation: DMat3,
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
            shape,
            position_m,
            rotation,
        })
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

    /// Reference position, ENU m.
    pub fn position_m(&self) -> DVec3 {
        self.position_m
    }

    /// Object-to-world rotation.
    pub fn rotation(&self) -> DMat3 {
        self.rotation
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

pub(super) fn build_object(i: usize, o: &ObjectSpec, base_dir: &Path) -> Result<SceneObject> {
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
            let mesh = TriangleMesh::load(&path, unit.metres() * scale).map_err(|e| {
                Error::unusable(f("mesh_file"), format!("\"{file}\""), "cannot be used", e)
            })?;
            ShapeGeometry::Mesh {
                mesh: std::sync::Arc::new(mesh),
            }
        }
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
    let position_m = finite_vec(
        &f("position_m"),
        o.position_m.ok_or_else(|| {
            Error::missing(
                f("position_m"),
                "every object needs position_m = [east, north, up]",
            )
        })?,
    )?;
    let yaw = finite(&f("yaw_deg"), o.yaw_deg.unwrap_or(0.0))?.to_radians();
    let pitch = finite(&f("pitch_deg"), o.pitch_deg.unwrap_or(0.0))?.to_radians();
    let roll = finite(&f("roll_deg"), o.roll_deg.unwrap_or(0.0))?.to_radians();
    Ok(SceneObject {
        class: o.class.clone().unwrap_or_else(|| "object".to_string()),
        name,
        shape,
        position_m,
        rotation: object_frame(yaw, pitch, roll),
    })
}
