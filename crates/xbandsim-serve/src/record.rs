//! Recordings (docs/formats.md, "Live recordings"): the spoke stream and the NMEA lines as
//! the live radar sent them, each with its scenario time, so that `xbandsim replay` sends
//! them again byte for byte. The file: the magic `XBSREC01`, a u32 length and that many bytes
//! of JSON header (the radar's description and the run's settings), then records — kind
//! (u8: 1 a spoke message, 2 a group of NMEA sentences, 3 a restart of the scenario, whose
//! clock starts again from 0), scenario time (f64, s), length (u32) and payload — and, once
//! the server has stopped cleanly, an end record: kind 255 and the count of records (u64).
//! All numbers little-endian.

use crate::error::{Result, ServeError};
use bytes::Bytes;
use serde_json::Value;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::sync::Mutex;
use std::thread::JoinHandle;

/// The file's first eight bytes.
pub const MAGIC: &[u8; 8] = b"XBSREC01";

/// The end record's kind.
const END: u8 = 255;

/// Records waiting for the writer; a sender waits beyond this (the disk is behind).
const QUEUE_RECORDS: usize = 8192;

/// What a record holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordKind {
    /// An encoded `RadarMessage` of the spoke stream.
    Spokes = 1,
    /// A group of NMEA 0183 sentences, each ending CR LF.
    Nmea = 2,
    /// The scenario restarted at this time: the next records' times count from 0 again.
    Restart = 3,
}

/// One record.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// What it holds.
    pub kind: RecordKind,
    /// Scenario time it was sent at, s.
    pub time_s: f64,
    /// The bytes sent.
    pub payload: Bytes,
}

/// Writes a recording from the live radar's threads, on a thread of its own.
pub struct Recorder {
    path: PathBuf,
    sender: Mutex<Option<SyncSender<Record>>>,
    writer: Mutex<Option<JoinHandle<std::io::Result<u64>>>>,
}

fn io_error(path: &Path, what: &str, e: std::io::Error) -> ServeError {
    ServeError::Recording {
        path: path.to_path_buf(),
        message: format!("{what}: {e}"),
    }
}

impl Recorder {
    /// Starts a recording at `path` (replaced if it exists) with `header`.
    pub fn create(path: &Path, header: &Value) -> Result<Recorder> {
        Recorder::create_raw(
            path,
            &serde_json::to_vec(header).expect("a JSON value serialises"),
        )
    }

    /// Starts a recording at `path` with the header's bytes as they are (a replay's
    /// recording keeps its original's).
    pub fn create_raw(path: &Path, header: &[u8]) -> Result<Recorder> {
        let file = File::create(path).map_err(|e| io_error(path, "creating it", e))?;
        let mut out = BufWriter::new(file);
        let written = out
            .write_all(MAGIC)
            .and_then(|_| out.write_all(&(header.len() as u32).to_le_bytes()))
            .and_then(|_| out.write_all(header))
            .and_then(|_| out.flush());
        written.map_err(|e| io_error(path, "writing its header", e))?;
        let (sender, receiver) = sync_channel::<Record>(QUEUE_RECORDS);
        let writer = std::thread::Builder::new()
            .name("xbandsim-record".into())
            .spawn(move || -> std::io::Result<u64> {
                let mut count = 0u64;
                for r in receiver {
                    out.write_all(&[r.kind as u8])?;
                    out.write_all(&r.time_s.to_le_bytes())?;
                    out.write_all(&(r.payload.len() as u32).to_le_bytes())?;
                    out.write_all(&r.payload)?;
                    count += 1;
                }
                out.write_all(&[END])?;
                out.write_all(&count.to_le_bytes())?;
                out.flush()?;
                out.get_ref().sync_all()?;
                Ok(count)
            })
            .map_err(|e| io_error(path, "starting its writer", e))?;
        Ok(Recorder {
            path: path.to_path_buf(),
            sender: Mutex::new(Some(sender)),
            writer: Mutex::new(Some(writer)),
        })
    }

    /// Queues a record (dropped once the recording has finished).
    pub fn write(&self, record: Record) {
        let sender = self
            .sender
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        if let Some(s) = sender {
            let _ = s.send(record);
        }
    }

    /// Ends the recording: every queued record written, then the end record; returns the
    /// count of records.
    pub fn finish(&self) -> Result<u64> {
        self.sender.lock().unwrap_or_else(|e| e.into_inner()).take();
        let writer = self.writer.lock().unwrap_or_else(|e| e.into_inner()).take();
        match writer {
            Some(w) => match w.join() {
                Ok(r) => r.map_err(|e| io_error(&self.path, "writing it", e)),
                Err(_) => Err(ServeError::Recording {
                    path: self.path.clone(),
                    message: "its writer stopped".into(),
                }),
            },
            None => Err(ServeError::Recording {
                path: self.path.clone(),
                message: "it was finished already".into(),
            }),
        }
    }
}

/// A recording read back.
#[derive(Debug, Clone)]
pub struct Recording {
    /// The file it was read from.
    pub path: PathBuf,
    /// Its header.
    pub header: Value,
    /// The header's bytes, as written.
    pub header_raw: Vec<u8>,
    /// Its records, in the order they were sent.
    pub records: Vec<Record>,
    /// Whether it has its end record (the server stopped cleanly).
    pub complete: bool,
}

/// Reads the recording at `path`.
pub fn read(path: &Path) -> Result<Recording> {
    let bytes = Bytes::from(std::fs::read(path).map_err(|e| io_error(path, "reading it", e))?);
    let bad = |message: String| ServeError::Recording {
        path: path.to_path_buf(),
        message,
    };
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return Err(bad(format!(
            "not an xbandsim recording: it does not start with {:?}",
            std::str::from_utf8(MAGIC).expect("ASCII")
        )));
    }
    let header_len = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes")) as usize;
    let body = bytes
        .get(12..12 + header_len)
        .ok_or_else(|| bad("its header is cut short".into()))?;
    let header: Value =
        serde_json::from_slice(body).map_err(|e| bad(format!("its header: {e}")))?;
    let mut at = 12 + header_len;
    let mut records = Vec::new();
    let mut complete = false;
    while at < bytes.len() {
        let kind = bytes[at];
        if kind == END {
            let count = bytes
                .get(at + 1..at + 9)
                .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
                .ok_or_else(|| bad("its end record is cut short".into()))?;
            if count != records.len() as u64 {
                return Err(bad(format!(
                    "its end record counts {count} records, but it holds {}",
                    records.len()
                )));
            }
            complete = true;
            break;
        }
        let Some(head) = bytes.get(at + 1..at + 13) else {
            break;
        };
        let time_s = f64::from_le_bytes(head[..8].try_into().expect("8 bytes"));
        let len = u32::from_le_bytes(head[8..].try_into().expect("4 bytes")) as usize;
        if at + 13 + len > bytes.len() {
            break;
        }
        let kind = match kind {
            1 => RecordKind::Spokes,
            2 => RecordKind::Nmea,
            3 => RecordKind::Restart,
            k => {
                return Err(bad(format!(
                    "record {} at byte {at} has kind {k} (1 spokes, 2 NMEA, 3 restart, 255 end)",
                    records.len()
                )))
            }
        };
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(bad(format!(
                "record {} at byte {at} has time {time_s} s: must be a finite time of 0 or more",
                records.len()
            )));
        }
        records.push(Record {
            kind,
            time_s,
            payload: bytes.slice(at + 13..at + 13 + len),
        });
        at += 13 + len;
    }
    Ok(Recording {
        path: path.to_path_buf(),
        header,
        header_raw: body.to_vec(),
        records,
        complete,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recording_reads_back_as_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.xbsrec");
        let r = Recorder::create(&path, &serde_json::json!({"spokes": 2048})).unwrap();
        let records = vec![
            Record {
                kind: RecordKind::Spokes,
                time_s: 0.5,
                payload: Bytes::from_static(&[8, 1, 18, 0]),
            },
            Record {
                kind: RecordKind::Nmea,
                time_s: 1.0,
                payload: Bytes::from_static(b"$GPVTG,,T,,M,0.0,N,0.0,K,A*0D\r\n"),
            },
            Record {
                kind: RecordKind::Restart,
                time_s: 1.5,
                payload: Bytes::new(),
            },
            Record {
                kind: RecordKind::Spokes,
                time_s: 0.0,
                payload: Bytes::from_static(&[8, 1]),
            },
        ];
        for x in &records {
            r.write(x.clone());
        }
        assert_eq!(r.finish().unwrap(), 4);
        let back = read(&path).unwrap();
        assert!(back.complete);
        assert_eq!(back.records, records);
        assert_eq!(back.header["spokes"], 2048);
        assert_eq!(back.header_raw, br#"{"spokes":2048}"#);
        // Cut short (no end record): the whole records read, marked incomplete.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 10]).unwrap();
        let cut = read(&path).unwrap();
        assert!(!cut.complete);
        assert_eq!(cut.records, records[..3]);
        std::fs::write(&path, b"PK\x03\x04 not one").unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("not an xbandsim recording"), "{e}");
    }
}
