//! The scene file as written by users (TOML), before validation. Friendly units, each in the
//! field's name. `docs/formats.md` documents every field; `xbandsim schema` prints the JSON
//! Schema generated from these types.

use crate::choice::{Colormap, Motion, Orientation};
use crate::choice::{
    Integration, Polarisation, ProcessingMode, PulseLength, ScatteringModel, Transmitter,
};
use crate::choice::{InterferenceRejection, StcMode};
use crate::environment::clutter::Sigma0Model;
use crate::geometry::MeshUnit;
use crate::propagation::SeaRoughness;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `radar.preset`: the radar a scene starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum RadarPreset {
    /// A Furuno DRS4D-NXT-like solid-state X-band radar (docs/formats.md lists its values).
    #[default]
    #[serde(rename = "drs4d-nxt")]
    Drs4dNxt,
    /// A 4 kW magnetron set in a 24-inch radome for small craft.
    #[serde(rename = "magnetron-4kw-radome")]
    Magnetron4kwRadome,
    /// A 25 kW magnetron set with a 6 ft open array, as fitted to fishing vessels and ships.
    #[serde(rename = "magnetron-25kw-open-array")]
    Magnetron25kwOpenArray,
    /// An IMO-class S-band ship radar: 3 GHz, 30 kW magnetron, 12 ft open array.
    #[serde(rename = "s-band-30kw")]
    SBand30kw,
    /// A solid-state set with a 4 ft open array.
    #[serde(rename = "solid-state-open-array")]
    SolidStateOpenArray,
}

/// `radar.antenna_pattern`: the azimuth plane's pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum AntennaPatternName {
    /// A uniformly illuminated aperture's sinc² (first sidelobe −13.3 dB).
    #[default]
    Sinc2,
    /// A tapered slotted-waveguide array: Taylor's n̄ pattern, a far-sidelobe floor and a
    /// back lobe.
    Taylor,
}

/// `radar.window`: the matched filter's reference window.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum WindowName {
    /// Rectangular (no weighting); "rectangular" also reads.
    #[default]
    #[serde(alias = "rectangular")]
    None,
    /// Hamming.
    Hamming,
    /// Taylor with `taylor_nbar` and `taylor_sidelobe_db`.
    Taylor,
}

/// `radar.pulse_mode`: one pulse, or a short pulse for near range joined to the long one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum PulseModeName {
    /// The LFM pulse alone (ranges inside c·T/2 are eclipsed).
    #[default]
    Single,
    /// A short pulse (`short_pulse_width_us`, `short_bandwidth_mhz`) for the range bins inside
    /// the long pulse's eclipse, the long LFM pulse beyond: no blind zone.
    Combined,
}

/// `environment.clutter_distribution`: the amplitude statistics of sea clutter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ClutterDistributionName {
    /// K (Gamma texture × exponential speckle).
    #[default]
    K,
    /// Weibull amplitude.
    Weibull,
    /// Log-normal texture.
    Lognormal,
    /// Complex Gaussian (Rayleigh amplitude).
    Rayleigh,
}

pub use crate::choice::ShapeName;

impl ShapeName {
    /// Every shape, in the order the documentation lists them.
    pub const ALL: [ShapeName; 10] = [
        ShapeName::Point,
        ShapeName::Sphere,
        ShapeName::Plate,
        ShapeName::Trihedral,
        ShapeName::Dihedral,
        ShapeName::Cylinder,
        ShapeName::Box,
        ShapeName::Mesh,
        ShapeName::Vessel,
        ShapeName::Buoy,
    ];

    /// The name as written in a scene file.
    pub fn as_str(&self) -> &'static str {
        match self {
            ShapeName::Point => "point",
            ShapeName::Sphere => "sphere",
            ShapeName::Plate => "plate",
            ShapeName::Trihedral => "trihedral",
            ShapeName::Dihedral => "dihedral",
            ShapeName::Cylinder => "cylinder",
            ShapeName::Box => "box",
            ShapeName::Mesh => "mesh",
            ShapeName::Vessel => "vessel",
            ShapeName::Buoy => "buoy",
        }
    }
}

/// A whole scene file: radar, environment, display, scattering settings and objects.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// The radar: a preset and any overrides.
    #[serde(default)]
    pub radar: RadarSpec,
    /// Noise and (later) sea, rain and propagation.
    #[serde(default)]
    pub environment: EnvironmentSpec,
    /// How the PPI pictures are drawn.
    #[serde(default)]
    pub display: DisplaySpec,
    /// Which scattering model and how many rays.
    #[serde(default)]
    pub scattering: ScatteringSpec,
    /// The ship the radar rides on (none: the radar stands still).
    pub own_ship: Option<OwnShipSpec>,
    /// How pulses are fired and processed.
    #[serde(default)]
    pub processing: ProcessingSpec,
    /// The receiver's video chain (none: the calibrated outputs only).
    pub receiver: Option<ReceiverSpec>,
    /// Artefacts switched on: other radars' interference (none by default).
    #[serde(default)]
    pub artefacts: ArtefactsSpec,
    /// The objects in the scene (`[[object]]` tables).
    #[serde(default, rename = "object")]
    pub objects: Vec<ObjectSpec>,
    /// Where the scene lies on the earth: the origin of lon/lat inputs.
    pub geo: Option<GeoSpec>,
    /// Land: coast polygons with a height and a terrain (`[[land]]` tables).
    #[serde(default)]
    pub land: Vec<LandSpec>,
    /// Man-made structures: breakwaters, quays, piers, buildings, tanks, cranes
    /// (`[[structure]]` tables), traced as triangles like every object.
    #[serde(default)]
    pub structure: Vec<BuiltStructureSpec>,
}

/// `[[structure]]`: a breakwater, quay, pier, building, tank or crane: a footprint extruded
/// to a height (a polygon written here, every polygon of a GeoJSON file, a box or a
/// circle), made into triangles and traced with physical optics like an object.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BuiltStructureSpec {
    /// Name (default: each feature's `name` property, else `structure-<i>`).
    pub name: Option<String>,
    /// What it is: "breakwater", "quay", "pier", "building" (default), "tank" or "crane";
    /// its class in the ground truth.
    pub kind: Option<crate::land::StructureKind>,
    /// Footprint corners `[x, y]` in metres (local), not closed.
    pub polygon_m: Option<Vec<[f64; 2]>>,
    /// Footprints from a GeoJSON file of Polygon/MultiPolygon features (holes allowed),
    /// relative to the scene file; a feature's `height_m` property overrides `height_m`.
    pub geojson: Option<String>,
    /// Coordinates of the GeoJSON: "local_m" (default) or "wgs84" (needs `[geo]`).
    pub crs: Option<LandCrs>,
    /// A box or circle's centre `[x, y]`, m (with `size_m` or `radius_m`).
    pub position_m: Option<[f64; 2]>,
    /// A box's length along its heading and its width, `[length, width]`, m.
    pub size_m: Option<[f64; 2]>,
    /// A box's heading: its length turned from north toward east, degrees (default 0).
    pub yaw_deg: Option<f64>,
    /// A circular footprint's radius (a tank), m.
    pub radius_m: Option<f64>,
    /// Height of its top over its base, m (required unless every feature sets `height_m`).
    pub height_m: Option<f64>,
    /// Height of its base over the sea, m (default: the ground's height under the
    /// footprint's first corner: 0 on the water, the land's top on land).
    pub base_m: Option<f64>,
}

/// `[geo]`: the scene's origin on the WGS84 ellipsoid. Lon/lat inputs (`[[land]]` with
/// `crs = "wgs84"`) go to local metres by the azimuthal equidistant projection about it.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GeoSpec {
    /// Longitude of the scene's origin (x = y = 0), degrees east (required).
    pub origin_lon_deg: Option<f64>,
    /// Latitude of the scene's origin, degrees north (required).
    pub origin_lat_deg: Option<f64>,
}

/// `[[land]].crs`: the coordinates of a land table's polygons.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum LandCrs {
    /// x east, y north in metres from the scene's origin.
    #[default]
    LocalM,
    /// Longitude, latitude in degrees (WGS84), placed about `[geo]`'s origin.
    Wgs84,
}

/// `[[land]].edge`: how the ground rises from the shoreline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum LandEdgeName {
    /// A vertical face to the top at the shoreline.
    #[default]
    Cliff,
    /// A plane slope to the top over `beach_width_m`.
    Beach,
}

/// `[[land]]`: land polygons from a GeoJSON file or written here, with a flat top, an edge
/// and a terrain.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LandSpec {
    /// Name (default: each feature's `name` property, else `land-<k>`).
    pub name: Option<String>,
    /// A GeoJSON file of Polygon/MultiPolygon features, relative to the scene file.
    pub geojson: Option<String>,
    /// One polygon written here instead: its corners `[x, y]` in metres (crs `local_m`), not
    /// closed (the last corner joins the first).
    pub polygon_m: Option<Vec<[f64; 2]>>,
    /// Coordinates of the GeoJSON: "local_m" (default) or "wgs84" (needs `[geo]`).
    pub crs: Option<LandCrs>,
    /// Height of the flat top over the sea, m (default 10; a feature's `height_m` property
    /// overrides it).
    pub height_m: Option<f64>,
    /// "cliff" (default) or "beach".
    pub edge: Option<LandEdgeName>,
    /// Width of a beach's slope from the shoreline to the top, m (default 50).
    pub beach_width_m: Option<f64>,
    /// "rock" (default), "sand", "grass", "forest" or "urban".
    pub terrain: Option<crate::land::Terrain>,
    /// γ of `σ0 = γ·sin ψ` at 10 GHz, dB (default: the terrain's).
    pub gamma_db: Option<f64>,
    /// Weibull shape of a land cell's amplitude (default: the terrain's; 2 is Rayleigh).
    pub weibull_shape: Option<f64>,
    /// A height map instead of the flat top: a 16-bit grey PNG or a 2-D `.npy` array
    /// (north row first), relative to the scene file.
    pub height_map: Option<String>,
    /// The height map's extent `[x_min, y_min, x_max, y_max]`, local metres: its corner
    /// samples lie on its corners; every polygon of the table must lie inside it.
    pub height_map_extent_m: Option<[f64; 4]>,
    /// Metres per unit of the height map's values (default 1).
    pub height_map_scale_m: Option<f64>,
}

/// `[radar]`: every field overrides the preset's value.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RadarSpec {
    /// Preset to start from: "drs4d-nxt" (default).
    pub preset: Option<RadarPreset>,
    /// Antenna phase centre, ENU metres; z is the height above the sea.
    pub position_m: Option<[f64; 3]>,
    /// Carrier frequency, GHz.
    pub frequency_ghz: Option<f64>,
    /// LFM swept bandwidth, MHz.
    pub bandwidth_mhz: Option<f64>,
    /// Pulse width, microseconds.
    pub pulse_width_us: Option<f64>,
    /// Matched-filter reference window: "none", "hamming" or "taylor".
    pub window: Option<WindowName>,
    /// Taylor window: number of nearly constant sidelobes n̄ (default 4).
    pub taylor_nbar: Option<usize>,
    /// Taylor window: peak sidelobe level, dB (default -35).
    pub taylor_sidelobe_db: Option<f64>,
    /// Peak transmit power, W.
    pub peak_power_w: Option<f64>,
    /// Receiver noise figure, dB.
    pub noise_figure_db: Option<f64>,
    /// Total system loss L, dB (≥ 0).
    pub system_loss_db: Option<f64>,
    /// Peak antenna gain, dBi (default: from the beamwidths, uniform aperture).
    pub gain_dbi: Option<f64>,
    /// Azimuth 3-dB beamwidth, degrees.
    pub azimuth_beamwidth_deg: Option<f64>,
    /// Elevation 3-dB beamwidth, degrees.
    pub elevation_beamwidth_deg: Option<f64>,
    /// Beam axis elevation above horizontal, degrees.
    pub tilt_deg: Option<f64>,
    /// A measured azimuth cut, CSV `angle_deg,gain_db` (relative to the scene file): sets the
    /// azimuth pattern and beamwidth.
    pub azimuth_pattern_file: Option<String>,
    /// A measured elevation cut, CSV `angle_deg,gain_db` (angles from the beam axis): sets the
    /// elevation pattern and beamwidth.
    pub elevation_pattern_file: Option<String>,
    /// The azimuth pattern: "sinc2" (a uniform aperture) or "taylor" (a tapered array over
    /// the whole circle, with `sidelobe_db`, `pattern_nbar`, `far_sidelobe_db`, `back_lobe_db`).
    pub antenna_pattern: Option<AntennaPatternName>,
    /// Taylor pattern: its near sidelobes, dB under the peak (one-way), −60 … −14.
    pub sidelobe_db: Option<f64>,
    /// Taylor pattern: n̄, 2 … 12.
    pub pattern_nbar: Option<usize>,
    /// Taylor pattern: the floor of its far sidelobes, dB under the peak (one-way).
    pub far_sidelobe_db: Option<f64>,
    /// Taylor pattern: the back lobe (behind the antenna), dB under the peak (one-way).
    pub back_lobe_db: Option<f64>,
    /// Complex (I/Q) sample rate, MHz.
    pub sample_rate_mhz: Option<f64>,
    /// Pulse repetition frequency, Hz (the mean rate when `prf_stagger` is given).
    pub prf_hz: Option<f64>,
    /// Staggered pulse intervals: a list of 2 to 8 positive PRI ratios, cycled pulse after
    /// pulse (e.g. [4, 5]: intervals 4/4.5 and 5/4.5 of 1/prf_hz). Pulse mode only matters.
    pub prf_stagger: Option<Vec<f64>>,
    /// "solid_state" (default: an LFM chirp, pulse compression, coherent) or "magnetron" (an
    /// unmodulated pulse of random start phase; no `bandwidth_mhz`, no combined mode).
    pub transmitter: Option<Transmitter>,
    /// The displayed range scale, nautical miles: one of the preset's scales; sets
    /// `max_range_m`, the pulse and the PRF from the preset's pulse table.
    pub range_scale_nm: Option<f64>,
    /// With `range_scale_nm`: "short", "medium" or "long", one the scale offers (default:
    /// the scale's own).
    pub pulse_length: Option<PulseLength>,
    /// "single" (default) or "combined" (short pulse near, long pulse far).
    pub pulse_mode: Option<PulseModeName>,
    /// Combined mode: width of the short pulse, microseconds (default 0.08).
    pub short_pulse_width_us: Option<f64>,
    /// Combined mode: LFM bandwidth of the short pulse, MHz (default: unmodulated).
    pub short_bandwidth_mhz: Option<f64>,
    /// Antenna rotation rate, revolutions per minute.
    pub rotation_rpm: Option<f64>,
    /// Largest range written to the outputs, m.
    pub max_range_m: Option<f64>,
    /// Number of spokes (beam positions) per revolution, 1..=8192.
    pub spokes: Option<usize>,
    /// Blank the receiver while transmitting (targets nearer than c·T/2 are eclipsed).
    pub receiver_blanking: Option<bool>,
    /// Transmit/receive polarisation: "HH" (default) or "VV".
    pub polarisation: Option<Polarisation>,
}

/// `[environment]`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Add receiver thermal noise (default true).
    pub noise: Option<bool>,
    /// Reflections from the sea surface at z = 0: four-path multipath (default true).
    pub multipath: Option<bool>,
    /// Sea surface temperature, °C (default 20), for the sea-water permittivity.
    pub sea_temperature_c: Option<f64>,
    /// Sea salinity, psu (default 35).
    pub sea_salinity_psu: Option<f64>,
    /// Rms height of the sea surface, m (default: from the sea state), for the specular
    /// roughness factor.
    pub sea_rms_height_m: Option<f64>,
    /// Two-way atmospheric attenuation, dB per km of range (default 0).
    pub two_way_attenuation_db_per_km: Option<f64>,
    /// Douglas/WMO sea state 0–6 (default 2): sets σ0, the wave height and the wind.
    pub sea_state: Option<f64>,
    /// Direction the wind blows from, nautical degrees (default 0: from the north).
    pub wind_direction_deg: Option<f64>,
    /// Direction the swell comes from, nautical degrees (default: the wind direction); sets
    /// the K shape's look-direction term −cos(2θ_sw)/3.
    pub swell_direction_deg: Option<f64>,
    /// Rough-sea reduction of the specular reflection: "miller-brown-vegh" (default) or
    /// "ament".
    pub sea_roughness: Option<SeaRoughness>,
    /// Polarisation "HH" or "VV" (same as `radar.polarisation`; give one of the two).
    pub polarisation: Option<Polarisation>,
    /// Sea clutter on or off (default true).
    pub clutter: Option<bool>,
    /// σ0 model: "nrl" (default) or "git".
    pub clutter_model: Option<Sigma0Model>,
    /// Amplitude statistics: "k" (default), "weibull", "lognormal" or "rayleigh".
    pub clutter_distribution: Option<ClutterDistributionName>,
    /// K shape ν of a resolution cell's Gamma texture (default: Ward's empirical formula
    /// for the cell's area, grazing angle and swell direction).
    pub clutter_shape_nu: Option<f64>,
    /// Weibull shape c of the clutter amplitude, 0.3–2 (2 = Rayleigh; default 1.5).
    pub clutter_weibull_shape: Option<f64>,
    /// Log-normal texture: standard deviation of 10·log10 of a cell's texture, dB
    /// (default 3).
    pub clutter_lognormal_sigma_db: Option<f64>,
    /// Correlation length of the clutter texture, m (default 30).
    pub clutter_correlation_m: Option<f64>,
    /// Speed at which the texture drifts downwind, m/s (default 1.14 × the sea state's wind).
    pub clutter_drift_m_per_s: Option<f64>,
    /// Mean drift speed of sea-clutter scatterers downwind, m/s, for their Doppler (pulse
    /// mode; default 0.25 × the sea state's wind for HH, 0.12 × for VV).
    pub clutter_doppler_velocity_mps: Option<f64>,
    /// Standard deviation of the sea clutter's radial velocity, m/s (default 0.1 × the
    /// wind, at least 0.1).
    pub clutter_doppler_spread_mps: Option<f64>,
    /// Speed at which rain drifts downwind, m/s (default: the sea state's wind).
    pub rain_velocity_mps: Option<f64>,
    /// Standard deviation of the rain's radial velocity, m/s (default 1.5).
    pub rain_doppler_spread_mps: Option<f64>,
    /// Rain on or off (default true; rain needs a rate or cells).
    pub rain: Option<bool>,
    /// Uniform rain rate everywhere, mm/h (default 0).
    pub rain_rate_mm_per_h: Option<f64>,
    /// Height of the rain top, m (default 3000).
    pub rain_top_m: Option<f64>,
    /// Rain cells: `[[environment.rain_cell]]` tables.
    #[serde(default, rename = "rain_cell")]
    pub rain_cells: Vec<RainCellSpec>,
    /// Earth curvature with the 4/3-earth model: horizon and grazing angles (default true).
    pub earth_curvature: Option<bool>,
}

/// One `[[environment.rain_cell]]`: a vertical cylinder of rain.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RainCellSpec {
    /// Centre, east and north, m.
    pub centre_m: Option<[f64; 2]>,
    /// Radius, m.
    pub radius_m: Option<f64>,
    /// Rain rate, mm/h.
    pub rate_mm_per_h: Option<f64>,
}

/// `[display]`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DisplaySpec {
    /// Side of the square PPI images, pixels (default 1024).
    pub image_size_px: Option<u32>,
    /// Spacing of the range rings drawn on ppi.png, m (default 100; 0 for none).
    pub range_ring_spacing_m: Option<f64>,
    /// Colour map of ppi.png: "viridis" (default), "green" or "gray".
    pub colormap: Option<Colormap>,
    /// Power mapped to the bottom of the colour scale, dB over noise (default 0).
    pub min_db: Option<f64>,
    /// Power mapped to the top of the colour scale, dB over noise (default 60).
    pub max_db: Option<f64>,
    /// "north-up" (default), "head-up" or "course-up" (the last two need `[own_ship]`).
    pub orientation: Option<Orientation>,
    /// "relative" (default: the own ship at the image centre) or "true" (the picture fixed to
    /// the ground, centred on the antenna's position at t = 0; the own ship moves across it).
    pub motion: Option<Motion>,
    /// Draw echoes closing at 3 kn or faster in red on ppi.png, from each cell's pulse-pair
    /// radial velocity, and write radial_velocity.npy (default false; needs
    /// `[processing] mode = "pulse"`).
    pub doppler_colour: Option<bool>,
    /// Mean pulse power a cell needs to be coloured, dB over noise (default 10).
    pub doppler_colour_threshold_db: Option<f64>,
}

/// `[scattering]`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ScatteringSpec {
    /// "po" (physical-optics ray tubes, calibrated; default) or "paper" (the seed paper's
    /// amplitude law A = 1/(1 + l²/1000) on a uniform scan grid of rays).
    pub model: Option<ScatteringModel>,
    /// Ray-tube spacing in wavelengths for the "po" model (default 0.5).
    pub ray_spacing_wavelengths: Option<f64>,
    /// Cap on rays per object and grid for the "po" model (default 32768); the spacing grows
    /// to respect it.
    pub max_rays_per_object: Option<usize>,
    /// Maximum number of bounces traced (default 3).
    pub max_bounces: Option<usize>,
    /// "po" model: add the fringe returns of the objects' wedge edges (physical theory of
    /// diffraction; default true).
    pub edge_diffraction: Option<bool>,
    /// "paper" model: rays per degree of azimuth in the scan grid (default 100).
    pub paper_rays_per_degree_az: Option<usize>,
    /// "paper" model: rays across the elevation beamwidth (default 100).
    pub paper_rays_elevation: Option<usize>,
    /// "paper" model: voltage of a unit-amplitude ray, microvolts (default 1000).
    pub paper_reference_voltage_uv: Option<f64>,
}

/// One `[[object]]`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Unique name (default "object-N").
    pub name: Option<String>,
    /// Class label for ML ground truth (default "object").
    pub class: Option<String>,
    /// "point", "sphere", "plate", "trihedral", "dihedral", "cylinder", "box", "mesh",
    /// "vessel" or "buoy".
    pub shape: Option<ShapeName>,
    /// Position in ENU metres (reference point of the shape, see docs/formats.md).
    pub position_m: Option<[f64; 3]>,
    /// Heading: turns the object's +y toward +x (clockwise from above), degrees.
    pub yaw_deg: Option<f64>,
    /// Raises the object's +y toward +z, degrees.
    pub pitch_deg: Option<f64>,
    /// Turns the object's +x toward -z about its +y, degrees.
    pub roll_deg: Option<f64>,
    /// point: radar cross-section, m².
    pub rcs_m2: Option<f64>,
    /// sphere, cylinder, buoy (its float): radius, m.
    pub radius_m: Option<f64>,
    /// plate, dihedral: width, m.
    pub width_m: Option<f64>,
    /// plate, dihedral, cylinder: height, m; buoy: the float's height above the waterline, m.
    pub height_m: Option<f64>,
    /// trihedral: edge length, m.
    pub edge_m: Option<f64>,
    /// box: edge lengths along x, y, z, m.
    pub size_m: Option<[f64; 3]>,
    /// mesh: OBJ, STL or glTF file, relative to the scene file.
    pub mesh_file: Option<String>,
    /// mesh: unit of the file's coordinates: "m" (default), "cm", "mm", "ft" or "in".
    pub mesh_units: Option<MeshUnit>,
    /// mesh: extra scale factor applied after the unit (default 1).
    pub mesh_scale: Option<f64>,
    /// vessel: length overall, m.
    pub length_m: Option<f64>,
    /// vessel: beam (deck width), m (default 0.25 × length).
    pub beam_m: Option<f64>,
    /// vessel: height of the deck above the waterline, m (default 0.1 × length).
    pub freeboard_m: Option<f64>,
    /// vessel: deck structures, "none" (default), "cabin", "wheelhouse", "bridge-aft",
    /// "bridge-fore" or "decks".
    pub superstructure: Option<crate::geometry::Superstructure>,
    /// vessel: height of the deck structures above the deck, m (default: a fraction of the
    /// beam that depends on `superstructure`).
    pub superstructure_height_m: Option<f64>,
    /// vessel: a detailed vessel with the structures of its type (instead of
    /// `superstructure`): "container-ship", "bulk-carrier", "tanker", "ferry", "trawler",
    /// "workboat", "yacht", "rib" or "kayak" (docs/targets.md, "Detailed vessels");
    /// `superstructure_height_m` is then its deck house's height.
    pub outfit: Option<crate::geometry::Outfit>,
    /// vessel: the draw that varies a detailed vessel's structures (stack heights, holds,
    /// cranes, booms), an integer from 0 to 2⁶³ − 1 (default 0).
    pub outfit_seed: Option<u64>,
    /// vessel, buoy: height of the mast's (buoy: the structure's) top above the waterline, m
    /// (default: no mast).
    pub mast_height_m: Option<f64>,
    /// buoy: edge of each corner of the octahedral radar reflector on top, m (default: none).
    pub reflector_edge_m: Option<f64>,
    /// Speed over ground, knots (with `course_deg`).
    pub speed_kn: Option<f64>,
    /// Course over ground, nautical degrees (0 = north, 90 = east); the heading follows it
    /// unless `yaw_deg` is given.
    pub course_deg: Option<f64>,
    /// Velocity `[east, north, up]`, m/s (instead of `speed_kn` + `course_deg`).
    pub velocity_mps: Option<[f64; 3]>,
    /// Constant rate of turn, degrees per second (positive to starboard: clockwise from
    /// above); needs a speed.
    pub turn_rate_deg_per_s: Option<f64>,
    /// Piecewise-linear track `[[t_s, east_m, north_m], ...]` (at least two waypoints, in
    /// strictly increasing time); the heading follows the track unless `yaw_deg` is given.
    pub track: Option<Vec<[f64; 3]>>,
    /// Wave-induced heave amplitude, m (needs `motion_period_s`).
    pub heave_amplitude_m: Option<f64>,
    /// Wave-induced roll amplitude, degrees (needs `motion_period_s`).
    pub roll_amplitude_deg: Option<f64>,
    /// Wave-induced pitch amplitude, degrees (needs `motion_period_s`).
    pub pitch_amplitude_deg: Option<f64>,
    /// Period of the wave-induced motion, s.
    pub motion_period_s: Option<f64>,
    /// Phase of the wave-induced motion at t = 0, degrees (default 0).
    pub motion_phase_deg: Option<f64>,
    /// Its MMSI (1–999 999 999): the object carries an AIS transponder, and `xbandsim nmea`
    /// sends its reports (docs/live.md). Unique among the scene's objects.
    pub mmsi: Option<u32>,
    /// Its AIS transponder's class: "A" (default; ships under SOLAS) or "B" (small craft).
    /// Needs `mmsi`.
    pub ais_class: Option<AisClass>,
}

/// `[[object]].ais_class`: an AIS transponder's class (ITU-R M.1371).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
pub enum AisClass {
    /// Class A: position reports every 2–10 s under way (messages 1–3), static and voyage
    /// data every 6 minutes (message 5).
    #[default]
    A,
    /// Class B (carrier sense): position reports every 30 s above 2 kn (message 18), static
    /// data every 6 minutes (message 24, parts A and B).
    B,
}

/// `[processing]`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProcessingSpec {
    /// "spoke" (default: one pulse per spoke, the fast path) or "pulse" (every pulse at the
    /// PRF, each seeing the scene at its own time).
    pub mode: Option<ProcessingMode>,
    /// How a spoke's pulses are combined: "noncoherent" (default), "coherent" or "none".
    pub integration: Option<Integration>,
    /// Pulses per Doppler CPI (pulse mode; default: the fewest pulses a spoke gets).
    pub doppler_pulses: Option<usize>,
    /// Window across the CPI: "hamming" (default), "none" or "taylor" (n̄ = 4, −35 dB).
    pub doppler_window: Option<WindowName>,
}

/// `[own_ship]`: the ship the radar rides on. The antenna (`radar.position_m` at t = 0)
/// moves with it.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OwnShipSpec {
    /// Speed over ground, knots (default 0).
    pub speed_kn: Option<f64>,
    /// Course over ground, nautical degrees (default 0).
    pub course_deg: Option<f64>,
    /// Heading of the bow, nautical degrees (default: the course).
    pub heading_deg: Option<f64>,
    /// Roll amplitude in the waves, degrees (0–60): roll = A·sin(2πt/T + φ), starboard down
    /// positive. Tilts the beam and swings the antenna on its mast.
    pub roll_amplitude_deg: Option<f64>,
    /// Pitch amplitude, degrees (0–60): pitch = A·cos(2πt/T + φ), bow up positive.
    pub pitch_amplitude_deg: Option<f64>,
    /// Period T of the roll and pitch, s (needed with an amplitude).
    pub motion_period_s: Option<f64>,
    /// Phase φ of the roll and pitch, degrees (default 0).
    pub motion_phase_deg: Option<f64>,
    /// Its structure in the beam (`[[own_ship.structure]]`): masts and funnels, each a blind
    /// sector behind it and, with `indirect_db`, indirect echoes on its bearing.
    #[serde(default)]
    pub structure: Vec<StructureSpec>,
}

/// `[receiver]`: the log receiver and video chain after detection (docs/formats.md,
/// "[receiver]"). Its presence adds `video.npy` to a frame's outputs.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ReceiverSpec {
    /// Bits a video sample is quantised to, 1–8 (default 4).
    pub video_bits: Option<u32>,
    /// Video spokes a revolution, 1–8192 (default 2048).
    pub video_spokes: Option<usize>,
    /// Video samples a spoke, 1–8192 (default 512), evenly over the recorded range.
    pub video_samples: Option<usize>,
    /// The log amplifier's dynamic range above the noise, dB: it saturates there (default 80).
    pub log_dynamic_range_db: Option<f64>,
    /// Gain, dB (default 0): lowers the video threshold (6 dB over the noise at 0 dB).
    pub gain_db: Option<f64>,
    /// The span of the video levels above the threshold, dB (default 40).
    pub video_span_db: Option<f64>,
    /// Sea clutter control: "off" (default), "manual" or "auto".
    pub stc: Option<StcMode>,
    /// Manual STC: the deepest attenuation, dB (default 20).
    pub stc_level_db: Option<f64>,
    /// Manual STC: range where the attenuation ends, m (default 4000).
    pub stc_range_m: Option<f64>,
    /// Manual STC: the law's exponent k, attenuation `10·k·log10(stc_range_m/R)` (default 3).
    pub stc_law: Option<f64>,
    /// Auto STC: the level it brings the median clutter down to, dB over noise (default 3).
    pub stc_auto_level_db: Option<f64>,
    /// Rain clutter control: the FTC differentiator's time constant, µs (none: off).
    pub ftc_time_constant_us: Option<f64>,
    /// Interference rejection: "off" (default), "low", "medium" or "high".
    pub interference_rejection: Option<InterferenceRejection>,
    /// Echo averaging over this many scans (1, the default: off), 1–16.
    pub echo_average_scans: Option<u32>,
    /// Echo stretch along range, video samples (0, the default: off), 0–16.
    pub echo_stretch_samples: Option<usize>,
    /// Noise rejection: clear lone video samples (default false).
    pub noise_rejection: Option<bool>,
}

/// `[artefacts]`: the artefacts a scene switches on (docs/formats.md, "[artefacts]").
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ArtefactsSpec {
    /// Second-trace echoes: objects beyond the unambiguous range `c/(2·prf)` echo in the next
    /// pulse's record (default false: they are beyond the recorded range and leave none).
    pub second_trace: Option<bool>,
    /// Other radars nearby (`[[artefacts.interferer]]`): their pulses reach the receiver.
    #[serde(default)]
    pub interferer: Vec<InterfererSpec>,
    /// Radar beacons (`[[artefacts.racon]]`): a Morse character behind the beacon.
    #[serde(default)]
    pub racon: Vec<BeaconSpec>,
    /// Search and rescue transponders (`[[artefacts.sart]]`): 12 dots outward.
    #[serde(default)]
    pub sart: Vec<BeaconSpec>,
    /// Multiple echoes between the own ship's side and a ship abeam
    /// (`[artefacts.multiple_echoes]`; off when left out).
    pub multiple_echoes: Option<MultipleEchoesSpec>,
}

/// `[artefacts.multiple_echoes]`: a ship's echo bouncing between its side and the own ship's
/// side when it lies abeam, parallel, and shows again at 2R, 3R, ...
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MultipleEchoesSpec {
    /// Power lost on each extra round trip to the two sides' reflections, dB (default 6).
    pub round_trip_loss_db: Option<f64>,
    /// The highest echo order drawn: 2 draws the echo at 2R only (default 3).
    pub max_order: Option<u32>,
    /// How far from abeam (and from parallel) the two sides may be, degrees (default 10).
    pub abeam_tolerance_deg: Option<f64>,
    /// The shortest ship whose side bounces the echo back, m along its bow axis (default 30).
    pub min_length_m: Option<f64>,
}

/// `[[artefacts.racon]]` and `[[artefacts.sart]]`: a transponder answering this radar.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BeaconSpec {
    /// Its name (default `racon-<k>` or `sart-<k>`).
    pub name: Option<String>,
    /// Its antenna, ENU m (required).
    pub position_m: Option<[f64; 3]>,
    /// Its effective isotropic radiated power, W (racon 1 W, SART 0.4 W).
    pub eirp_w: Option<f64>,
    /// The power of this radar's pulse at it that triggers it, dBm (−50).
    pub sensitivity_dbm: Option<f64>,
    /// Racon: the Morse letter it sends (default "K").
    pub morse: Option<String>,
    /// Racon: its response's length in range, NM (default 1).
    pub length_nm: Option<f64>,
    /// Racon: its delay before answering, µs (default 0.5).
    pub delay_us: Option<f64>,
}

/// `[[artefacts.interferer]]`: another radar whose pulses reach this one's receiver.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InterfererSpec {
    /// Its name (default `interferer-<k>`).
    pub name: Option<String>,
    /// Its antenna, ENU m (required).
    pub position_m: Option<[f64; 3]>,
    /// Its pulse repetition frequency, Hz (default 1000).
    pub prf_hz: Option<f64>,
    /// Its rotation, rpm (default 22: a set turning a little slower than 24).
    pub rotation_rpm: Option<f64>,
    /// Its antenna's azimuth at t = 0, degrees (default 0).
    pub start_azimuth_deg: Option<f64>,
    /// Its peak power, W (default 4000).
    pub peak_power_w: Option<f64>,
    /// Its pulse width, µs (default 0.3).
    pub pulse_width_us: Option<f64>,
    /// Its antenna's peak gain, dBi (default 25).
    pub gain_dbi: Option<f64>,
    /// Its azimuth beamwidth, degrees (default 3.9).
    pub azimuth_beamwidth_deg: Option<f64>,
    /// Its antenna's sidelobe floor, dB one-way (default −25).
    pub sidelobe_db: Option<f64>,
}

/// `[[own_ship.structure]]`: the own ship's structure (a mast, a funnel) standing in the beam
/// over a sector of bearings relative to the bow: a blind sector, and indirect echoes.
#[derive(Debug, Clone, Default, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StructureSpec {
    /// What stands there (default `sector-<k>`).
    pub name: Option<String>,
    /// Where it starts, degrees clockwise from the bow (required).
    pub from_deg: Option<f64>,
    /// Where it ends, degrees clockwise from the bow (required; may wrap through the bow).
    pub to_deg: Option<f64>,
    /// Two-way loss of everything received through it, dB (default 20).
    pub loss_db: Option<f64>,
    /// Indirect echoes: the power the structure scatters from the beam toward other bearings
    /// on each pass, dB (e.g. -10; no indirect echoes when left out). Needs `distance_m`.
    pub indirect_db: Option<f64>,
    /// The structure's horizontal distance from the antenna, m (needed by `indirect_db`).
    pub distance_m: Option<f64>,
}
