//! The sea surface as a smooth-to-rough dielectric reflector at z = 0.
//!
//! Permittivity of sea water: Klein & Swift, "An improved model for the dielectric constant of
//! sea water at microwave frequencies", IEEE J. Oceanic Eng. OE-2(1):104–111, 1977 — a Debye
//! relaxation with salinity and temperature dependence plus ionic conductivity,
//! `ε = ε∞ + (εs − ε∞)/(1 + jωτ) − jσ/(ωε0)` with ε∞ = 4.9 and εs(T, S), τ(T, S), σ(T, S)
//! the polynomials below (T in °C, S in psu; ε = ε′ − jε″ for our exp(j(ωt − kr))
//! convention). At 9.41 GHz, 20 °C, 35 psu: ε ≈ 57 − j37. docs/physics.md lists them.
//!
//! Fresnel coefficients at grazing angle ψ (Beckmann & Spizzichino, *The Scattering of
//! Electromagnetic Waves from Rough Surfaces*, 1963; Long, *Radar Reflectivity of Land and
//! Sea*, 3rd ed., §3): `Γ_H = (sinψ − √(ε − cos²ψ))/(sinψ + √(ε − cos²ψ))` and
//! `Γ_V = (ε sinψ − √(ε − cos²ψ))/(ε sinψ + √(ε − cos²ψ))`, in the basis where a perfect
//! conductor has Γ_H = −1, Γ_V = +1. Rough-surface specular factor, with
//! `g = 2πσ_h sinψ/λ`: Miller, Brown & Vegh (IEE Proc. 131(2):114–116, 1984)
//! `ρ_s = exp(−2g²)·I0(2g²)` (default), or Ament (1953) `ρ_s = exp(−2g²)`. Ament assumes
//! Gaussian heights; Miller–Brown–Vegh derived theirs for the sea's wave height distribution
//! and it matches measured sea forward scatter where Ament falls off too fast (g ≳ 0.5), so
//! it is the usual choice for the sea at low grazing; both agree for a smooth sea.

use crate::special::exp_scaled_bessel_i0;
use num_complex::Complex64;

/// Vacuum permittivity, F/m (CODATA 2018).
pub const VACUUM_PERMITTIVITY_F_PER_M: f64 = 8.854_187_812_8e-12;

/// Complex relative permittivity of sea water (Klein & Swift 1977), `ε′ − jε″`.
pub fn sea_water_permittivity(freq_hz: f64, temperature_c: f64, salinity_psu: f64) -> Complex64 {
    let t = temperature_c;
    let s = salinity_psu;
    let eps_inf = 4.9;
    let eps_s = (87.134 - 1.949e-1 * t - 1.276e-2 * t * t + 2.491e-4 * t * t * t)
        * (1.0 + 1.613e-5 * t * s - 3.656e-3 * s + 3.210e-5 * s * s - 4.232e-7 * s * s * s);
    let tau_s = (1.768e-11 - 6.086e-13 * t + 1.104e-14 * t * t - 8.111e-17 * t * t * t)
        * (1.0 + 2.282e-5 * t * s - 7.638e-4 * s - 7.760e-6 * s * s + 1.105e-8 * s * s * s);
    let delta = 25.0 - t;
    let beta = 2.033e-2 + 1.266e-4 * delta + 2.464e-6 * delta * delta
        - s * (1.849e-5 - 2.551e-7 * delta + 2.551e-8 * delta * delta);
    let sigma_s_per_m = s
        * (0.182521 - 1.46192e-3 * s + 2.09324e-5 * s * s - 1.28205e-7 * s * s * s)
        * (-delta * beta).exp();
    let omega = std::f64::consts::TAU * freq_hz;
    let debye = (eps_s - eps_inf) / Complex64::new(1.0, omega * tau_s);
    Complex64::new(eps_inf, 0.0) + debye
        - Complex64::new(0.0, sigma_s_per_m / (omega * VACUUM_PERMITTIVITY_F_PER_M))
}

/// Fresnel reflection coefficients (Γ_H, Γ_V) of a flat surface of relative permittivity
/// `eps` at grazing angle `grazing_rad`.
pub fn fresnel_reflection(eps: Complex64, grazing_rad: f64) -> (Complex64, Complex64) {
    let s = grazing_rad.sin();
    let c2 = grazing_rad.cos().powi(2);
    let root = (eps - c2).sqrt();
    let gh = (s - root) / (s + root);
    let gv = (eps * s - root) / (eps * s + root);
    (gh, gv)
}

/// [`fresnel_reflection`] from `sin ψ` (the ray's −k_z), with the principal square root
/// taken algebraically, `√(a + jb) = t + j·b/(2t)`, `t = √((|z| + a)/2)` for a ≥ 0 (and the
/// mirror form for a < 0), instead of through polar form: no asin, sin, cos, atan2 or hypot
/// per ray. Equal to [`fresnel_reflection`] within 1e-13 (tested).
#[inline]
pub fn fresnel_reflection_sin(eps: Complex64, sin_grazing: f64) -> (Complex64, Complex64) {
    let s = sin_grazing;
    let root = principal_sqrt(eps - (1.0 - s * s));
    let gh = (s - root) / (s + root);
    let gv = (eps * s - root) / (eps * s + root);
    (gh, gv)
}

/// Principal square root (Re ≥ 0) of a complex number, algebraically.
#[inline]
fn principal_sqrt(z: Complex64) -> Complex64 {
    if z.re == 0.0 && z.im == 0.0 {
        return Complex64::new(0.0, 0.0);
    }
    // |z| as √(re² + im²) rather than libm's `hypot` (a call per ray): the same to a unit
    // or two in the last place for the permittivities' range (|z| within 10^±150).
    let modulus = (z.re * z.re + z.im * z.im).sqrt();
    if z.re >= 0.0 {
        let t = (0.5 * (modulus + z.re)).sqrt();
        Complex64::new(t, z.im / (2.0 * t))
    } else {
        let t = (0.5 * (modulus - z.re)).sqrt();
        Complex64::new(z.im.abs() / (2.0 * t), t.copysign(z.im))
    }
}

/// Which rough-surface specular reduction is used (`environment.sea_roughness`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum SeaRoughness {
    /// Miller, Brown & Vegh 1984: `exp(−2g²)·I0(2g²)`.
    MillerBrownVegh,
    /// Ament 1953: `exp(−2g²)`.
    Ament,
}

/// Specular reduction ρ_s for a surface of rms height `rms_height_m`.
pub fn roughness_factor(
    model: SeaRoughness,
    rms_height_m: f64,
    grazing_rad: f64,
    wavelength_m: f64,
) -> f64 {
    roughness_factor_sin(model, rms_height_m, grazing_rad.sin(), wavelength_m)
}

/// [`roughness_factor`] from `sin ψ`.
#[inline]
pub fn roughness_factor_sin(
    model: SeaRoughness,
    rms_height_m: f64,
    sin_grazing: f64,
    wavelength_m: f64,
) -> f64 {
    let g = std::f64::consts::TAU * rms_height_m * sin_grazing / wavelength_m;
    let x = 2.0 * g * g;
    match model {
        SeaRoughness::Ament => (-x).exp(),
        SeaRoughness::MillerBrownVegh => exp_scaled_bessel_i0(x),
    }
}

/// The sea surface at z = 0 as seen by the scattering code.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeaSurface {
    /// Complex relative permittivity.
    pub permittivity: Complex64,
    /// Rms wave height σ_h, m.
    pub rms_height_m: f64,
    /// Rough-surface specular reduction.
    pub roughness: SeaRoughness,
}

impl SeaSurface {
    /// Specular reflection (Γ_H·ρ, Γ_V·ρ) at `grazing_rad` for `wavelength_m`.
    pub fn reflection(&self, grazing_rad: f64, wavelength_m: f64) -> (Complex64, Complex64) {
        let (gh, gv) = fresnel_reflection(self.permittivity, grazing_rad);
        let rho = roughness_factor(self.roughness, self.rms_height_m, grazing_rad, wavelength_m);
        (gh * rho, gv * rho)
    }

    /// [`SeaSurface::reflection`] from `sin ψ` (the ray tracer's form: no angle per ray).
    #[inline]
    pub fn reflection_sin(&self, sin_grazing: f64, wavelength_m: f64) -> (Complex64, Complex64) {
        let (gh, gv) = fresnel_reflection_sin(self.permittivity, sin_grazing);
        let rho =
            roughness_factor_sin(self.roughness, self.rms_height_m, sin_grazing, wavelength_m);
        (gh * rho, gv * rho)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sea_water_at_x_band() {
        let e = sea_water_permittivity(9.41e9, 20.0, 35.0);
        assert!(
            (e.re - 57.3).abs() < 1.0 && (e.im + 37.3).abs() < 1.0,
            "{e}"
        );
    }

    #[test]
    fn fresnel_limits() {
        // Grazing incidence reflects totally with Γ_H → −1 (and Γ_V → −1 below Brewster).
        let (gh, gv) = fresnel_reflection(Complex64::new(57.0, -37.0), 1e-6);
        assert!((gh + 1.0).norm() < 1e-3 && (gv + 1.0).norm() < 1e-3);
        // Normal incidence: both equal (1 − √ε)/(1 + √ε) up to the basis sign.
        let eps = Complex64::new(57.0, -37.0);
        let (gh, gv) = fresnel_reflection(eps, std::f64::consts::FRAC_PI_2);
        let r = (1.0 - eps.sqrt()) / (1.0 + eps.sqrt());
        assert!((gh - r).norm() < 1e-9 && (gv + r).norm() < 1e-9);
        // A perfect conductor: Γ_H = −1, Γ_V = +1 at any angle.
        let (gh, gv) = fresnel_reflection(Complex64::new(1e12, -1e12), 0.3);
        assert!((gh + 1.0).norm() < 1e-5 && (gv - 1.0).norm() < 1e-5);
    }

    /// The per-ray form (sin ψ in, algebraic square root) against the angle form (polar
    /// square root from num-complex) over grazing angles and permittivities, both signs of
    /// Re(ε − cos²ψ).
    #[test]
    fn sin_form_matches_angle_form() {
        for eps in [
            Complex64::new(57.3, -37.3),
            Complex64::new(4.0, -0.5),
            Complex64::new(0.2, -3.0),
            Complex64::new(-2.0, -1.0),
            Complex64::new(1e12, -1e12),
        ] {
            for k in 0..=200 {
                let psi = std::f64::consts::FRAC_PI_2 * k as f64 / 200.0;
                let (a_h, a_v) = fresnel_reflection(eps, psi);
                let (b_h, b_v) = fresnel_reflection_sin(eps, psi.sin());
                assert!((a_h - b_h).norm() < 1e-13, "{eps} {psi}: {a_h} {b_h}");
                assert!((a_v - b_v).norm() < 1e-13, "{eps} {psi}: {a_v} {b_v}");
                let sea = SeaSurface {
                    permittivity: eps,
                    rms_height_m: 0.4,
                    roughness: SeaRoughness::MillerBrownVegh,
                };
                let (c_h, c_v) = sea.reflection(psi, 0.0319);
                let (d_h, d_v) = sea.reflection_sin(psi.sin(), 0.0319);
                assert!((c_h - d_h).norm() < 1e-13 && (c_v - d_v).norm() < 1e-13);
            }
        }
        assert_eq!(
            principal_sqrt(Complex64::new(-4.0, 0.0)),
            Complex64::new(0.0, 2.0)
        );
        assert_eq!(
            principal_sqrt(Complex64::new(-4.0, -0.0)),
            Complex64::new(0.0, -2.0)
        );
    }

    /// Miller–Brown–Vegh reflects more than Ament on a rough sea and both tend to 1 on a
    /// smooth one: ρ = exp(−2g²)·I0(2g²) vs exp(−2g²), g = 2πσ_h·sinψ/λ.
    #[test]
    fn roughness_models() {
        let lambda = 0.0319;
        let psi = 1f64.to_radians();
        for h in [0.0, 0.1, 0.3, 1.0] {
            let g = std::f64::consts::TAU * h * psi.sin() / lambda;
            let x = 2.0 * g * g;
            let mbv = roughness_factor(SeaRoughness::MillerBrownVegh, h, psi, lambda);
            let ament = roughness_factor(SeaRoughness::Ament, h, psi, lambda);
            assert!((ament - (-x).exp()).abs() < 1e-15);
            assert!((mbv - exp_scaled_bessel_i0(x)).abs() < 1e-15);
            assert!(mbv >= ament);
        }
        assert_eq!(
            roughness_factor(SeaRoughness::MillerBrownVegh, 0.0, psi, lambda),
            1.0
        );
    }
}
