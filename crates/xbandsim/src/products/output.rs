//! Output files: NumPy `.npy`, PNG and JSON, each written to a temporary file in the target
//! directory and renamed into place, so a reader never sees a half-written file and an
//! existing file is replaced only by a complete one. A frame's files are written as a set
//! ([`write_set`]): all of them or none replace the previous set.
//!
//! `.npy` format version 1.0 (NumPy Enhancement Proposal 1, "A simple file format for NumPy
//! arrays").

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// This process's part of temporary file names: host name, process id and the nanoseconds of
/// the first temporary name the process (or the one it was forked from) made, so processes on
/// different machines sharing one file system (pods, which are all process 1, or a job
/// array's tasks) and processes forked from one another never pick the same temporary name.
/// The process id is read at every call: a forked child's names differ from its parent's.
pub fn temp_tag() -> String {
    static HOST_AND_TIME: std::sync::OnceLock<(String, u32)> = std::sync::OnceLock::new();
    let (host, nanos) = HOST_AND_TIME.get_or_init(|| {
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .ok()
            .or_else(|| std::env::var("HOSTNAME").ok())
            .or_else(|| std::env::var("COMPUTERNAME").ok())
            .unwrap_or_default();
        let host: Vec<char> = host
            .trim()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        // The end of a long name: pods of one job share the start and differ at the end.
        let host = host[host.len().saturating_sub(32)..].iter().collect();
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        (host, nanos)
    });
    format!("{host}-{}-{nanos:08x}", std::process::id())
}

/// A temporary name's suffix no other writer uses: [`temp_tag`] and a count of the
/// process's temporary names (two threads of one process writing one file at once differ).
pub fn temp_suffix() -> String {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    format!("{}-{n}", temp_tag())
}

/// Writes `bytes` to `path` atomically (temp file + rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.tmp-{}", temp_suffix()));
    let result = (|| -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    Ok(())
}

/// Writes several files into `dir` as a set: every file is first written in full to a
/// staging folder inside `dir`, then the previous files are moved aside and the new ones
/// renamed into place; if anything fails, the previous files are put back and the staging
/// folder is removed, so `dir` holds either the whole old set or the whole new one and no
/// temporary files. (Renames within one folder are atomic on POSIX file systems; the set as
/// a whole is replaced in a few renames with a rollback.)
pub fn write_set(dir: &Path, files: &[(&str, Vec<u8>)]) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    // Only plain files are ever replaced: anything else in the way stops the set unwritten.
    for (name, _) in files {
        let target = dir.join(name);
        if let Ok(meta) = std::fs::symlink_metadata(&target) {
            if !meta.is_file() {
                return Err(Error::io(
                    &target,
                    std::io::Error::other(
                        "is in the way and is not a plain file (a directory or link); nothing was written",
                    ),
                ));
            }
        }
    }
    let staging = dir.join(format!(".xbandsim-staging-{}", temp_suffix()));
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir(&staging).map_err(|e| Error::io(&staging, e))?;
    let cleanup = |e: Error| {
        let _ = std::fs::remove_dir_all(&staging);
        e
    };
    for (name, bytes) in files {
        let path = staging.join(name);
        let written = std::fs::File::create(&path).and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
        if let Err(e) = written {
            return Err(cleanup(Error::io(dir.join(name), e)));
        }
    }
    // Move the old files aside, then the new ones in; undo on the first failure.
    let mut moved_aside: Vec<&str> = Vec::new();
    let mut placed: Vec<&str> = Vec::new();
    let mut failure: Option<Error> = None;
    for (name, _) in files {
        let target = dir.join(name);
        if target.exists() {
            if let Err(e) = std::fs::rename(&target, staging.join(format!("{name}.previous"))) {
                failure = Some(Error::io(&target, e));
                break;
            }
            moved_aside.push(name);
        }
        if let Err(e) = std::fs::rename(staging.join(name), &target) {
            failure = Some(Error::io(&target, e));
            break;
        }
        placed.push(name);
    }
    if let Some(e) = failure {
        for name in &placed {
            let _ = std::fs::remove_file(dir.join(name));
        }
        for name in &moved_aside {
            let _ = std::fs::rename(staging.join(format!("{name}.previous")), dir.join(name));
        }
        return Err(cleanup(e));
    }
    let _ = std::fs::remove_dir_all(&staging);
    Ok(())
}

/// `.npy` bytes of a little-endian float32 array of `shape` (C order).
pub fn npy_f32_bytes(shape: &[usize], data: &[f32]) -> Vec<u8> {
    assert_eq!(
        shape.iter().product::<usize>(),
        data.len(),
        "npy shape does not match data"
    );
    npy_bytes("<f4", shape, data.len() * 4, |out| {
        for v in data {
            out.extend_from_slice(&v.to_le_bytes());
        }
    })
}

/// `.npy` bytes of a uint8 array of `shape` (C order).
pub fn npy_u8_bytes(shape: &[usize], data: &[u8]) -> Vec<u8> {
    assert_eq!(
        shape.iter().product::<usize>(),
        data.len(),
        "npy shape does not match data"
    );
    npy_bytes("|u1", shape, data.len(), |out| out.extend_from_slice(data))
}

/// `.npy` bytes of a little-endian int32 array of `shape` (C order).
pub fn npy_i32_bytes(shape: &[usize], data: &[i32]) -> Vec<u8> {
    assert_eq!(
        shape.iter().product::<usize>(),
        data.len(),
        "npy shape does not match data"
    );
    npy_bytes("<i4", shape, data.len() * 4, |out| {
        for v in data {
            out.extend_from_slice(&v.to_le_bytes());
        }
    })
}

/// `.npy` bytes of a little-endian float64 array of `shape` (C order).
pub fn npy_f64_bytes(shape: &[usize], data: &[f64]) -> Vec<u8> {
    assert_eq!(
        shape.iter().product::<usize>(),
        data.len(),
        "npy shape does not match data"
    );
    npy_bytes("<f8", shape, data.len() * 8, |out| {
        for v in data {
            out.extend_from_slice(&v.to_le_bytes());
        }
    })
}

/// `.npy` bytes of a little-endian complex64 array of `shape` (C order; NumPy's `<c8`:
/// real then imaginary float32 per element).
pub fn npy_c64_bytes(shape: &[usize], data: &[num_complex::Complex32]) -> Vec<u8> {
    assert_eq!(
        shape.iter().product::<usize>(),
        data.len(),
        "npy shape does not match data"
    );
    npy_bytes("<c8", shape, data.len() * 8, |out| {
        for v in data {
            out.extend_from_slice(&v.re.to_le_bytes());
            out.extend_from_slice(&v.im.to_le_bytes());
        }
    })
}

/// An `.npy` (version 1.0) file: header for `descr` and `shape`, then `write_data`'s bytes.
fn npy_bytes(
    descr: &str,
    shape: &[usize],
    data_bytes: usize,
    write_data: impl FnOnce(&mut Vec<u8>),
) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_txt = if dims.len() == 1 {
        format!("({},)", dims[0])
    } else {
        format!("({})", dims.join(", "))
    };
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape_txt}, }}");
    // Magic (6) + version (2) + header length (2) + header + '\n' is a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + data_bytes);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    write_data(&mut out);
    out
}

/// Writes a float32 `.npy` file atomically.
pub fn write_npy_f32(path: &Path, shape: &[usize], data: &[f32]) -> Result<()> {
    write_atomic(path, &npy_f32_bytes(shape, data))
}

/// Reads a float32 `.npy` file written by [`write_npy_f32`]: (shape, data).
pub fn read_npy_f32(path: &Path) -> Result<(Vec<usize>, Vec<f32>)> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let bad = |m: &str| Error::Encode {
        path: path.to_path_buf(),
        message: m.to_string(),
    };
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("not an .npy file"));
    }
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(
        bytes
            .get(10..10 + hlen)
            .ok_or_else(|| bad("truncated header"))?,
    )
    .map_err(|_| bad("header is not text"))?;
    if !header.contains("'<f4'") {
        return Err(bad("only little-endian float32 is read"));
    }
    let open = header.find("'shape': (").ok_or_else(|| bad("no shape"))? + 10;
    let close = header[open..].find(')').ok_or_else(|| bad("no shape"))? + open;
    let shape: Vec<usize> = header[open..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().map_err(|_| bad("bad shape")))
        .collect::<Result<_>>()?;
    let data: Vec<f32> = bytes[10 + hlen..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    if data.len() != shape.iter().product::<usize>() {
        return Err(bad("data length does not match shape"));
    }
    Ok((shape, data))
}

/// PNG bytes of an 8-bit image with `channels` = 1 (gray) or 3 (RGB).
pub fn png_bytes(
    path: &Path,
    width: u32,
    height: u32,
    channels: u8,
    pixels: &[u8],
) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(if channels == 1 {
            png::ColorType::Grayscale
        } else {
            png::ColorType::Rgb
        });
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        let mut w = enc.write_header().map_err(|e| Error::Encode {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        w.write_image_data(pixels).map_err(|e| Error::Encode {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    }
    Ok(out)
}

/// Writes an 8-bit PNG atomically.
pub fn write_png(path: &Path, width: u32, height: u32, channels: u8, pixels: &[u8]) -> Result<()> {
    write_atomic(path, &png_bytes(path, width, height, channels, pixels)?)
}

/// Pretty JSON bytes (with a final newline).
pub fn json_bytes<T: serde::Serialize>(path: &Path, value: &T) -> Result<Vec<u8>> {
    let mut text = serde_json::to_string_pretty(value).map_err(|e| Error::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    text.push('\n');
    Ok(text.into_bytes())
}

/// Writes pretty JSON atomically.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    write_atomic(path, &json_bytes(path, value)?)
}
