//! Stage: environment. What the radar sees besides its targets: sea clutter (σ0 models,
//! amplitude statistics; the per-frame clutter map built from them is a signal source,
//! `crate::signal::clutter_map`) and rain (its field and volume
//! reflectivity). How waves travel — horizon, sea reflection, atmosphere, rain loss — is in
//! [`crate::propagation`] (docs/physics.md).

pub mod clutter;
pub mod rain;
