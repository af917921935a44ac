//! Special functions used by several stages, each in one place: the modified Bessel function
//! I0 (Kaiser kernel, wind-direction factor, Miller–Brown–Vegh roughness), the complementary
//! error function, ln Γ and the regularised incomplete gamma function (clutter statistics),
//! and, for the hot paths, sine, cosine and rounding without libm calls, and a stable radix
//! sort of keyed indices (echo groups, the BVH's Morton order).
//! docs/physics.md lists where each is used; docs/architecture.md says why these are ours and
//! not a crate's.

/// Modified Bessel function of the first kind, order 0, by its power series
/// `Σ ((x/2)^k / k!)²` (Abramowitz & Stegun 9.6.12), summed until a term no longer changes the
/// sum. Accurate to rounding for |x| up to about 30; use [`exp_scaled_bessel_i0`] above.
pub fn bessel_i0(x: f64) -> f64 {
    let (mut sum, mut term) = (1.0f64, 1.0f64);
    for k in 1..200 {
        term *= (x / 2.0) * (x / 2.0) / (k as f64 * k as f64);
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
    }
    sum
}

/// `exp(−x)·I0(x)` for x ≥ 0, without overflow: the power series below 30 and the
/// asymptotic series `(1 + 1/(8x) + 9/(2(8x)²) + …)/√(2πx)` above (Abramowitz & Stegun
/// 9.7.1; the first omitted term is below 1e-8 there).
pub fn exp_scaled_bessel_i0(x: f64) -> f64 {
    if x < 30.0 {
        bessel_i0(x) * (-x).exp()
    } else {
        let z = 1.0 / (8.0 * x);
        (1.0 + z * (1.0 + z * (9.0 / 2.0 + z * (225.0 / 6.0 + z * 11025.0 / 24.0))))
            / (2.0 * std::f64::consts::PI * x).sqrt()
    }
}

/// Complementary error function (Numerical Recipes `erfcc`, fractional error < 1.2e-7).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let ans = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 {
        ans
    } else {
        2.0 - ans
    }
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9).
pub fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised lower incomplete gamma P(a, x) (series / continued fraction, Press et al.,
/// *Numerical Recipes*, 3rd ed., §6.2).
pub fn gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let gln = ln_gamma(a);
    if x < a + 1.0 {
        let (mut ap, mut sum) = (a, 1.0 / a);
        let mut del = sum;
        for _ in 0..1000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        (sum.ln() - x + a * x.ln() - gln).exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        1.0 - (-x + a * x.ln() - gln).exp() * h
    }
}

/// Whether `f64::trunc`, `floor` and `round` compile to instructions rather than libm calls:
/// SSE4.1's `roundsd` (x86-64-v2 and up, so the default build, .cargo/config.toml), AArch64's
/// `frint*` (with its floating-point unit, which the `neon` feature implies). The functions
/// below then are those methods; elsewhere (the x86-64 baseline, soft-float targets) they
/// compute the same values without a call.
const HARDWARE_ROUNDING: bool = cfg!(any(
    target_feature = "sse4.1",
    all(target_arch = "aarch64", target_feature = "neon")
));

/// `x.trunc()` without a libm call: the same value, signed zero included.
#[inline]
pub fn trunc_exact(x: f64) -> f64 {
    if HARDWARE_ROUNDING {
        x.trunc()
    } else {
        trunc_portable(x)
    }
}

/// [`trunc_exact`] in plain arithmetic (the x86-64 baseline has no rounding instruction, so
/// `f64::trunc`, `floor` and `round` are calls there).
#[inline]
fn trunc_portable(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        ((x as i64) as f64).copysign(x)
    } else {
        x // integral already, infinite or NaN
    }
}

/// `⌊x⌋` as an integer without a libm call (x well inside the i64 range).
#[inline]
pub fn floor_i64(x: f64) -> i64 {
    let i = x as i64;
    i - i64::from((i as f64) > x)
}

/// `x.floor()` without a libm call: the same value.
#[inline]
pub fn floor_exact(x: f64) -> f64 {
    if HARDWARE_ROUNDING {
        x.floor()
    } else {
        floor_portable(x)
    }
}

/// [`floor_exact`] in plain arithmetic.
#[inline]
fn floor_portable(x: f64) -> f64 {
    let t = trunc_portable(x);
    if t > x {
        t - 1.0
    } else {
        t
    }
}

/// `x.round()` (half away from zero) without a libm call: the same value.
#[inline]
pub fn round_exact(x: f64) -> f64 {
    if HARDWARE_ROUNDING {
        x.round()
    } else {
        round_portable(x)
    }
}

/// [`round_exact`] in plain arithmetic: `x − trunc x` is exact, so the half-way test is.
#[inline]
fn round_portable(x: f64) -> f64 {
    let t = trunc_portable(x);
    let d = x - t;
    if d >= 0.5 {
        t + 1.0
    } else if d <= -0.5 {
        t - 1.0
    } else {
        t
    }
}

/// `v.round() as u8` (half away from zero, saturating, NaN to 0) without a libm call: the
/// same value for every `f32`. For `0 ≤ v < 256` the fraction `v − trunc v` is exact, so the
/// half-way test is; below 0 both give 0, from 255.5 up both give 255.
#[inline]
pub fn round_to_u8(v: f32) -> u8 {
    let whole = v as u8; // truncates and saturates; NaN gives 0
    whole.saturating_add(u8::from(v - f32::from(whole) >= 0.5))
}

/// `x.rem_euclid(2π)` without libm's `fmod` for |x| < 2π (every azimuth difference of the
/// hot paths): there `x % 2π` is x itself, so this is the same value bit for bit.
#[inline]
pub fn rem_euclid_tau(x: f64) -> f64 {
    const TAU: f64 = std::f64::consts::TAU;
    if x.abs() < TAU {
        if x < 0.0 {
            x + TAU
        } else {
            x
        }
    } else {
        x.rem_euclid(TAU)
    }
}

/// The first 33 bits of π/2, the next 33, and the rest (Cody & Waite's three-part split, as
/// in fdlibm's `__ieee754_rem_pio2`): `k·PIO2_1` and `k·PIO2_2` are exact for |k| < 2²⁰.
const PIO2_1: f64 = 1.570_796_326_734_125_6;
const PIO2_2: f64 = 6.077_100_506_303_966e-11;
const PIO2_3: f64 = 2.022_266_248_795_950_6e-21;

/// `x = k·π/2 + r` with |r| ≤ π/4 (for |x| ≤ 10⁶): r and k mod 4.
#[inline]
fn reduce_half_pi(x: f64) -> (f64, i64) {
    let k = round_exact(x * std::f64::consts::FRAC_2_PI);
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    (r, (k as i64) & 3)
}

/// Taylor series of sin r to r¹³ (truncation below 3·10⁻¹⁴ at |r| = π/4).
#[inline]
fn sin_poly(r: f64) -> f64 {
    let r2 = r * r;
    r + r
        * r2
        * (-1.0 / 6.0
            + r2 * (1.0 / 120.0
                + r2 * (-1.0 / 5040.0
                    + r2 * (1.0 / 362_880.0
                        + r2 * (-1.0 / 39_916_800.0 + r2 * (1.0 / 6_227_020_800.0))))))
}

/// Taylor series of cos r to r¹⁴ (truncation below 10⁻¹⁵ at |r| = π/4).
#[inline]
fn cos_poly(r: f64) -> f64 {
    let r2 = r * r;
    1.0 + r2
        * (-0.5
            + r2 * (1.0 / 24.0
                + r2 * (-1.0 / 720.0
                    + r2 * (1.0 / 40_320.0
                        + r2 * (-1.0 / 3_628_800.0
                            + r2 * (1.0 / 479_001_600.0 + r2 * (-1.0 / 87_178_291_200.0)))))))
}

/// `sin x` without libm, for the hot paths (antenna patterns per group and pulse, tube
/// footprints): the argument is reduced to `r = x − k·π/2`, |r| ≤ π/4, with π/2 split in
/// three parts (Cody & Waite, "Software Manual for the Elementary Functions", 1980), then the
/// Taylor series of sin or cos on r. Absolute error below 10⁻¹³ for |x| ≤ 10⁶ (tested
/// against `f64::sin`); beyond that, and for non-finite x, it is `f64::sin`.
#[inline]
pub fn sin_fast(x: f64) -> f64 {
    if x.is_nan() || x.abs() > 1e6 {
        return x.sin();
    }
    let (r, quadrant) = reduce_half_pi(x);
    let value = if quadrant & 1 == 0 {
        sin_poly(r)
    } else {
        cos_poly(r)
    };
    if quadrant >= 2 {
        -value
    } else {
        value
    }
}

/// `(sin x, cos x)` as [`sin_fast`] computes them (one reduction for both; the same error
/// bound, tested against libm's).
#[inline]
pub fn sin_cos_fast(x: f64) -> (f64, f64) {
    if x.is_nan() || x.abs() > 1e6 {
        return x.sin_cos();
    }
    let (r, quadrant) = reduce_half_pi(x);
    let (s, c) = (sin_poly(r), cos_poly(r));
    match quadrant {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Coefficients of the odd minimax polynomial `atan r ≈ r − r·(r²·P(r⁴) + r⁴·Q(r⁴))` for
/// |r| ≤ 7/16 (fdlibm's `s_atan.c`, Sun Microsystems 1993: error below one unit in the last
/// place there): the even-indexed ones form P, the odd-indexed Q.
const ATAN_COEFFICIENTS: [f64; 11] = [
    0.3333333333333293,
    -0.19999999999876483,
    0.14285714272503466,
    -0.11111110405462356,
    0.09090887133436507,
    -0.0769187620504483,
    0.06661073137387531,
    -0.058335701337905735,
    0.049768779946159324,
    -0.036531572744216916,
    0.016285820115365782,
];

/// `π/4` in two parts (the nearest f64 and the rest), and the same for `π/2` and `π`.
const FRAC_PI_4_LO: f64 = 3.061_616_997_868_383e-17;
const FRAC_PI_2_LO: f64 = 6.123_233_995_736_766e-17;
const PI_LO: f64 = 1.224_646_799_147_353_2e-16;

/// `tan(π/8) = √2 − 1`: at and below it the ratio itself is the polynomial's argument.
const TAN_PI_8: f64 = 0.414_213_562_373_095_03;

/// `r·(r²·P(r⁴) + r⁴·Q(r⁴))`, so that `atan r = r − atan_tail(r)` for |r| ≤ 7/16.
#[inline]
fn atan_tail(r: f64) -> f64 {
    let a = &ATAN_COEFFICIENTS;
    let z = r * r;
    let w = z * z;
    let even = z * (a[0] + w * (a[2] + w * (a[4] + w * (a[6] + w * (a[8] + w * a[10])))));
    let odd = w * (a[1] + w * (a[3] + w * (a[5] + w * (a[7] + w * a[9]))));
    r * (even + odd)
}

/// `y.atan2(x)` without libm, for the contributions' directions (glibc's saves and restores
/// the rounding mode on every call; with `hypot`, 4 % of a dataset sample). The octant is
/// folded away: `t = min(|x|,|y|)/max(|x|,|y|)`, then `atan t = π/4 + atan((t − 1)/(t + 1))`
/// above `tan(π/8)`, so the polynomial's argument stays within ±(√2 − 1) and one division
/// makes it; the quarter turns are added back with their low parts. Over the test's
/// directions it is within one unit in the last place of π (4.4·10⁻¹⁶ rad) and two of the
/// angle of `f64::atan2` (measured, not proven: the fold's `small − large` is not always
/// exact). Zeros, infinities, NaN and components beyond 10³⁰⁰ (where `small + large` could
/// overflow) go to `f64::atan2`.
#[inline]
pub fn atan2_fast(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    if !(ax > 0.0 && ay > 0.0 && ax <= 1e300 && ay <= 1e300) {
        return y.atan2(x);
    }
    let (small, large) = if ay > ax { (ax, ay) } else { (ay, ax) };
    // atan(small/large) ∈ [0, π/4].
    let octant = if small > TAN_PI_8 * large {
        let r = (small - large) / (small + large);
        std::f64::consts::FRAC_PI_4 - ((atan_tail(r) - FRAC_PI_4_LO) - r)
    } else {
        let r = small / large;
        r - atan_tail(r)
    };
    let quadrant = if ay > ax {
        std::f64::consts::FRAC_PI_2 - (octant - FRAC_PI_2_LO)
    } else {
        octant
    };
    let half = if x < 0.0 {
        std::f64::consts::PI - (quadrant - PI_LO)
    } else {
        quadrant
    };
    half.copysign(y)
}

/// `max(10·log10(x·scale), floor_db)` for every power x of `row`, in place, without libm:
/// the polar records' dB conversion (360 × up to 2001 cells a frame, where glibc's `log10f`
/// took 3 % of a dataset sample). With `x = 2^e·m`, m in [√½, √2), `ln m = 2·atanh(s)`,
/// `s = (m − 1)/(m + 1)`, by its series to s⁹ (|s| ≤ 0.172: truncation below 3·10⁻⁹), and
/// `ln 2` in two parts so that `e·ln 2` keeps f32's precision (Cody & Waite, "Software Manual
/// for the Elementary Functions", 1980, ch. 5). In f32, branch-free, so the loop vectorises;
/// within 3·10⁻⁶ dB + 4·10⁻⁷ relative of the exact value (tested against f64's `log10`).
/// Zero, subnormal and NaN powers give `floor_db` (as `max` does for zero and NaN; a
/// subnormal power is below any floor above −380 dB), +∞ gives +∞.
pub fn power_db_in_place(row: &mut [f32], scale: f32, floor_db: f32) {
    const LN2_HI: f32 = 0.693_359_4; // 0x3F318000: exact times any exponent
    const LN2_LO: f32 = -2.121_944_4e-4;
    const DB_PER_NEPER: f32 = 4.342_944_8; // 10/ln 10
    for o in row.iter_mut() {
        let x = *o * scale;
        let bits = x.to_bits();
        let mut e = ((bits >> 23) as i32 - 127) as f32;
        let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
        let high = m > std::f32::consts::SQRT_2;
        m = if high { 0.5 * m } else { m };
        e = if high { e + 1.0 } else { e };
        let s = (m - 1.0) / (m + 1.0);
        let z = s * s;
        let series = 1.0 + z * (1.0 / 3.0 + z * (1.0 / 5.0 + z * (1.0 / 7.0 + z * (1.0 / 9.0))));
        let ln_x = e * LN2_HI + (e * LN2_LO + 2.0 * s * series);
        let db = (DB_PER_NEPER * ln_x).max(floor_db);
        *o = if (f32::MIN_POSITIVE..f32::INFINITY).contains(&x) {
            db
        } else if x == f32::INFINITY {
            f32::INFINITY
        } else {
            floor_db
        };
    }
}

/// The last key and value of a pure computation, to skip it when the next key is the same
/// (hot loops see runs of one argument: a tube's returns share its launch direction). Give
/// f64 arguments as their bits (`to_bits`), so that a value is reused only for the very bits
/// it was computed from, and the results are those of computing every time.
#[derive(Debug, Clone, Copy)]
pub struct LastCall<K, V> {
    last: Option<(K, V)>,
}

impl<K: PartialEq + Copy, V: Copy> LastCall<K, V> {
    /// Nothing computed yet.
    pub fn new() -> Self {
        LastCall { last: None }
    }

    /// The value for `key`: the last one if `key` is the last key, else `compute()`.
    #[inline]
    pub fn get_or(&mut self, key: K, compute: impl FnOnce() -> V) -> V {
        match self.last {
            Some((k, v)) if k == key => v,
            _ => {
                let v = compute();
                self.last = Some((key, v));
                v
            }
        }
    }
}

impl<K: PartialEq + Copy, V: Copy> Default for LastCall<K, V> {
    fn default() -> Self {
        Self::new()
    }
}

/// Sorts `(key, index)` pairs by key, keeping the order of equal keys: for pairs made in
/// ascending index order, the order `sort_unstable` gives, without its comparisons. An LSD
/// radix sort over the key's bytes that are not the same in every pair (echo-group keys share
/// most of theirs: few objects, azimuth cells near each other; Morton codes fill four).
pub fn sort_by_key_stable(pairs: &mut Vec<(u64, u32)>) {
    let (Some(&(first, _)), true) = (pairs.first(), pairs.len() > 1) else {
        return;
    };
    let varying = pairs.iter().fold(0u64, |acc, &(k, _)| acc | (k ^ first));
    let mut other = vec![(0u64, 0u32); pairs.len()];
    for byte in 0..8 {
        let shift = 8 * byte;
        if (varying >> shift) & 0xff == 0 {
            continue;
        }
        let mut start = [0usize; 256];
        for &(k, _) in pairs.iter() {
            start[((k >> shift) & 0xff) as usize] += 1;
        }
        let mut sum = 0;
        for s in start.iter_mut() {
            let count = *s;
            *s = sum;
            sum += count;
        }
        for &pair in pairs.iter() {
            let digit = ((pair.0 >> shift) & 0xff) as usize;
            other[start[digit]] = pair;
            start[digit] += 1;
        }
        std::mem::swap(pairs, &mut other);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The radix sort gives `sort_unstable`'s order for pairs made in index order: keys
    /// that differ in a few bytes or in all, with many equal keys, and the trivial lengths.
    #[test]
    fn sort_by_key_stable_is_sort_unstable() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for (len, mask) in [
            (0usize, u64::MAX),
            (1, u64::MAX),
            (2, 1),
            (1000, 0x0000_0300_000f_f00f),
            (5000, u64::MAX),
            (5000, 0xff00_0000_0000_00ff),
            (20000, 0x0000_0700_3ff0_03ff),
        ] {
            let mut pairs: Vec<(u64, u32)> = (0..len as u32).map(|i| (next() & mask, i)).collect();
            // Runs of equal keys, as a group's members have.
            for i in 1..pairs.len() {
                if next() % 3 == 0 {
                    pairs[i].0 = pairs[i - 1].0;
                }
            }
            let mut expected = pairs.clone();
            expected.sort_unstable();
            sort_by_key_stable(&mut pairs);
            assert_eq!(pairs, expected, "{len} pairs, mask {mask:x}");
        }
    }

    /// The libm-free dB conversion against f64's `10·log10` over powers from the smallest
    /// normal f32 to 10^30 (every exponent, 4000 mantissas each), the special values, and the
    /// floor.
    #[test]
    fn power_db_in_place_matches_log10() {
        let mut values: Vec<f32> = Vec::new();
        for e in -126..100 {
            for k in 0..4000u32 {
                let m = 1.0 + k as f64 / 4000.0;
                let v = (m * 2f64.powi(e)) as f32;
                if v.is_finite() && v <= 1e30 {
                    values.push(v);
                }
            }
        }
        let mut row = values.clone();
        power_db_in_place(&mut row, 1.0, -1000.0);
        let mut worst = 0f64;
        for (&v, &db) in values.iter().zip(&row) {
            let exact = 10.0 * f64::from(v).log10();
            let err = (f64::from(db) - exact).abs();
            worst = worst.max(err / (3e-6 + 4e-7 * exact.abs()));
            assert!(
                err <= 3e-6 + 4e-7 * exact.abs(),
                "{v:e}: {db} against {exact}"
            );
        }
        assert!(worst > 0.05, "the bound is loose: worst {worst}");
        let mut special = [0.0, -0.0, 1e-40, f32::NAN, f32::INFINITY, 1e-13, 1.0, 1e12];
        power_db_in_place(&mut special, 1.0, -120.0);
        assert_eq!(
            special[..5],
            [-120.0, -120.0, -120.0, -120.0, f32::INFINITY]
        );
        assert_eq!(special[5], -120.0);
        assert_eq!(special[6], 0.0);
        assert!((special[7] - 120.0).abs() < 1e-4);
        // The scale multiplies first.
        let mut scaled = [8.0f32];
        power_db_in_place(&mut scaled, 0.25, -120.0);
        assert!((f64::from(scaled[0]) - 10.0 * 2f64.log10()).abs() < 1e-6);
    }

    /// `LastCall` computes on a new key, reuses on a repeated one, and tells −0.0 from 0.0
    /// when given bits.
    #[test]
    fn last_call_reuses_only_the_same_key() {
        let mut calls = 0;
        let mut memo = LastCall::new();
        let keys = [1.5f64, 1.5, 2.0, 0.0, -0.0, -0.0, 1.5];
        let values: Vec<f64> = keys
            .iter()
            .map(|&x| {
                memo.get_or(x.to_bits(), || {
                    calls += 1;
                    2.0 * x
                })
            })
            .collect();
        assert_eq!(calls, 5);
        for (v, x) in values.iter().zip(keys) {
            assert_eq!(v.to_bits(), (2.0 * x).to_bits());
        }
    }

    /// The libm-free trunc, floor (also as an integer), round and rem_euclid(2π) give `f64`'s
    /// values bit for bit, halves, signed zeros, huge values and non-finite ones included:
    /// the plain-arithmetic forms too where this build uses the instructions.
    #[test]
    fn rounding_without_libm_matches_std() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            9.1e15,
            -9.1e15,
            4_503_599_627_370_496.0,
            -4_503_599_627_370_496.0,
            4_503_599_627_370_497.0,
            4_503_599_627_370_495.0,
            9_007_199_254_740_992.0,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        let mut x = -1000.0f64;
        while x < 1000.0 {
            xs.push(x);
            x += 0.123_456_7;
        }
        for x in xs.iter().copied().chain([
            std::f64::consts::TAU,
            -std::f64::consts::TAU,
            std::f64::consts::TAU - 1e-15,
            -std::f64::consts::TAU + 1e-15,
            -1e-300,
        ]) {
            let want = x.rem_euclid(std::f64::consts::TAU);
            assert_eq!(
                rem_euclid_tau(x).to_bits(),
                want.to_bits(),
                "rem_euclid {x}"
            );
        }
        for x in xs {
            // Both forms, whichever this build uses.
            for (trunc, floor, round) in [
                (trunc_exact(x), floor_exact(x), round_exact(x)),
                (trunc_portable(x), floor_portable(x), round_portable(x)),
            ] {
                assert_eq!(trunc.to_bits(), x.trunc().to_bits(), "trunc {x}");
                assert_eq!(floor.to_bits(), x.floor().to_bits(), "floor {x}");
                assert_eq!(round.to_bits(), x.round().to_bits(), "round {x}");
            }
            if x.abs() < 1e15 {
                assert_eq!(floor_i64(x), x.floor() as i64, "floor_i64 {x}");
            }
        }
        assert!(trunc_exact(f64::NAN).is_nan() && floor_exact(f64::NAN).is_nan());
        assert!(round_exact(f64::NAN).is_nan());
        assert!(trunc_portable(f64::NAN).is_nan() && floor_portable(f64::NAN).is_nan());
        assert!(round_portable(f64::NAN).is_nan());
    }

    /// `atan2_fast` against libm's over directions all round the circle (a fine sweep, the
    /// octant boundaries, tan(π/8) and its neighbours, ratios down to 10⁻³⁰⁰), scaled from
    /// 10⁻³⁰⁰ to 10³⁰⁰, and components near f64::MAX: each within one unit in the last place
    /// of π (4.4·10⁻¹⁶ rad), the worst within two of the angle itself (it fails at 1 and at
    /// 1.5 of them); a NaN fails; the special cases are libm's exactly.
    #[test]
    fn atan2_fast_matches_libm() {
        let mut worst_abs = 0f64;
        let mut worst_ulps = 0f64;
        let mut check = |y: f64, x: f64| {
            let (fast, libm) = (atan2_fast(y, x), y.atan2(x));
            let err = (fast - libm).abs();
            assert!(err <= 4.5e-16, "({y}, {x}): {fast} against {libm}");
            worst_abs = worst_abs.max(err);
            if libm != 0.0 {
                let ulp = f64::from_bits(libm.abs().to_bits() + 1) - libm.abs();
                worst_ulps = worst_ulps.max(err / ulp);
            }
            assert_eq!(
                fast.is_sign_negative(),
                libm.is_sign_negative(),
                "sign ({y}, {x})"
            );
        };
        let mut angles: Vec<f64> = (0..200_000)
            .map(|i| -std::f64::consts::PI + i as f64 * std::f64::consts::TAU / 200_000.0)
            .collect();
        for k in -8..=8 {
            let a = k as f64 * std::f64::consts::FRAC_PI_4;
            angles.extend([a, a + 1e-12, a - 1e-12, a + 1e-15, a - 1e-15]);
        }
        for a in angles {
            let (sin, cos) = a.sin_cos();
            for scale in [1.0, 1e-300, 3.7e-5, 2.5e4, 1e300] {
                check(sin * scale, cos * scale);
            }
        }
        // The fold between the two branches, and extreme ratios.
        let t = TAN_PI_8;
        for r in [
            t,
            f64::from_bits(t.to_bits() + 1),
            f64::from_bits(t.to_bits() - 1),
        ] {
            for (y, x) in [(r, 1.0), (1.0, r), (-r, 1.0), (r, -1.0), (-1.0, -r)] {
                check(y, x);
            }
        }
        for (y, x) in [
            (1e-300, 1.0),
            (1.0, 1e-300),
            (-1e-300, -1.0),
            (1.0, 1.0),
            (-1.0, 1.0),
        ] {
            check(y, x);
        }
        // Past 10³⁰⁰ libm's (the fold's sum would overflow near f64::MAX).
        for (y, x) in [(1.5e308, 1e308), (-1e308, 1.7e308), (1e301, -1e301)] {
            check(y, x);
        }
        assert!(worst_abs <= 4.5e-16, "worst absolute error {worst_abs:e}");
        assert!(worst_ulps <= 2.0, "worst error {worst_ulps} ulp");
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, -0.0),
            (0.0, 0.0),
            (f64::INFINITY, 1.0),
            (1.0, f64::NEG_INFINITY),
            (f64::INFINITY, f64::INFINITY),
        ] {
            assert_eq!(
                atan2_fast(y, x).to_bits(),
                y.atan2(x).to_bits(),
                "({y}, {x})"
            );
        }
        assert!(atan2_fast(f64::NAN, 1.0).is_nan() && atan2_fast(1.0, f64::NAN).is_nan());
    }

    /// `round_to_u8` against `round() as u8` over every f32 from −2 to 258 in steps of
    /// 1/4096, the values next to each half-way point and the specials.
    #[test]
    fn round_to_u8_matches_round_as_u8() {
        let mut vs = vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            -0.0,
            0.0,
            1e30,
            -1e30,
        ];
        for i in -2 * 4096..258 * 4096 {
            vs.push(i as f32 / 4096.0);
        }
        for k in -2..258 {
            let half = k as f32 + 0.5;
            let bits = half.to_bits();
            vs.extend([half, f32::from_bits(bits - 1), f32::from_bits(bits + 1)]);
        }
        for v in vs {
            assert_eq!(round_to_u8(v), v.round() as u8, "{v}");
        }
    }

    /// The fast sine and cosine against libm's over the antenna patterns' range (|u| up to a few
    /// hundred) and far beyond, including the quadrant boundaries and signed zero.
    #[test]
    fn sin_fast_matches_libm() {
        let mut worst = 0f64;
        let mut check = |x: f64| {
            let (s, c) = sin_cos_fast(x);
            // One reduction, the same polynomials: the sine is sin_fast's bit for bit.
            assert_eq!(s.to_bits(), sin_fast(x).to_bits(), "{x}");
            worst = worst
                .max((sin_fast(x) - x.sin()).abs())
                .max((s - x.sin()).abs())
                .max((c - x.cos()).abs());
        };
        let mut x = -2000.0f64;
        while x <= 2000.0 {
            check(x);
            x += 0.000_731;
        }
        for k in -400..=400 {
            for d in [-1e-12, 0.0, 1e-12] {
                check(k as f64 * std::f64::consts::FRAC_PI_2 + d);
            }
        }
        for x in [1e3, 12_345.678, 9.99e5, -7.77e5] {
            check(x);
        }
        assert!(worst < 1e-13, "largest error {worst:e}");
        assert_eq!(sin_fast(0.0), 0.0);
        assert!(sin_fast(f64::NAN).is_nan());
        assert_eq!(sin_fast(3e6), 3e6f64.sin());
        assert_eq!(sin_cos_fast(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_fast(-3e6), (-3e6f64).sin_cos());
    }

    /// I0 against tabulated values (Abramowitz & Stegun, Table 9.8: I0(1) = 1.266065878,
    /// I0(2) = 2.279585302, I0(5) = 27.23987182, I0(7) = 168.5939085).
    #[test]
    fn bessel_i0_values() {
        assert_eq!(bessel_i0(0.0), 1.0);
        for (x, want) in [
            (1.0, 1.266_065_878),
            (2.0, 2.279_585_302),
            (5.0, 27.239_871_82),
            (7.0, 168.593_908_5),
        ] {
            let got = bessel_i0(x);
            assert!((got / want - 1.0).abs() < 1e-9, "x {x}: {got} vs {want}");
        }
    }

    /// exp(−x)·I0(x) against tabulated values (Abramowitz & Stegun, Table 9.8; here to
    /// 1e-9 from SciPy's `i0e`), on both sides of the series/asymptotic switch at 30.
    #[test]
    fn scaled_bessel_i0_values() {
        for (x, want) in [
            (0.1, 0.907_100_925_782_301_1),
            (1.0, 0.465_759_607_593_640_4),
            (5.0, 0.183_540_812_609_328_3),
            (14.9, 0.104_253_872_824_291_3),
            (15.0, 0.103_899_531_448_822_7),
            (29.9, 0.073_269_219_046_001_91),
            (30.0, 0.073_145_946_482_237_3),
            (40.0, 0.063_278_279_875_235_32),
        ] {
            let got = exp_scaled_bessel_i0(x);
            assert!((got / want - 1.0).abs() < 1e-6, "x {x}: {got} vs {want}");
        }
    }
    #[test]
    fn erfc_values() {
        assert!((erfc(0.0) - 1.0).abs() < 1e-7);
        assert!((erfc(1.0) - 0.157_299_207).abs() < 1e-7);
        assert!((erfc(-1.0) - 1.842_700_793).abs() < 1e-7);
    }

    /// P(1, x) = 1 − e^−x and P(a, ∞) → 1; ln Γ(n) = ln (n−1)!.
    #[test]
    fn gamma_functions() {
        assert!((gamma_p(1.0, 2.0) - (1.0 - (-2.0f64).exp())).abs() < 1e-12);
        assert!((gamma_p(3.5, 200.0) - 1.0).abs() < 1e-12);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    }
}
