//! The engagement answer as JSON (docs/spec/engagement.md §3), byte for byte what
//! `serde_json::to_vec` writes, but cheaper:
//! the samples, nearly all of the 40 MB of a 1 m path at 0.01 mm, are written
//! by hand straight into one pre-sized buffer; the rest of the answer, a few kilobytes, still
//! goes through serde.
//!
//! Derived serialisation pays per sample for escaping every key and growing the buffer by
//! doubling; here the keys are constants and the numbers use the formatters `serde_json` uses
//! (`zmij` for floats, `itoa` for integers), so the text is identical.

use super::answer::{ArcDetail, EngagementSample, EngagementSolution, PathEngagement, SampleFlag};
use super::arcs::MillingMode;
use super::capability::EngagementAnswer;
use crate::wire::float;

/// What `serde_json` writes for a candidate whose samples were taken out.
const EMPTY_SAMPLES: &[u8] = b"\"samples\":[]";
/// A generous bound on one sample's text, bytes, before the per-count fields (the buffer only
/// needs to be about right: it still grows if a sample is longer).
const SAMPLE_BYTES: usize = 320;
/// Bytes per arc, flute count or flag of a sample.
const ITEM_BYTES: usize = 48;

/// The answer as JSON, exactly as `serde_json::to_vec(&answer)` would write it.
///
/// # Errors
/// When serde cannot write the answer's other fields.
pub fn to_json(mut answer: EngagementAnswer) -> serde_json::Result<Vec<u8>> {
    let mut taken: Vec<Vec<EngagementSample>> =
        candidates_mut(&mut answer.result).map(|c| std::mem::take(&mut c.samples)).collect();
    let rest = serde_json::to_vec(&answer)?;
    // Each candidate's `samples` key is written once, in candidate order, and no string can hold
    // the unescaped quotes of the marker; anything else (a key `samples` in a map the request
    // gave) is left to serde.
    let marks: Vec<usize> = crate::wire::marks(&rest, EMPTY_SAMPLES);
    if marks.len() != taken.len() {
        for (candidate, samples) in candidates_mut(&mut answer.result).zip(taken.drain(..)) {
            candidate.samples = samples;
        }
        return serde_json::to_vec(&answer);
    }
    let size = rest.len() + taken.iter().flatten().map(estimate).sum::<usize>();
    let mut out = Vec::with_capacity(size);
    let mut copied = 0;
    for (mark, samples) in marks.iter().zip(&taken) {
        // Up to and with `"samples":`, then the array in place of `[]`.
        let array = mark + EMPTY_SAMPLES.len() - 2;
        out.extend_from_slice(&rest[copied..array]);
        write_samples(&mut out, samples);
        copied = mark + EMPTY_SAMPLES.len();
    }
    out.extend_from_slice(&rest[copied..]);
    Ok(out)
}

fn candidates_mut(answer: &mut EngagementSolution) -> impl Iterator<Item = &mut PathEngagement> {
    let slice: &mut [PathEngagement] = match answer {
        EngagementSolution::Single(result) => std::slice::from_mut(result.as_mut()),
        EngagementSolution::Comparison(comparison) => &mut comparison.candidates,
    };
    slice.iter_mut()
}

pub(super) fn estimate(sample: &EngagementSample) -> usize {
    let items = sample.arcs.len() * 3
        + sample.thickness.len()
        + sample.teeth.len()
        + sample.torque_nm.len()
        + sample.peak_torque_nm.len()
        + sample.power_kw.len()
        + sample.peak_force_n.len()
        + sample.flags.len();
    SAMPLE_BYTES + ITEM_BYTES * items
}

/// `samples` as a JSON array.
pub(crate) fn write_samples(out: &mut Vec<u8>, samples: &[EngagementSample]) {
    out.push(b'[');
    for (index, sample) in samples.iter().enumerate() {
        if index > 0 {
            out.push(b',');
        }
        write_sample(out, sample);
    }
    out.push(b']');
}

fn key(out: &mut Vec<u8>, name: &[u8]) {
    out.push(b',');
    out.extend_from_slice(name);
}

fn list<T: Copy>(out: &mut Vec<u8>, items: &[T], mut one: impl FnMut(&mut Vec<u8>, T)) {
    out.push(b'[');
    for (index, &item) in items.iter().enumerate() {
        if index > 0 {
            out.push(b',');
        }
        one(out, item);
    }
    out.push(b']');
}

/// A list that serde skips when empty.
fn floats_unless_empty(out: &mut Vec<u8>, name: &[u8], values: &[f64]) {
    if !values.is_empty() {
        key(out, name);
        list(out, values, float);
    }
}

fn write_sample(out: &mut Vec<u8>, sample: &EngagementSample) {
    out.extend_from_slice(b"{\"s\":");
    float(out, sample.s);
    key(out, b"\"t\":");
    float(out, sample.t);
    key(out, b"\"position\":");
    list(out, &sample.position, float);
    key(out, b"\"heading_deg\":");
    float(out, sample.heading_deg);
    key(out, b"\"segment\":");
    out.extend_from_slice(itoa::Buffer::new().format(sample.segment).as_bytes());
    key(out, b"\"arcs\":");
    list(out, &sample.arcs, |out, pair| list(out, &pair, float));
    key(out, b"\"engaged_deg\":");
    float(out, sample.engaged_deg);
    key(out, b"\"radial_depth\":");
    float(out, sample.radial_depth);
    if !sample.arc_details.is_empty() {
        key(out, b"\"arc_details\":");
        out.push(b'[');
        for (index, detail) in sample.arc_details.iter().enumerate() {
            if index > 0 {
                out.push(b',');
            }
            write_detail(out, detail);
        }
        out.push(b']');
    }
    key(out, b"\"mean_chip_thickness\":");
    float(out, sample.mean_chip_thickness);
    key(out, b"\"thickness\":");
    list(out, &sample.thickness, float);
    key(out, b"\"teeth\":");
    list(out, &sample.teeth, |out, n| out.extend_from_slice(itoa::Buffer::new().format(n).as_bytes()));
    floats_unless_empty(out, b"\"torque_nm\":", &sample.torque_nm);
    floats_unless_empty(out, b"\"peak_torque_nm\":", &sample.peak_torque_nm);
    floats_unless_empty(out, b"\"power_kw\":", &sample.power_kw);
    floats_unless_empty(out, b"\"peak_force_n\":", &sample.peak_force_n);
    if let Some(mrr) = sample.mrr {
        key(out, b"\"mrr\":");
        float(out, mrr);
    }
    if !sample.flags.is_empty() {
        key(out, b"\"flags\":");
        list(out, &sample.flags, |out, flag| {
            out.push(b'"');
            out.extend_from_slice(flag_name(flag));
            out.push(b'"');
        });
    }
    out.push(b'}');
}

fn write_detail(out: &mut Vec<u8>, detail: &ArcDetail) {
    out.extend_from_slice(b"{\"entry_deg\":");
    float(out, detail.entry_deg);
    key(out, b"\"exit_deg\":");
    float(out, detail.exit_deg);
    key(out, b"\"engage_deg\":");
    float(out, detail.engage_deg);
    key(out, b"\"disengage_deg\":");
    float(out, detail.disengage_deg);
    key(out, b"\"entry_thickness_ratio\":");
    float(out, detail.entry_thickness_ratio);
    key(out, b"\"exit_thickness_ratio\":");
    float(out, detail.exit_thickness_ratio);
    key(out, b"\"mode\":\"");
    out.extend_from_slice(match detail.mode {
        MillingMode::Slot => b"slot",
        MillingMode::Climb => b"climb",
        MillingMode::Conventional => b"conventional",
        MillingMode::Interior => b"interior",
    });
    out.extend_from_slice(b"\"}");
}

fn flag_name(flag: SampleFlag) -> &'static [u8] {
    match flag {
        SampleFlag::BurrRisk => b"burr_risk",
        SampleFlag::ChippingRisk => b"chipping_risk",
        SampleFlag::Plunge => b"plunge",
        SampleFlag::BackContact => b"back_contact",
        SampleFlag::VibrationRisk => b"vibration_risk",
        SampleFlag::RubbingRisk => b"rubbing_risk",
        SampleFlag::Rapid => b"rapid",
        SampleFlag::Collision => b"collision",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engagement::answer::{SampleArcDetails, SampleArcs, SampleFlags};
    use smallvec::smallvec;

    fn sample(index: usize) -> EngagementSample {
        let odd = index % 2 == 1;
        let detail = ArcDetail {
            entry_deg: -12.345_678_901_234_5,
            exit_deg: 90.0,
            engage_deg: 1e-300,
            disengage_deg: f64::NAN,
            entry_thickness_ratio: 0.1 + 0.2,
            exit_thickness_ratio: 0.0,
            mode: [MillingMode::Slot, MillingMode::Climb, MillingMode::Conventional, MillingMode::Interior][index % 4],
        };
        EngagementSample {
            s: index as f64 * 0.01,
            t: 1.0 / 3.0,
            position: [-0.0, 1e21],
            heading_deg: -180.0,
            segment: index * 1_000_003,
            arcs: if odd { smallvec![[-90.0, 12.5], [100.0, f64::INFINITY]] } else { SampleArcs::new() },
            engaged_deg: 123_456_789.125,
            radial_depth: 5e-7,
            arc_details: if odd { vec![detail.clone(), detail].into() } else { SampleArcDetails::default() },
            mean_chip_thickness: 0.049_999_999_999_999_996,
            thickness: smallvec![0.05, 1e16, 2.5e-5],
            teeth: smallvec![0, 3, u32::MAX],
            torque_nm: if odd { vec![1.5, 2.25] } else { Vec::new() },
            peak_torque_nm: if odd { vec![f64::NEG_INFINITY] } else { Vec::new() },
            power_kw: if odd { vec![7.0] } else { Vec::new() },
            peak_force_n: if odd { vec![123.456] } else { Vec::new() },
            mrr: odd.then_some(4321.0),
            flags: if odd {
                smallvec![
                    SampleFlag::BurrRisk,
                    SampleFlag::ChippingRisk,
                    SampleFlag::Plunge,
                    SampleFlag::BackContact,
                    SampleFlag::VibrationRisk,
                    SampleFlag::RubbingRisk,
                    SampleFlag::Rapid,
                    SampleFlag::Collision,
                ]
            } else {
                SampleFlags::new()
            },
        }
    }

    #[test]
    fn samples_are_written_as_serde_writes_them() {
        let samples: Vec<EngagementSample> = (0..8).map(sample).collect();
        let mut ours = Vec::new();
        write_samples(&mut ours, &samples);
        assert_eq!(String::from_utf8(ours).unwrap(), serde_json::to_string(&samples).unwrap());
        let mut empty = Vec::new();
        write_samples(&mut empty, &[]);
        assert_eq!(empty, b"[]");
    }
}
