//! Product: the artefacts of a frame, labelled in its truth beside the objects (docs/formats.md,
//! "truth.json", `artefacts`): echoes that are not a target where they appear — each with its
//! kind, the object or emitter it comes from, the physical reason, and its boxes in the polar
//! record and the PPI — so that a detector can learn not to call them targets.
//!
//! **Sidelobe echoes.** A target's echo reaches the spokes off its bearing through the
//! antenna's sidelobes at `Gn(Δaz)²` of its peak (docs/physics.md §3): where its expected SNR
//! plus `20·log10 Gn(Δaz)` is at least [`SIDELOBE_LABEL_DB`] over the noise outside the main
//! lobe (beyond the first null), each run of such spokes is one artefact at the object's range.
//!
//! **Interference.** Each interferer is one artefact: every pulse of it that lands in a
//! pulse's record of the revolution (`crate::signal::interference`) at an expected level of
//! [`SIDELOBE_LABEL_DB`] or more is a box on that pulse's spoke, `N_T` samples either side of
//! its arrival (where the matched filter spreads it). Its level is the matched filter's peak
//! `a²·min(n_i, N_T)²/N_T` (`crate::signal::interference`); for a pulse-mode dwell, one
//! pulse's level before the dwell's integration.

use super::labels::{EchoRegion, ObjectTruth, PolarBox};
use crate::antenna::{wrap_angle_rad, Pattern};
use crate::model::artefacts::{Beacon, BeaconKind};
use crate::schedule::Schedule;
use crate::signal::beacons::Beacons;
use crate::signal::interference::Interference;
use serde::Serialize;

/// A sidelobe echo is labelled where it is expected at least this far over the noise, dB (the
/// receiver video's threshold at 0 dB gain).
pub const SIDELOBE_LABEL_DB: f64 = 6.0;

/// What made an artefact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ArtefactKind {
    /// A target's echo through the antenna's sidelobes.
    Sidelobe,
    /// An echo from beyond the unambiguous range, in the next pulse's record.
    SecondTrace,
    /// Another radar's pulses.
    Interference,
    /// A racon's Morse character behind it.
    Racon,
    /// A SART's dots outward from it.
    Sart,
    /// A sector behind the own ship's structure, where every echo is weakened.
    BlindSector,
    /// A target's echo via the own ship's structure, on the structure's bearing.
    IndirectEcho,
    /// A ship's echo bounced between its side and the own ship's side, at a multiple of its
    /// range.
    MultipleEcho,
}

/// One artefact of a frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArtefactTruth {
    /// Its kind.
    pub kind: ArtefactKind,
    /// The object (or emitter) it comes from.
    pub source: String,
    /// Why it is there, in words.
    pub reason: String,
    /// Its expected level, dB over the noise (the strongest of its cells); null for a blind
    /// sector, which weakens echoes rather than making one (its loss is in its reason and in
    /// each object's `losses.blind_sector`).
    pub expected_level_db: Option<f64>,
    /// Its boxes in the polar record.
    pub polar_boxes: Vec<PolarBox>,
    /// Its boxes in the PPI, `[x_min, y_min, x_max, y_max]` px, each null when outside the
    /// image (set by the PPI product).
    pub ppi_boxes_px: Vec<Option<[f64; 4]>>,
    /// Its regions (for the products' pixel boxes).
    #[serde(skip)]
    pub regions: Vec<EchoRegion>,
}

impl ArtefactTruth {
    /// An artefact of one box `polar_box` over `region`, expected at `level_db` over the noise.
    fn one_box(
        kind: ArtefactKind,
        source: String,
        reason: String,
        level_db: f64,
        polar_box: PolarBox,
        region: EchoRegion,
    ) -> ArtefactTruth {
        ArtefactTruth {
            kind,
            source,
            reason,
            expected_level_db: Some(level_db),
            polar_boxes: vec![polar_box],
            ppi_boxes_px: Vec::new(),
            regions: vec![region],
        }
    }

    /// Adds a box on spoke `spoke` over bins `bin_min ..= bin_max`, raising the level to
    /// `level_db` (spokes `spoke_rad` apart, bins `bin_m`).
    fn add_spoke_box(
        &mut self,
        spoke: usize,
        bin_min: usize,
        bin_max: usize,
        level_db: f64,
        spoke_rad: f64,
        bin_m: f64,
    ) {
        self.expected_level_db = Some(self.expected_level_db.map_or(level_db, |l| l.max(level_db)));
        self.polar_boxes.push(PolarBox {
            spoke_min: spoke,
            spoke_max: spoke,
            bin_min,
            bin_max,
        });
        self.regions.push(EchoRegion {
            range_min_m: bin_min as f64 * bin_m,
            range_max_m: bin_max as f64 * bin_m,
            height_above_radar_m: 0.0,
            azimuth_rad: spoke as f64 * spoke_rad,
            half_width_rad: spoke_rad / 2.0,
        });
    }
}

/// The truth of an echo that an artefact shows away from its object `o` — at `level_db`
/// over the noise in `region`, and `blind_sector_db` stronger than that where the blind
/// sectors at its bearing cost nothing — for [`sidelobe_artefacts`]: that echo too reaches the
/// spokes off its bearing through the antenna's sidelobes.
pub fn echo_image(
    o: &ObjectTruth,
    level_db: f64,
    region: EchoRegion,
    blind_sector_db: f64,
) -> ObjectTruth {
    let mut image = o.clone();
    image.expected_snr_db = Some(level_db);
    image.snr_before_eclipse_db = Some(level_db);
    image.echo_region = Some(region);
    image.region = region;
    image.far_region = None;
    image.azimuth_deg = region.azimuth_rad.to_degrees();
    image.range_m = 0.5 * (region.range_min_m + region.range_max_m);
    image.losses_db.blind_sector = blind_sector_db;
    image
}

/// The sidelobe echoes of `objects` for the azimuth `pattern` (and the own ship's blind
/// sectors `blind`) on `spokes` spokes, with range bins `bin_m` apart up to `num_bins`.
pub fn sidelobe_artefacts(
    objects: &[ObjectTruth],
    pattern: &Pattern,
    blind: &crate::model::artefacts::BlindView,
    spokes: usize,
    bin_m: f64,
    num_bins: usize,
) -> Vec<ArtefactTruth> {
    let null = pattern.first_null_rad();
    let spoke_rad = std::f64::consts::TAU / spokes as f64;
    let mut out = Vec::new();
    for o in objects {
        let (Some(snr_db), Some(region)) = (o.expected_snr_db, o.echo_region) else {
            continue;
        };
        let az = o.azimuth_deg.to_radians();
        let level = |k: usize| {
            let off = wrap_angle_rad(k as f64 * spoke_rad - az);
            if off.abs() <= null + region.half_width_rad {
                return None;
            }
            // The blind sectors at the spoke's azimuth, not the object's bearing.
            let l = snr_db + o.losses_db.blind_sector - blind.two_way_loss_db(k as f64 * spoke_rad)
                + 20.0 * pattern.value(off).max(1e-300).log10();
            (l >= SIDELOBE_LABEL_DB).then_some(l)
        };
        let marked: Vec<Option<f64>> = (0..spokes).map(level).collect();
        // Runs of marked spokes, joined across north.
        let Some(start) = (0..spokes).find(|&k| marked[k].is_none()) else {
            continue;
        };
        let mut k = 0;
        while k < spokes {
            let s = (start + k) % spokes;
            if marked[s].is_none() {
                k += 1;
                continue;
            }
            let first = s;
            let mut best = f64::MIN;
            let mut len = 0;
            while k < spokes && marked[(start + k) % spokes].is_some() {
                best = best.max(marked[(start + k) % spokes].unwrap_or(f64::MIN));
                len += 1;
                k += 1;
            }
            let centre = (first as f64 + (len as f64 - 1.0) / 2.0) * spoke_rad;
            let run = EchoRegion {
                azimuth_rad: centre.rem_euclid(std::f64::consts::TAU),
                half_width_rad: len as f64 * spoke_rad / 2.0,
                ..region
            };
            let Some(mut polar_box) = run.polar_box(bin_m, num_bins, spokes) else {
                continue;
            };
            polar_box.spoke_min = first;
            polar_box.spoke_max = (first + len - 1) % spokes;
            out.push(ArtefactTruth::one_box(
                ArtefactKind::Sidelobe,
                o.name.clone(),
                format!(
                    "the echo of \"{}\" through the antenna's sidelobes, {:.0}°–{:.0}° off its bearing {:.1}°",
                    o.name,
                    wrap_angle_rad(first as f64 * spoke_rad - az).to_degrees(),
                    wrap_angle_rad((first + len - 1) as f64 * spoke_rad - az).to_degrees(),
                    o.azimuth_deg
                ),
                best,
                polar_box,
                run,
            ));
        }
    }
    out
}

/// The interference of `interference` in the pulses of `schedule`: one artefact per
/// interferer, a box per pulse it lands in at [`SIDELOBE_LABEL_DB`] or more; `record_len`
/// is the pulse record's length, samples.
pub fn interference_artefacts(
    interference: &Interference,
    names: &[String],
    schedule: &Schedule,
    record_len: usize,
    bin_m: f64,
    num_bins: usize,
) -> Vec<ArtefactTruth> {
    let pulse_len = interference.pulse_len();
    let spokes = schedule.spokes();
    let spoke_rad = std::f64::consts::TAU / spokes as f64;
    let mut out = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let mut a = ArtefactTruth {
            kind: ArtefactKind::Interference,
            source: name.clone(),
            reason: format!(
                "pulses of the radar \"{name}\" (another transmitter), landing at ranges that walk from sweep to sweep"
            ),
            expected_level_db: None,
            polar_boxes: Vec::new(),
            ppi_boxes_px: Vec::new(),
            regions: Vec::new(),
        };
        for dwell in schedule.dwells() {
            for pulse in &dwell.pulses {
                interference.pulses_in_record(i, pulse.time_s, pulse.azimuth_rad, |p| {
                    let level_db = 10.0 * interference.peak_power(&p).log10();
                    // Only what lands in the record (the source adds nothing else).
                    if level_db < SIDELOBE_LABEL_DB
                        || p.first_sample < 0
                        || p.first_sample as usize >= record_len
                    {
                        return;
                    }
                    let first = p.first_sample - pulse_len as i64;
                    let last = p.first_sample + pulse_len as i64;
                    if first >= num_bins as i64 {
                        return;
                    }
                    a.add_spoke_box(
                        dwell.spoke,
                        first.max(0) as usize,
                        (last as usize).min(num_bins - 1),
                        level_db,
                        spoke_rad,
                        bin_m,
                    );
                });
            }
        }
        if !a.polar_boxes.is_empty() {
            out.push(a);
        }
    }
    out
}

/// The answers of the beacons `beacons` (as `seen`) to the pulses of `schedule`: one
/// artefact per beacon, a box per spoke whose pulse triggers it, from its first mark to its
/// last within the record (with the matched filter's spread, `N_T` samples either side); its
/// level the strongest mark's `a²·N_T·min(D/N_T, 1)²`.
pub fn beacon_artefacts(
    seen: &Beacons,
    beacons: &[Beacon],
    schedule: &Schedule,
    record_len: usize,
    bin_m: f64,
    num_bins: usize,
) -> Vec<ArtefactTruth> {
    let pulse_len = seen.pulse_len();
    let spokes = schedule.spokes();
    let spoke_rad = std::f64::consts::TAU / spokes as f64;
    let mut out = Vec::new();
    for (i, b) in beacons.iter().enumerate() {
        let (kind, reason) = match &b.kind {
            BeaconKind::Racon { letter, .. } => (
                ArtefactKind::Racon,
                format!(
                    "the racon \"{}\" answers the radar's pulses with the Morse letter {letter} behind it",
                    b.name
                ),
            ),
            BeaconKind::Sart => (
                ArtefactKind::Sart,
                format!(
                    "the SART \"{}\" answers the radar's pulses with 12 dots outward from it",
                    b.name
                ),
            ),
        };
        let mut a = ArtefactTruth {
            kind,
            source: b.name.clone(),
            reason,
            expected_level_db: None,
            polar_boxes: Vec::new(),
            ppi_boxes_px: Vec::new(),
            regions: Vec::new(),
        };
        for dwell in schedule.dwells() {
            // The dwell's pulses together: the box spans them all, the level is the highest.
            let (mut lo, mut hi, mut best) = (usize::MAX, 0usize, f64::MIN);
            for pulse in &dwell.pulses {
                seen.answer(i, pulse.azimuth_rad, |m| {
                    let level_db = 10.0 * seen.peak_power(&m).log10();
                    if level_db < SIDELOBE_LABEL_DB || m.first >= record_len {
                        return;
                    }
                    lo = lo.min(m.first.saturating_sub(pulse_len));
                    hi = hi.max(m.end.min(record_len) + pulse_len);
                    best = best.max(level_db);
                });
            }
            if lo >= num_bins || best == f64::MIN {
                continue;
            }
            a.add_spoke_box(
                dwell.spoke,
                lo,
                hi.min(num_bins - 1),
                best,
                spoke_rad,
                bin_m,
            );
        }
        if !a.polar_boxes.is_empty() {
            out.push(a);
        }
    }
    out
}

/// What an object's echo shown at another range loses there, dB:
/// `shown_loss_db(object's range, range shown at, extra two-way path)` — the eclipse where it
/// shows, the atmosphere over the extra path, and in combined pulse mode the difference of the
/// two ranges' pulse channels' noise (levels are over the noise where they show); None where
/// nothing of it is received. The engine's is built from the radar
/// (`labels::eclipse_loss_db_at`).
pub type ShownLoss<'a> = &'a dyn Fn(f64, f64, f64) -> Option<f64>;

/// The second-trace echoes among `objects`: each object beyond the recorded range whose echo
/// arrives after the next pulse (`[artefacts] second_trace`) appears one pulse interval `T`
/// nearer, at `R − c·T/2`. `folds` gives each interval's `c·T/2`, m, and the share of the
/// pulses it precedes (one fold of share 1 without a stagger;
/// [`crate::scattering::via_own_ship::stagger_folds`]): each fold carries that share of the
/// power. One artefact per object and fold whose expected level — the object's SNR before the
/// eclipse, plus `10·log10 share`, less `shown_loss_db` there — is at least
/// [`SIDELOBE_LABEL_DB`], its box the object's echo region moved in by `c·T/2` (inside the
/// record). Each one's [`echo_image`] goes to `images`.
#[allow(clippy::too_many_arguments)]
pub fn second_trace_artefacts(
    objects: &[ObjectTruth],
    images: &mut Vec<ObjectTruth>,
    shown_loss_db: ShownLoss,
    folds: &[(f64, f64)],
    max_range_m: f64,
    spokes: usize,
    bin_m: f64,
    num_bins: usize,
) -> Vec<ArtefactTruth> {
    let mut out = Vec::new();
    for o in objects {
        let (Some(snr_db), Some(region)) = (o.snr_before_eclipse_db, o.far_region) else {
            continue;
        };
        for &(fold_m, share) in folds {
            let folded = EchoRegion {
                range_min_m: (region.range_min_m - fold_m).max(0.0),
                range_max_m: region.range_max_m - fold_m,
                ..region
            };
            if folded.range_max_m <= 0.0 || folded.range_min_m >= max_range_m {
                continue;
            }
            let Some(shown_db) = shown_loss_db(o.range_m, o.range_m - fold_m, 0.0) else {
                continue;
            };
            let level_db = snr_db + 10.0 * share.log10() - shown_db;
            if level_db < SIDELOBE_LABEL_DB {
                continue;
            }
            let Some(polar_box) = folded.polar_box(bin_m, num_bins, spokes) else {
                continue;
            };
            images.push(echo_image(o, level_db, folded, o.losses_db.blind_sector));
            out.push(ArtefactTruth::one_box(
                ArtefactKind::SecondTrace,
                o.name.clone(),
                if folds.len() == 1 {
                    format!(
                        "\"{}\" at {:.0} m is beyond the unambiguous range {:.0} m: its echo arrives after the next pulse and shows {:.0} m nearer",
                        o.name, o.range_m, fold_m, fold_m
                    )
                } else {
                    format!(
                        "\"{}\" at {:.0} m is beyond the unambiguous range: after each pulse interval of {:.1} µs in the staggered train ({:.0} % of the pulses) its echo shows {:.0} m nearer",
                        o.name,
                        o.range_m,
                        2.0 * fold_m / crate::constants::SPEED_OF_LIGHT_M_PER_S * 1e6,
                        100.0 * share,
                        fold_m
                    )
                },
                level_db,
                polar_box,
                folded,
            ));
        }
    }
    out
}

/// The indirect echoes of `objects` via the own ship's structures (blind sectors with
/// `indirect`; [`crate::scattering::via_own_ship`]) for a bow heading `heading_rad` and an
/// azimuth beamwidth `beamwidth_rad`: one artefact per object and structure whose expected
/// level — the object's SNR before the eclipse with its own blind-sector loss taken off (the
/// echo comes from the structure, not through it), plus twice the structure's `indirect_db`,
/// less `shown_loss_db` at `d + |P − S|` — is at least [`SIDELOBE_LABEL_DB`]; its box on the
/// structure's bearing, over the ranges `d + |P − S|` of the object's extent (taken at the
/// bearings of its edges) widened by the echo region's own margins. Each one's
/// [`echo_image`] (with no blind-sector loss: these echoes take none) goes to `images`.
#[allow(clippy::too_many_arguments)]
pub fn indirect_echo_artefacts(
    objects: &[ObjectTruth],
    images: &mut Vec<ObjectTruth>,
    shown_loss_db: ShownLoss,
    sectors: &[crate::model::artefacts::BlindSector],
    heading_rad: f64,
    beamwidth_rad: f64,
    spokes: usize,
    bin_m: f64,
    num_bins: usize,
) -> Vec<ArtefactTruth> {
    let mut out = Vec::new();
    for s in sectors {
        let Some(indirect) = s.indirect else {
            continue;
        };
        let theta = (heading_rad + s.centre_rad()).rem_euclid(std::f64::consts::TAU);
        let structure = glam::DVec2::new(theta.sin(), theta.cos()) * indirect.distance_m;
        for o in objects {
            let (Some(snr_db), region) = (o.snr_before_eclipse_db, o.region) else {
                continue;
            };
            if o.far_region.is_some() {
                continue;
            }
            let height = region.height_above_radar_m;
            // The range shown for a point at slant range r on bearing az.
            let apparent = |r: f64, az: f64| {
                let ground = (r * r - height * height).max(0.0).sqrt();
                let p = glam::DVec2::new(az.sin(), az.cos()) * ground - structure;
                indirect.distance_m + p.length().hypot(height)
            };
            let az = o.azimuth_deg.to_radians();
            let shown_m = apparent(o.range_m, az);
            let Some(shown_db) = shown_loss_db(o.range_m, shown_m, 2.0 * (shown_m - o.range_m))
            else {
                continue;
            };
            let level_db = snr_db + o.losses_db.blind_sector + 2.0 * indirect.power_db - shown_db;
            if level_db < SIDELOBE_LABEL_DB {
                continue;
            }
            // The object's own extent: its bounding radius (the echo region less the margins
            // the beamwidth and the compressed pulse add), at the bearings of its edges.
            let extent_rad = (region.half_width_rad - beamwidth_rad / 2.0).max(0.0);
            let radius_m = o.range_m * extent_rad.tan();
            let (near_m, far_m) = (
                o.range_m - radius_m - region.range_min_m,
                region.range_max_m - o.range_m - radius_m,
            );
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            for r in [o.range_m - radius_m, o.range_m, o.range_m + radius_m] {
                for a in [az - extent_rad, az, az + extent_rad] {
                    let v = apparent(r.max(0.0), a);
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            let shown = EchoRegion {
                range_min_m: (lo - near_m.max(0.0)).max(0.0),
                range_max_m: hi + far_m.max(0.0),
                height_above_radar_m: height,
                azimuth_rad: theta,
                half_width_rad: beamwidth_rad / 2.0,
            };
            let Some(polar_box) = shown.polar_box(bin_m, num_bins, spokes) else {
                continue;
            };
            images.push(echo_image(o, level_db, shown, 0.0));
            out.push(ArtefactTruth::one_box(
                ArtefactKind::IndirectEcho,
                o.name.clone(),
                format!(
                    "the echo of \"{}\" (bearing {:.1}°) via the own ship's {} {:.0} m away, on the structure's bearing {:.1}°",
                    o.name,
                    o.azimuth_deg,
                    s.name,
                    indirect.distance_m,
                    theta.to_degrees()
                ),
                level_db,
                polar_box,
                shown,
            ));
        }
    }
    out
}

/// The multiple echoes of the `objects` that `abeam` marks
/// ([`crate::scattering::via_own_ship::abeam_objects`]): orders 2 to `multiple.max_order`,
/// each at `n` times its echo region's ranges on its bearing, its level the object's SNR
/// before the eclipse plus [`MultipleEchoes::relative_level_db`], less `shown_loss_db` at
/// `n·R` over the extra path `2(n−1)R`; one artefact per object and order at least
/// [`SIDELOBE_LABEL_DB`] over the noise and inside the record. Each one's [`echo_image`] goes
/// to `images`.
///
/// [`MultipleEchoes::relative_level_db`]: crate::model::artefacts::MultipleEchoes::relative_level_db
pub fn multiple_echo_artefacts(
    objects: &[ObjectTruth],
    images: &mut Vec<ObjectTruth>,
    shown_loss_db: ShownLoss,
    abeam: &[bool],
    multiple: &crate::model::artefacts::MultipleEchoes,
    spokes: usize,
    bin_m: f64,
    num_bins: usize,
) -> Vec<ArtefactTruth> {
    let mut out = Vec::new();
    for (o, _) in objects.iter().zip(abeam).filter(|(_, &a)| a) {
        let (Some(snr_db), region) = (o.snr_before_eclipse_db, o.region) else {
            continue;
        };
        if o.far_region.is_some() {
            continue;
        }
        for n in 2..=multiple.max_order {
            let shown_m = n as f64 * o.range_m;
            let Some(shown_db) = shown_loss_db(o.range_m, shown_m, 2.0 * (shown_m - o.range_m))
            else {
                continue;
            };
            let level_db = snr_db + multiple.relative_level_db(n) - shown_db;
            if level_db < SIDELOBE_LABEL_DB {
                continue;
            }
            let shown = EchoRegion {
                range_min_m: region.range_min_m * n as f64,
                range_max_m: region.range_max_m * n as f64,
                ..region
            };
            let Some(polar_box) = shown.polar_box(bin_m, num_bins, spokes) else {
                continue;
            };
            images.push(echo_image(o, level_db, shown, o.losses_db.blind_sector));
            out.push(ArtefactTruth::one_box(
                ArtefactKind::MultipleEcho,
                o.name.clone(),
                format!(
                    "the echo of \"{}\" abeam at {:.0} m, bounced {} more time{} between its side and the own ship's: it shows at {} times its range",
                    o.name,
                    o.range_m,
                    n - 1,
                    if n == 2 { "" } else { "s" },
                    n
                ),
                level_db,
                polar_box,
                shown,
            ));
        }
    }
    out
}

/// The blind sectors of the own ship (`[[own_ship.structure]]`) at bow heading
/// `heading_rad`: one artefact each, its box the sector's spokes over the whole record.
pub fn blind_sector_artefacts(
    sectors: &[crate::model::artefacts::BlindSector],
    heading_rad: f64,
    spokes: usize,
    bin_m: f64,
    num_bins: usize,
) -> Vec<ArtefactTruth> {
    let spoke_rad = std::f64::consts::TAU / spokes as f64;
    sectors
        .iter()
        .filter_map(|s| {
            let inside: Vec<usize> = (0..spokes)
                .filter(|&k| s.contains(k as f64 * spoke_rad - heading_rad))
                .collect();
            let first = *inside.iter().find(|&&k| {
                !s.contains((k + spokes - 1) as f64 * spoke_rad - heading_rad) || inside.len() == spokes
            })?;
            let region = EchoRegion {
                range_min_m: 0.0,
                range_max_m: (num_bins - 1) as f64 * bin_m,
                height_above_radar_m: 0.0,
                azimuth_rad: (heading_rad + s.from_rad + s.width_rad / 2.0)
                    .rem_euclid(std::f64::consts::TAU),
                half_width_rad: s.width_rad / 2.0,
            };
            Some(ArtefactTruth {
                kind: ArtefactKind::BlindSector,
                source: s.name.clone(),
                reason: format!(
                    "the own ship's {} stands in the beam from {:.1}° to {:.1}° off the bow: echoes there lose {:.1} dB",
                    s.name,
                    s.from_rad.to_degrees(),
                    (s.from_rad + s.width_rad).to_degrees().rem_euclid(360.0),
                    s.loss_db
                ),
                expected_level_db: None,
                polar_boxes: vec![PolarBox {
                    spoke_min: first,
                    spoke_max: (first + inside.len() - 1) % spokes,
                    bin_min: 0,
                    bin_max: num_bins - 1,
                }],
                ppi_boxes_px: Vec::new(),
                regions: vec![region],
            })
        })
        .collect()
}
