//! Stage: model. The validated, immutable runtime description of a scene in SI units, built
//! from a [`SceneSpec`](crate::scene::SceneSpec): the [`Radar`], the [`Environment`], the
//! scattering settings and the objects of the world. Every bad value is an [`Error`] naming
//! the field and the value; nothing here panics on user input. Display settings are not part
//! of the model: they belong to the PPI product (`crate::products::ppi::PpiSettings`).

pub mod artefacts;
pub(crate) mod checks;
mod environment;
mod land;
pub mod motion;
pub mod processing;
pub mod radar;
pub mod receiver;
pub mod revolution;
mod scattering;
mod world;

pub use environment::{ClutterDoppler, Environment, SeaClutter};
pub use motion::{Kinematics, Motion, OwnShip};
pub use processing::{Integration, Processing, ProcessingMode};
pub use radar::{
    Polarisation, Radar, Scan, ShortPulse, Stagger, Transmitter, MAX_POLAR_CELLS, MAX_PRF_STAGGER,
    MAX_SPOKES,
};
pub use revolution::Revolution;
pub use scattering::{
    object_max_rays, tube_grid_cells, ScatteringConfig, ScatteringModel, BYTES_PER_TUBE,
    MAX_TRACE_BYTES,
};
pub use world::SceneObject;

use crate::error::{Error, Problem, Result};
use crate::geometry::ShapeGeometry;
use crate::scene::{LoadedSpec, SceneSpec};
use checks::fmt_vec;
use std::path::Path;

/// A validated scene: the radar, the environment, the scattering settings and the objects.
/// Immutable once built; read it through its accessors.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    radar: Radar,
    environment: Environment,
    scattering: ScatteringConfig,
    objects: Vec<SceneObject>,
    own_ship: Option<OwnShip>,
    processing: Processing,
    receiver: Option<receiver::VideoSettings>,
    artefacts: artefacts::Artefacts,
}

/// Refuses a ray budget whose PO trace would need more than [`MAX_TRACE_BYTES`]: every
/// extended object's tube grids (two with the sea on: direct and via the sea) at
/// [`BYTES_PER_TUBE`], before anything is traced. Names the field that sets the grids: the
/// budget where it binds, else the spacing.
fn check_trace_memory(
    radar: &Radar,
    environment: &Environment,
    scattering: &ScatteringConfig,
    objects: &[SceneObject],
) -> Result<()> {
    if scattering.model() != ScatteringModel::PhysicalOptics {
        return Ok(());
    }
    let spacing_m = scattering.ray_spacing_wavelengths() * radar.wavelength_m();
    let grids = if environment.sea().is_some() {
        2.0
    } else {
        1.0
    };
    let (mut tubes, mut capped) = (0.0, false);
    for obj in objects {
        if matches!(obj.shape(), ShapeGeometry::Point { .. }) {
            continue;
        }
        let radius_m = obj.shape().bounding_radius_m();
        let (cells, bound) = tube_grid_cells(
            radius_m,
            spacing_m,
            object_max_rays(
                scattering.max_rays_per_object(),
                radius_m,
                obj.shape().max_tube_side_m(),
            ),
        );
        tubes += grids * std::f64::consts::FRAC_PI_4 * (cells as f64).powi(2);
        capped |= bound;
    }
    let bytes = tubes * BYTES_PER_TUBE;
    if bytes <= MAX_TRACE_BYTES {
        return Ok(());
    }
    let what = format!(
        "tracing the scene would take about {:.3e} ray tubes, {:.1} GB of memory; the limit is {:.0} GB",
        tubes,
        bytes / 1e9,
        MAX_TRACE_BYTES / 1e9
    );
    Err(if capped {
        Error::invalid(
            Problem::OutOfRange,
            "scattering.max_rays_per_object",
            scattering.max_rays_per_object(),
            format!("{what}: lower max_rays_per_object (default 32768)"),
        )
    } else {
        Error::invalid(
            Problem::OutOfRange,
            "scattering.ray_spacing_wavelengths",
            scattering.ray_spacing_wavelengths(),
            format!(
                "{what}: raise ray_spacing_wavelengths (default 0.5) or lower max_rays_per_object"
            ),
        )
    })
}

/// Refuses an antenna at or below the ground of the land it stands on (a radar on land
/// stands on its mast above it).
fn check_antenna_above_ground(radar: &Radar, land: &crate::land::Land) -> Result<()> {
    let p = radar.position_m();
    if let Some(k) = land.polygon_at(p.truncate()) {
        let ground = land.height_at(p.truncate());
        if p.z <= ground {
            let poly = &land.polygons()[k];
            return Err(Error::invalid(
                Problem::Conflict,
                "radar.position_m",
                fmt_vec(p),
                format!(
                    "the antenna stands on land polygon {:?} from {} whose ground is {ground:.1} m high there: raise it above the ground or move it onto the water",
                    poly.name, poly.source
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses an object whose reference point stands on land (targets float on water),
/// naming the object and the land polygon.
fn check_objects_on_water(objects: &[SceneObject], land: &crate::land::Land) -> Result<()> {
    for (i, o) in objects.iter().enumerate() {
        let p = o.position_m().truncate();
        if let Some(k) = land.polygon_at(p) {
            let poly = &land.polygons()[k];
            return Err(Error::invalid(
                Problem::Conflict,
                format!("object[{i}].position_m"),
                fmt_vec(o.position_m()),
                format!(
                    "object {:?} stands on land: inside land polygon {:?} from {}; move it onto the water",
                    o.name(),
                    poly.name,
                    poly.source
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses objects standing inside a structure's footprint.
fn check_objects_outside_structures(
    objects: &[SceneObject],
    land: &crate::land::Land,
) -> Result<()> {
    for (i, o) in objects.iter().enumerate() {
        let p = o.position_m();
        if let Some(k) = land.structure_at(p.truncate()) {
            let s = &land.surface()[k];
            if p.z < s.top_m {
                return Err(Error::invalid(
                    Problem::Conflict,
                    format!("object[{i}].position_m"),
                    fmt_vec(p),
                    format!(
                        "object {:?} stands inside structure {:?} from {}; move it onto the water",
                        o.name(),
                        s.name,
                        s.source
                    ),
                ));
            }
        }
    }
    Ok(())
}

impl Scene {
    /// Whether `other` is this scene but for its radar's waveform and receiver
    /// ([`Radar::with_waveform_of`]): the same objects, environment, scattering, own ship,
    /// processing, and the same radar position, carrier, power, antenna and scan — so that
    /// both trace alike.
    pub fn same_world_as(&self, other: &Scene) -> bool {
        let mut mine = self.clone();
        mine.radar = self.radar.with_waveform_of(&other.radar);
        mine == *other
    }

    /// Assembles a scene from validated parts, checking what involves more than one of them:
    /// object names are unique, every object reaches above the sea surface and none sits on
    /// the radar.
    pub fn new(
        radar: Radar,
        environment: Environment,
        scattering: ScatteringConfig,
        objects: Vec<SceneObject>,
    ) -> Result<Scene> {
        for (i, obj) in objects.iter().enumerate() {
            if objects[..i].iter().any(|p| p.name() == obj.name()) {
                return Err(Error::invalid(
                    Problem::Conflict,
                    format!("object[{i}].name"),
                    format!("\"{}\"", obj.name()),
                    "another object already has this name",
                ));
            }
            let top_m = obj.top_m();
            if top_m < 0.0 {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    format!("object \"{}\".position_m", obj.name()),
                    fmt_vec(obj.position_m()),
                    format!("the object lies entirely below the sea surface (its highest point is at z = {top_m:.2} m; the sea is the plane z = 0): a radar cannot see it; raise it"),
                ));
            }
            let radius_m = obj.shape().bounding_radius_m();
            let clearance = radius_m.max(0.5);
            let dist = (obj.bounding_centre_m() - radar.position_m()).length();
            if dist < clearance {
                let why = if radius_m > 0.5 {
                    format!("the radar (radar.position_m = {}) is inside the object's bounding sphere: its centre is {dist:.1} m from the radar and its bounding radius is {radius_m:.1} m; move it at least {clearance:.2} m away or make it smaller", fmt_vec(radar.position_m()))
                } else {
                    format!("the object is at the radar's position (radar.position_m = {}); it must be at least {clearance:.2} m away", fmt_vec(radar.position_m()))
                };
                return Err(Error::invalid(
                    Problem::Conflict,
                    format!("object \"{}\".position_m", obj.name()),
                    fmt_vec(obj.position_m()),
                    why,
                ));
            }
        }
        check_trace_memory(&radar, &environment, &scattering, &objects)?;
        Ok(Scene {
            radar,
            environment,
            scattering,
            objects,
            own_ship: None,
            processing: Processing::default(),
            receiver: None,
            artefacts: artefacts::Artefacts::default(),
        })
    }

    /// The scene with the video chain `receiver` (None: calibrated outputs only).
    pub fn with_receiver(mut self, receiver: Option<receiver::VideoSettings>) -> Scene {
        self.receiver = receiver;
        self
    }

    /// The scene with the artefacts `artefacts` switched on.
    pub fn with_artefacts(mut self, artefacts: artefacts::Artefacts) -> Scene {
        self.artefacts = artefacts;
        self
    }

    /// The artefacts the scene switches on.
    pub fn artefacts(&self) -> &artefacts::Artefacts {
        &self.artefacts
    }

    /// The receiver's video chain, if the scene has a `[receiver]` table.
    pub fn receiver(&self) -> Option<&receiver::VideoSettings> {
        self.receiver.as_ref()
    }

    /// The scene processed with `processing`.
    pub fn with_processing(mut self, processing: Processing) -> Scene {
        self.processing = processing;
        self
    }

    /// The scene with the radar riding on `own_ship`.
    pub fn with_own_ship(mut self, own_ship: OwnShip) -> Scene {
        self.own_ship = Some(own_ship);
        self
    }

    /// Reads and validates a scene file (errors name the file, line and field).
    pub fn load(path: &Path) -> Result<Scene> {
        LoadedSpec::read(path)?.build()
    }

    /// Parses and validates scene TOML; `origin` names the source in errors and mesh files are
    /// found relative to the current directory.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Scene> {
        LoadedSpec::from_toml(text, origin, Path::new("."))?.build()
    }

    /// Validates a parsed scene description; mesh files are found relative to the current
    /// directory.
    pub fn from_spec(spec: &SceneSpec) -> Result<Scene> {
        Scene::from_spec_in(spec, Path::new("."))
    }

    /// Validates a parsed scene description whose mesh files are relative to `base_dir`. The
    /// `[display]` table is not part of the model (see [`crate::products::ppi::PpiSettings`]).
    pub fn from_spec_in(spec: &SceneSpec, base_dir: &Path) -> Result<Scene> {
        let radar = radar::build_radar(&spec.radar, spec.environment.polarisation, base_dir)?;
        let ground = land::build_land(&spec.land, spec.geo.as_ref(), base_dir)?;
        let structures =
            land::build_structures(&spec.structure, spec.geo.as_ref(), base_dir, &ground)?;
        let scattering = scattering::build_scattering(&spec.scattering)?;
        let mut meshes = world::LoadedMeshes::new();
        let mut objects = spec
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| world::build_object(i, o, base_dir, &mut meshes))
            .collect::<Result<Vec<_>>>()?;
        for (i, o) in spec.objects.iter().enumerate() {
            let Some(mmsi) = o.mmsi else { continue };
            if let Some(first) = spec.objects[..i].iter().position(|p| p.mmsi == Some(mmsi)) {
                return Err(Error::invalid(
                    Problem::Conflict,
                    format!("object \"{}\".mmsi", objects[i].name()),
                    mmsi,
                    format!(
                        "object \"{}\" has the same MMSI: each transponder has its own",
                        objects[first].name()
                    ),
                ));
            }
        }
        check_objects_on_water(&objects, &ground)?;
        check_antenna_above_ground(&radar, &ground)?;
        let first_structure = objects.len();
        let footprints = structures
            .iter()
            .enumerate()
            .map(|(k, s)| s.footprint(k, (first_structure + k) as u32))
            .collect();
        for s in &structures {
            // A footprint named like an earlier object (features of one name: a pier's
            // segments) takes the first free `-k`.
            let mut name = s.name.clone();
            let mut k = 1;
            while objects.iter().any(|o| o.name() == name) {
                name = format!("{}-{k}", s.name);
                k += 1;
            }
            let centre = s.bounding_centre_m();
            let radius = s.bounding_radius_m();
            if (centre - radar.position_m()).length() < radius.max(0.5) {
                return Err(Error::invalid(
                    Problem::Conflict,
                    s.source.clone(),
                    format!("{:?}", s.name),
                    format!(
                        "the radar (radar.position_m = {}) stands within structure {:?}'s bounding sphere ({radius:.0} m about its middle), where its ray tubes cannot be aimed: split it into shorter structures or move the radar",
                        fmt_vec(radar.position_m()),
                        s.name
                    ),
                ));
            }
            objects.push(SceneObject::new(
                name,
                s.kind.as_str(),
                crate::geometry::ShapeGeometry::Mesh {
                    mesh: std::sync::Arc::new(s.mesh()?),
                },
                s.anchor_m(),
                glam::DMat3::IDENTITY,
            )?);
        }
        let environment = environment::build_environment(
            &spec.environment,
            radar.carrier_freq_hz(),
            radar.polarisation() == Polarisation::Hh,
        )?
        .with_land(ground.with_structures(footprints));
        check_objects_outside_structures(&objects[..first_structure], environment.land())?;
        let processing = processing::build_processing(&spec.processing, &radar)?;
        let video = spec
            .receiver
            .as_ref()
            .map(receiver::VideoSettings::from_spec)
            .transpose()?;
        let artefacts = artefacts::build_artefacts(&spec.artefacts, spec.own_ship.as_ref())?;
        if artefacts.multiple_echoes.is_some() && spec.own_ship.is_none() {
            return Err(Error::invalid(
                Problem::Conflict,
                "artefacts.multiple_echoes",
                "given",
                "multiple echoes bounce between a ship abeam and the own ship's side: add an [own_ship] table",
            ));
        }
        let scene = Scene::new(radar, environment, scattering, objects)?
            .with_processing(processing)
            .with_receiver(video)
            .with_artefacts(artefacts);
        Ok(match &spec.own_ship {
            None => scene,
            Some(s) => {
                let course_deg = s.course_deg.unwrap_or(0.0);
                let ship = OwnShip::new(
                    s.speed_kn.unwrap_or(0.0),
                    course_deg,
                    s.heading_deg.unwrap_or(course_deg),
                )?;
                let mast_height_m = scene.radar().position_m().z;
                scene.with_own_ship(world::build_own_ship_wave(ship, s, mast_height_m)?)
            }
        })
    }

    /// The radar.
    pub fn radar(&self) -> &Radar {
        &self.radar
    }

    /// The environment.
    pub fn environment(&self) -> &Environment {
        &self.environment
    }

    /// The scattering settings.
    pub fn scattering(&self) -> &ScatteringConfig {
        &self.scattering
    }

    /// The objects, in scene-file order (their index is their truth id).
    pub fn objects(&self) -> &[SceneObject] {
        &self.objects
    }

    /// The processing settings.
    pub fn processing(&self) -> &Processing {
        &self.processing
    }

    /// The ship the radar rides on (None: the radar stands still).
    pub fn own_ship(&self) -> Option<&OwnShip> {
        self.own_ship.as_ref()
    }

    /// Whether nothing moves: no object has a motion and there is no own ship. A still
    /// scene is the same at every time and is traced once.
    pub fn is_still(&self) -> bool {
        self.own_ship.is_none() && self.objects.iter().all(|o| o.motion().is_none())
    }
}
