//! Kalman filters of a ship on the sea surface, state `[x, y, vx, vy]` (east, north, m and
//! m/s), measured in position. Two motion models, each linear (Bar-Shalom, Li & Kirubarajan,
//! *Estimation with Applications to Tracking and Navigation*, Wiley 2001, "BLK" below):
//!
//! - **constant velocity** with discrete white-noise acceleration (BLK §6.3.3):
//!   `F = [[I, T·I], [0, I]]`, `Q = σa²·Γ·Γᵀ` per axis with `Γ = [T²/2, T]ᵀ`;
//! - **coordinated turn** at a known rate ω (BLK §11.7.1), the velocity turning by ωT:
//!   `x' = x + (sin ωT/ω)·vx − ((1 − cos ωT)/ω)·vy`, `y' = y + ((1 − cos ωT)/ω)·vx +
//!   (sin ωT/ω)·vy`, `v' = R(ωT)·v` (ω > 0 turns anticlockwise seen from above, to port), with
//!   the same Q.
//!
//! The update is the standard Kalman step with the measurement `z = H·x + w`, `H = [I, 0]`,
//! `w ~ N(0, R)`, in Joseph form (BLK §5.2.3) so that P stays symmetric positive definite.

/// A 4-vector: `[x, y, vx, vy]`.
pub type State = [f64; 4];
/// A 4 × 4 matrix, row-major.
pub type Cov = [[f64; 4]; 4];
/// A 2 × 2 matrix.
pub type Mat2 = [[f64; 2]; 2];

/// One motion model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Constant velocity.
    ConstantVelocity,
    /// A coordinated turn at `rate_rad_s` (positive anticlockwise).
    CoordinatedTurn {
        /// Turn rate, rad/s.
        rate_rad_s: f64,
    },
}

impl Motion {
    /// The transition matrix over `dt_s`.
    pub fn transition(&self, dt_s: f64) -> Cov {
        let t = dt_s;
        match *self {
            Motion::ConstantVelocity => [
                [1.0, 0.0, t, 0.0],
                [0.0, 1.0, 0.0, t],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ],
            Motion::CoordinatedTurn { rate_rad_s: w } => {
                let (s, c) = (w * t).sin_cos();
                // sin(ωT)/ω and (1 − cos ωT)/ω, by their series where ωT is tiny.
                let (a, b) = if (w * t).abs() < 1e-6 {
                    (t, w * t * t / 2.0)
                } else {
                    (s / w, (1.0 - c) / w)
                };
                [
                    [1.0, 0.0, a, -b],
                    [0.0, 1.0, b, a],
                    [0.0, 0.0, c, -s],
                    [0.0, 0.0, s, c],
                ]
            }
        }
    }
}

/// The discrete white-noise acceleration covariance over `dt_s` with acceleration standard
/// deviation `sigma_a` (m/s²) on each axis.
pub fn process_noise(dt_s: f64, sigma_a: f64) -> Cov {
    let t = dt_s;
    let q = sigma_a * sigma_a;
    let (pp, pv, vv) = (q * t.powi(4) / 4.0, q * t.powi(3) / 2.0, q * t * t);
    [
        [pp, 0.0, pv, 0.0],
        [0.0, pp, 0.0, pv],
        [pv, 0.0, vv, 0.0],
        [0.0, pv, 0.0, vv],
    ]
}

fn mul(a: &Cov, b: &Cov) -> Cov {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            c[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn transpose(a: &Cov) -> Cov {
    let mut t = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// `F·x`.
pub fn apply(f: &Cov, x: &State) -> State {
    let mut y = [0.0; 4];
    for i in 0..4 {
        y[i] = (0..4).map(|k| f[i][k] * x[k]).sum();
    }
    y
}

/// The inverse and determinant of a 2 × 2 matrix.
pub fn inverse2(m: &Mat2) -> (Mat2, f64) {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    (
        [
            [m[1][1] / det, -m[0][1] / det],
            [-m[1][0] / det, m[0][0] / det],
        ],
        det,
    )
}

/// A Gaussian estimate: mean and covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// `[x, y, vx, vy]`.
    pub x: State,
    /// Its covariance.
    pub p: Cov,
}

/// The innovation of a measurement against a prediction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Innovation {
    /// `z − H·x`.
    pub nu: [f64; 2],
    /// `S = H·P·Hᵀ + R`.
    pub s: Mat2,
}

impl Innovation {
    /// The squared Mahalanobis distance `νᵀS⁻¹ν`.
    pub fn distance2(&self) -> f64 {
        let (si, _) = inverse2(&self.s);
        let n = self.nu;
        n[0] * (si[0][0] * n[0] + si[0][1] * n[1]) + n[1] * (si[1][0] * n[0] + si[1][1] * n[1])
    }

    /// The Gaussian likelihood `N(ν; 0, S)`.
    pub fn likelihood(&self) -> f64 {
        let (_, det) = inverse2(&self.s);
        (-0.5 * self.distance2()).exp() / (std::f64::consts::TAU * det.sqrt())
    }
}

impl Estimate {
    /// The prediction over `dt_s` under `motion` with acceleration noise `sigma_a`.
    pub fn predict(&self, motion: Motion, dt_s: f64, sigma_a: f64) -> Estimate {
        let f = motion.transition(dt_s);
        let q = process_noise(dt_s, sigma_a);
        let fp = mul(&mul(&f, &self.p), &transpose(&f));
        let mut p = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                p[i][j] = fp[i][j] + q[i][j];
            }
        }
        Estimate {
            x: apply(&f, &self.x),
            p,
        }
    }

    /// The innovation of position measurement `z` with covariance `r`.
    pub fn innovation(&self, z: [f64; 2], r: &Mat2) -> Innovation {
        Innovation {
            nu: [z[0] - self.x[0], z[1] - self.x[1]],
            s: [
                [self.p[0][0] + r[0][0], self.p[0][1] + r[0][1]],
                [self.p[1][0] + r[1][0], self.p[1][1] + r[1][1]],
            ],
        }
    }

    /// The Kalman gain `K = P·Hᵀ·S⁻¹` (4 × 2) for `innovation`.
    pub fn gain(&self, innovation: &Innovation) -> [[f64; 2]; 4] {
        let (si, _) = inverse2(&innovation.s);
        let mut k = [[0.0; 2]; 4];
        for i in 0..4 {
            for j in 0..2 {
                k[i][j] = self.p[i][0] * si[0][j] + self.p[i][1] * si[1][j];
            }
        }
        k
    }

    /// The update with position measurement `z` of covariance `r` (Joseph form).
    pub fn update(&self, z: [f64; 2], r: &Mat2) -> Estimate {
        let innovation = self.innovation(z, r);
        let k = self.gain(&innovation);
        let mut x = self.x;
        for i in 0..4 {
            x[i] += k[i][0] * innovation.nu[0] + k[i][1] * innovation.nu[1];
        }
        // (I − KH)·P·(I − KH)ᵀ + K·R·Kᵀ.
        let mut a = [[0.0; 4]; 4];
        for i in 0..4 {
            a[i][i] = 1.0;
            a[i][0] -= k[i][0];
            a[i][1] -= k[i][1];
        }
        let apa = mul(&mul(&a, &self.p), &transpose(&a));
        let mut p = apa;
        for i in 0..4 {
            for j in 0..4 {
                let krk: f64 = (0..2)
                    .map(|m| (0..2).map(|n| k[i][m] * r[m][n] * k[j][n]).sum::<f64>())
                    .sum();
                p[i][j] += krk;
            }
        }
        Estimate { x, p }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The constant-velocity filter's steady state against Kalata's closed form for the
    /// discrete white-noise acceleration model (Kalata, "The tracking index", IEEE Trans. AES
    /// 20(2), 1984; BLK §6.5.3): with the tracking index `λ = σa·T²/σw`,
    /// `α = −(λ² + 8λ − (λ + 4)·√(λ² + 8λ))/8` and `β = (λ² + 4λ − λ·√(λ² + 8λ))/4`, the
    /// gains on position and velocity being α and β/T.
    #[test]
    fn constant_velocity_gains_reach_kalatas_steady_state() {
        for (dt, sigma_a, sigma_w) in [(2.5, 0.05, 10.0), (2.5, 0.5, 10.0), (1.0, 1.0, 2.0)] {
            let r = [[sigma_w * sigma_w, 0.0], [0.0, sigma_w * sigma_w]];
            let mut e = Estimate {
                x: [0.0; 4],
                p: [
                    [1e4, 0.0, 0.0, 0.0],
                    [0.0, 1e4, 0.0, 0.0],
                    [0.0, 0.0, 1e2, 0.0],
                    [0.0, 0.0, 0.0, 1e2],
                ],
            };
            let mut k = [[0.0; 2]; 4];
            for _ in 0..2000 {
                let predicted = e.predict(Motion::ConstantVelocity, dt, sigma_a);
                k = predicted.gain(&predicted.innovation([0.0, 0.0], &r));
                e = predicted.update([0.0, 0.0], &r);
            }
            let lambda: f64 = sigma_a * dt * dt / sigma_w;
            let root = (lambda * lambda + 8.0 * lambda).sqrt();
            let alpha = -(lambda * lambda + 8.0 * lambda - (lambda + 4.0) * root) / 8.0;
            let beta = (lambda * lambda + 4.0 * lambda - lambda * root) / 4.0;
            for axis in 0..2 {
                assert!(
                    (k[axis][axis] - alpha).abs() < 1e-9,
                    "α {} vs {alpha}",
                    k[axis][axis]
                );
                assert!(
                    (k[axis + 2][axis] - beta / dt).abs() < 1e-9,
                    "β/T {} vs {}",
                    k[axis + 2][axis],
                    beta / dt
                );
                assert!(k[axis][1 - axis].abs() < 1e-12);
            }
        }
    }

    /// A coordinated turn carries a state along its circle exactly: after a full circle's
    /// time the position and velocity are back, and a quarter turn turns the velocity by 90°.
    #[test]
    fn a_coordinated_turn_follows_its_circle() {
        let w = 0.05;
        let turn = Motion::CoordinatedTurn { rate_rad_s: w };
        let x0 = [100.0, -50.0, 5.0, 0.0];
        let mut x = x0;
        let steps = 1000;
        let dt = std::f64::consts::TAU / w / steps as f64;
        for _ in 0..steps {
            x = apply(&turn.transition(dt), &x);
        }
        for i in 0..4 {
            assert!((x[i] - x0[i]).abs() < 1e-9, "{x:?}");
        }
        let quarter = apply(&turn.transition(std::f64::consts::FRAC_PI_2 / w), &x0);
        // Speed 5 m/s east turning to port: north after a quarter, the centre at 100 m north.
        assert!((quarter[2]).abs() < 1e-12 && (quarter[3] - 5.0).abs() < 1e-12);
        assert!((quarter[0] - 200.0).abs() < 1e-9 && (quarter[1] - 50.0).abs() < 1e-9);
        // A tiny rate is constant velocity.
        let cv = Motion::ConstantVelocity.transition(3.0);
        let almost = Motion::CoordinatedTurn { rate_rad_s: 1e-9 }.transition(3.0);
        for i in 0..4 {
            for j in 0..4 {
                assert!((cv[i][j] - almost[i][j]).abs() < 1e-8);
            }
        }
    }
}
