//! The interacting multiple model estimator (Blom & Bar-Shalom, IEEE Trans. AC 33(8), 1988;
//! BLK §11.6.6): each track runs one Kalman filter per motion model, mixed before every
//! prediction by the Markov switching probabilities `p_ij` and weighted after every update by
//! each model's likelihood:
//!
//! 1. `c_j = Σ_i p_ij·μ_i`, `μ_{i|j} = p_ij·μ_i/c_j`;
//! 2. mixed starts `x⁰_j = Σ_i μ_{i|j}·x_i`, `P⁰_j = Σ_i μ_{i|j}·(P_i + (x_i − x⁰_j)(x_i − x⁰_j)ᵀ)`;
//! 3. each model predicts from its mixed start and updates with the measurement, its
//!    likelihood `Λ_j = N(ν_j; 0, S_j)`;
//! 4. `μ_j = Λ_j·c_j/Σ_k Λ_k·c_k`; the output is the moment-matched mixture.
//!
//! Without a measurement (a missed scan) the predictions stand and `μ_j = c_j`.

use crate::filter::{Cov, Estimate, Mat2, Motion};

/// The models and how they switch.
#[derive(Debug, Clone, PartialEq)]
pub struct ImmModels {
    /// The motion models.
    pub motions: Vec<Motion>,
    /// Each model's acceleration noise, m/s².
    pub sigma_a: Vec<f64>,
    /// `p_ij`: the probability of switching from model i to model j in a scan, row-major.
    pub switching: Vec<f64>,
}

/// A track's IMM state: one estimate and one probability per model.
#[derive(Debug, Clone, PartialEq)]
pub struct ImmState {
    /// Each model's estimate.
    pub estimates: Vec<Estimate>,
    /// Each model's probability.
    pub probabilities: Vec<f64>,
}

/// A prediction: each model's predicted estimate and the predicted model probabilities `c_j`.
#[derive(Debug, Clone, PartialEq)]
pub struct ImmPrediction {
    /// Each model's prediction from its mixed start.
    pub estimates: Vec<Estimate>,
    /// `c_j`.
    pub probabilities: Vec<f64>,
}

/// The moment-matched combination of weighted estimates.
pub fn combine(estimates: &[Estimate], weights: &[f64]) -> Estimate {
    let mut x = [0.0; 4];
    for (e, &w) in estimates.iter().zip(weights) {
        for i in 0..4 {
            x[i] += w * e.x[i];
        }
    }
    let mut p: Cov = [[0.0; 4]; 4];
    for (e, &w) in estimates.iter().zip(weights) {
        for i in 0..4 {
            for j in 0..4 {
                p[i][j] += w * (e.p[i][j] + (e.x[i] - x[i]) * (e.x[j] - x[j]));
            }
        }
    }
    Estimate { x, p }
}

impl ImmModels {
    /// Steps 1–3's prediction over `dt_s`.
    pub fn predict(&self, state: &ImmState, dt_s: f64) -> ImmPrediction {
        let m = self.motions.len();
        let mu = &state.probabilities;
        let c: Vec<f64> = (0..m)
            .map(|j| (0..m).map(|i| self.switching[i * m + j] * mu[i]).sum())
            .collect();
        let estimates = (0..m)
            .map(|j| {
                let weights: Vec<f64> = (0..m)
                    .map(|i| {
                        if c[j] > 0.0 {
                            self.switching[i * m + j] * mu[i] / c[j]
                        } else {
                            0.0
                        }
                    })
                    .collect();
                combine(&state.estimates, &weights).predict(self.motions[j], dt_s, self.sigma_a[j])
            })
            .collect();
        ImmPrediction {
            estimates,
            probabilities: c,
        }
    }

    /// Step 3's updates and step 4 with position measurement `z` of covariance `r`.
    pub fn update(&self, prediction: &ImmPrediction, z: [f64; 2], r: &Mat2) -> ImmState {
        let likelihoods: Vec<f64> = prediction
            .estimates
            .iter()
            .map(|e| e.innovation(z, r).likelihood())
            .collect();
        let total: f64 = likelihoods
            .iter()
            .zip(&prediction.probabilities)
            .map(|(l, c)| l * c)
            .sum();
        let probabilities = if total > 0.0 && total.is_finite() {
            likelihoods
                .iter()
                .zip(&prediction.probabilities)
                .map(|(l, c)| l * c / total)
                .collect()
        } else {
            prediction.probabilities.clone()
        };
        ImmState {
            estimates: prediction
                .estimates
                .iter()
                .map(|e| e.update(z, r))
                .collect(),
            probabilities,
        }
    }

    /// A missed scan: the predictions stand.
    pub fn coast(&self, prediction: &ImmPrediction) -> ImmState {
        ImmState {
            estimates: prediction.estimates.clone(),
            probabilities: prediction.probabilities.clone(),
        }
    }
}

impl ImmPrediction {
    /// The combined prediction.
    pub fn combined(&self) -> Estimate {
        combine(&self.estimates, &self.probabilities)
    }
}

impl ImmState {
    /// The combined estimate.
    pub fn combined(&self) -> Estimate {
        combine(&self.estimates, &self.probabilities)
    }
}
