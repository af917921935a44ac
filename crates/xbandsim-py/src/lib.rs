//! The Python binding of xbandsim (`import xbandsim`; docs/python.md).
//!
//! It converts, and does nothing else: Python values to scene text and overrides, the
//! library's results to NumPy arrays (moved, not copied) and JSON text, and each kind of
//! library error to its own Python exception class (declared in `python/xbandsim/errors.py`
//! and looked up here by name). The simulation runs with the GIL released. The Python layer
//! (`python/xbandsim/`) wraps these functions in classes.

use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use xbandsim::engine::Request as RenderRequest;
use xbandsim::engine::{Outputs, Simulation};
use xbandsim::products::frame_files::{frame_products, Images};
use xbandsim::scene::LoadedSpec;
use xbandsim_dataset::{generate_until, DatasetError, DatasetSpec, Format, Request, Shard};

/// The Python exception for a library error: `(class name in xbandsim.errors, message)`.
fn library_error_class(e: &xbandsim::Error) -> &'static str {
    use xbandsim::Error as E;
    match e {
        E::SceneSyntax { .. } => "SceneSyntaxError",
        E::InvalidField { .. } => "InvalidFieldError",
        E::MissingField { .. } => "MissingFieldError",
        E::Io { .. } => "XbandsimIOError",
        E::Mesh { .. } => "MeshError",
        E::Encode { .. } => "EncodeError",
        _ => "XbandsimError",
    }
}

/// Raises `class_name` from `xbandsim.errors` with `message`, and the error's field and
/// problem as attributes when it has them.
fn raise(
    py: Python<'_>,
    class_name: &str,
    message: String,
    field: Option<String>,
    problem: Option<String>,
) -> PyErr {
    let made = (|| -> PyResult<PyErr> {
        let class = py.import("xbandsim.errors")?.getattr(class_name)?;
        let exc = class.call1((message.clone(),))?;
        exc.setattr("field", field)?;
        exc.setattr("problem", problem)?;
        Ok(PyErr::from_value(exc))
    })();
    made.unwrap_or_else(|e| e)
}

fn library_error(py: Python<'_>, e: xbandsim::Error) -> PyErr {
    let field = e.field().map(str::to_string);
    let problem = e.problem().map(|p| p.to_string());
    raise(py, library_error_class(&e), e.to_string(), field, problem)
}

fn dataset_error(py: Python<'_>, e: DatasetError) -> PyErr {
    match e {
        DatasetError::Scene {
            error: source,
            index,
        } => {
            let class = library_error_class(&source);
            let field = source.field().map(str::to_string);
            let problem = source.problem().map(|p| p.to_string());
            raise(
                py,
                class,
                format!("sample {index}: {source}"),
                field,
                problem,
            )
        }
        DatasetError::Spec { ref field, .. } => {
            let field = Some(field.clone());
            raise(py, "DatasetSpecError", e.to_string(), field, None)
        }
        // A generate() argument (the message names it as the CLI's option, `--shard`): the
        // class of every bad argument (errors.py), its Python name in `field` (`shard`).
        DatasetError::Argument { ref name, .. } => {
            let field = Some(name.trim_start_matches('-').replace('-', "_"));
            raise(py, "InvalidArgumentError", e.to_string(), field, None)
        }
        DatasetError::Io { .. } => raise(py, "XbandsimIOError", e.to_string(), None, None),
        DatasetError::Mismatch { .. } => {
            raise(py, "DatasetMismatchError", e.to_string(), None, None)
        }
        DatasetError::Interrupted { .. } => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err(e.to_string())
        }
    }
}

/// A parsed scene file with its overrides (`xbandsim.Scene` wraps it).
#[pyclass(module = "xbandsim._xbandsim", frozen)]
struct SceneSpec {
    spec: LoadedSpec,
}

/// The scene's objects and settings, built and checked, ready to render
/// (`xbandsim.Simulation` wraps it).
#[pyclass(module = "xbandsim._xbandsim", frozen)]
struct Sim {
    sim: Simulation,
    display: xbandsim::products::ppi::PpiSettings,
    name: String,
}

/// A JSON value as a TOML value (TOML has no null).
fn json_to_toml(v: &serde_json::Value, path: &str) -> Result<toml::Value, String> {
    use serde_json::Value as J;
    Ok(match v {
        J::Null => {
            return Err(format!(
                "{path}: None has no TOML form; leave the field out instead"
            ))
        }
        J::Bool(b) => toml::Value::Boolean(*b),
        J::Number(n) => match n.as_i64() {
            Some(i) => toml::Value::Integer(i),
            None => toml::Value::Float(n.as_f64().ok_or_else(|| format!("{path}: {n}"))?),
        },
        J::String(s) => toml::Value::String(s.clone()),
        J::Array(a) => toml::Value::Array(
            a.iter()
                .enumerate()
                .map(|(i, x)| json_to_toml(x, &format!("{path}[{i}]")))
                .collect::<Result<_, _>>()?,
        ),
        J::Object(m) => {
            let mut t = toml::map::Map::new();
            for (k, x) in m {
                let sub = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                t.insert(k.clone(), json_to_toml(x, &sub)?);
            }
            toml::Value::Table(t)
        }
    })
}

#[pymethods]
impl SceneSpec {
    /// Reads a scene file (mesh files relative to its folder).
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<SceneSpec> {
        let spec = py
            .detach(|| LoadedSpec::read(&path))
            .map_err(|e| library_error(py, e))?;
        Ok(SceneSpec { spec })
    }

    /// Parses scene TOML text; `name` names it in errors, mesh files relative to `base_dir`.
    #[staticmethod]
    fn from_toml(py: Python<'_>, text: &str, name: &str, base_dir: PathBuf) -> PyResult<SceneSpec> {
        let spec =
            LoadedSpec::from_toml(text, name, &base_dir).map_err(|e| library_error(py, e))?;
        Ok(SceneSpec { spec })
    }

    /// Parses a scene given as JSON text (the Python layer's `json.dumps` of a dict).
    #[staticmethod]
    fn from_json(py: Python<'_>, json: &str, name: &str, base_dir: PathBuf) -> PyResult<SceneSpec> {
        let value: serde_json::Value =
            serde_json::from_str(json).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let toml_value = json_to_toml(&value, "")
            .map_err(|m| raise(py, "SceneSyntaxError", format!("{name}: {m}"), None, None))?;
        let text = toml::to_string(&toml_value)
            .map_err(|e| raise(py, "SceneSyntaxError", format!("{name}: {e}"), None, None))?;
        Self::from_toml(py, &text, name, base_dir)
    }

    /// The same scene with `(field, JSON value)` overrides applied in order.
    fn with_overrides(&self, py: Python<'_>, pairs: Vec<(String, String)>) -> PyResult<SceneSpec> {
        let mut sets = Vec::with_capacity(pairs.len());
        for (field, json) in pairs {
            let value: serde_json::Value =
                serde_json::from_str(&json).map_err(|e| PyValueError::new_err(e.to_string()))?;
            let v = json_to_toml(&value, &field)
                .map_err(|m| raise(py, "InvalidFieldError", m, Some(field.clone()), None))?;
            sets.push(format!("{field}={v}"));
        }
        let spec = self
            .spec
            .clone()
            .with_overrides_named("settings", &sets)
            .map_err(|e| library_error(py, e))?;
        Ok(SceneSpec { spec })
    }

    /// Where the scene came from (file path or name).
    #[getter]
    fn origin(&self) -> String {
        self.spec.origin().to_string()
    }

    /// Builds and checks the scene.
    fn build(&self, py: Python<'_>) -> PyResult<Sim> {
        let spec = &self.spec;
        let pool = library_pool()?;
        // The scene, its BVH and its caches are built with the GIL released.
        let (sim, display) = py
            .detach(|| {
                pool.install(|| {
                    Ok::<_, xbandsim::Error>((Simulation::new(spec.build()?), spec.ppi_settings()?))
                })
            })
            .map_err(|e| library_error(py, e))?;
        Ok(Sim {
            sim,
            display,
            name: spec.origin().to_string(),
        })
    }
}

/// The thread pool the library's parallel work runs on. Rayon's global pool does not survive
/// `fork()`: a process forked after using it (a torch DataLoader worker, multiprocessing's
/// fork start method) has none of its threads and would wait for them forever. So the binding
/// keeps one pool per process and builds a new one in a forked child (its parent's pool is
/// left alone: its threads are not in this process). Threads: `RAYON_NUM_THREADS` or one per
/// core.
fn library_pool() -> PyResult<Arc<rayon::ThreadPool>> {
    static POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);
    let pid = std::process::id();
    let mut slot = POOL.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((owner, pool)) = slot.as_ref() {
        if *owner == pid {
            return Ok(pool.clone());
        }
    }
    if let Some(parents) = slot.take() {
        std::mem::forget(parents);
    }
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .build()
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?,
    );
    *slot = Some((pid, pool.clone()));
    Ok(pool)
}

#[pymethods]
impl Sim {
    /// Renders revolution `frame` with `seed`: a dict of NumPy arrays and the truth JSON.
    #[pyo3(signature = (seed, frame, iq, doppler_cube, images))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        seed: u64,
        frame: u64,
        iq: bool,
        doppler_cube: bool,
        images: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let outputs = Outputs {
            doppler_cube,
            iq,
            radial_velocity: self.display.doppler_colour,
        };
        let radar = self.sim.scene().radar();
        let pool = library_pool()?;
        let rendered = py.detach(|| {
            pool.install(|| {
                self.sim.check_outputs(outputs)?;
                let f = self
                    .sim
                    .run(&RenderRequest::new(seed).frame(frame).outputs(outputs))?;
                let products = frame_products(
                    radar,
                    &self.display,
                    &f,
                    Path::new("."),
                    &self.name,
                    seed,
                    Images {
                        colour: images,
                        gray: images,
                    },
                )?;
                Ok::<_, xbandsim::Error>((f, products))
            })
        });
        let (f, p) = rendered.map_err(|e| library_error(py, e))?;
        let out = PyDict::new(py);
        let size = p.converter.size_px() as usize;
        out.set_item(
            "polar_db",
            f.polar_db
                .into_pyarray(py)
                .reshape([f.spokes, f.range_bins])?,
        )?;
        out.set_item("ppi_db", p.ppi_db.into_pyarray(py).reshape([size, size])?)?;
        match p.gray {
            Some(g) => out.set_item("ppi_gray", g.into_pyarray(py).reshape([size, size])?)?,
            None => out.set_item("ppi_gray", py.None())?,
        }
        match p.colour_rgb {
            Some(c) => out.set_item("ppi_rgb", c.into_pyarray(py).reshape([size, size, 3])?)?,
            None => out.set_item("ppi_rgb", py.None())?,
        }
        match f.doppler_cube {
            Some(c) => out.set_item(
                "doppler_cube_db",
                c.values_db
                    .into_pyarray(py)
                    .reshape([c.spokes, c.doppler_bins, c.range_bins])?,
            )?,
            None => out.set_item("doppler_cube_db", py.None())?,
        }
        match f.iq {
            Some(q) => {
                let (pulses, samples) = (q.pulses, q.samples);
                let values: Vec<numpy::Complex32> = q
                    .values
                    .iter()
                    .map(|c| numpy::Complex32::new(c.re, c.im))
                    .collect();
                out.set_item("iq", values.into_pyarray(py).reshape([pulses, samples])?)?;
                out.set_item("iq_times_s", PyArray1::from_vec(py, q.times_s))?;
                let az: Vec<f64> = q.azimuths_rad.iter().map(|a| a.to_degrees()).collect();
                out.set_item("iq_azimuth_deg", PyArray1::from_vec(py, az))?;
                let spokes: Vec<u64> = q.spokes.iter().map(|&s| s as u64).collect();
                out.set_item("iq_spoke", PyArray1::from_vec(py, spokes))?;
            }
            None => out.set_item("iq", py.None())?,
        }
        match f.video {
            Some(v) => out.set_item(
                "video",
                v.levels.into_pyarray(py).reshape([v.spokes, v.samples])?,
            )?,
            None => out.set_item("video", py.None())?,
        }
        match f.land {
            Some(l) => {
                let shape = [l.spokes, l.range_bins];
                out.set_item("land_mask", l.mask().into_pyarray(py).reshape(shape)?)?;
                if l.has_structures() {
                    out.set_item(
                        "structure_mask",
                        l.structure.into_pyarray(py).reshape(shape)?,
                    )?;
                } else {
                    out.set_item("structure_mask", py.None())?;
                }
                out.set_item("land_polygon", l.polygon.into_pyarray(py).reshape(shape)?)?;
            }
            None => {
                out.set_item("land_mask", py.None())?;
                out.set_item("land_polygon", py.None())?;
                out.set_item("structure_mask", py.None())?;
            }
        }
        let truth =
            String::from_utf8(p.truth_json).map_err(|e| PyValueError::new_err(e.to_string()))?;
        out.set_item("truth_json", truth)?;
        Ok(out)
    }

    /// (spokes, range bins, range bin m, image size px).
    #[getter]
    fn shape(&self) -> (usize, usize, f64, u32) {
        let r = self.sim.scene().radar();
        (
            r.spokes(),
            r.num_range_bins(),
            r.range_bin_m(),
            self.display.image_size_px,
        )
    }
}

/// Generates (or resumes) a dataset; returns the run's counts.
#[pyfunction]
#[pyo3(signature = (spec_path, out, count, seed, shard, jobs, shard_samples, assemble=true))]
fn generate_dataset<'py>(
    py: Python<'py>,
    spec_path: PathBuf,
    out: PathBuf,
    count: u64,
    seed: u64,
    shard: Option<String>,
    jobs: usize,
    shard_samples: Option<u64>,
    assemble: bool,
) -> PyResult<Bound<'py, PyDict>> {
    // The run goes on a thread of its own while this one waits with the GIL released and
    // wakes every 50 ms to let Python handle signals: on Ctrl-C (a KeyboardInterrupt from
    // check_signals) the run is told to stop, finishes the samples it is writing and
    // returns, and the interrupt is raised; the folder resumes like a killed run's.
    let stop = AtomicBool::new(false);
    let run_dataset = || {
        let spec = DatasetSpec::read(&spec_path)?;
        let shard = match &shard {
            Some(s) => Shard::resolve(s, &|name| std::env::var(name).ok())?,
            None => Shard::ALL,
        };
        let format = match shard_samples {
            Some(n) => Format::WebDataset {
                samples_per_shard: n,
            },
            None => Format::Dir,
        };
        let request = Request {
            count,
            seed,
            shard,
            jobs,
            format,
            assemble,
        };
        generate_until(&spec, &out, &request, &|| {}, &stop)
    };
    let mut interrupt = None;
    let done = (Mutex::new(false), Condvar::new());
    let run = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            // Set when the run ends, also by a panic (then re-raised below).
            struct Finished<'a>(&'a (Mutex<bool>, Condvar));
            impl Drop for Finished<'_> {
                fn drop(&mut self) {
                    *self.0 .0.lock().unwrap_or_else(|p| p.into_inner()) = true;
                    self.0 .1.notify_all();
                }
            }
            let _finished = Finished(&done);
            run_dataset()
        });
        let tick = std::time::Duration::from_millis(50);
        let finished = || {
            let flag = done.0.lock().unwrap_or_else(|p| p.into_inner());
            let waited = done.1.wait_timeout_while(flag, tick, |finished| !*finished);
            waited.map_or(true, |(flag, _)| *flag)
        };
        while !py.detach(finished) {
            if interrupt.is_none() {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::Relaxed);
                    interrupt = Some(e);
                }
            }
        }
        worker.join()
    });
    let run = run.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
    if let Some(e) = interrupt {
        return Err(e);
    }
    let summary = run.map_err(|e| dataset_error(py, e))?;
    let d = PyDict::new(py);
    d.set_item("in_shard", summary.in_shard)?;
    d.set_item("skipped", summary.skipped)?;
    d.set_item("made", summary.made)?;
    d.set_item("missing", summary.missing)?;
    d.set_item("assembled", summary.assembled.is_some())?;
    Ok(d)
}

/// The files of sample `index` of the dataset of `spec_path` made with `seed`, rendered in
/// memory (the bytes `xbandsim dataset` stores): `[(relative name, bytes)]`.
#[pyfunction]
fn render_sample<'py>(
    py: Python<'py>,
    spec_path: PathBuf,
    seed: u64,
    index: u64,
) -> PyResult<Vec<(String, Bound<'py, pyo3::types::PyBytes>)>> {
    let pool = library_pool()?;
    let files = py
        .detach(|| {
            pool.install(|| {
                let spec = DatasetSpec::read(&spec_path)?;
                xbandsim_dataset::render_sample(&spec, seed, index, Format::Dir)
            })
        })
        .map_err(|e| dataset_error(py, e))?;
    Ok(files
        .into_iter()
        .map(|(name, bytes)| (name, pyo3::types::PyBytes::new(py, &bytes)))
        .collect())
}

mod layout;

/// A COCO compressed-RLE mask as a `height × width` uint8 array (1 inside).
#[pyfunction]
fn decode_rle<'py>(
    py: Python<'py>,
    counts: &str,
    height: usize,
    width: usize,
) -> PyResult<Bound<'py, numpy::PyArray2<u8>>> {
    use xbandsim_dataset::labels::{mask_from_rle, rle_from_string};
    let mask = rle_from_string(counts)
        .and_then(|c| mask_from_rle(&c, height, width))
        .map_err(PyValueError::new_err)?;
    mask.into_pyarray(py).reshape([height, width])
}

/// An 8-bit PNG (gray or RGB, as the dataset writes them) as a `(height, width)` or
/// `(height, width, 3)` uint8 array.
#[pyfunction]
fn decode_png<'py>(py: Python<'py>, data: &[u8]) -> PyResult<Bound<'py, PyAny>> {
    let decoded = (|| -> Result<(Vec<u8>, usize, usize, usize), String> {
        let mut reader = png::Decoder::new(std::io::Cursor::new(data))
            .read_info()
            .map_err(|e| e.to_string())?;
        let mut buf = vec![0u8; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).map_err(|e| e.to_string())?;
        if info.bit_depth != png::BitDepth::Eight {
            return Err(format!(
                "{:?}-bit PNG: only 8-bit images are read",
                info.bit_depth
            ));
        }
        let channels = match info.color_type {
            png::ColorType::Grayscale => 1,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => return Err(format!("{other:?} PNG: only gray, RGB and RGBA are read")),
        };
        buf.truncate(info.buffer_size());
        Ok((buf, info.height as usize, info.width as usize, channels))
    })();
    let (buf, h, w, c) = decoded.map_err(PyValueError::new_err)?;
    let array = buf.into_pyarray(py);
    Ok(if c == 1 {
        array.reshape([h, w])?.into_any()
    } else {
        array.reshape([h, w, c])?.into_any()
    })
}

/// The library's version.
/// One reinforcement-learning environment (`xbandsim.envs` wraps it in Gymnasium's API;
/// docs/rl.md): the episode, its display and its scoring live in xbandsim-rl.
#[pyclass(module = "xbandsim._xbandsim")]
struct Env {
    episode: xbandsim_rl::Episode,
}

fn episode_info<'py>(
    py: Python<'py>,
    e: &xbandsim_rl::Episode,
    o: &xbandsim_rl::StepOutcome,
) -> PyResult<Bound<'py, PyDict>> {
    let info = PyDict::new(py);
    info.set_item("revolution", e.steps_done())?;
    info.set_item("pulses", o.pulses)?;
    info.set_item("plots", o.plots.len())?;
    info.set_item("false_plots", o.false_plots)?;
    let observed = o.targets.iter().filter(|t| t.observed).count();
    info.set_item("targets_observed", observed)?;
    info.set_item(
        "targets_detected",
        o.targets.iter().filter(|t| t.detected).count(),
    )?;
    info.set_item(
        "targets_in_track",
        o.targets.iter().filter(|t| t.in_track).count(),
    )?;
    let targets = pyo3::types::PyList::empty(py);
    for t in &o.targets {
        let d = PyDict::new(py);
        d.set_item("name", &t.name)?;
        d.set_item("class", &t.class)?;
        d.set_item("range_m", t.range_m)?;
        d.set_item("azimuth_deg", t.azimuth_deg)?;
        d.set_item("rcs_m2", t.rcs_m2)?;
        d.set_item("expected_snr_db", t.expected_snr_db)?;
        d.set_item("visibility", &t.visibility)?;
        d.set_item("observed", t.observed)?;
        d.set_item("detected", t.detected)?;
        d.set_item("in_track", t.in_track)?;
        d.set_item("position_m", t.position_m)?;
        d.set_item("track_id", t.track_id)?;
        targets.append(d)?;
    }
    info.set_item("targets", targets)?;
    let tracks = pyo3::types::PyList::empty(py);
    for t in &o.tracks {
        let d = PyDict::new(py);
        d.set_item("id", t.id)?;
        d.set_item("time_s", t.time_s)?;
        d.set_item("position_m", t.position_m)?;
        d.set_item("velocity_mps", t.velocity_mps)?;
        d.set_item("course_deg", t.course_deg)?;
        d.set_item("speed_kn", t.speed_kn)?;
        d.set_item("cpa_m", t.cpa_m)?;
        d.set_item("tcpa_s", t.tcpa_s)?;
        d.set_item("score", t.score)?;
        d.set_item("recent_hits", t.recent_hits)?;
        tracks.append(d)?;
    }
    info.set_item("tracks", tracks)?;
    info.set_item("false_tracks", o.false_tracks)?;
    let plots = pyo3::types::PyList::empty(py);
    for p in &o.plots {
        plots.append((p.range_m, p.azimuth_deg, p.cells, p.peak_db))?;
    }
    info.set_item("plot_list", plots)?;
    let s = e.scene();
    info.set_item("sea_state", s.sea_state)?;
    info.set_item("rain_cells", s.rain_cells)?;
    info.set_item("own_ship_speed_kn", s.own_ship.speed_kn)?;
    info.set_item("own_ship_course_deg", s.own_ship.course_deg)?;
    Ok(info)
}

#[pymethods]
impl Env {
    #[new]
    #[pyo3(signature = (task, level, image_size_px, max_steps, threads, sea_clutter=true, reward="plots"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        task: &str,
        level: usize,
        image_size_px: u32,
        max_steps: usize,
        threads: usize,
        sea_clutter: bool,
        reward: &str,
    ) -> PyResult<Env> {
        let reward = match reward {
            "plots" => xbandsim_rl::Reward::Plots,
            "tracks" => xbandsim_rl::Reward::Tracks,
            other => {
                return Err(library_error(
                    py,
                    xbandsim::Error::invalid(
                        xbandsim::Problem::UnknownChoice,
                        "reward",
                        other,
                        "\"plots\" or \"tracks\"",
                    ),
                ))
            }
        };
        let task = match task {
            "detection" => xbandsim_rl::Task::Detection,
            "tracking" => xbandsim_rl::Task::Tracking,
            other => {
                return Err(library_error(
                    py,
                    xbandsim::Error::invalid(
                        xbandsim::Problem::UnknownChoice,
                        "task",
                        other,
                        "\"detection\" or \"tracking\"",
                    ),
                ))
            }
        };
        let config = xbandsim_rl::EpisodeConfig {
            task,
            level,
            image_size_px,
            max_steps,
            threads,
            sea_clutter,
            reward,
        };
        let episode = xbandsim_rl::Episode::new(config).map_err(|e| library_error(py, e))?;
        Ok(Env { episode })
    }

    /// Starts an episode: (observation, info).
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        let e = &mut self.episode;
        let (o, obs) = py
            .detach(|| {
                let o = e.reset(seed)?;
                Ok::<_, xbandsim::Error>((o, e.observation()))
            })
            .map_err(|err| library_error(py, err))?;
        let size = self.episode.config().image_size_px as usize;
        let obs = obs.into_pyarray(py).reshape([size, size])?.into_any();
        Ok((obs, episode_info(py, &self.episode, &o)?))
    }

    /// One revolution: (observation, reward, terminated, truncated, info).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: Vec<i64>,
    ) -> PyResult<(Bound<'py, PyAny>, f64, bool, bool, Bound<'py, PyDict>)> {
        let action = xbandsim_rl::Action::from_vector(&action).map_err(|e| library_error(py, e))?;
        let e = &mut self.episode;
        let (o, obs) = py
            .detach(|| {
                let o = e.step(&action)?;
                Ok::<_, xbandsim::Error>((o, e.observation()))
            })
            .map_err(|err| library_error(py, err))?;
        let size = self.episode.config().image_size_px as usize;
        let obs = obs.into_pyarray(py).reshape([size, size])?.into_any();
        let info = episode_info(py, &self.episode, &o)?;
        Ok((obs, o.reward, o.terminated, o.truncated, info))
    }

    /// The display in colour: uint8 (size, size, 3).
    fn render_rgb<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let size = self.episode.config().image_size_px as usize;
        let rgb = self.episode.render_rgb();
        Ok(rgb.into_pyarray(py).reshape([size, size, 3])?.into_any())
    }

    /// The current episode's scene file (it renders with `xbandsim render`).
    #[getter]
    fn scene_toml(&self) -> String {
        self.episode.scene().toml.clone()
    }

    /// Revolutions before truncation.
    #[getter]
    fn max_steps(&self) -> usize {
        self.episode.max_steps()
    }
}

/// Reads a spoke stream (`spokes.bin`): its spokes a revolution and, per record, angle,
/// heading (None without an own ship), range, bits, time and levels.
#[pyfunction]
fn read_spokes<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let bytes =
        std::fs::read(&path).map_err(|e| library_error(py, xbandsim::Error::io(&path, e)))?;
    let stream =
        xbandsim::products::spokes::decode(&path, &bytes).map_err(|e| library_error(py, e))?;
    let out = PyDict::new(py);
    let r = &stream.records;
    out.set_item("spokes_per_revolution", stream.spokes_per_revolution)?;
    out.set_item(
        "angle_deg",
        PyArray1::from_vec(py, r.iter().map(|x| x.angle_deg).collect()),
    )?;
    if r.iter().all(|x| x.heading_deg.is_some()) && !r.is_empty() {
        let h: Vec<f64> = r.iter().filter_map(|x| x.heading_deg).collect();
        out.set_item("heading_deg", PyArray1::from_vec(py, h))?;
    } else {
        out.set_item("heading_deg", py.None())?;
    }
    out.set_item(
        "range_m",
        PyArray1::from_vec(py, r.iter().map(|x| x.range_m).collect()),
    )?;
    out.set_item(
        "bits",
        PyArray1::from_vec(py, r.iter().map(|x| x.bits).collect()),
    )?;
    out.set_item(
        "time_s",
        PyArray1::from_vec(py, r.iter().map(|x| x.time_s).collect()),
    )?;
    let samples = r.first().map_or(0, |x| x.levels.len());
    if r.iter().all(|x| x.levels.len() == samples) {
        let flat: Vec<u8> = r.iter().flat_map(|x| x.levels.iter().copied()).collect();
        out.set_item("levels", flat.into_pyarray(py).reshape([r.len(), samples])?)?;
    } else {
        let rows: Vec<Bound<'py, PyArray1<u8>>> = r
            .iter()
            .map(|x| PyArray1::from_vec(py, x.levels.clone()))
            .collect();
        out.set_item("levels", rows)?;
    }
    Ok(out)
}

/// Choices per action component and their names (docs/rl.md).
#[pyfunction]
fn action_space() -> (Vec<u32>, Vec<&'static str>) {
    (
        xbandsim_rl::ACTION_NVEC.to_vec(),
        xbandsim_rl::ACTION_NAMES.to_vec(),
    )
}

#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _xbandsim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SceneSpec>()?;
    m.add_class::<Sim>()?;
    m.add_class::<Env>()?;
    m.add_function(wrap_pyfunction!(action_space, m)?)?;
    m.add_function(wrap_pyfunction!(generate_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(render_sample, m)?)?;
    m.add_function(wrap_pyfunction!(decode_rle, m)?)?;
    m.add_function(wrap_pyfunction!(decode_png, m)?)?;
    m.add_function(wrap_pyfunction!(read_spokes, m)?)?;
    layout::add(m)?;
    Ok(())
}
