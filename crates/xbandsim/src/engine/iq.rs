//! Raw I/Q capture (`render --iq`, docs/formats.md "iq.npy"): the received record of every
//! pulse of a revolution — echoes, clutter and noise, blanked while transmitting, before the
//! matched filter — in noise-rms units. Capturing a pulse sends it through the matched
//! filter's exact path (the record formed in time), so the compressed outputs are the same
//! signals to float32 rounding.

use crate::error::{Error, Problem, Result};
use crate::products::PulseIq;
use crate::schedule::Schedule;
use num_complex::Complex32;

/// Largest raw I/Q capture of one revolution, bytes (complex64): raw I/Q is for short runs.
pub const MAX_IQ_BYTES: usize = 1 << 30;

/// One revolution's capture buffers: the pulses of spoke 0's dwell, then spoke 1's, ..., each
/// dwell's in fire order.
pub(crate) struct IqCapture {
    record: usize,
    /// First row of each spoke's dwell (spokes + 1 entries).
    spoke_rows: Vec<usize>,
    values: Vec<Complex32>,
}

impl IqCapture {
    /// Buffers for `schedule` with records of `record` samples; refuses a capture over
    /// [`MAX_IQ_BYTES`].
    pub(crate) fn new(schedule: &Schedule, record: usize) -> Result<IqCapture> {
        let spoke_rows = IqCapture::rows(schedule, record)?;
        let rows = spoke_rows.last().copied().unwrap_or(0);
        Ok(IqCapture {
            record,
            spoke_rows,
            values: vec![Complex32::new(0.0, 0.0); rows * record],
        })
    }

    /// First row of each spoke's dwell (spokes + 1 entries), checking the capture's size
    /// against [`MAX_IQ_BYTES`] without allocating it.
    pub(crate) fn rows(schedule: &Schedule, record: usize) -> Result<Vec<usize>> {
        let spokes = schedule.spokes();
        let mut counts = vec![0usize; spokes];
        for d in schedule.dwells() {
            counts[d.spoke] = d.pulses.len();
        }
        let mut spoke_rows = Vec::with_capacity(spokes + 1);
        let mut rows = 0usize;
        spoke_rows.push(0);
        for c in counts {
            rows += c;
            spoke_rows.push(rows);
        }
        let bytes = rows.saturating_mul(record).saturating_mul(8);
        if bytes > MAX_IQ_BYTES {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "--iq",
                format!("{rows} pulses x {record} samples"),
                format!(
                    "the raw I/Q of one revolution would take {:.1} GB (limit {} GB): raw I/Q is for short runs; lower radar.max_range_m, radar.prf_hz or radar.spokes",
                    bytes as f64 / 1e9,
                    MAX_IQ_BYTES >> 30
                ),
            ));
        }
        Ok(spoke_rows)
    }

    /// Each spoke's rows, to fill in parallel with the spokes.
    pub(crate) fn slabs(&mut self) -> Vec<Option<&mut [Complex32]>> {
        let mut rest: &mut [Complex32] = &mut self.values;
        let mut out = Vec::with_capacity(self.spoke_rows.len() - 1);
        for w in self.spoke_rows.windows(2) {
            let (slab, tail) = std::mem::take(&mut rest).split_at_mut((w[1] - w[0]) * self.record);
            out.push(Some(slab));
            rest = tail;
        }
        out
    }

    /// The finished product: the values and each row's pulse time, azimuth and spoke.
    pub(crate) fn finish(self, schedule: &Schedule, sample_rate_hz: f64) -> PulseIq {
        let spokes = schedule.spokes();
        let mut dwell_of_spoke = vec![0usize; spokes];
        for (i, d) in schedule.dwells().iter().enumerate() {
            dwell_of_spoke[d.spoke] = i;
        }
        let mut times_s = Vec::new();
        let mut azimuths_rad = Vec::new();
        let mut row_spokes = Vec::new();
        for (k, &i) in dwell_of_spoke.iter().enumerate() {
            for p in &schedule.dwells()[i].pulses {
                times_s.push(p.time_s);
                azimuths_rad.push(p.azimuth_rad);
                row_spokes.push(k);
            }
        }
        PulseIq {
            pulses: times_s.len(),
            samples: self.record,
            sample_rate_hz,
            values: self.values,
            times_s,
            azimuths_rad,
            spokes: row_spokes,
        }
    }
}
