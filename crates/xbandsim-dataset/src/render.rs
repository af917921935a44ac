//! Rendering one sample into its files, in memory: the frames' records and images
//! (xbandsim's frame files), their labels ([`crate::labels`]) and the scene that renders the
//! sample again. The bytes depend only on (spec, seed, index) and on the storage format's
//! image names ([`Format::image_name`]); [`crate::generate`] writes them into a folder,
//! [`crate::webdataset`] into a tar shard.

use crate::baseline::SampleBaseline;
use crate::error::{DatasetError, Result};
use crate::labels::{
    frame_labels, mask_spokes, object_masks, ArtefactInput, FrameContext, LandInput,
};
use crate::layout::{frame_file, frame_subdir, Format};
use crate::spec::DatasetSpec;
use std::path::Path;
use xbandsim::engine::Outputs;
use xbandsim::engine::Request as RenderRequest;
use xbandsim::products::frame_files::encode_frame_files;
use xbandsim::receiver::video_chain::EchoHistory;
use xbandsim::Simulation;

/// A sample's files: relative names and bytes, in storage order.
pub type SampleFiles = Vec<(String, Vec<u8>)>;

/// Renders sample `index` of the dataset made with `seed` into its files, in the order they
/// are stored (relative names, `frame_KKKK/` for sequences): per frame the polar record, the
/// PPI image(s), truth.json and the labels (coco.json, yolo.txt, yolo_obb.txt,
/// targets.jsonl; [`crate::labels`]); then baseline.json ([`crate::baseline`], unless
/// `[dataset] baseline = false`) and scene.toml. The labels name the image as
/// `format` stores it.
pub fn render_sample(
    spec: &DatasetSpec,
    seed: u64,
    index: u64,
    format: Format,
) -> Result<SampleFiles> {
    let sample = spec.sample(seed, index)?;
    let scene_err = |error| DatasetError::Scene { index, error };
    let loaded = xbandsim::LoadedSpec::from_toml(&sample.scene_toml, "scene.toml", &spec.base_dir)
        .map_err(scene_err)?;
    let scene = loaded.build().map_err(scene_err)?;
    let display = loaded.ppi_settings().map_err(scene_err)?;
    let sim = Simulation::new(scene);
    let quiet = sim.targets_only();
    let outputs = Outputs {
        doppler_cube: spec.datacube,
        radial_velocity: display.doppler_colour,
        ..Default::default()
    };
    let name = format!("sample {index}");
    let categories = spec.categories();
    let mut written: Vec<(String, Vec<u8>)> = Vec::new();
    // The receiver's echo averaging runs on through a sequence's frames.
    let echo_history = std::sync::Mutex::new(EchoHistory::default());
    let mut baseline = spec
        .baseline
        .then(|| SampleBaseline::new(sim.scene(), spec.frames, index))
        .transpose()?;
    for k in 0..spec.frames {
        let frame = sim
            .run(
                &RenderRequest::new(sample.render_seed)
                    .frame(k)
                    .outputs(outputs)
                    .echo_history(&echo_history),
            )
            .map_err(scene_err)?;
        let baseline_objects = baseline.as_mut().map(|b| b.add_frame(&frame));
        let sub = frame_subdir(spec.frames, k);
        let encoded = encode_frame_files(
            sim.scene().radar(),
            &display,
            &frame,
            Path::new(&sub),
            &name,
            sample.render_seed,
            spec.image.images(),
        )
        .map_err(scene_err)?;
        let targets_only = quiet
            .only_spokes(&mask_spokes(&encoded.objects, frame.spokes))
            .run(&RenderRequest::new(sample.render_seed).frame(k))
            .map_err(scene_err)?;
        let masks = object_masks(
            &encoded.objects,
            &targets_only.polar_db,
            frame.spokes,
            frame.range_bins,
            &encoded.converter,
            spec.mask_threshold_db as f32,
            sim.scene()
                .radar()
                .short_pulse_noise_db()
                .map(|n| (sim.scene().radar().join_bin(), n as f32)),
        );
        let image = format.image_name(index, spec.frames, k, spec.image.labelled_file());
        let labels = frame_labels(
            &FrameContext {
                sample: index,
                frame: k,
                frame_start_time_s: frame.start_time_s,
                image: &image,
                size_px: encoded.converter.size_px() as usize,
                range_scale_m: encoded.converter.display_range_m(),
                azimuth_beamwidth_rad: sim.scene().radar().antenna().az_beamwidth_rad,
                range_resolution_m: sim.scene().radar().range_resolution_m(),
                categories: &categories,
                baseline: baseline_objects.as_deref(),
            },
            &encoded.objects,
            &masks,
            spec.artefact_labels.then_some(ArtefactInput {
                artefacts: &encoded.artefacts,
                converter: &encoded.converter,
                bins: frame.range_bins,
            }),
            frame.land.as_ref().map(|land| LandInput {
                polygon: &land.polygon,
                converter: &encoded.converter,
                bins: land.range_bins,
            }),
        );
        let mut files = encoded.files;
        files.push(("coco.json", json_line(&labels.coco)));
        files.push(("yolo.txt", labels.yolo.into_bytes()));
        files.push(("yolo_obb.txt", labels.yolo_obb.into_bytes()));
        files.push(("targets.jsonl", labels.targets_jsonl.into_bytes()));
        for (file, bytes) in files {
            written.push((frame_file(spec.frames, k, file), bytes));
        }
    }
    let header = format!(
        "# xbandsim dataset sample {index}: re-render with\n#   xbandsim render scene.toml --seed {}{}\n",
        sample.render_seed,
        if spec.frames > 1 {
            format!(" --frames {}", spec.frames)
        } else {
            String::new()
        }
    );
    if let Some(baseline) = baseline {
        let sea_state = sim.scene().environment().clutter().map(|c| c.sea_state());
        written.push((
            "baseline.json".into(),
            json_line(&baseline.finish(index, sea_state)),
        ));
    }
    written.push((
        "scene.toml".into(),
        format!("{header}{}", sample.scene_toml).into_bytes(),
    ));
    Ok(written)
}

fn json_line(v: &serde_json::Value) -> Vec<u8> {
    let mut bytes = v.to_string().into_bytes();
    bytes.push(b'\n');
    bytes
}
