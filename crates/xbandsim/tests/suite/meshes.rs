//! Mesh loading (OBJ, ASCII and binary STL, glTF with an embedded buffer) and the RCS of
//! meshed shapes against the analytic primitives (±0.5 dB).

use base64::Engine as _;
use std::path::Path;
use xbandsim::constants::linear_to_db;
use xbandsim::geometry::TriangleMesh;
use xbandsim::model::{Polarisation, Scene};
use xbandsim::scattering::rcs::{RcsSettings, RcsTarget};

/// A plate `w × h` facing +y, and a trihedral with edge `a` opening toward +y, as triangles,
/// built from the same frames as the primitives (docs/formats.md).
fn plate_triangles(w: f64, h: f64) -> Vec<[[f64; 3]; 3]> {
    let (x, z) = (w / 2.0, h / 2.0);
    vec![
        [[-x, 0.0, -z], [x, 0.0, -z], [x, 0.0, z]],
        [[-x, 0.0, -z], [x, 0.0, z], [-x, 0.0, z]],
    ]
}

fn trihedral_triangles(a: f64) -> Vec<[[f64; 3]; 3]> {
    let s3 = 3f64.sqrt();
    let e3 = [0.0, 1.0 / s3, (2.0f64 / 3.0).sqrt()];
    let e1 = [-1.0 / 2f64.sqrt(), 1.0 / s3, -1.0 / 6f64.sqrt()];
    let e2 = [1.0 / 2f64.sqrt(), 1.0 / s3, -1.0 / 6f64.sqrt()];
    let m = |e: [f64; 3]| [e[0] * a, e[1] * a, e[2] * a];
    let o = [0.0; 3];
    vec![[o, m(e1), m(e2)], [o, m(e2), m(e3)], [o, m(e3), m(e1)]]
}

fn write_obj(path: &Path, tris: &[[[f64; 3]; 3]], scale: f64) {
    let mut s = String::from("# test mesh\n");
    for t in tris {
        for v in t {
            s += &format!("v {} {} {}\n", v[0] / scale, v[1] / scale, v[2] / scale);
        }
    }
    for i in 0..tris.len() {
        s += &format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    std::fs::write(path, s).unwrap();
}

fn write_stl_ascii(path: &Path, tris: &[[[f64; 3]; 3]]) {
    let mut s = String::from("solid test\n");
    for t in tris {
        s += "facet normal 0 0 0\nouter loop\n";
        for v in t {
            s += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
        }
        s += "endloop\nendfacet\n";
    }
    s += "endsolid test\n";
    std::fs::write(path, s).unwrap();
}

fn write_stl_binary(path: &Path, tris: &[[[f64; 3]; 3]]) {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for v in t {
            for c in v {
                b.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    std::fs::write(path, b).unwrap();
}

/// glTF is +Y up, front +Z: our (x, y, z) is stored as (−x, z, y).
fn write_gltf(path: &Path, tris: &[[[f64; 3]; 3]]) {
    let mut buf = Vec::new();
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for t in tris {
        for v in t {
            let g = [-v[0] as f32, v[2] as f32, v[1] as f32];
            for k in 0..3 {
                lo[k] = lo[k].min(g[k]);
                hi[k] = hi[k].max(g[k]);
                buf.extend_from_slice(&g[k].to_le_bytes());
            }
        }
    }
    let n = tris.len() * 3;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buf)
    );
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}}],
        "bufferViews":[{{"buffer":0,"byteLength":{}}}],"buffers":[{{"byteLength":{},"uri":"{uri}"}}]}}"#,
        lo[0],
        lo[1],
        lo[2],
        hi[0],
        hi[1],
        hi[2],
        buf.len(),
        buf.len()
    );
    std::fs::write(path, json).unwrap();
}

fn rcs_db(scene_text: &str, base: &Path, az_rad: f64) -> f64 {
    let spec: xbandsim::scene::SceneSpec = toml::from_str(scene_text).unwrap();
    let scene = Scene::from_spec_in(&spec, base).unwrap();
    let t = RcsTarget::new(&scene.objects()[0]);
    let s = RcsSettings {
        freq_hz: 9.41e9,
        polarisation: Polarisation::Hh,
        ray_spacing_wavelengths: 0.25,
        max_rays: 1 << 20,
        max_bounces: 3,
        edge_diffraction: false,
    };
    linear_to_db(t.rcs_m2(az_rad, 0.0, &s))
}

fn mesh_object(file: &str, extra: &str) -> String {
    format!("[[object]]\nname = \"m\"\nshape = \"mesh\"\nmesh_file = \"{file}\"\n{extra}\nposition_m = [0.0, 100.0, 0.0]\n")
}

#[test]
fn every_format_loads_the_same_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let tris = trihedral_triangles(0.5);
    write_obj(&dir.path().join("t.obj"), &tris, 1.0);
    write_stl_ascii(&dir.path().join("t_ascii.stl"), &tris);
    write_stl_binary(&dir.path().join("t_bin.stl"), &tris);
    write_gltf(&dir.path().join("t.gltf"), &tris);
    let area = |name: &str| {
        TriangleMesh::load(&dir.path().join(name), 1.0)
            .unwrap()
            .area_m2()
    };
    let expected = 3.0 * 0.5 * 0.5 / 2.0; // three right triangles with legs 0.5
    for name in ["t.obj", "t_ascii.stl", "t_bin.stl", "t.gltf"] {
        let a = area(name);
        assert!(
            (a - expected).abs() < 1e-6,
            "{name}: area {a}, expected {expected}"
        );
        let m = TriangleMesh::load(&dir.path().join(name), 1.0).unwrap();
        // The corner vertex is at the origin and the opening points to +y in every format.
        let mean_y: f64 = m.vertices_m.iter().map(|v| v.y).sum::<f64>() / m.vertices_m.len() as f64;
        assert!(mean_y > 0.1, "{name}: mean y {mean_y}");
    }
}

#[test]
fn mesh_plate_and_trihedral_match_the_primitives() {
    let dir = tempfile::tempdir().unwrap();
    write_obj(
        &dir.path().join("plate_cm.obj"),
        &plate_triangles(0.8, 0.5),
        0.01,
    );
    write_stl_binary(&dir.path().join("tri.stl"), &trihedral_triangles(0.5));
    write_gltf(&dir.path().join("tri.gltf"), &trihedral_triangles(0.5));
    for az in [0.0f64, 0.2] {
        let prim = rcs_db("[[object]]\nname = \"p\"\nshape = \"plate\"\nwidth_m = 0.8\nheight_m = 0.5\nposition_m = [0.0, 100.0, 0.0]\n", dir.path(), az.to_radians());
        let mesh = rcs_db(
            &mesh_object("plate_cm.obj", "mesh_units = \"cm\""),
            dir.path(),
            az.to_radians(),
        );
        assert!(
            (prim - mesh).abs() < 0.5,
            "plate at {az} deg: primitive {prim:.2} dBsm, mesh {mesh:.2} dBsm"
        );
    }
    for az in [0.0f64, 20.0] {
        let prim = rcs_db("[[object]]\nname = \"t\"\nshape = \"trihedral\"\nedge_m = 0.5\nposition_m = [0.0, 100.0, 0.0]\n", dir.path(), az.to_radians());
        for file in ["tri.stl", "tri.gltf"] {
            let mesh = rcs_db(&mesh_object(file, ""), dir.path(), az.to_radians());
            assert!(
                (prim - mesh).abs() < 0.5,
                "trihedral ({file}) at {az} deg: primitive {prim:.2} dBsm, mesh {mesh:.2} dBsm"
            );
        }
    }
}

#[test]
fn bad_mesh_input_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let err = |text: &str| {
        // The message with its causes, as the CLI prints it.
        let e = xbandsim::scene::LoadedSpec::from_toml(text, "scene.toml", dir.path())
            .and_then(|l| l.build())
            .unwrap_err();
        let mut text = e.to_string();
        let mut cause = std::error::Error::source(&e);
        while let Some(c) = cause {
            text.push_str(&format!(": {c}"));
            cause = c.source();
        }
        text
    };
    let e = err(&mesh_object("missing.obj", ""));
    assert!(
        e.contains("object \"m\".mesh_file")
            && e.contains("missing.obj")
            && e.contains("no such file"),
        "{e}"
    );
    std::fs::write(dir.path().join("junk.stl"), b"this is not an stl").unwrap();
    let e = err(&mesh_object("junk.stl", ""));
    assert!(e.contains("junk.stl"), "{e}");
    std::fs::write(dir.path().join("x.ply"), b"ply").unwrap();
    let e = err(&mesh_object("x.ply", ""));
    assert!(e.contains("unknown mesh format"), "{e}");
    write_obj(&dir.path().join("ok.obj"), &plate_triangles(1.0, 1.0), 1.0);
    let e = err(&mesh_object("ok.obj", "mesh_units = \"furlong\""));
    assert!(e.contains("mesh_units") && e.contains("furlong"), "{e}");
    let e = err(&mesh_object("ok.obj", "mesh_scale = -1.0"));
    assert!(e.contains("mesh_scale"), "{e}");
    let e = err("[[object]]\nname = \"m\"\nshape = \"mesh\"\nposition_m = [0.0, 100.0, 0.0]\n");
    assert!(e.contains("mesh_file") && e.contains("missing"), "{e}");
    // A binary STL cut short: the header's triangle count says how long it must be.
    let mut bytes = Vec::new();
    write_stl_binary(&dir.path().join("full.stl"), &trihedral_triangles(0.7));
    bytes.extend(std::fs::read(dir.path().join("full.stl")).unwrap());
    std::fs::write(dir.path().join("cut.stl"), &bytes[..bytes.len() - 30]).unwrap();
    let e = err(&mesh_object("cut.stl", ""));
    assert!(e.contains("truncated") && e.contains("3 triangles"), "{e}");
    std::fs::write(dir.path().join("tiny.stl"), [7u8; 40]).unwrap();
    let e = err(&mesh_object("tiny.stl", ""));
    assert!(e.contains("not an STL file"), "{e}");
    // Garbage named .glb, and a glTF whose buffer is shorter than it declares.
    std::fs::write(dir.path().join("junk.glb"), [0x5au8; 64]).unwrap();
    let e = err(&mesh_object("junk.glb", ""));
    assert!(e.contains("not a binary glTF"), "{e}");
    write_gltf(&dir.path().join("ok.gltf"), &plate_triangles(2.0, 1.0));
    let text = std::fs::read_to_string(dir.path().join("ok.gltf")).unwrap();
    let short = text.replacen("\"byteLength\":72,\"uri\"", "\"byteLength\":720,\"uri\"", 1);
    assert_ne!(text, short, "test glTF layout changed");
    std::fs::write(dir.path().join("short.gltf"), short).unwrap();
    let e = err(&mesh_object("short.gltf", ""));
    assert!(
        e.contains("holds 72 bytes but the file declares 720"),
        "{e}"
    );
    // A directory where a mesh file should be, and a mesh with no area.
    std::fs::create_dir(dir.path().join("folder.obj")).unwrap();
    let e = err(&mesh_object("folder.obj", ""));
    assert!(e.contains("is a directory"), "{e}");
    std::fs::write(
        dir.path().join("flat.obj"),
        "v 0 0 0\nv 1 1 1\nv 3 3 3\nf 1 2 3\n",
    )
    .unwrap();
    let e = err(&mesh_object("flat.obj", ""));
    assert!(e.contains("zero surface area"), "{e}");
}

/// The shipped vessel mesh is what `vessel()` generates (so it can be regenerated).
#[test]
fn shipped_vessel_mesh_is_reproducible() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/meshes/vessel.obj");
    let shipped = TriangleMesh::load(&path, 1.0).unwrap();
    let made = xbandsim::geometry::mesh::vessel(30.0, 128);
    assert_eq!(shipped.triangles.len(), made.triangles.len());
    assert!(shipped.triangles.len() >= 10_000);
    // Compare corner by corner (a loader may renumber vertices, not reorder triangles).
    let corner = |m: &TriangleMesh, t: usize, k: usize| m.vertices_m[m.triangles[t][k] as usize];
    let max_dev = (0..made.triangles.len())
        .flat_map(|t| (0..3).map(move |k| (t, k)))
        .map(|(t, k)| (corner(&shipped, t, k) - corner(&made, t, k)).length())
        .fold(0.0, f64::max);
    assert!(max_dev < 1e-5, "vertex deviation {max_dev}");
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/vessel.toml")).unwrap();
}

/// Objects that name one mesh file at one scale share one loaded mesh (which the BVH then
/// builds once for all of them); another scale is another mesh.
#[test]
fn objects_of_one_mesh_file_share_it() {
    use xbandsim::geometry::ShapeGeometry;
    let dir = tempfile::tempdir().unwrap();
    write_obj(&dir.path().join("t.obj"), &trihedral_triangles(0.5), 1.0);
    let object = |name: &str, x: f64, extra: &str| {
        format!("[[object]]\nname = \"{name}\"\nshape = \"mesh\"\nmesh_file = \"t.obj\"\n{extra}\nposition_m = [{x}, 100.0, 0.0]\n")
    };
    let text = [
        object("a", 0.0, ""),
        object("b", 20.0, ""),
        object("c", 40.0, "mesh_scale = 2.0"),
    ]
    .concat();
    let spec: xbandsim::scene::SceneSpec = toml::from_str(&text).unwrap();
    let scene = Scene::from_spec_in(&spec, dir.path()).unwrap();
    let mesh = |k: usize| match scene.objects()[k].shape() {
        ShapeGeometry::Mesh { mesh } => std::sync::Arc::clone(mesh),
        other => panic!("object {k} is {other:?}"),
    };
    assert!(std::sync::Arc::ptr_eq(&mesh(0), &mesh(1)));
    assert!(!std::sync::Arc::ptr_eq(&mesh(0), &mesh(2)));
    assert_eq!(mesh(2).area_m2(), 4.0 * mesh(0).area_m2());
}
