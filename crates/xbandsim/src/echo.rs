//! Stage: echo synthesis. Bins scattering contributions into band-limited impulse responses,
//! grouped by object and by direction cell so that each beam only rescales and adds groups.
//!
//! The received baseband of one pulse is `r(t) = Σ_i g_i·a_i·s(t − τ_i)` (docs/physics.md §5),
//! with `a_i` the contribution's peak-gain voltage (carrier phase `exp(−j2πf0τ_i)` included)
//! and `g_i` the two-way antenna voltage weight of the beam. Because `s` is band-limited,
//! `r = h ⊛ s` where `h[n] = Σ_i g_i·a_i·k(n − τ_i·fs)` and `k` is a band-limited
//! fractional-delay kernel (Kaiser-windowed sinc, Laakso et al., "Splitting the unit delay",
//! IEEE SP Magazine 13(1), 1996). Nearest-sample rounding would cost up to 0.9 dB of peak.
//!
//! Contributions are grouped by (object, transmit-azimuth cell, receive-azimuth cell), cells
//! `θaz/64` wide, so the azimuth weight is evaluated once per group and beam (error < 0.05 dB
//! inside the main lobe). The elevation weight does not change as the antenna turns and is
//! applied exactly per contribution.

use crate::antenna::Antenna;
use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::scattering::Contribution;
use num_complex::{Complex32, Complex64};

/// Taps of the fractional-delay kernel.
pub const KERNEL_TAPS: usize = 16;
/// Fractional phases tabulated.
const KERNEL_PHASES: usize = 512;
/// Kaiser window shape β of the kernel.
const KERNEL_KAISER_BETA: f64 = 7.0;
/// Azimuth cells per beamwidth used to group contributions.
pub const AZIMUTH_CELLS_PER_BEAMWIDTH: f64 = 64.0;

/// Tabulated Kaiser-windowed-sinc fractional-delay kernel (one table per process, shared:
/// it depends on nothing but the constants above).
#[derive(Debug, Clone)]
pub struct FractionalDelayKernel {
    table: std::sync::Arc<[f32]>,
}

impl Default for FractionalDelayKernel {
    fn default() -> Self {
        Self::new()
    }
}

impl FractionalDelayKernel {
    /// The table: for each fraction μ, taps at offsets `1 − TAPS/2 ..= TAPS/2` (tabulated
    /// on first use, then shared).
    pub fn new() -> Self {
        static TABLE: std::sync::OnceLock<std::sync::Arc<[f32]>> = std::sync::OnceLock::new();
        FractionalDelayKernel {
            table: TABLE.get_or_init(Self::tabulate).clone(),
        }
    }

    fn tabulate() -> std::sync::Arc<[f32]> {
        let half = (KERNEL_TAPS / 2) as f64;
        let i0_beta = crate::special::bessel_i0(KERNEL_KAISER_BETA);
        let mut table = Vec::with_capacity(KERNEL_PHASES * KERNEL_TAPS);
        for p in 0..KERNEL_PHASES {
            let mu = p as f64 / KERNEL_PHASES as f64;
            let taps: Vec<f64> = (0..KERNEL_TAPS)
                .map(|t| {
                    let x = (t as f64 + 1.0 - half) - mu;
                    let sinc = if x.abs() < 1e-12 {
                        1.0
                    } else {
                        (std::f64::consts::PI * x).sin() / (std::f64::consts::PI * x)
                    };
                    let r = (x / half).clamp(-1.0, 1.0);
                    sinc * crate::special::bessel_i0(KERNEL_KAISER_BETA * (1.0 - r * r).sqrt())
                        / i0_beta
                })
                .collect();
            let dc: f64 = taps.iter().sum();
            table.extend(taps.iter().map(|v| (v / dc) as f32));
        }
        table.into()
    }

    /// Offset of the first tap relative to `floor(delay)`.
    pub const FIRST_TAP_OFFSET: i64 = 1 - (KERNEL_TAPS as i64) / 2;

    /// Taps for a delay of `delay_samples`: returns (index of the first tap, taps).
    #[inline]
    pub fn taps(&self, delay_samples: f64) -> (i64, &[f32]) {
        let (first, at) = self.taps_index(delay_samples);
        (first, self.taps_at(at))
    }

    /// As [`FractionalDelayKernel::taps`], with the taps as their place in the table
    /// ([`FractionalDelayKernel::taps_at`]).
    #[inline]
    fn taps_index(&self, delay_samples: f64) -> (i64, u32) {
        let base = crate::special::floor_exact(delay_samples);
        let mut idx =
            crate::special::round_exact((delay_samples - base) * KERNEL_PHASES as f64) as usize;
        let mut first = base as i64 + Self::FIRST_TAP_OFFSET;
        if idx == KERNEL_PHASES {
            idx = 0;
            first += 1;
        }
        (first, (idx * KERNEL_TAPS) as u32)
    }

    /// The taps starting at `at` in the table.
    #[inline]
    fn taps_at(&self, at: u32) -> &[f32] {
        &self.table[at as usize..at as usize + KERNEL_TAPS]
    }
}

/// A group of contributions sharing object and azimuth cells, as one short impulse response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EchoGroup {
    /// Object index.
    pub object: u32,
    /// Mean transmit azimuth, rad.
    pub az_tx_rad: f64,
    /// Mean receive azimuth, rad.
    pub az_rx_rad: f64,
    /// Sample index of the first stored value.
    pub first_sample: usize,
    /// Number of stored samples.
    pub len: usize,
    /// Offset into the sample arena.
    offset: usize,
    /// Largest |h| in the group (noise-rms units).
    pub peak: f32,
}

/// What one contribution adds to its group ([`EchoGroups::build_tilted`]).
#[derive(Debug, Clone, Copy, Default)]
struct Member {
    /// Sample of its first kernel tap.
    first: i64,
    /// Where its taps start in the kernel's table.
    taps_at: u32,
    /// Amplitude with its elevation weight, noise-rms units.
    a: Complex64,
    /// Unit phasor of its transmit azimuth (for the group's mean).
    az_tx: Complex64,
    /// Unit phasor of its receive azimuth.
    az_rx: Complex64,
}

/// All groups of one scene state, impulse responses in units of the noise rms voltage.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EchoGroups {
    /// Groups sorted by key.
    pub groups: Vec<EchoGroup>,
    arena: Vec<Complex32>,
}

impl EchoGroups {
    /// Groups `contributions`, applying the elevation pattern, dividing by the noise rms
    /// voltage `noise_rms_v` and spreading each over the fractional-delay kernel.
    /// Contributions whose delay falls at or beyond `num_samples` are dropped.
    pub fn build(
        contributions: &[Contribution],
        antenna: &Antenna,
        sample_rate_hz: f64,
        num_samples: usize,
        noise_rms_v: f64,
        kernel: &FractionalDelayKernel,
    ) -> EchoGroups {
        EchoGroups::build_tilted(
            contributions,
            antenna,
            &[],
            sample_rate_hz,
            num_samples,
            noise_rms_v,
            kernel,
        )
    }

    /// As [`EchoGroups::build`], with object i's elevation pattern centred
    /// `object_tilt_rad[i]` above the antenna's tilt (the own ship's roll and pitch when the
    /// beam crosses it); objects beyond the slice's end get none.
    pub fn build_tilted(
        contributions: &[Contribution],
        antenna: &Antenna,
        object_tilt_rad: &[f64],
        sample_rate_hz: f64,
        num_samples: usize,
        noise_rms_v: f64,
        kernel: &FractionalDelayKernel,
    ) -> EchoGroups {
        EchoGroups::build_folded(
            contributions,
            antenna,
            object_tilt_rad,
            sample_rate_hz,
            num_samples,
            noise_rms_v,
            kernel,
            None,
        )
    }

    /// As [`EchoGroups::build_tilted`]; with `fold_samples` (the pulse interval in samples,
    /// `[artefacts] second_trace`), a contribution whose delay falls at or beyond the record
    /// arrives after the next pulse: its delay less one interval, if that falls in the record
    /// (a second-trace echo, docs/physics.md §14).
    #[allow(clippy::too_many_arguments)]
    pub fn build_folded(
        contributions: &[Contribution],
        antenna: &Antenna,
        object_tilt_rad: &[f64],
        sample_rate_hz: f64,
        num_samples: usize,
        noise_rms_v: f64,
        kernel: &FractionalDelayKernel,
        fold_samples: Option<f64>,
    ) -> EchoGroups {
        let delay_of = |c: &Contribution| -> f64 {
            let d = c.delay_s() * sample_rate_hz;
            match fold_samples {
                Some(f) if d >= num_samples as f64 => d - f,
                _ => d,
            }
        };
        let cell_rad = antenna.az_beamwidth_rad / AZIMUTH_CELLS_PER_BEAMWIDTH;
        let cells = (std::f64::consts::TAU / cell_rad).ceil() as u64;
        let key = |c: &Contribution| -> u64 {
            let tx =
                ((crate::special::rem_euclid_tau(c.az_tx_rad) / cell_rad) as u64).min(cells - 1);
            let rx =
                ((crate::special::rem_euclid_tau(c.az_rx_rad) / cell_rad) as u64).min(cells - 1);
            ((c.object as u64) << 40) | (tx << 20) | rx
        };
        let mut order: Vec<(u64, u32)> = contributions
            .iter()
            .enumerate()
            .filter(|(_, c)| (0.0..num_samples as f64).contains(&delay_of(c)))
            .map(|(i, c)| (key(c), i as u32))
            .collect();
        crate::special::sort_by_key_stable(&mut order);
        // Each kept contribution's place in group order.
        const DROPPED: u32 = u32::MAX;
        debug_assert!(contributions.len() < DROPPED as usize);
        let mut place = vec![DROPPED; contributions.len()];
        for (pos, &(_, i)) in order.iter().enumerate() {
            place[i as usize] = pos as u32;
        }
        // What each member adds, computed in the contributions' own order (a tube's returns
        // are neighbours there and share their transmit direction and elevation) and stored
        // at its place in group order, so that the groups then read their members in one
        // sequential pass: the members of a group lie far apart in `contributions`, and
        // reading them there was a cache miss each. The values, and the order in which each
        // group sums them, are those of taking the members one by one.
        let mut members_out = vec![Member::default(); order.len()];
        let inv_noise = 1.0 / noise_rms_v;
        let mut tx_sin_cos = crate::special::LastCall::new();
        // Elevation pattern values, kept for the next member with the same elevation and
        // the same object tilt (the key holds both, so a value is reused only for its own
        // antenna).
        let mut pattern_tx = crate::special::LastCall::new();
        let mut pattern_rx = crate::special::LastCall::new();
        for (c, &pos) in contributions.iter().zip(&place) {
            if pos == DROPPED {
                continue;
            }
            let (first, taps_at) = kernel.taps_index(delay_of(c));
            let tilt = object_tilt_rad
                .get(crate::scattering::via_own_ship::traced_object(c.object) as usize)
                .copied()
                .unwrap_or(0.0);
            let ant = if tilt != 0.0 {
                antenna.tilted_by(tilt)
            } else {
                *antenna
            };
            let (el_tx, el_rx) = (c.el_tx_rad, c.el_rx_rad);
            let g_tx = pattern_tx.get_or((el_tx.to_bits(), tilt.to_bits()), || {
                ant.elevation_pattern(el_tx)
            });
            let g_rx = pattern_rx.get_or((el_rx.to_bits(), tilt.to_bits()), || {
                ant.elevation_pattern(el_rx)
            });
            let el_weight = (g_tx * g_rx).sqrt();
            let (sin_tx, cos_tx) = tx_sin_cos.get_or(c.az_tx_rad.to_bits(), || {
                crate::special::sin_cos_fast(c.az_tx_rad)
            });
            let (sin_rx, cos_rx) = crate::special::sin_cos_fast(c.az_rx_rad);
            members_out[pos as usize] = Member {
                first,
                taps_at,
                a: c.amplitude_v * (el_weight * inv_noise),
                az_tx: Complex64::new(cos_tx, sin_tx),
                az_rx: Complex64::new(cos_rx, sin_rx),
            };
        }
        drop(place);
        let mut groups = Vec::new();
        let mut arena: Vec<Complex32> = Vec::new();
        // One group's sum before rounding to f32, reused from group to group.
        let mut acc: Vec<Complex64> = Vec::new();
        let mut start = 0;
        while start < order.len() {
            let k = order[start].0;
            let mut end = start;
            while end < order.len() && order[end].0 == k {
                end += 1;
            }
            let members = &members_out[start..end];
            let mut lo = i64::MAX;
            let mut hi = i64::MIN;
            let (mut az_tx_sum, mut az_rx_sum) =
                (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
            for m in members {
                lo = lo.min(m.first.max(0));
                hi = hi.max(m.first + KERNEL_TAPS as i64);
                az_tx_sum += m.az_tx;
                az_rx_sum += m.az_rx;
            }
            let lo = lo as usize;
            let len = (hi.max(lo as i64 + 1) as usize) - lo;
            let offset = arena.len();
            arena.resize(offset + len, Complex32::new(0.0, 0.0));
            let slot = &mut arena[offset..offset + len];
            acc.clear();
            acc.resize(len, Complex64::new(0.0, 0.0));
            for m in members {
                let taps = kernel.taps_at(m.taps_at);
                let a = m.a;
                let start = m.first - lo as i64;
                if start >= 0 {
                    // Every tap inside the group (all but taps before sample 0): one slice.
                    let start = start as usize;
                    for (dst, &w) in acc[start..start + taps.len()].iter_mut().zip(taps) {
                        *dst += a * w as f64;
                    }
                } else {
                    for (t, &w) in taps.iter().enumerate() {
                        let n = start + t as i64;
                        if n >= 0 {
                            acc[n as usize] += a * w as f64;
                        }
                    }
                }
            }
            let mut peak = 0f32;
            for (dst, src) in slot.iter_mut().zip(&acc) {
                *dst = Complex32::new(src.re as f32, src.im as f32);
                peak = peak.max(dst.norm());
            }
            groups.push(EchoGroup {
                object: contributions[order[start].1 as usize].object,
                az_tx_rad: crate::special::rem_euclid_tau(az_tx_sum.arg()),
                az_rx_rad: crate::special::rem_euclid_tau(az_rx_sum.arg()),
                first_sample: lo,
                len,
                offset,
                peak,
            });
            start = end;
        }
        EchoGroups { groups, arena }
    }

    /// The groups of `parts` one after another: for parts built from the contributions of
    /// distinct objects in ascending order, the groups one build of all those contributions
    /// gives (a group never spans objects, and each is summed from its own members alone).
    pub fn concat(parts: &[&EchoGroups]) -> EchoGroups {
        let mut all = EchoGroups {
            groups: Vec::with_capacity(parts.iter().map(|p| p.groups.len()).sum()),
            arena: Vec::with_capacity(parts.iter().map(|p| p.arena.len()).sum()),
        };
        for part in parts {
            let shift = all.arena.len();
            all.groups.extend(part.groups.iter().map(|g| EchoGroup {
                offset: g.offset + shift,
                ..*g
            }));
            all.arena.extend_from_slice(&part.arena);
        }
        all
    }

    /// Adds every group, weighted by the azimuth pattern for a beam at `beam_az_rad`, into
    /// `impulse_response` (which must be long enough). Groups whose weighted peak is below
    /// `min_amplitude` (noise-rms units) are skipped. Returns the earliest sample written.
    pub fn accumulate(
        &self,
        antenna: &Antenna,
        beam_az_rad: f64,
        min_amplitude: f32,
        impulse_response: &mut [Complex32],
    ) -> Option<usize> {
        self.accumulate_groups(
            &self.groups,
            antenna,
            beam_az_rad,
            min_amplitude,
            impulse_response,
        )
        .0
    }

    /// The groups of object `object` (contiguous: groups are sorted by object first).
    pub fn groups_of(&self, object: u32) -> &[EchoGroup] {
        let lo = self.groups.partition_point(|g| g.object < object);
        let hi = self.groups.partition_point(|g| g.object <= object);
        &self.groups[lo..hi]
    }

    /// As [`EchoGroups::accumulate`] for the groups of the objects `include` accepts, taken
    /// a run of equal objects at a time. Returns the earliest sample written.
    pub fn accumulate_where(
        &self,
        antenna: &Antenna,
        beam_az_rad: f64,
        min_amplitude: f32,
        impulse_response: &mut [Complex32],
        include: impl Fn(u32) -> bool,
    ) -> Option<usize> {
        let mut earliest: Option<usize> = None;
        let mut start = 0;
        while start < self.groups.len() {
            let object = self.groups[start].object;
            let end = start + self.groups[start..].partition_point(|g| g.object == object);
            if include(object) {
                let (e, _) = self.accumulate_groups(
                    &self.groups[start..end],
                    antenna,
                    beam_az_rad,
                    min_amplitude,
                    impulse_response,
                );
                if let Some(e) = e {
                    earliest = Some(earliest.map_or(e, |x| x.min(e)));
                }
            }
            start = end;
        }
        earliest
    }

    /// The earliest first sample and the sum of the weighted peaks (an upper bound on the
    /// accumulated impulse response's peak) of the `groups` that
    /// [`EchoGroups::accumulate_groups`] would add for a beam at `beam_az_rad`; nothing is
    /// written.
    pub fn weighted_peak_bound(
        groups: &[EchoGroup],
        antenna: &Antenna,
        beam_az_rad: f64,
        min_amplitude: f32,
    ) -> (Option<usize>, f32) {
        let mut earliest: Option<usize> = None;
        let mut sum = 0f32;
        for g in groups {
            let Some(w) = weight_at_or_above(g, antenna, beam_az_rad, min_amplitude) else {
                continue;
            };
            sum += w * g.peak;
            earliest = Some(earliest.map_or(g.first_sample, |e: usize| e.min(g.first_sample)));
        }
        (earliest, sum)
    }

    /// Adds `groups` (a slice of this set's) weighted by the azimuth pattern; returns the
    /// earliest sample written and the sum of the weighted group peaks, the same bound
    /// [`EchoGroups::weighted_peak_bound`] gives.
    pub fn accumulate_groups(
        &self,
        groups: &[EchoGroup],
        antenna: &Antenna,
        beam_az_rad: f64,
        min_amplitude: f32,
        impulse_response: &mut [Complex32],
    ) -> (Option<usize>, f32) {
        let mut earliest: Option<usize> = None;
        let mut sum = 0f32;
        for g in groups {
            let Some(w) = weight_at_or_above(g, antenna, beam_az_rad, min_amplitude) else {
                continue;
            };
            sum += w * g.peak;
            let end = (g.first_sample + g.len).min(impulse_response.len());
            if g.first_sample >= end {
                continue;
            }
            let dst = &mut impulse_response[g.first_sample..end];
            for (d, s) in dst
                .iter_mut()
                .zip(&self.arena[g.offset..g.offset + (end - g.first_sample)])
            {
                *d += s * w;
            }
            earliest = Some(earliest.map_or(g.first_sample, |e: usize| e.min(g.first_sample)));
        }
        (earliest, sum)
    }

    /// Number of stored impulse-response samples.
    pub fn arena_len(&self) -> usize {
        self.arena.len()
    }
}

/// Two-way azimuth voltage weight `√(Gn(az_tx − beam)·Gn(az_rx − beam))` of a group for a
/// beam at `beam_az_rad`.
#[inline]
fn azimuth_weight(g: &EchoGroup, antenna: &Antenna, beam_az_rad: f64) -> f32 {
    let tx = antenna.azimuth_pattern(g.az_tx_rad - beam_az_rad);
    if g.az_rx_rad.to_bits() == g.az_tx_rad.to_bits() {
        // Most groups leave and return along one azimuth: √(p·p) is p exactly (a correctly
        // rounded square root of a correctly rounded square, p well above underflow).
        return tx as f32;
    }
    (tx * antenna.azimuth_pattern(g.az_rx_rad - beam_az_rad)).sqrt() as f32
}

/// The azimuth weight of group `g` for a beam at `beam_az_rad`, if its weighted peak is at
/// least `min_amplitude` (None: the group is skipped; where the pattern's envelope already
/// says so, [`surely_below`], without its sine).
#[inline]
fn weight_at_or_above(
    g: &EchoGroup,
    antenna: &Antenna,
    beam_az_rad: f64,
    min_amplitude: f32,
) -> Option<f32> {
    if surely_below(g, antenna, beam_az_rad, min_amplitude) {
        return None;
    }
    let w = azimuth_weight(g, antenna, beam_az_rad);
    // (Written as the skip test, so that a NaN product keeps the group, as it always did.)
    let below = w * g.peak < min_amplitude;
    (!below).then_some(w)
}

/// Relative margin of [`surely_below`] over the envelope: the computed weight exceeds its
/// bound `1/|u_tx·u_rx|` by the sine's error (10⁻¹³), a few f64 roundings and the two f32
/// roundings of the weight and its product with the peak (6·10⁻⁸ each).
const ENVELOPE_MARGIN: f64 = 1.0 + 1e-6;

/// Whether `azimuth_weight(g)·g.peak < min_amplitude` for a beam at `beam_az_rad` is sure
/// from the pattern's envelope alone (`[sin(u)/u]² ≤ 1/u²`, so the two-way voltage weight
/// `√(Gn_tx·Gn_rx) ≤ 1/|u_tx·u_rx|`): true only where that test skips the group too, so
/// the groups added, and their sums, are the same; most groups of a frame are far in the
/// sidelobes of most beams, and their sines are not computed.
#[inline]
fn surely_below(g: &EchoGroup, antenna: &Antenna, beam_az_rad: f64, min_amplitude: f32) -> bool {
    let u_tx = antenna.azimuth_inverse_envelope(g.az_tx_rad - beam_az_rad);
    let u_rx = if g.az_rx_rad.to_bits() == g.az_tx_rad.to_bits() {
        u_tx
    } else {
        antenna.azimuth_inverse_envelope(g.az_rx_rad - beam_az_rad)
    };
    f64::from(g.peak) * ENVELOPE_MARGIN < f64::from(min_amplitude) * (u_tx * u_rx)
}

/// Sample index of a two-way path, `ℓ/c·fs`.
pub fn path_to_samples(path_m: f64, sample_rate_hz: f64) -> f64 {
    path_m / SPEED_OF_LIGHT_M_PER_S * sample_rate_hz
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `build_tilted` against the definition, group by group: each group's members taken one
    /// by one from the contributions (a map of keys in key order), their kernel taps summed in
    /// f64 with each object's own tilted antenna. Objects interleaved in the contributions,
    /// tilted and level ones (with a tilt slice shorter than the objects), contributions past
    /// the record (dropped) and taps before sample 0: the same groups and impulse responses,
    /// bit for bit.
    #[test]
    fn build_tilted_matches_the_member_by_member_sum() {
        use std::collections::BTreeMap;
        let antenna = Antenna {
            az_beamwidth_rad: 3.9f64.to_radians(),
            el_beamwidth_rad: 22f64.to_radians(),
            peak_gain_linear: 1000.0,
            tilt_rad: 0.01,
            azimuth_taper: None,
            azimuth_table: None,
            elevation_table: None,
        };
        let (fs, num_samples, noise) = (30e6, 600usize, 3e-6);
        let kernel = FractionalDelayKernel::new();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            crate::rng::unit_f64(state)
        };
        let metres_per_sample = SPEED_OF_LIGHT_M_PER_S / fs;
        let mut contributions = Vec::new();
        let (mut az_tx, mut el_tx) = (0.0, 0.0);
        for i in 0..4000 {
            // Runs of three returns sharing their transmit direction, as a tube's do, each
            // run another object's; two runs in a row share their elevation, so a cached
            // pattern value must not be reused where a tilted object follows a level one.
            let run = i / 3;
            let object = (run % 5) as u32;
            if i % 3 == 0 {
                az_tx = 1.0 + 0.004 * object as f64 + 0.003 * uniform();
                if run % 2 == 0 {
                    el_tx = -0.02 + 0.01 * uniform();
                }
            }
            let shared = i % 2 == 0;
            let samples = -3.0 + (num_samples as f64 + 8.0) * uniform();
            contributions.push(Contribution {
                amplitude_v: Complex64::new(uniform() - 0.5, uniform() - 0.5) * 1e-4,
                root_rcs_m: Complex64::new(0.0, 0.0),
                path_m: samples.max(0.0) * metres_per_sample,
                az_tx_rad: az_tx,
                el_tx_rad: el_tx,
                az_rx_rad: if shared {
                    az_tx
                } else {
                    az_tx + 1e-4 * uniform()
                },
                el_rx_rad: if shared { el_tx } else { el_tx - 0.001 },
                object,
                bounces: 1,
                sea_reflections: 0,
            });
        }
        let tilts = [0.0, 0.03, -0.02, 0.0];
        let built = EchoGroups::build_tilted(
            &contributions,
            &antenna,
            &tilts,
            fs,
            num_samples,
            noise,
            &kernel,
        );
        let cell = antenna.az_beamwidth_rad / AZIMUTH_CELLS_PER_BEAMWIDTH;
        let mut by_key: BTreeMap<(u32, u64, u64), Vec<&Contribution>> = BTreeMap::new();
        for c in &contributions {
            if c.delay_s() * fs < num_samples as f64 {
                let tx = (c.az_tx_rad.rem_euclid(std::f64::consts::TAU) / cell) as u64;
                let rx = (c.az_rx_rad.rem_euclid(std::f64::consts::TAU) / cell) as u64;
                by_key.entry((c.object, tx, rx)).or_default().push(c);
            }
        }
        assert!(contributions.len() > by_key.values().map(Vec::len).sum::<usize>());
        assert_eq!(built.groups.len(), by_key.len());
        for (g, ((object, _, _), members)) in built.groups.iter().zip(&by_key) {
            assert_eq!(g.object, *object);
            let ant = match tilts.get(*object as usize) {
                Some(&t) if t != 0.0 => antenna.tilted_by(t),
                _ => antenna,
            };
            let taps: Vec<(i64, &[f32])> = members
                .iter()
                .map(|c| kernel.taps(c.delay_s() * fs))
                .collect();
            let lo = taps.iter().map(|t| t.0.max(0)).min().unwrap();
            let hi = taps.iter().map(|t| t.0 + KERNEL_TAPS as i64).max().unwrap();
            let mut acc = vec![Complex64::new(0.0, 0.0); (hi - lo) as usize];
            let (mut tx_sum, mut rx_sum) = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
            for (c, (first, w)) in members.iter().zip(&taps) {
                let weight = (ant.elevation_pattern(c.el_tx_rad)
                    * ant.elevation_pattern(c.el_rx_rad))
                .sqrt();
                let a = c.amplitude_v * (weight * (1.0 / noise));
                for (t, &w) in w.iter().enumerate() {
                    let n = first + t as i64;
                    if n >= 0 {
                        acc[(n - lo) as usize] += a * w as f64;
                    }
                }
                let (s, co) = crate::special::sin_cos_fast(c.az_tx_rad);
                tx_sum += Complex64::new(co, s);
                let (s, co) = crate::special::sin_cos_fast(c.az_rx_rad);
                rx_sum += Complex64::new(co, s);
            }
            assert_eq!((g.first_sample, g.len), (lo as usize, acc.len()));
            let stored = &built.arena[g.offset..g.offset + g.len];
            let mut peak = 0f32;
            for (got, want) in stored.iter().zip(&acc) {
                let want = Complex32::new(want.re as f32, want.im as f32);
                assert_eq!(*got, want);
                peak = peak.max(want.norm());
            }
            assert_eq!(g.peak, peak);
            assert_eq!(g.az_tx_rad, tx_sum.arg().rem_euclid(std::f64::consts::TAU));
            assert_eq!(g.az_rx_rad, rx_sum.arg().rem_euclid(std::f64::consts::TAU));
        }
        // Each object's contributions built alone, the parts joined: the same groups and
        // arena, bit for bit.
        let parts: Vec<EchoGroups> = (0..5u32)
            .map(|object| {
                let own: Vec<Contribution> = contributions
                    .iter()
                    .filter(|c| c.object == object)
                    .copied()
                    .collect();
                EchoGroups::build_tilted(&own, &antenna, &tilts, fs, num_samples, noise, &kernel)
            })
            .collect();
        let joined = EchoGroups::concat(&parts.iter().collect::<Vec<_>>());
        assert!(parts.iter().all(|p| !p.groups.is_empty()));
        assert_eq!(joined, built);
    }

    /// `surely_below` skips a group only where the weight test skips it too: at the offsets
    /// where the sidelobes touch their envelope (`|sin u| = 1`, the tightest case) and in
    /// between, for transmit and receive azimuths equal and apart, with peaks a hair above
    /// and below the envelope's threshold. Far in the sidelobes it does skip.
    #[test]
    fn surely_below_only_where_the_weight_test_skips() {
        let antenna = Antenna {
            az_beamwidth_rad: 1.2f64.to_radians(),
            el_beamwidth_rad: 22f64.to_radians(),
            peak_gain_linear: 1000.0,
            tilt_rad: 0.0,
            azimuth_taper: None,
            azimuth_table: None,
            elevation_table: None,
        };
        let min = crate::engine::MIN_GROUP_AMPLITUDE;
        let u_to_rad = antenna.az_beamwidth_rad / crate::antenna::SINC_BEAMWIDTH_FACTOR;
        let mut skipped = 0;
        // u reaches 2.783·π/θ3dB at the back of the beam (417 here).
        let u_max =
            crate::antenna::SINC_BEAMWIDTH_FACTOR * std::f64::consts::PI / antenna.az_beamwidth_rad;
        let peaks = (0..).map(|k| (k as f64 + 0.5) * std::f64::consts::PI);
        // The sidelobes' peaks, where the pattern touches its envelope (|sin u| = 1), and
        // points between them.
        let us: Vec<f64> = peaks
            .take_while(|&u| u < u_max - 1.0)
            .flat_map(|u| [u, u + 0.4, u + 1.1])
            .collect();
        assert!(us.len() > 390, "{}", us.len());
        for &u in &us {
            for (beam, apart) in [(0.3, 0.0), (5.9, 0.0), (0.3, 2e-4), (2.0, -3e-4)] {
                let az_tx = (beam + u * u_to_rad) % std::f64::consts::TAU;
                let group = |peak: f32| EchoGroup {
                    object: 0,
                    az_tx_rad: az_tx,
                    az_rx_rad: az_tx + apart,
                    first_sample: 0,
                    len: 1,
                    offset: 0,
                    peak,
                };
                let u_tx = antenna.azimuth_inverse_envelope(az_tx - beam);
                let u_rx = antenna.azimuth_inverse_envelope(az_tx + apart - beam);
                let threshold = f64::from(min) * u_tx * u_rx;
                for scale in [0.5, 0.999_998, 0.999_999_5, 1.0, 1.000_001, 2.0] {
                    let g = group((threshold * scale) as f32);
                    if surely_below(&g, &antenna, beam, min) {
                        skipped += 1;
                        assert!(
                            azimuth_weight(&g, &antenna, beam) * g.peak < min,
                            "u {u}, beam {beam}, apart {apart}, scale {scale}"
                        );
                    }
                }
            }
        }
        assert!(skipped > 3_000, "{skipped}");
    }

    /// The one-azimuth shortcut of `azimuth_weight` gives the bits of the two-pattern form
    /// `√(Gn·Gn)` at every beam offset, main lobe and far sidelobes alike.
    #[test]
    fn one_azimuth_weight_is_the_two_pattern_weight() {
        let antenna = Antenna {
            az_beamwidth_rad: 3.9f64.to_radians(),
            el_beamwidth_rad: 22f64.to_radians(),
            peak_gain_linear: 1000.0,
            tilt_rad: 0.0,
            azimuth_taper: None,
            azimuth_table: None,
            elevation_table: None,
        };
        for i in 0..20_000 {
            let az = 0.3 + i as f64 * 3.1e-4;
            let group = EchoGroup {
                object: 0,
                az_tx_rad: az,
                az_rx_rad: az,
                first_sample: 0,
                len: 1,
                offset: 0,
                peak: 1.0,
            };
            for beam_deg in [0.0, 0.7, 17.0, 95.0, 181.0, 359.5] {
                let beam = f64::to_radians(beam_deg);
                let p = antenna.azimuth_pattern(az - beam);
                assert_eq!(
                    azimuth_weight(&group, &antenna, beam).to_bits(),
                    ((p * p).sqrt() as f32).to_bits(),
                    "az {az}, beam {beam}"
                );
            }
        }
    }
}
