//! Helpers shared by the integration tests; the measuring helpers are the library's own
//! (`xbandsim_validate`), so `xbandsim validate` and the tests measure the same way.
#![allow(dead_code, unused_imports)]

use xbandsim::model::Scene;
use xbandsim::{Frame, Simulation};
pub use xbandsim_validate::{
    argmax, bin_range_m, fine_profile, first_null_bins, point_north, pslr_db, radar_block,
    radar_block_no_noise, spoke, width_at_db,
};

/// A scene from TOML text, panicking with the error (tests only).
pub fn scene(toml_text: &str) -> Scene {
    Scene::from_toml_str(toml_text, "test").unwrap_or_else(|e| panic!("{e}"))
}

/// Renders a scene with a seed.
pub fn render(toml_text: &str, seed: u64) -> (Simulation, Frame) {
    let sim = Simulation::new(scene(toml_text));
    let frame = sim.render(seed);
    (sim, frame)
}
