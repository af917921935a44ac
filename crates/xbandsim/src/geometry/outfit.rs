//! Detailed procedural vessels: the hull with sheer, bow flare and a raked stem, and the
//! structures that make real ships bright at every aspect — stepped deck houses with bridge
//! wings, container stacks of real container sizes with their gaps, hatch coamings, cranes,
//! deck piping and manifolds, gantries, booms, rigging, rails and masts (scene field
//! `outfit`, docs/targets.md "Detailed vessels").
//!
//! Three kinds of part: flat-sided structures as triangles (traced by the PO ray tubes), the
//! round funnels, masts and pedestals thicker than a tube as traced cylinders, and the thin
//! members (rails, stanchions, stays, yards, booms, pipes, jibs) as [`Rod`]s whose PO is
//! computed in closed form (`scattering::po::rods`). Per-vessel variation (stack heights,
//! crane positions, deck counts) comes from `outfit_seed` through a SplitMix64 stream
//! (Steele, Lea & Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014), so
//! the same fields give the same vessel.

use super::mesh::TriangleMesh;
use super::rod::Rod;
use glam::DVec3;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `object.outfit`: which detailed vessel to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Outfit {
    /// Container stacks (12.2 × 2.44 × 2.59 m boxes in bays with lashing gaps) on hatch
    /// coamings, the house aft with bridge wings, lashing bridges, rails.
    ContainerShip,
    /// Hatch coamings and covers over seven to nine holds, deck cranes between them.
    BulkCarrier,
    /// Deck piping on supports, a catwalk, the cargo manifold and its cranes amidships.
    Tanker,
    /// Passenger decks stepped in from the sides with promenades, rails and window
    /// mullions, lifeboats in davits, funnel and mast.
    Ferry,
    /// Wheelhouse forward, bulwarks, an A-frame gantry aft, a net drum, outrigger booms.
    Trawler,
    /// Wheelhouse with a mast and radar, roof rails, a fender along the sheer, deck rails.
    Workboat,
    /// A sailing yacht: cabin, mast with spreaders, forestay, backstay and shrouds, boom,
    /// pulpit, pushpit and guard rails.
    Yacht,
    /// A rigid inflatable: tubes along the gunwale, a console with a windscreen and grab
    /// rails, a radar arch, an outboard.
    Rib,
    /// A kayak with its paddler and paddle.
    Kayak,
}

impl Outfit {
    /// Every choice, in the order the documentation lists them.
    pub const ALL: [Outfit; 9] = [
        Outfit::ContainerShip,
        Outfit::BulkCarrier,
        Outfit::Tanker,
        Outfit::Ferry,
        Outfit::Trawler,
        Outfit::Workboat,
        Outfit::Yacht,
        Outfit::Rib,
        Outfit::Kayak,
    ];

    /// The name as written in a scene file.
    pub fn as_str(&self) -> &'static str {
        match self {
            Outfit::ContainerShip => "container-ship",
            Outfit::BulkCarrier => "bulk-carrier",
            Outfit::Tanker => "tanker",
            Outfit::Ferry => "ferry",
            Outfit::Trawler => "trawler",
            Outfit::Workboat => "workboat",
            Outfit::Yacht => "yacht",
            Outfit::Rib => "rib",
            Outfit::Kayak => "kayak",
        }
    }

    /// The lengths overall it is built for, m: its fixed-size parts (40-ft container bays,
    /// lifeboats, a paddler) fit these.
    pub fn length_range_m(&self) -> (f64, f64) {
        match self {
            Outfit::ContainerShip | Outfit::BulkCarrier | Outfit::Tanker => (60.0, 500.0),
            Outfit::Ferry => (25.0, 300.0),
            Outfit::Trawler | Outfit::Workboat => (8.0, 100.0),
            Outfit::Yacht => (5.0, 60.0),
            Outfit::Rib => (3.0, 15.0),
            Outfit::Kayak => (2.0, 8.0),
        }
    }

    /// Amplitude reflectivity of the hull and deck structures (the traced parts): 1 for steel
    /// and aluminium craft, the laminate's or plastic's for GRP and polyethylene ones.
    pub fn hull_reflectivity(&self) -> f64 {
        match self {
            Outfit::Yacht | Outfit::Rib => dielectric_reflectivity(GRP_PERMITTIVITY),
            Outfit::Kayak => dielectric_reflectivity(POLYETHYLENE_PERMITTIVITY),
            _ => 1.0,
        }
    }

    /// Default height of the deck house above the deck for a beam `beam_m`, m.
    pub fn default_house_height_m(&self, beam_m: f64) -> f64 {
        match self {
            Outfit::ContainerShip | Outfit::BulkCarrier | Outfit::Tanker => 0.55 * beam_m,
            Outfit::Ferry => 0.55 * beam_m,
            Outfit::Trawler | Outfit::Workboat => 0.5 * beam_m,
            Outfit::Yacht => 0.2 * beam_m,
            Outfit::Rib => 1.2,
            Outfit::Kayak => 0.0,
        }
    }
}

/// Amplitude reflectivity `|(√ε − 1)/(√ε + 1)|` at normal incidence of a half-space of
/// relative permittivity `permittivity` (real part; the losses of these materials move it by
/// under 1 %).
pub fn dielectric_reflectivity(permittivity: f64) -> f64 {
    let n = permittivity.sqrt();
    (n - 1.0) / (n + 1.0)
}

/// Glass-reinforced plastic (E-glass/polyester laminate), ε ≈ 4.2 at X band (Kozakoff,
/// *Analysis of Radome-Enclosed Antennas*, 2nd ed., 2010, ch. 2): yacht and RIB hulls.
pub const GRP_PERMITTIVITY: f64 = 4.2;
/// Polyethylene, ε = 2.26 (von Hippel, *Dielectric Materials and Applications*, 1954):
/// kayak hulls.
pub const POLYETHYLENE_PERMITTIVITY: f64 = 2.26;
/// PVC- or Hypalon-coated fabric, ε ≈ 2.9 (von Hippel, PVC): a RIB's tubes.
pub const RIB_TUBE_PERMITTIVITY: f64 = 2.9;
/// Wet skin at 10 GHz, `|√ε|` of ε ≈ 31 − j15 (Gabriel, Lau & Gabriel, Phys. Med. Biol. 41,
/// 2271, 1996) gives the amplitude reflectivity 0.71: a person.
pub const SKIN_REFLECTIVITY: f64 = 0.71;

/// A detailed vessel's parts in the object frame (waterline z = 0 amidships, bow +y).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OutfitParts {
    /// Hull and flat-sided structures.
    pub mesh: TriangleMesh,
    /// Traced vertical cylinders: (base centre, radius, height), m.
    pub cylinders: Vec<(DVec3, f64, f64)>,
    /// Thin members.
    pub rods: Vec<Rod>,
}

/// SplitMix64: the vessel's own stream of unit draws.
struct Draws(u64);

impl Draws {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [a, b).
    fn between(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }

    /// Uniform integer in [a, b].
    fn int(&mut self, a: usize, b: usize) -> usize {
        a + (self.unit() * (b - a + 1) as f64) as usize
    }
}

/// The hull's shape: deck half-width, waterline half-width and deck height along y.
#[derive(Debug, Clone, Copy)]
struct HullForm {
    length_m: f64,
    beam_m: f64,
    freeboard_m: f64,
    /// Rise of the deck at the stem over the freeboard (fraction).
    sheer_bow: f64,
    /// Rise of the deck at the stern (fraction).
    sheer_stern: f64,
    /// Waterline half-width over deck half-width amidships.
    flare_mid: f64,
}

impl HullForm {
    fn u(&self, y: f64) -> f64 {
        (2.0 * y / self.length_m).clamp(-1.0, 1.0)
    }

    /// Half-width at the deck, m: parallel midbody, an elliptical bow from u = 0.2, the
    /// stern narrowing to 0.85 at the transom.
    fn deck_half_width_m(&self, y: f64) -> f64 {
        let u = self.u(y);
        let half = 0.5 * self.beam_m;
        if u > 0.2 {
            half * (1.0 - ((u - 0.2) / 0.8).powi(2)).max(0.0).sqrt()
        } else if u < -0.6 {
            half * (1.0 - 0.15 * ((-0.6 - u) / 0.4).powi(2))
        } else {
            half
        }
    }

    /// Half-width at the waterline, m: the deck's times the flare, which opens toward the
    /// bow (bow flare); the stem rakes, ending the waterline at u = 0.94.
    fn waterline_half_width_m(&self, y: f64) -> f64 {
        let u = self.u(y);
        let flare = if u > 0.35 {
            self.flare_mid - (self.flare_mid - 0.35) * ((u - 0.35) / 0.65).powi(2)
        } else {
            self.flare_mid
        };
        let raked = if u > 0.94 { 0.0 } else { 1.0 };
        self.deck_half_width_m(y.min(0.47 * self.length_m)) * flare * raked
    }

    /// Height of the deck edge, m: the freeboard with sheer rising to the bow and stern.
    fn deck_z_m(&self, y: f64) -> f64 {
        let u = self.u(y);
        let bow = ((u - 0.3) / 0.7).max(0.0).powi(2);
        let stern = ((-u - 0.6) / 0.4).max(0.0).powi(2);
        self.freeboard_m * (1.0 + self.sheer_bow * bow + self.sheer_stern * stern)
    }

    /// The lowest deck height over [y0, y1], m (a structure stands on it).
    fn deck_z_over_m(&self, y0: f64, y1: f64) -> f64 {
        (0..=8)
            .map(|i| self.deck_z_m(y0 + (y1 - y0) * i as f64 / 8.0))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Spacing of hatch-coaming stays, m (assumed: stays stand at every second or third frame of
/// 0.8–0.9 m).
const COAMING_STAY_SPACING_M: f64 = 2.0;

/// Depth of a tanker's above-deck web frames and girders, m (assumed).
const DECK_FRAME_DEPTH_M: f64 = 1.2;

/// Collects triangles, cylinders and rods.
struct Builder {
    parts: OutfitParts,
    hull: HullForm,
}

impl Builder {
    fn quad(&mut self, corner: DVec3, u: DVec3, v: DVec3) {
        let m = &mut self.parts.mesh;
        let base = m.vertices_m.len() as u32;
        m.vertices_m
            .extend([corner, corner + u, corner + u + v, corner + v]);
        m.triangles.push([base, base + 1, base + 2]);
        m.triangles.push([base, base + 2, base + 3]);
    }

    /// A box from its bottom centre, without the bottom face: 10 triangles.
    fn block(&mut self, bottom_centre: DVec3, size: DVec3) {
        let (hx, hy) = (0.5 * size.x, 0.5 * size.y);
        let c = bottom_centre;
        let (x, y, z) = (DVec3::X * size.x, DVec3::Y * size.y, DVec3::Z * size.z);
        let sw = c + DVec3::new(-hx, -hy, 0.0);
        self.quad(sw, y, z); // port side (−x)
        self.quad(sw + x, z, y); // starboard
        self.quad(sw, z, x); // aft (−y)
        self.quad(sw + y, x, z); // fore
        self.quad(sw + z, x, y); // top
    }

    /// A block standing on the deck between y0 and y1 (stern to bow), `width` across,
    /// `height` tall, centred at x; returns its top height.
    fn on_deck(&mut self, x: f64, y0: f64, y1: f64, width: f64, height: f64) -> f64 {
        let z0 = self.hull.deck_z_over_m(y0, y1);
        self.block(
            DVec3::new(x, 0.5 * (y0 + y1), z0),
            DVec3::new(width, y1 - y0, height),
        );
        z0 + height
    }

    fn rod(&mut self, a: DVec3, b: DVec3, radius_m: f64) {
        self.parts.rods.push(Rod::new(a, b, radius_m));
    }

    fn cylinder(&mut self, base: DVec3, radius_m: f64, height_m: f64) {
        self.parts.cylinders.push((base, radius_m, height_m));
    }

    /// A rail along the polyline `points` (each at the foot of the rail): stanchions every
    /// `spacing` m, a top rail `height` up and a mid rail, all of radius `radius`.
    fn rail(&mut self, points: &[DVec3], height: f64, spacing: f64, radius: f64) {
        for w in points.windows(2) {
            let (a, b) = (w[0], w[1]);
            let len = (b - a).length();
            if len <= 0.0 {
                continue;
            }
            let n = (len / spacing).ceil().max(1.0) as usize;
            for i in 0..n {
                let p = a + (b - a) * (i as f64 / n as f64);
                self.rod(p, p + DVec3::Z * height, radius);
            }
            for h in [height, 0.5 * height] {
                self.rod(a + DVec3::Z * h, b + DVec3::Z * h, radius);
            }
        }
        if let Some(&last) = points.last() {
            self.rod(last, last + DVec3::Z * height, radius);
        }
    }

    /// Points along one side's deck edge between y0 and y1 (`side` ±1), `inset` m inboard.
    fn deck_edge(&self, side: f64, y0: f64, y1: f64, inset: f64) -> Vec<DVec3> {
        let n = (((y1 - y0) / (0.05 * self.hull.length_m)).ceil() as usize).max(1);
        (0..=n)
            .map(|i| {
                let y = y0 + (y1 - y0) * i as f64 / n as f64;
                DVec3::new(
                    side * (self.hull.deck_half_width_m(y) - inset).max(0.0),
                    y,
                    self.hull.deck_z_m(y),
                )
            })
            .collect()
    }

    /// Rails along both sides between y0 and y1.
    fn side_rails(&mut self, y0: f64, y1: f64, height: f64, spacing: f64, radius: f64) {
        for side in [-1.0, 1.0] {
            let pts = self.deck_edge(side, y0, y1, 0.05);
            self.rail(&pts, height, spacing, radius);
        }
    }

    /// Bulwarks (plates standing on the deck edge) along both sides between y0 and y1.
    fn bulwarks(&mut self, y0: f64, y1: f64, height: f64) {
        for side in [-1.0, 1.0] {
            let pts = self.deck_edge(side, y0, y1, 0.0);
            for w in pts.windows(2) {
                self.quad(w[0], w[1] - w[0], DVec3::Z * height);
            }
        }
    }

    /// Coaming stays: triangular brackets standing on the deck against the walls of a
    /// hatch coaming (centred on the ship, `width` across, from y0 to y1, its foot at `z0`,
    /// `height` tall), about every [`COAMING_STAY_SPACING_M`] along its sides and, with
    /// `ends`, its ends. Each is a vertical plate reaching `depth` out over the deck and 0.85
    /// of the way up the wall; with the wall it makes two upright corners opening outboard,
    /// which return toward a radar over a wide spread of azimuth.
    #[allow(clippy::too_many_arguments)]
    fn coaming_stays(
        &mut self,
        width: f64,
        y0: f64,
        y1: f64,
        z0: f64,
        height: f64,
        depth: f64,
        ends: bool,
    ) {
        let spacing = COAMING_STAY_SPACING_M;
        let hw = 0.5 * width;
        let top = DVec3::Z * (0.85 * height);
        let along = |a: f64, b: f64| {
            let n = (((b - a) / spacing).round() as usize).max(1);
            (1..n).map(move |i| a + (b - a) * i as f64 / n as f64)
        };
        let m = &mut self.parts.mesh;
        let mut tri = |a: DVec3, out: DVec3| {
            let base = m.vertices_m.len() as u32;
            m.vertices_m.extend([a, a + out, a + top]);
            m.triangles.push([base, base + 1, base + 2]);
        };
        for y in along(y0, y1) {
            for side in [-1.0, 1.0] {
                tri(DVec3::new(side * hw, y, z0), DVec3::X * (side * depth));
            }
        }
        for x in along(-hw, hw).filter(|_| ends) {
            tri(DVec3::new(x, y0, z0), DVec3::Y * -depth);
            tri(DVec3::new(x, y1, z0), DVec3::Y * depth);
        }
    }

    /// Open bridge wings at the floor `z` of the top tier, each side from the wall of the
    /// tier below (`below_width` across) out to the ship's side, from y0 to y1 fore and
    /// aft: a deck 0.6 m deep (its top, underside and after edge) with a bulwark 1.2 m high
    /// along its front and its outboard end.
    fn bridge_wings(&mut self, z: f64, below_width: f64, y0: f64, y1: f64) {
        const BULWARK_M: f64 = 1.2;
        const DEPTH_M: f64 = 0.6;
        let span = self.hull.beam_m;
        if span <= below_width {
            return;
        }
        for side in [-1.0, 1.0] {
            let (xa, xb) = (side * 0.5 * below_width, side * 0.5 * span);
            let (across, along) = (DVec3::X * (xb - xa), DVec3::Y * (y1 - y0));
            let height = DVec3::Z * (BULWARK_M + DEPTH_M);
            self.quad(DVec3::new(xa, y0, z), across, along);
            self.quad(DVec3::new(xa, y0, z - DEPTH_M), across, along);
            self.quad(DVec3::new(xa, y0, z - DEPTH_M), across, DVec3::Z * DEPTH_M);
            self.quad(DVec3::new(xa, y1, z - DEPTH_M), across, height);
            self.quad(DVec3::new(xb, y0, z - DEPTH_M), along, height);
        }
    }

    /// An enclosed lifeboat (7.5 × 2.4 × 2.6 m) in its davits each side of a house from
    /// y0 to y1, `width` across and `tiers` tiers of `tier_h`, alongside its second tier:
    /// two davit posts on the house side and their arms over the boat. The boat hangs in
    /// its davits up to 0.6 m outboard of the deck edge; none where the deck beside the
    /// house is narrower than 2 m, or the house too low for the bridge wings to clear the
    /// davits (under four tiers).
    fn house_lifeboats(&mut self, y0: f64, y1: f64, width: f64, tiers: usize, tier_h: f64) {
        let z = self.hull.deck_z_over_m(y0, y1) + tier_h;
        let y = y0 + 0.4 * (y1 - y0);
        let deck_m = [-3.75, 0.0, 3.75]
            .map(|dy| self.hull.deck_half_width_m(y + dy))
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        if tiers < 4 || deck_m - 0.5 * width < 2.0 {
            return;
        }
        for side in [-1.0, 1.0] {
            let (wall, x) = (side * 0.5 * width, side * (0.5 * width + 1.4));
            self.block(DVec3::new(x, y, z), DVec3::new(2.4, 7.5, 2.6));
            for dy in [-2.8, 2.8] {
                let head = DVec3::new(wall, y + dy, z + 4.0);
                self.rod(DVec3::new(wall, y + dy, z - 1.0), head, 0.15);
                self.rod(head, DVec3::new(x, y + dy, z + 3.4), 0.12);
            }
        }
    }

    /// A mast from `at` up to z1 of radius r, with a yard `yard_span` across (none at 0)
    /// six tenths of the way up.
    fn mast(&mut self, at: DVec3, z1: f64, r: f64, yard_span: f64) {
        self.rod(at, DVec3::new(at.x, at.y, z1), r);
        if yard_span > 0.0 {
            let yard = DVec3::new(at.x, at.y, at.z + 0.6 * (z1 - at.z));
            self.rod(
                yard - DVec3::X * (0.5 * yard_span),
                yard + DVec3::X * (0.5 * yard_span),
                0.6 * r,
            );
        }
    }

    /// A stepped deck house from y0 to y1: `tiers` decks of `tier_h`, each set in from the
    /// one below by `setback` at the sides and the front; bridge wings across `beam` on the
    /// top tier; rails round every tier's exposed deck. Returns the top height.
    #[allow(clippy::too_many_arguments)]
    fn house(
        &mut self,
        y0: f64,
        y1: f64,
        width: f64,
        tiers: usize,
        tier_h: f64,
        setback: f64,
        wings: bool,
    ) -> f64 {
        let mut z = self.hull.deck_z_over_m(y0, y1);
        let (mut w, mut front) = (width, y1);
        for t in 0..tiers {
            let top_tier = t + 1 == tiers;
            self.block(
                DVec3::new(0.0, 0.5 * (y0 + front), z),
                DVec3::new(w, front - y0, tier_h),
            );
            if t > 0 {
                // Rails round the deck the tier stands on.
                let (hw, hy) = (0.5 * (w + setback), front + 0.5 * setback);
                let pts = [
                    DVec3::new(-hw, y0, z),
                    DVec3::new(-hw, hy, z),
                    DVec3::new(hw, hy, z),
                    DVec3::new(hw, y0, z),
                ];
                self.rail(&pts, 1.0, 1.5, 0.025);
            }
            if top_tier && wings {
                // (The wing's inner end meets the tier below, whose roof it stands on.)
                let below = if t > 0 { w + 2.0 * setback } else { w };
                self.bridge_wings(z, below, front - (0.6 * (front - y0)).min(4.0), front);
            }
            z += tier_h;
            w = (w - 2.0 * setback).max(0.3 * width);
            front -= setback;
        }
        z
    }
}

/// The size-dependent defaults a detailed vessel is built from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutfitSizes {
    /// Length overall, m.
    pub length_m: f64,
    /// Beam, m.
    pub beam_m: f64,
    /// Freeboard amidships, m.
    pub freeboard_m: f64,
    /// Deck house height above the deck, m.
    pub house_height_m: f64,
    /// Height of the mast's top above the waterline, m (None: the outfit's own).
    pub mast_height_m: Option<f64>,
}

/// Builds `outfit` at `sizes`, varied by `seed`.
pub fn build_outfit(outfit: Outfit, sizes: &OutfitSizes, seed: u64) -> OutfitParts {
    let (l, b, f, h) = (
        sizes.length_m,
        sizes.beam_m,
        sizes.freeboard_m,
        sizes.house_height_m,
    );
    let mut d = Draws(seed ^ 0x5851_F42D_4C95_7F2D);
    let (sheer_bow, sheer_stern, flare_mid) = match outfit {
        Outfit::ContainerShip | Outfit::BulkCarrier | Outfit::Tanker => (0.35, 0.1, 1.0),
        Outfit::Ferry => (0.2, 0.05, 1.0),
        Outfit::Trawler | Outfit::Workboat => (0.45, 0.1, 0.85),
        Outfit::Yacht => (0.25, 0.1, 0.8),
        Outfit::Rib => (0.3, 0.0, 0.75),
        Outfit::Kayak => (0.35, 0.35, 0.8),
    };
    let hull = HullForm {
        length_m: l,
        beam_m: b,
        freeboard_m: f,
        sheer_bow,
        sheer_stern,
        flare_mid,
    };
    let mut k = Builder {
        parts: OutfitParts::default(),
        hull,
    };
    hull_surfaces(&mut k);
    let y = |frac: f64| frac * l;
    let mast_top = |default: f64| sizes.mast_height_m.unwrap_or(default);
    match outfit {
        Outfit::ContainerShip | Outfit::BulkCarrier | Outfit::Tanker => {
            // House aft: tiers of 2.8 m, bridge wings on the top.
            let tiers = ((h / 2.8).round() as usize).clamp(3, 9);
            let (y0, y1) = (y(-0.44), y(-0.44) + (0.12 * l).max(10.0));
            let top = k.house(y0, y1, 0.8 * b, tiers, h / tiers as f64, 0.8, true);
            // Funnel behind the house, a mast on the house.
            // (On a beamy ship the funnel narrows to stay forward of the transom.)
            let funnel_r = (0.09 * b).min(0.02 * l);
            let zf = k.hull.deck_z_m(y0 - funnel_r);
            k.cylinder(
                DVec3::new(0.0, y0 - 1.5 * funnel_r, zf),
                funnel_r,
                top - zf + 0.2 * h,
            );
            let mast_z = mast_top(top + 0.04 * l);
            k.mast(DVec3::new(0.0, 0.5 * (y0 + y1), top), mast_z, 0.25, 0.6 * b);
            // An enclosed lifeboat in davits each side of the house.
            k.house_lifeboats(y0, y1, 0.8 * b, tiers, h / tiers as f64);
            // Forecastle: a raised deck whose after face stands across the ship, bulwarks
            // round it, mooring winches on it and aft on the poop.
            let fwd = y(0.4);
            let fc_half = k.hull.deck_half_width_m(y(0.46));
            let fc_top = k.on_deck(0.0, fwd, y(0.46), 1.9 * fc_half, 2.6);
            for side in [-1.0, 1.0] {
                k.block(
                    DVec3::new(side * 0.4 * fc_half, y(0.43), fc_top),
                    DVec3::new(2.0, 3.0, 1.4),
                );
                let yp = y(-0.47);
                let zp = k.hull.deck_z_m(yp);
                k.block(
                    DVec3::new(side * 0.25 * b, yp, zp),
                    DVec3::new(2.0, 3.0, 1.4),
                );
            }
            k.bulwarks(fwd, y(0.49), 1.4 + 2.6);
            let zb = k.hull.deck_z_m(y(0.44));
            k.mast(DVec3::new(0.0, y(0.44), zb), zb + 0.06 * l, 0.2, 0.0);
            // Rails along the midbody.
            k.side_rails(y(-0.49), fwd, 1.1, 2.0, 0.025);
            let (cargo0, cargo1) = (y1 + 2.0, fwd - 2.0);
            match outfit {
                Outfit::ContainerShip => {
                    breakwater(&mut k, fwd, fc_top);
                    container_bays(&mut k, &mut d, cargo0, cargo1, top)
                }
                Outfit::BulkCarrier => bulk_holds(&mut k, &mut d, cargo0, cargo1),
                _ => tanker_deck(&mut k, &mut d, cargo0, cargo1),
            }
        }
        Outfit::Ferry => {
            let tiers = ((h / 2.8).round() as usize).clamp(2, 9);
            let (y0, y1) = (y(-0.40), y(0.22));
            let tier_h = h / tiers as f64;
            // Promenades: each deck set in 1.2 m at the sides and the front.
            let top = k.house(y0, y1, 0.92 * b, tiers, tier_h, 1.2, true);
            // Window mullions on every tier's sides, every 2 m.
            let mut z = k.hull.deck_z_over_m(y0, y1);
            let mut w = 0.92 * b;
            for t in 0..tiers {
                let front = y1 - 1.2 * t as f64;
                let n = ((front - y0) / 2.0) as usize;
                // (Mullions only between the sill at 0.9 m and 0.3 m under the deck head.)
                for i in (0..=n).filter(|_| tier_h > 1.5) {
                    let yy = y0 + (front - y0) * i as f64 / n.max(1) as f64;
                    for side in [-1.0, 1.0] {
                        let x = side * (0.5 * w + 0.06);
                        k.rod(
                            DVec3::new(x, yy, z + 0.9),
                            DVec3::new(x, yy, z + tier_h - 0.3),
                            0.05,
                        );
                    }
                }
                z += tier_h;
                w = (w - 2.4).max(0.3 * 0.92 * b);
            }
            // Lifeboats in davits along both sides of the second tier.
            // Boats of 7.5 m, as many a side as fit (none on a hull too narrow for davits).
            let boats = d.int(2, 4).min(((y1 - y0) / 9.0) as usize);
            let boats = if b < 8.0 { 0 } else { boats };
            let z_boat = k.hull.deck_z_m(0.0) + tier_h * 1.3;
            for i in 0..boats {
                let yy = y0 + (y1 - y0) * (i as f64 + 0.5) / boats as f64;
                for side in [-1.0, 1.0] {
                    let x = side * (0.5 * b - 1.2);
                    k.block(DVec3::new(x, yy, z_boat), DVec3::new(2.4, 7.5, 2.4));
                    for dy in [-3.0, 3.0] {
                        k.rod(
                            DVec3::new(side * (0.5 * b - 3.0), yy + dy, z_boat + tier_h),
                            DVec3::new(x, yy + dy, z_boat + 2.6),
                            0.12,
                        );
                    }
                }
            }
            let funnel_r = 0.12 * b;
            let zt = top;
            k.cylinder(
                DVec3::new(0.0, y0 + 2.0 * funnel_r, zt),
                funnel_r,
                0.25 * h + 2.0,
            );
            let mast_z = mast_top(top + 0.05 * l);
            k.mast(
                DVec3::new(0.0, y1 - 0.1 * (y1 - y0), top),
                mast_z,
                0.2,
                0.5 * b,
            );
            k.side_rails(y(-0.49), y(0.45), 1.1, 2.0, 0.025);
            k.bulwarks(y(0.35), y(0.49), 1.2);
        }
        Outfit::Trawler | Outfit::Workboat => {
            let (y0, y1) = if outfit == Outfit::Trawler {
                (y(-0.02), y(0.2))
            } else {
                (y(-0.1), y(0.18))
            };
            let top = k.house(y0, y1, 0.65 * b, 2, 0.5 * h, 0.3, false);
            // Roof rails and a mast with a yard and a radar.
            let (hw, rf) = (0.5 * (0.65 * b - 0.6), y1 - 0.3);
            k.rail(
                &[
                    DVec3::new(-hw, y0, top),
                    DVec3::new(-hw, rf, top),
                    DVec3::new(hw, rf, top),
                    DVec3::new(hw, y0, top),
                ],
                0.9,
                1.0,
                0.02,
            );
            let mast_z = mast_top(top + 0.15 * l);
            k.mast(DVec3::new(0.0, 0.5 * (y0 + y1), top), mast_z, 0.08, 0.5 * b);
            k.block(
                DVec3::new(0.0, 0.5 * (y0 + y1), top + 0.5 * (mast_z - top)),
                DVec3::new(1.2, 0.3, 0.25),
            );
            if outfit == Outfit::Trawler {
                k.bulwarks(y(-0.49), y(0.49), 0.9);
                // A-frame gantry at the stern, net drum forward of it.
                let ys = y(-0.45);
                let zs = k.hull.deck_z_m(ys);
                let gh = d.between(0.25, 0.35) * l;
                let gx = 0.4 * b;
                for side in [-1.0, 1.0] {
                    k.rod(
                        DVec3::new(side * gx, ys, zs),
                        DVec3::new(side * 0.3 * gx, ys, zs + gh),
                        0.12,
                    );
                }
                k.rod(
                    DVec3::new(-0.3 * gx, ys, zs + gh),
                    DVec3::new(0.3 * gx, ys, zs + gh),
                    0.12,
                );
                let yd = y(-0.32);
                let zd = k.hull.deck_z_m(yd);
                k.rod(
                    DVec3::new(-0.3 * b, yd, zd + 0.9),
                    DVec3::new(0.3 * b, yd, zd + 0.9),
                    0.6,
                );
                // Outrigger booms from the mast's foot, raised at 45° over each side.
                let foot = DVec3::new(0.0, 0.5 * (y0 + y1), top);
                let reach = d.between(0.3, 0.45) * l;
                for side in [-1.0, 1.0] {
                    k.rod(
                        foot,
                        foot + DVec3::new(side * reach * 0.7, 0.0, reach * 0.7),
                        0.08,
                    );
                }
            } else {
                k.side_rails(y(-0.49), y(0.45), 1.0, 1.2, 0.02);
                // Fender along the sheer line.
                for side in [-1.0, 1.0] {
                    let pts = k.deck_edge(side, y(-0.49), y(0.45), -0.1);
                    for w in pts.windows(2) {
                        // 0.3 m under the deck edge, but never in the water.
                        let drop = |p: DVec3| DVec3::new(p.x, p.y, (p.z - 0.3).max(0.15));
                        k.rod(drop(w[0]), drop(w[1]), 0.15);
                    }
                }
                let yt = y(-0.35);
                let zt = k.hull.deck_z_m(yt);
                k.rod(DVec3::new(0.0, yt, zt), DVec3::new(0.0, yt, zt + 1.2), 0.15);
            }
        }
        Outfit::Yacht => {
            let (y0, y1) = (y(-0.22), y(0.12));
            let top = k.house(y0, y1, 0.6 * b, 1, h, 0.0, false);
            let ym = y(0.08);
            let zd = k.hull.deck_z_m(ym);
            let mast_z = mast_top(f + 1.3 * l);
            let mr = 0.004 * l + 0.03;
            k.rod(
                DVec3::new(0.0, ym, top.max(zd)),
                DVec3::new(0.0, ym, mast_z),
                mr,
            );
            // Boom aft over the cockpit.
            let zb = top + 1.0;
            k.rod(
                DVec3::new(0.0, ym, zb),
                DVec3::new(0.0, y(-0.4), zb + 0.2),
                0.6 * mr,
            );
            // Forestay with its furled sail, backstay, shrouds with two spreaders.
            let head = DVec3::new(0.0, ym, mast_z - 0.04 * (mast_z - zd));
            let stem = DVec3::new(0.0, y(0.49), k.hull.deck_z_m(y(0.49)));
            k.rod(stem, head, 0.05);
            let stern = DVec3::new(0.0, y(-0.49), k.hull.deck_z_m(y(-0.49)));
            k.rod(stern, DVec3::new(0.0, ym, mast_z), 0.005);
            let spreaders = [0.35, 0.68];
            for side in [-1.0, 1.0] {
                let chain = DVec3::new(side * 0.45 * b, ym - 0.3, zd);
                let mut prev = chain;
                for s in spreaders {
                    let z = zd + s * (mast_z - zd);
                    let tip = DVec3::new(side * (0.45 * b) * (1.0 - 0.5 * s), ym, z);
                    k.rod(DVec3::new(0.0, ym, z), tip, 0.02);
                    k.rod(prev, tip, 0.005);
                    prev = tip;
                }
                k.rod(
                    prev,
                    DVec3::new(0.0, ym, mast_z - 0.02 * (mast_z - zd)),
                    0.005,
                );
            }
            // Pulpit, pushpit and guard rails (stanchions every 2 m, wires between).
            k.side_rails(y(-0.47), y(0.45), 0.65, 2.0, 0.012);
        }
        Outfit::Rib => {
            // Tubes along both gunwales, round the bow.
            let r_tube = 0.22 * b / 2.5;
            for side in [-1.0, 1.0] {
                let pts = k.deck_edge(side, y(-0.49), y(0.46), 0.0);
                for w in pts.windows(2) {
                    k.parts.rods.push(
                        Rod::new(w[0], w[1], r_tube)
                            .of(dielectric_reflectivity(RIB_TUBE_PERMITTIVITY)),
                    );
                }
            }
            let (yc0, yc1) = (y(-0.1), y(0.06));
            let top = k.on_deck(0.0, yc0, yc1, 0.55, h);
            // Windscreen frame and grab rails round the console.
            k.rod(
                DVec3::new(-0.35, yc1, top),
                DVec3::new(0.35, yc1, top + 0.4),
                0.015,
            );
            k.rail(
                &[
                    DVec3::new(-0.4, yc0, top - 0.2),
                    DVec3::new(-0.4, yc1, top - 0.2),
                    DVec3::new(0.4, yc1, top - 0.2),
                    DVec3::new(0.4, yc0, top - 0.2),
                ],
                0.3,
                0.5,
                0.015,
            );
            // Radar arch over the stern seats.
            let ya = y(-0.3);
            let za = k.hull.deck_z_m(ya);
            let hw = 0.35 * b;
            let arch_h = h + 0.6;
            k.rod(
                DVec3::new(-hw, ya, za),
                DVec3::new(-0.7 * hw, ya, za + arch_h),
                0.03,
            );
            k.rod(
                DVec3::new(hw, ya, za),
                DVec3::new(0.7 * hw, ya, za + arch_h),
                0.03,
            );
            k.rod(
                DVec3::new(-0.7 * hw, ya, za + arch_h),
                DVec3::new(0.7 * hw, ya, za + arch_h),
                0.03,
            );
            k.block(
                DVec3::new(0.0, ya, za + arch_h + 0.03),
                DVec3::new(0.6, 0.6, 0.25),
            );
            // Outboard on the transom.
            let yt = y(-0.5) - 0.25;
            k.block(DVec3::new(0.0, yt, 0.0), DVec3::new(0.45, 0.5, f + 0.6));
        }
        Outfit::Kayak => {
            // The paddler (a torso of 0.15 m radius, skin) and the paddle's shaft across.
            let z = k.hull.deck_z_m(0.0);
            k.parts.rods.push(
                Rod::new(DVec3::new(0.0, 0.0, z), DVec3::new(0.0, 0.0, z + 0.6), 0.15)
                    .of(SKIN_REFLECTIVITY),
            );
            let tilt = d.between(-0.3, 0.3);
            k.rod(
                DVec3::new(-1.1, 0.25, z + 0.45 - tilt),
                DVec3::new(1.1, 0.25, z + 0.45 + tilt),
                0.016,
            );
        }
    }
    k.parts
}

/// The hull's surfaces: both sides in three rows (flare widening toward the deck), the deck
/// with its sheer, the waterline plane closing it and the transom.
fn hull_surfaces(k: &mut Builder) {
    let hull = k.hull;
    let rows = 3usize;
    let cols = 4usize;
    let ys = hull_stations_m(hull.length_m);
    let n = ys.len() - 1;
    let side_point = |y: f64, t: f64, side: f64| {
        let (wd, ww) = (hull.deck_half_width_m(y), hull.waterline_half_width_m(y));
        DVec3::new(side * (ww + (wd - ww) * t * t), y, hull.deck_z_m(y) * t)
    };
    for side in [-1.0, 1.0] {
        for i in 0..n {
            for j in 0..rows {
                let (t0, t1) = (j as f64 / rows as f64, (j + 1) as f64 / rows as f64);
                let a = side_point(ys[i], t0, side);
                let bq = side_point(ys[i + 1], t0, side);
                let c = side_point(ys[i + 1], t1, side);
                let dq = side_point(ys[i], t1, side);
                tri_pair(&mut k.parts.mesh, a, bq, c, dq);
            }
        }
    }
    for i in 0..n {
        for j in 0..cols {
            let across = |_y: f64, j: usize, w: f64| -w + 2.0 * w * j as f64 / cols as f64;
            let (y0, y1) = (ys[i], ys[i + 1]);
            let (w0, w1) = (hull.deck_half_width_m(y0), hull.deck_half_width_m(y1));
            let (z0, z1) = (hull.deck_z_m(y0), hull.deck_z_m(y1));
            tri_pair(
                &mut k.parts.mesh,
                DVec3::new(across(y0, j, w0), y0, z0),
                DVec3::new(across(y0, j + 1, w0), y0, z0),
                DVec3::new(across(y1, j + 1, w1), y1, z1),
                DVec3::new(across(y1, j, w1), y1, z1),
            );
            let (v0, v1) = (
                hull.waterline_half_width_m(y0),
                hull.waterline_half_width_m(y1),
            );
            tri_pair(
                &mut k.parts.mesh,
                DVec3::new(across(y0, j, v0), y0, 0.0),
                DVec3::new(across(y1, j, v1), y1, 0.0),
                DVec3::new(across(y1, j + 1, v1), y1, 0.0),
                DVec3::new(across(y0, j + 1, v0), y0, 0.0),
            );
        }
    }
    // Transom: the stern section as a fan of strips.
    let y_t = -0.5 * hull.length_m;
    for j in 0..rows {
        let (t0, t1) = (j as f64 / rows as f64, (j + 1) as f64 / rows as f64);
        let (p0, p1) = (side_point(y_t, t0, -1.0), side_point(y_t, t1, -1.0));
        let (q0, q1) = (side_point(y_t, t0, 1.0), side_point(y_t, t1, 1.0));
        tri_pair(&mut k.parts.mesh, p0, q0, q1, p1);
    }
}

/// Stations along the hull, stern to bow, m: the parallel midbody (u from −0.6 to 0.2) in
/// `⌈4·√(L/m)⌉`-rule steps, the curved bow and stern in steps of `max(0.5 m, L/200)`, so
/// that their facets stay near the Fresnel zone `√(λR_c/2)` of the curvature and the bow
/// returns over a continuous spread of aspects rather than in a few flat flashes.
fn hull_stations_m(length_m: f64) -> Vec<f64> {
    let coarse = length_m / ((4.0 * length_m.sqrt()).ceil()).clamp(10.0, 96.0);
    let fine = (length_m / 200.0).max(0.5).min(coarse);
    let half = 0.5 * length_m;
    let mut out = Vec::new();
    let push_span = |u0: f64, u1: f64, step: f64, out: &mut Vec<f64>| {
        let n = (((u1 - u0) * half / step).ceil() as usize).max(1);
        for i in 0..n {
            out.push((u0 + (u1 - u0) * i as f64 / n as f64) * half);
        }
    };
    push_span(-1.0, -0.6, fine, &mut out);
    push_span(-0.6, 0.2, coarse, &mut out);
    push_span(0.2, 1.0, fine, &mut out);
    out.push(half);
    out
}

/// Two triangles over the quadrilateral a, b, c, d (skipping degenerate ones later).
fn tri_pair(m: &mut TriangleMesh, a: DVec3, b: DVec3, c: DVec3, d: DVec3) {
    let base = m.vertices_m.len() as u32;
    m.vertices_m.extend([a, b, c, d]);
    m.triangles.push([base, base + 1, base + 2]);
    m.triangles.push([base, base + 2, base + 3]);
}

/// Container bays from y0 to y1 (stern to bow): 40-ft bays (12.19 m) with 1.2 m gaps for
/// the lashing bridges, each on a hatch coaming; across, the beam's rows (2.44 m) in three
/// groups whose stacks of 2.59 m tiers are drawn separately (0 to the visibility line under
/// the bridge, `bridge_z`).
fn container_bays(k: &mut Builder, d: &mut Draws, y0: f64, y1: f64, bridge_z: f64) {
    const BAY_M: f64 = 12.19;
    const GAP_M: f64 = 1.2;
    const ROW_M: f64 = 2.44;
    const TIER_M: f64 = 2.59;
    let mut y = y0;
    while y + BAY_M <= y1 {
        let (ya, yb) = (y, y + BAY_M);
        let half = k
            .hull
            .deck_half_width_m(yb)
            .min(k.hull.deck_half_width_m(ya));
        let fit = (((2.0 * half * 0.92) / ROW_M).floor() as usize).max(1);
        let z0 = k.hull.deck_z_over_m(ya, yb);
        let coaming = k.on_deck(0.0, ya, yb, fit as f64 * ROW_M, 1.6) - z0;
        // (Stays on the sides only: the bays' 1.2 m gaps hold the lashing bridges.)
        k.coaming_stays(fit as f64 * ROW_M, ya, yb, z0, coaming, 0.6, false);
        let max_tiers = (((bridge_z - z0 - coaming) / TIER_M).floor() as usize).clamp(1, 8);
        // Stacks in three groups of rows (port, centre, starboard), each group's height
        // drawn (an empty group one time in ten), so that the stacks step up and down
        // across the bay as loading leaves them.
        let groups = [fit / 3, fit - 2 * (fit / 3), fit / 3];
        let mut x = -0.5 * ROW_M * fit as f64;
        for rows in groups {
            let width = rows as f64 * ROW_M;
            let tiers = if d.unit() < 0.1 {
                0
            } else {
                d.int(max_tiers / 2, max_tiers)
            };
            if tiers > 0 && rows > 0 {
                k.block(
                    DVec3::new(x + 0.5 * width, 0.5 * (ya + yb), z0 + coaming),
                    DVec3::new(width - 0.05, BAY_M, tiers as f64 * TIER_M),
                );
            }
            x += width;
        }
        // Lashing bridge in the gap: posts and rails two tiers high.
        let yl = yb + 0.5 * GAP_M;
        if yl < y1 {
            let zl = z0 + coaming;
            let hw = 0.5 * ROW_M * fit as f64;
            let posts = (fit / 2).max(2);
            for i in 0..=posts {
                let x = -hw + 2.0 * hw * i as f64 / posts as f64;
                k.rod(
                    DVec3::new(x, yl, zl),
                    DVec3::new(x, yl, zl + 2.0 * TIER_M),
                    0.08,
                );
            }
            for hgt in [TIER_M, 2.0 * TIER_M] {
                k.rod(
                    DVec3::new(-hw, yl, zl + hgt),
                    DVec3::new(hw, yl, zl + hgt),
                    0.06,
                );
            }
        }
        y = yb + GAP_M;
    }
}

/// A container ship's breakwater on the forecastle: a V of plates 4 m high whose point is
/// forward, stiffened on its after face by ribs every 1.5 m, which with the plates and the
/// deck make rows of corners facing aft and up.
fn breakwater(k: &mut Builder, y_aft: f64, deck_z: f64) {
    let half = k.hull.deck_half_width_m(y_aft + 6.0) - 0.3;
    if half < 2.0 {
        return; // no room for a V on so fine a bow
    }
    let (apex, height) = (DVec3::new(0.0, y_aft + 6.0, deck_z), 4.0);
    for side in [-1.0, 1.0] {
        let end = DVec3::new(side * half, y_aft + 1.0, deck_z);
        let along = end - apex;
        k.quad(apex, along, DVec3::Z * height);
        let n = (along.length() / 1.5).floor() as usize;
        let inward = DVec3::new(0.0, -1.0, 0.0) * 0.35;
        for i in 1..n {
            let p = apex + along * (i as f64 / n as f64);
            k.quad(p, inward, DVec3::Z * height);
        }
    }
}

/// Bulk carrier holds: 7–9 hatch coamings (2 m) with covers (0.8 m, wider), and a deck
/// crane (pedestal, cab, jib stowed fore and aft) between every second pair.
fn bulk_holds(k: &mut Builder, d: &mut Draws, y0: f64, y1: f64) {
    let b = k.hull.beam_m;
    let holds = d.int(7, 9);
    let pitch = (y1 - y0) / holds as f64;
    let hatch = 0.75 * pitch;
    let cranes = d.unit() < 0.6;
    for i in 0..holds {
        let yc = y0 + pitch * (i as f64 + 0.5);
        let (ya, yb) = (yc - 0.5 * hatch, yc + 0.5 * hatch);
        let top = k.on_deck(0.0, ya, yb, 0.6 * b, 2.0);
        k.coaming_stays(0.6 * b, ya, yb, top - 2.0, 2.0, 0.8, true);
        k.block(
            DVec3::new(0.0, yc, top),
            DVec3::new(0.6 * b + 0.6, hatch + 0.6, 0.8),
        );
        if cranes && i % 2 == 1 && i + 1 < holds {
            let yp = yc + 0.5 * pitch;
            let zp = k.hull.deck_z_m(yp);
            let ped_h = 0.2 * b;
            k.cylinder(DVec3::new(0.3 * b, yp, zp), 1.2, ped_h);
            k.block(
                DVec3::new(0.3 * b, yp, zp + ped_h),
                DVec3::new(2.5, 3.0, 2.8),
            );
            let jib = 0.8 * pitch;
            k.rod(
                DVec3::new(0.3 * b, yp, zp + ped_h + 1.0),
                DVec3::new(0.0, yp - jib, zp + ped_h + 3.0),
                0.35,
            );
        }
    }
}

/// Above-deck framing of a tanker's cargo deck from y0 to y1 (stern to bow), as product and
/// chemical tankers carry it to leave their tanks smooth inside: transverse web frames every
/// 4 m across the deck (a gap on the centre line for the catwalk's posts) and four
/// longitudinal girders, all 1.2 m deep (assumed).
fn above_deck_frames(k: &mut Builder, y0: f64, y1: f64) {
    let b = k.hull.beam_m;
    let depth = DVec3::Z * DECK_FRAME_DEPTH_M;
    // Everything stays 0.3 m inside the deck edge, where the bow narrows the deck too.
    let reach = |k: &Builder, y: f64| k.hull.deck_half_width_m(y) - 0.3;
    let webs = (((y1 - y0) / 4.0).ceil() as usize).max(1);
    for i in 0..=webs {
        let y = y0 + (y1 - y0) * i as f64 / webs as f64;
        let (z, outer) = (k.hull.deck_z_m(y), reach(k, y).min(0.43 * b));
        if outer <= 0.05 * b {
            continue;
        }
        for side in [-1.0, 1.0] {
            k.quad(
                DVec3::new(side * 0.05 * b, y, z),
                DVec3::X * (side * (outer - 0.05 * b)),
                depth,
            );
        }
    }
    let pieces = (((y1 - y0) / 8.0).ceil() as usize).max(1);
    for x in [-0.43 * b, -0.25 * b, 0.25 * b, 0.43 * b] {
        for i in 0..pieces {
            let ya = y0 + (y1 - y0) * i as f64 / pieces as f64;
            let yb = y0 + (y1 - y0) * (i + 1) as f64 / pieces as f64;
            if x.abs() > reach(k, ya).min(reach(k, yb)) {
                continue;
            }
            let (za, zb) = (k.hull.deck_z_m(ya), k.hull.deck_z_m(yb));
            k.quad(
                DVec3::new(x, ya, za),
                DVec3::new(0.0, yb - ya, zb - za),
                depth,
            );
        }
    }
}

/// Tanker deck: above-deck framing, pipes along the deck carried on the web frames, a raised
/// catwalk on the centreline, the manifold amidships with its hose cranes.
fn tanker_deck(k: &mut Builder, d: &mut Draws, y0: f64, y1: f64) {
    let b = k.hull.beam_m;
    let pipes = d.int(6, 10);
    let z = |k: &Builder, y: f64| k.hull.deck_z_m(y);
    for p in 0..pipes {
        let x = -0.3 * b + 0.6 * b * p as f64 / (pipes - 1) as f64;
        let r = d.between(0.12, 0.35);
        // On the web frames; a pipe in their centre-line gap on supports of its own.
        let lift = DECK_FRAME_DEPTH_M + r;
        let supported = x.abs() < 0.05 * b;
        let n = (((y1 - y0) / 8.0).ceil() as usize).max(1);
        for i in 0..n {
            let (ya, yb) = (
                y0 + (y1 - y0) * i as f64 / n as f64,
                y0 + (y1 - y0) * (i + 1) as f64 / n as f64,
            );
            k.rod(
                DVec3::new(x, ya, z(k, ya) + lift),
                DVec3::new(x, yb, z(k, yb) + lift),
                r,
            );
            if supported {
                k.rod(
                    DVec3::new(x, ya, z(k, ya)),
                    DVec3::new(x, ya, z(k, ya) + lift - r),
                    0.06,
                );
            }
        }
    }
    above_deck_frames(k, y0, y1);
    // Catwalk at 2.5 m on posts.
    let n = (((y1 - y0) / 6.0).ceil() as usize).max(1);
    for i in 0..n {
        let (ya, yb) = (
            y0 + (y1 - y0) * i as f64 / n as f64,
            y0 + (y1 - y0) * (i + 1) as f64 / n as f64,
        );
        let zc = k.hull.deck_z_over_m(ya, yb) + 2.5;
        k.block(
            DVec3::new(0.0, 0.5 * (ya + yb), zc),
            DVec3::new(1.2, yb - ya, 0.15),
        );
        k.rod(DVec3::new(0.0, ya, zc - 2.5), DVec3::new(0.0, ya, zc), 0.08);
        for side in [-0.6, 0.6] {
            k.rod(
                DVec3::new(side, ya, zc + 1.0),
                DVec3::new(side, yb, zc + 1.0),
                0.025,
            );
            k.rod(
                DVec3::new(side, ya, zc),
                DVec3::new(side, ya, zc + 1.0),
                0.025,
            );
        }
    }
    // Manifold: pipes across the deck and a hose crane each side.
    let ym = 0.5 * (y0 + y1) - 0.05 * k.hull.length_m;
    let zm = k.hull.deck_z_m(ym);
    for i in 0..4 {
        let yy = ym + 1.5 * i as f64;
        k.rod(
            DVec3::new(-0.45 * b, yy, zm + 1.5),
            DVec3::new(0.45 * b, yy, zm + 1.5),
            0.25,
        );
    }
    for side in [-1.0, 1.0] {
        let base = DVec3::new(side * 0.2 * b, ym - 4.0, zm);
        k.cylinder(base, 0.6, 4.0);
        k.rod(
            base + DVec3::Z * 4.0,
            base + DVec3::new(side * 0.25 * b, 8.0, 7.0),
            0.25,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sizes(length_m: f64, outfit: Outfit) -> OutfitSizes {
        let beam_m = match outfit {
            Outfit::Kayak => 0.65,
            Outfit::ContainerShip | Outfit::BulkCarrier => 0.15 * length_m,
            Outfit::Tanker => 0.175 * length_m,
            Outfit::Ferry => 0.2 * length_m,
            _ => 0.32 * length_m,
        };
        OutfitSizes {
            length_m,
            beam_m,
            freeboard_m: if outfit == Outfit::Kayak {
                0.3
            } else {
                0.06 * length_m
            },
            house_height_m: outfit.default_house_height_m(beam_m),
            mast_height_m: None,
        }
    }

    /// Every outfit at a small and a large size builds finite parts that stand on the sea
    /// within its length and a few beams, with rods of positive radius; the same seed gives
    /// the same parts and another seed other ones where the outfit draws.
    #[test]
    fn outfits_build_finite_repeatable_parts() {
        for outfit in Outfit::ALL {
            let (lo, hi) = outfit.length_range_m();
            for length in [lo, (lo * hi).sqrt(), hi] {
                let sz = sizes(length, outfit);
                let a = build_outfit(outfit, &sz, 7);
                assert_eq!(a, build_outfit(outfit, &sz, 7), "{outfit:?}");
                assert!(!a.mesh.triangles.is_empty());
                let reach = DVec3::new(
                    2.0 * sz.beam_m + 2.0,
                    0.5 * length + 1.0,
                    3.0 * length + 5.0,
                );
                let inside = |p: DVec3| {
                    p.is_finite()
                        && p.x.abs() <= reach.x
                        && p.y.abs() <= reach.y
                        && p.z >= -1e-9
                        && p.z <= reach.z
                };
                for v in &a.mesh.vertices_m {
                    assert!(inside(*v), "{outfit:?} {length}: vertex {v}");
                }
                for r in &a.rods {
                    assert!(
                        inside(r.a_m) && inside(r.b_m),
                        "{outfit:?} {length}: rod {r:?}"
                    );
                    assert!(r.radius_m > 0.0 && r.reflectivity > 0.0 && r.reflectivity <= 1.0);
                }
                for (base, radius, height) in &a.cylinders {
                    assert!(
                        inside(*base) && *radius > 0.0 && *height > 0.0,
                        "{outfit:?}"
                    );
                }
            }
        }
        let sz = sizes(190.0, Outfit::ContainerShip);
        assert_ne!(
            build_outfit(Outfit::ContainerShip, &sz, 1),
            build_outfit(Outfit::ContainerShip, &sz, 2)
        );
    }

    /// The upright corners stand where they belong, at every size the cargo outfits are
    /// built for: each coaming stay is a vertical plate standing on the deck against the
    /// coaming's wall and reaching outboard; a tanker's web frames and girders stay inside
    /// the deck edge; lifeboats hang at most 0.6 m outboard of the deck edge, below the
    /// bridge wings' undersides, and only on houses of four tiers or more.
    #[test]
    fn upright_corners_stand_where_they_belong() {
        let builder = |length_m: f64, outfit: Outfit| Builder {
            parts: OutfitParts::default(),
            hull: HullForm {
                length_m,
                beam_m: sizes(length_m, outfit).beam_m,
                freeboard_m: sizes(length_m, outfit).freeboard_m,
                sheer_bow: 0.35,
                sheer_stern: 0.1,
                flare_mid: 1.0,
            },
        };
        // Stays: (wall point, outboard foot, top) with the wall's outward normal.
        let mut k = builder(190.0, Outfit::BulkCarrier);
        k.coaming_stays(17.0, -10.0, 10.0, 12.0, 2.0, 0.8, true);
        let v = &k.parts.mesh.vertices_m;
        assert_eq!(k.parts.mesh.triangles.len(), 2 * 9 + 2 * 8);
        for t in &k.parts.mesh.triangles {
            let (wall, foot, top) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            let on_side = (wall.x.abs() - 8.5).abs() < 1e-9 && wall.y.abs() < 10.0;
            let on_end = (wall.y.abs() - 10.0).abs() < 1e-9 && wall.x.abs() < 8.5;
            assert!(on_side != on_end, "{wall}");
            assert_eq!((wall.z, foot.z), (12.0, 12.0));
            assert!((top - wall - DVec3::Z * 1.7).length() < 1e-9);
            let out = foot - wall;
            assert!((out.length() - 0.8).abs() < 1e-9);
            assert!(
                out.dot(DVec3::new(wall.x, wall.y, 0.0)) > 0.0,
                "{wall} {out}"
            );
        }
        let mut k = builder(190.0, Outfit::ContainerShip);
        k.coaming_stays(17.0, -10.0, 10.0, 12.0, 1.6, 0.6, false);
        assert_eq!(k.parts.mesh.triangles.len(), 2 * 9);
        for outfit in [Outfit::ContainerShip, Outfit::BulkCarrier, Outfit::Tanker] {
            let (lo, hi) = outfit.length_range_m();
            for length in [lo, 100.0, 190.0, 330.0, hi] {
                let sz = sizes(length, outfit);
                // Frames inside the deck edge, on the deck.
                let mut k = builder(length, outfit);
                above_deck_frames(&mut k, -0.3 * length, 0.38 * length);
                for p in &k.parts.mesh.vertices_m {
                    let edge = k.hull.deck_half_width_m(p.y);
                    assert!(
                        p.x.abs() <= edge - 0.3 + 1e-9,
                        "{length}: {p} beyond {edge}"
                    );
                    assert!(p.z >= k.hull.deck_z_m(p.y) - 1e-9);
                }
                // Lifeboats beside the house, clear of its wings.
                let tiers = ((sz.house_height_m / 2.8).round() as usize).clamp(3, 9);
                let tier_h = sz.house_height_m / tiers as f64;
                let (y0, y1) = (-0.44 * length, -0.44 * length + (0.12 * length).max(10.0));
                let width = 0.8 * sz.beam_m;
                let mut k = builder(length, outfit);
                k.house_lifeboats(y0, y1, width, tiers, tier_h);
                if tiers < 4 {
                    assert!(k.parts.mesh.triangles.is_empty(), "{length}");
                }
                let wing_underside =
                    k.hull.deck_z_over_m(y0, y1) + (tiers - 1) as f64 * tier_h - 0.6;
                let parts = k.parts.rods.iter().flat_map(|r| [r.a_m, r.b_m]);
                for p in k.parts.mesh.vertices_m.iter().copied().chain(parts) {
                    assert!(p.x.abs() >= 0.5 * width - 1e-9, "{length}: {p}");
                    assert!(
                        p.x.abs() <= k.hull.deck_half_width_m(p.y) + 0.6,
                        "{length}: {p}"
                    );
                    assert!(p.z < wing_underside, "{length}: {p} above {wing_underside}");
                }
            }
        }
    }

    /// The hull's stations: the curved ends in steps of at most max(0.5 m, L/200), from the
    /// stern to the bow, strictly increasing.
    #[test]
    fn hull_stations_refine_the_curved_ends() {
        for length in [4.0, 40.0, 300.0] {
            let ys = hull_stations_m(length);
            assert_eq!(ys[0], -0.5 * length);
            assert_eq!(*ys.last().unwrap(), 0.5 * length);
            let fine = (length / 200.0).max(0.5);
            for w in ys.windows(2) {
                assert!(w[1] > w[0]);
                if w[0] >= 0.1 * length - 1e-9 || w[1] <= -0.3 * length + 1e-9 {
                    assert!(w[1] - w[0] <= fine + 1e-9, "{length}: {w:?}");
                }
            }
        }
    }

    /// The plastic hulls reflect as their materials' Fresnel coefficients: GRP 0.344,
    /// polyethylene 0.201; a steel outfit 1.
    #[test]
    fn hull_materials_reflect_as_their_permittivity() {
        assert!((Outfit::Yacht.hull_reflectivity() - 0.3438).abs() < 1e-3);
        assert!((Outfit::Kayak.hull_reflectivity() - 0.2012).abs() < 1e-3);
        assert_eq!(Outfit::Tanker.hull_reflectivity(), 1.0);
    }
}
