//! Model: the artefacts a scene switches on — second-trace and multiple echoes, other radars
//! nearby whose pulses reach the receiver, racons and SARTs answering this radar — validated
//! from the scene file's `[artefacts]` table, and the own ship's structure in the beam (blind
//! sectors, indirect echoes) from `[[own_ship.structure]]` (docs/formats.md, "[artefacts]",
//! "[own_ship]").

use crate::error::{Error, Problem, Result};
use crate::model::checks::{finite, finite_vec, positive};
use crate::scene::{
    ArtefactsSpec, BeaconSpec, InterfererSpec, MultipleEchoesSpec, OwnShipSpec, StructureSpec,
};
use glam::DVec3;

/// Another radar whose pulses reach this one's receiver.
#[derive(Debug, Clone, PartialEq)]
pub struct Interferer {
    /// Its name.
    pub name: String,
    /// Its antenna, ENU m.
    pub position_m: DVec3,
    /// Its PRF, Hz.
    pub prf_hz: f64,
    /// Its rotation, rpm.
    pub rotation_rpm: f64,
    /// Its antenna's azimuth at t = 0, rad.
    pub start_azimuth_rad: f64,
    /// Its peak power, W.
    pub peak_power_w: f64,
    /// Its pulse width, s.
    pub pulse_width_s: f64,
    /// Its antenna's peak gain (linear).
    pub peak_gain_linear: f64,
    /// Its azimuth beamwidth, rad.
    pub azimuth_beamwidth_rad: f64,
    /// Its antenna's sidelobe floor (linear, one-way).
    pub sidelobe_linear: f64,
}

impl Interferer {
    /// Its antenna's azimuth at time `t_s`, rad.
    pub fn azimuth_at_rad(&self, t_s: f64) -> f64 {
        self.start_azimuth_rad + std::f64::consts::TAU * self.rotation_rpm / 60.0 * t_s
    }

    /// Its one-way normalised gain toward a bearing `bearing_rad` at time `t_s`: the sinc² of
    /// its beamwidth over its sidelobe floor.
    pub fn pattern_toward(&self, bearing_rad: f64, t_s: f64) -> f64 {
        let off = crate::antenna::wrap_angle_rad(bearing_rad - self.azimuth_at_rad(t_s));
        crate::antenna::sinc2_pattern(off, self.azimuth_beamwidth_rad).max(self.sidelobe_linear)
    }
}

/// A transponder's kind and its answer.
#[derive(Debug, Clone, PartialEq)]
pub enum BeaconKind {
    /// A racon: after `delay_s` it sends a Morse character over `length_s`, its marks
    /// `(start, end)` as fractions of that length.
    Racon {
        /// The letter.
        letter: char,
        /// Its marks as fractions of the response's length.
        marks: Vec<(f64, f64)>,
        /// The response's length in time, s.
        length_s: f64,
        /// Its delay, s.
        delay_s: f64,
    },
    /// A SART: 12 slow sweeps of [`SART_SWEEP_S`] through the band, each crossing this
    /// radar's receiver once — 12 dots about 0.6 NM apart outward from it.
    Sart,
}

/// A transponder answering this radar's pulses.
#[derive(Debug, Clone, PartialEq)]
pub struct Beacon {
    /// Its name.
    pub name: String,
    /// Racon or SART.
    pub kind: BeaconKind,
    /// Its antenna, ENU m.
    pub position_m: DVec3,
    /// Its EIRP, W.
    pub eirp_w: f64,
    /// The pulse power at it that triggers it, W.
    pub sensitivity_w: f64,
}

/// A SART's slow sweep period, s: 12 of them make its answer (IMO performance standards for
/// SARTs, resolution A.802(19): 12 dots 0.64 NM apart; the sweep 7.5 µs, as makers' manuals
/// give it).
pub const SART_SWEEP_S: f64 = 7.5e-6;

/// A SART's dots.
pub const SART_DOTS: usize = 12;

/// The validated `[artefacts]` table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Artefacts {
    /// Second-trace echoes on.
    pub second_trace: bool,
    /// Other radars nearby.
    pub interferers: Vec<Interferer>,
    /// Racons and SARTs.
    pub beacons: Vec<Beacon>,
    /// Blind sectors behind the own ship's structure.
    pub blind_sectors: Vec<BlindSector>,
    /// Multiple echoes between the own ship's side and a ship abeam.
    pub multiple_echoes: Option<MultipleEchoes>,
}

impl Artefacts {
    /// Whether any echo takes a path via the own ship (indirect or multiple echoes,
    /// `crate::scattering::via_own_ship`).
    pub fn has_paths_via_own_ship(&self) -> bool {
        self.multiple_echoes.is_some() || self.blind_sectors.iter().any(|s| s.indirect.is_some())
    }
}

/// Multiple echoes (docs/physics.md §14): a ship abeam whose side is parallel to the own
/// ship's sends part of its echo back from the own ship's side; each round trip more shows it
/// again at `n·R` on its bearing, `20·log10 n + (n−1)·L` dB weaker (both sides flat mirrors
/// in each other's near field, the image method).
#[derive(Debug, Clone, PartialEq)]
pub struct MultipleEchoes {
    /// Power lost on each extra round trip, dB (≥ 0).
    pub round_trip_loss_db: f64,
    /// The highest order drawn (≥ 2).
    pub max_order: u32,
    /// How far from abeam and from parallel the sides may be, rad.
    pub abeam_tolerance_rad: f64,
    /// The shortest ship that bounces it, m along its bow axis.
    pub min_length_m: f64,
}

impl MultipleEchoes {
    /// Whether a ship at true bearing `bearing_rad` from the antenna, heading `heading_rad`,
    /// `length_m` long, lies abeam of an own ship heading `own_heading_rad` (its bearing off
    /// the bow within the tolerance of ±90°) with its side parallel (its heading within the
    /// tolerance of the own ship's or its reverse) and is long enough.
    pub fn applies(
        &self,
        own_heading_rad: f64,
        bearing_rad: f64,
        heading_rad: f64,
        length_m: f64,
    ) -> bool {
        let off_beam = (crate::antenna::wrap_angle_rad(bearing_rad - own_heading_rad).abs()
            - std::f64::consts::FRAC_PI_2)
            .abs();
        let crossing = crate::antenna::wrap_angle_rad(heading_rad - own_heading_rad).abs();
        let off_parallel = crossing.min(std::f64::consts::PI - crossing);
        length_m >= self.min_length_m
            && off_beam <= self.abeam_tolerance_rad
            && off_parallel <= self.abeam_tolerance_rad
    }

    /// The power of the order-`n` echo relative to the direct one, dB:
    /// `−20·log10 n − (n−1)·L`.
    pub fn relative_level_db(&self, n: u32) -> f64 {
        -20.0 * (n as f64).log10() - (n - 1) as f64 * self.round_trip_loss_db
    }
}

/// The indirect echoes of a structure (docs/physics.md §14): with the beam on it, the power
/// fraction `indirect_db` it scatters toward another bearing, on the way out and back.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Indirect {
    /// Power scattered toward other bearings on each pass, dB (≤ 0).
    pub power_db: f64,
    /// The structure's horizontal distance from the antenna, m.
    pub distance_m: f64,
}

/// A sector of bearings relative to the bow in which the own ship's structure blocks the beam.
#[derive(Debug, Clone, PartialEq)]
pub struct BlindSector {
    /// What stands there.
    pub name: String,
    /// Start, rad clockwise from the bow, in [0, 2π).
    pub from_rad: f64,
    /// Width, rad (0 < width < 2π).
    pub width_rad: f64,
    /// Two-way loss through it, dB.
    pub loss_db: f64,
    /// Its indirect echoes, when it makes them.
    pub indirect: Option<Indirect>,
}

impl BlindSector {
    /// The bearing of its middle relative to the bow, rad: where the beam meets the
    /// structure, and where its indirect echoes show.
    pub fn centre_rad(&self) -> f64 {
        (self.from_rad + self.width_rad / 2.0).rem_euclid(std::f64::consts::TAU)
    }

    /// Whether the relative bearing `relative_rad` (from the bow) lies in it.
    pub fn contains(&self, relative_rad: f64) -> bool {
        (relative_rad - self.from_rad).rem_euclid(std::f64::consts::TAU) < self.width_rad
    }
}

/// The blind sectors as a revolution sees them: the sectors and the bow's heading.
#[derive(Debug, Clone, Copy)]
pub struct BlindView<'a> {
    /// The sectors.
    pub sectors: &'a [BlindSector],
    /// The bow's heading, rad.
    pub heading_rad: f64,
}

impl BlindView<'_> {
    /// The two-way loss at antenna azimuth `azimuth_rad`, dB.
    pub fn two_way_loss_db(&self, azimuth_rad: f64) -> f64 {
        blind_loss_db(self.sectors, azimuth_rad, self.heading_rad)
    }

    /// The one-way power factor `10^{−L/20}` at antenna azimuth `azimuth_rad`: a path that
    /// crosses the structure once (another transmitter's pulse, a beacon's trigger or answer).
    pub fn one_way_power_factor(&self, azimuth_rad: f64) -> f64 {
        if self.sectors.is_empty() {
            return 1.0;
        }
        10f64.powf(-self.two_way_loss_db(azimuth_rad) / 20.0)
    }
}

/// The two-way loss, dB, of the blind sectors `sectors` at true bearing `bearing_rad` for a
/// bow heading `heading_rad` (the sum where sectors overlap).
pub fn blind_loss_db(sectors: &[BlindSector], bearing_rad: f64, heading_rad: f64) -> f64 {
    sectors
        .iter()
        .filter(|s| s.contains(bearing_rad - heading_rad))
        .map(|s| s.loss_db)
        .sum()
}

fn blind_sector(k: usize, s: &StructureSpec) -> Result<BlindSector> {
    let f = |name: &str| format!("own_ship.structure[{k}].{name}");
    let (Some(from), Some(to)) = (s.from_deg, s.to_deg) else {
        let missing = if s.from_deg.is_none() {
            "from_deg"
        } else {
            "to_deg"
        };
        return Err(Error::missing(
            f(missing),
            "a blind sector needs from_deg and to_deg, degrees clockwise from the bow",
        ));
    };
    let from = finite(&f("from_deg"), from)?;
    let to = finite(&f("to_deg"), to)?;
    let width = (to - from).rem_euclid(360.0);
    if width == 0.0 {
        return Err(Error::invalid(
            Problem::Conflict,
            f("to_deg"),
            to,
            format!("the sector from {from}° to {to}° is empty"),
        ));
    }
    let loss_db = finite(&f("loss_db"), s.loss_db.unwrap_or(20.0))?;
    if !(0.0..=200.0).contains(&loss_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("loss_db"),
            loss_db,
            "must be between 0 and 200 dB",
        ));
    }
    let indirect = match (s.indirect_db, s.distance_m) {
        (None, None) => None,
        (None, Some(_)) => return Err(Error::invalid(
            Problem::Conflict,
            f("distance_m"),
            "given",
            "the structure's distance is only used by its indirect echoes: give indirect_db too",
        )),
        (Some(_), None) => {
            return Err(Error::missing(
                f("distance_m"),
                "indirect echoes need the structure's horizontal distance from the antenna, m",
            ))
        }
        (Some(power_db), Some(distance_m)) => {
            let power_db = finite(&f("indirect_db"), power_db)?;
            if !(-60.0..=0.0).contains(&power_db) {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    f("indirect_db"),
                    power_db,
                    "must be between -60 and 0 dB (a fraction of the power on the structure)",
                ));
            }
            let distance_m = positive(&f("distance_m"), distance_m)?;
            if distance_m > 500.0 {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    f("distance_m"),
                    distance_m,
                    "must be at most 500 m (a structure on the own ship)",
                ));
            }
            Some(Indirect {
                power_db,
                distance_m,
            })
        }
    };
    Ok(BlindSector {
        name: s.name.clone().unwrap_or_else(|| format!("sector-{k}")),
        from_rad: from.rem_euclid(360.0).to_radians(),
        width_rad: width.to_radians(),
        loss_db,
        indirect,
    })
}

/// International Morse code of a letter: `.` a dot, `-` a dash (ITU-R M.1677-1).
fn morse(letter: char) -> Option<&'static str> {
    const CODES: [&str; 26] = [
        ".-", "-...", "-.-.", "-..", ".", "..-.", "--.", "....", "..", ".---", "-.-", ".-..", "--",
        "-.", "---", ".--.", "--.-", ".-.", "...", "-", "..-", "...-", ".--", "-..-", "-.--",
        "--..",
    ];
    let c = letter.to_ascii_uppercase();
    c.is_ascii_uppercase()
        .then(|| CODES[(c as u8 - b'A') as usize])
}

/// The marks of a Morse code as fractions of its length: a dot one unit, a dash three, one
/// unit between them (ITU-R M.1677-1).
pub fn morse_marks(code: &str) -> Vec<(f64, f64)> {
    let units: usize = code
        .chars()
        .map(|c| if c == '-' { 3 } else { 1 })
        .sum::<usize>()
        + code.len().saturating_sub(1);
    let mut t = 0usize;
    let mut marks = Vec::new();
    for c in code.chars() {
        let len = if c == '-' { 3 } else { 1 };
        marks.push((t as f64 / units as f64, (t + len) as f64 / units as f64));
        t += len + 1;
    }
    marks
}

fn beacon(k: usize, s: &BeaconSpec, sart: bool) -> Result<Beacon> {
    let table = if sart { "sart" } else { "racon" };
    let f = |name: &str| format!("artefacts.{table}[{k}].{name}");
    let Some(p) = s.position_m else {
        return Err(Error::missing(
            f("position_m"),
            "a beacon needs its position, [east, north, up] m",
        ));
    };
    let position_m = finite_vec(&f("position_m"), p)?;
    let eirp_w = positive(
        &f("eirp_w"),
        s.eirp_w.unwrap_or(if sart { 0.4 } else { 1.0 }),
    )?;
    let sensitivity_dbm = finite(&f("sensitivity_dbm"), s.sensitivity_dbm.unwrap_or(-50.0))?;
    let kind = if sart {
        for (field, given) in [
            ("morse", s.morse.is_some()),
            ("length_nm", s.length_nm.is_some()),
            ("delay_us", s.delay_us.is_some()),
        ] {
            if given {
                return Err(Error::invalid(
                    Problem::Conflict,
                    f(field),
                    "given",
                    "a SART answers with its 12 dots: only a racon has a Morse letter, length and delay",
                ));
            }
        }
        BeaconKind::Sart
    } else {
        let text = s.morse.clone().unwrap_or_else(|| "K".into());
        let mut chars = text.chars();
        let code = match (chars.next(), chars.next()) {
            (Some(letter), None) => morse(letter).map(|c| (letter, c)),
            _ => None,
        };
        let Some((letter, code)) = code else {
            return Err(Error::invalid(
                Problem::OutOfRange,
                f("morse"),
                format!("{text:?}"),
                "must be one letter A–Z",
            ));
        };
        let length_nm = positive(&f("length_nm"), s.length_nm.unwrap_or(1.0))?;
        if length_nm > 10.0 {
            return Err(Error::invalid(
                Problem::OutOfRange,
                f("length_nm"),
                length_nm,
                "must be at most 10 NM",
            ));
        }
        let delay_us = finite(&f("delay_us"), s.delay_us.unwrap_or(0.5))?;
        if !(0.0..=100.0).contains(&delay_us) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                f("delay_us"),
                delay_us,
                "must be between 0 and 100 µs",
            ));
        }
        BeaconKind::Racon {
            letter: letter.to_ascii_uppercase(),
            marks: morse_marks(code),
            length_s: length_nm * 1852.0 * 2.0 / crate::constants::SPEED_OF_LIGHT_M_PER_S,
            delay_s: delay_us * 1e-6,
        }
    };
    Ok(Beacon {
        name: s.name.clone().unwrap_or_else(|| format!("{table}-{k}")),
        kind,
        position_m,
        eirp_w,
        sensitivity_w: 10f64.powf(sensitivity_dbm / 10.0) * 1e-3,
    })
}

fn interferer(k: usize, s: &InterfererSpec) -> Result<Interferer> {
    let f = |name: &str| format!("artefacts.interferer[{k}].{name}");
    let Some(p) = s.position_m else {
        return Err(Error::missing(
            f("position_m"),
            "an interferer needs its antenna's position, [east, north, up] m",
        ));
    };
    let position_m = finite_vec(&f("position_m"), p)?;
    let sidelobe_db = finite(&f("sidelobe_db"), s.sidelobe_db.unwrap_or(-25.0))?;
    if !(-90.0..=0.0).contains(&sidelobe_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("sidelobe_db"),
            sidelobe_db,
            "must be between -90 and 0 dB",
        ));
    }
    let beamwidth_deg = positive(
        &f("azimuth_beamwidth_deg"),
        s.azimuth_beamwidth_deg.unwrap_or(3.9),
    )?;
    if beamwidth_deg >= 180.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("azimuth_beamwidth_deg"),
            beamwidth_deg,
            "must be less than 180",
        ));
    }
    let gain_dbi = finite(&f("gain_dbi"), s.gain_dbi.unwrap_or(25.0))?;
    if !(0.0..=50.0).contains(&gain_dbi) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("gain_dbi"),
            gain_dbi,
            "must be between 0 and 50 dBi",
        ));
    }
    let prf_hz = positive(&f("prf_hz"), s.prf_hz.unwrap_or(1000.0))?;
    if prf_hz > 100_000.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("prf_hz"),
            prf_hz,
            "must be at most 100 kHz",
        ));
    }
    let pulse_width_us = positive(&f("pulse_width_us"), s.pulse_width_us.unwrap_or(0.3))?;
    if pulse_width_us * 1e-6 >= 1.0 / prf_hz {
        return Err(Error::invalid(
            Problem::Conflict,
            f("pulse_width_us"),
            pulse_width_us,
            format!("must be shorter than its pulse interval 1/prf_hz (prf_hz = {prf_hz})"),
        ));
    }
    Ok(Interferer {
        name: s.name.clone().unwrap_or_else(|| format!("interferer-{k}")),
        position_m,
        prf_hz,
        rotation_rpm: positive(&f("rotation_rpm"), s.rotation_rpm.unwrap_or(22.0))?,
        start_azimuth_rad: finite(&f("start_azimuth_deg"), s.start_azimuth_deg.unwrap_or(0.0))?
            .to_radians(),
        peak_power_w: positive(&f("peak_power_w"), s.peak_power_w.unwrap_or(4000.0))?,
        pulse_width_s: pulse_width_us * 1e-6,
        peak_gain_linear: 10f64.powf(gain_dbi / 10.0),
        azimuth_beamwidth_rad: beamwidth_deg.to_radians(),
        sidelobe_linear: 10f64.powf(sidelobe_db / 10.0),
    })
}

/// Validates `[artefacts]` with the own ship's structure (`[[own_ship.structure]]`: the blind
/// sectors and indirect echoes).
pub fn build_artefacts(s: &ArtefactsSpec, own_ship: Option<&OwnShipSpec>) -> Result<Artefacts> {
    Ok(Artefacts {
        second_trace: s.second_trace.unwrap_or(false),
        interferers: s
            .interferer
            .iter()
            .enumerate()
            .map(|(k, i)| interferer(k, i))
            .collect::<Result<_>>()?,
        beacons: s
            .racon
            .iter()
            .enumerate()
            .map(|(k, b)| beacon(k, b, false))
            .chain(s.sart.iter().enumerate().map(|(k, b)| beacon(k, b, true)))
            .collect::<Result<_>>()?,
        blind_sectors: own_ship
            .map_or(&[][..], |o| &o.structure[..])
            .iter()
            .enumerate()
            .map(|(k, b)| blind_sector(k, b))
            .collect::<Result<_>>()?,
        multiple_echoes: s
            .multiple_echoes
            .as_ref()
            .map(multiple_echoes)
            .transpose()?,
    })
}

fn multiple_echoes(s: &MultipleEchoesSpec) -> Result<MultipleEchoes> {
    let f = |name: &str| format!("artefacts.multiple_echoes.{name}");
    let round_trip_loss_db = finite(
        &f("round_trip_loss_db"),
        s.round_trip_loss_db.unwrap_or(6.0),
    )?;
    if !(0.0..=60.0).contains(&round_trip_loss_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("round_trip_loss_db"),
            round_trip_loss_db,
            "must be between 0 and 60 dB",
        ));
    }
    let max_order = s.max_order.unwrap_or(3);
    if !(2..=8).contains(&max_order) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("max_order"),
            max_order,
            "must be between 2 and 8 (2 draws the echo at twice the range)",
        ));
    }
    let tolerance_deg = finite(
        &f("abeam_tolerance_deg"),
        s.abeam_tolerance_deg.unwrap_or(10.0),
    )?;
    if !(0.0..=45.0).contains(&tolerance_deg) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("abeam_tolerance_deg"),
            tolerance_deg,
            "must be between 0 and 45 degrees",
        ));
    }
    let min_length_m = finite(&f("min_length_m"), s.min_length_m.unwrap_or(30.0))?;
    if min_length_m < 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("min_length_m"),
            min_length_m,
            "must be at least 0 m",
        ));
    }
    Ok(MultipleEchoes {
        round_trip_loss_db,
        max_order,
        abeam_tolerance_rad: tolerance_deg.to_radians(),
        min_length_m,
    })
}
