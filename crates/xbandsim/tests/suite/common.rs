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

/// A scene from TOML text and its clutter map for frame key (3, 0) over the whole record
/// (one sample past it), with that sample count; panics when the scene makes no map.
pub fn clutter_map_of(
    toml_text: &str,
) -> (Scene, xbandsim::signal::clutter_map::ClutterMap, usize) {
    let scene = scene(toml_text);
    let radar = scene.radar();
    let samples = (radar.max_range_m() / radar.range_bin_m()).ceil() as usize + 2;
    let map = xbandsim::signal::clutter_map::ClutterMap::new(
        radar,
        scene.environment(),
        xbandsim::rng::FrameKey::new(3, 0),
        samples,
    )
    .expect("the scene makes a clutter map");
    (scene, map, samples)
}
