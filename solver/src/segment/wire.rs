//! The segment answer as JSON (docs/spec/api.md, Segment), byte for byte what `serde_json::to_vec`
//! writes, but cheaper: the windows, command points and arc lengths, nearly all of the answer of
//! a long curve (some 7 MB for 100 000 points in 3-D), are written by hand straight into one
//! buffer sized for them; the rest of the answer, a few kilobytes, still goes through serde.
//!
//! The numbers use the formatters `serde_json` uses (`zmij` for floats, `itoa` for integers, as
//! the engagement answer's writer), so the text is identical.

use super::answer::{CommandPoint, SegmentWindow, WindowStatus};
use super::capability::SegmentAnswer;

/// What `serde_json` writes for the three fields once they are taken out of the answer: they are
/// consecutive fields of the solution, in this order, and no string holds the unescaped quotes
/// of the marker.
const EMPTY: &[u8] = b"\"windows\":[],\"points\":[],\"s\":[]";
/// Most bytes one coordinate or arc length takes with its separator (24 characters at the
/// longest: `-2.2250738585072014e-308`, and a comma).
const NUMBER_BYTES: usize = 25;
/// Most bytes one window takes (every number at its longest, the longest status).
const WINDOW_TEXT_BYTES: usize = 256;

/// The answer as JSON, exactly as `serde_json::to_vec(&answer)` would write it.
///
/// # Errors
/// When serde cannot write the answer's other fields.
pub(crate) fn to_json(mut answer: SegmentAnswer) -> serde_json::Result<Vec<u8>> {
    let result = &mut answer.result;
    let windows = std::mem::take(&mut result.windows);
    let points = std::mem::take(&mut result.points);
    let s = std::mem::take(&mut result.s);
    let rest = serde_json::to_vec(&answer)?;
    let [mark] = crate::wire::marks(&rest, EMPTY)[..] else {
        // A key of that name elsewhere (in a machine's or tool's text): serde writes it all.
        let result = &mut answer.result;
        (result.windows, result.points, result.s) = (windows, points, s);
        return serde_json::to_vec(&answer);
    };
    let coordinates: usize = points.iter().map(CommandPoint::dimension).sum();
    let size =
        rest.len() + WINDOW_TEXT_BYTES * windows.len() + NUMBER_BYTES * (coordinates + s.len()) + 2 * points.len();
    let mut out = Text::with_capacity(size);
    out.extend(&rest[..mark]);
    out.extend(b"\"windows\":");
    write_windows(&mut out, &windows);
    out.extend(b",\"points\":");
    write_points(&mut out, &points);
    out.extend(b",\"s\":");
    write_floats(&mut out, &s);
    out.extend(&rest[mark + EMPTY.len()..]);
    Ok(out.finish())
}

/// Text written into a buffer whose next bytes are already there (zeros, grown a piece at a
/// time within the capacity reserved): a number is copied in by a few fixed-size moves instead
/// of a call to `memcpy` for its few bytes, which took a third of the writing of the points.
struct Text {
    bytes: Vec<u8>,
    /// Bytes written; `bytes[len..]` are zeros waiting to be overwritten.
    len: usize,
}

/// Zeros added to a [`Text`] at a time.
const PIECE: usize = 1 << 16;
/// Room a [`Text`] keeps ahead of what it has written for one number and its separator.
const ROOM: usize = 32;
/// Longest number `zmij` writes.
const LONGEST_NUMBER: usize = 24;

impl Text {
    fn with_capacity(capacity: usize) -> Self {
        Self { bytes: Vec::with_capacity(capacity), len: 0 }
    }

    /// Makes room for `more` bytes past those written.
    fn room(&mut self, more: usize) {
        if self.bytes.len() - self.len < more {
            self.bytes.resize(self.len + more.max(PIECE), 0);
        }
    }

    fn push(&mut self, byte: u8) {
        self.room(ROOM);
        self.bytes[self.len] = byte;
        self.len += 1;
    }

    fn extend(&mut self, text: &[u8]) {
        self.room(text.len());
        self.bytes[self.len..self.len + text.len()].copy_from_slice(text);
        self.len += text.len();
    }

    /// `value` as `serde_json` writes a float (as [`crate::wire::float`]): the shortest text that
    /// reads back the same, `null` when not finite.
    fn float(&mut self, value: f64) {
        if !value.is_finite() {
            self.extend(b"null");
            return;
        }
        self.room(ROOM);
        let mut buffer = zmij::Buffer::new();
        let text = buffer.format_finite(value).as_bytes();
        let end = self.len + text.len();
        copy_short(&mut self.bytes[self.len..self.len + LONGEST_NUMBER], text);
        self.len = end;
    }

    fn finish(mut self) -> Vec<u8> {
        self.bytes.truncate(self.len);
        self.bytes
    }
}

/// Copies `source` (1 to [`LONGEST_NUMBER`] bytes) to the start of `target` by two overlapping
/// moves of a fixed size.
fn copy_short(target: &mut [u8], source: &[u8]) {
    let n = source.len();
    if n >= 16 {
        target[..16].copy_from_slice(&source[..16]);
        target[n - 8..n].copy_from_slice(&source[n - 8..]);
    } else if n >= 8 {
        target[..8].copy_from_slice(&source[..8]);
        target[n - 8..n].copy_from_slice(&source[n - 8..]);
    } else if n >= 4 {
        target[..4].copy_from_slice(&source[..4]);
        target[n - 4..n].copy_from_slice(&source[n - 4..]);
    } else {
        target[..n].copy_from_slice(source);
    }
}

/// `points` as a JSON array of arrays.
fn write_points(out: &mut Text, points: &[CommandPoint]) {
    out.push(b'[');
    for (index, point) in points.iter().enumerate() {
        if index > 0 {
            out.push(b',');
        }
        write_floats(out, point.as_slice());
    }
    out.push(b']');
}

/// `values` as a JSON array.
fn write_floats(out: &mut Text, values: &[f64]) {
    out.push(b'[');
    for (index, &value) in values.iter().enumerate() {
        if index > 0 {
            out.push(b',');
        }
        out.float(value);
    }
    out.push(b']');
}

/// `windows` as a JSON array.
fn write_windows(out: &mut Text, windows: &[SegmentWindow]) {
    out.push(b'[');
    for (index, window) in windows.iter().enumerate() {
        if index > 0 {
            out.push(b',');
        }
        out.extend(b"{\"s_start\":");
        out.float(window.s_start);
        out.extend(b",\"s_end\":");
        out.float(window.s_end);
        out.extend(b",\"radius\":");
        match window.radius {
            Some(radius) => out.float(radius),
            None => out.extend(b"null"),
        }
        out.extend(b",\"chord_error\":");
        out.float(window.chord_error);
        out.extend(b",\"rule_chord_error\":");
        out.float(window.rule_chord_error);
        out.extend(b",\"status\":\"");
        out.extend(status_name(window.status));
        out.extend(b"\",\"blocks\":");
        out.extend(itoa::Buffer::new().format(window.blocks).as_bytes());
        out.push(b'}');
    }
    out.push(b']');
}

fn status_name(status: WindowStatus) -> &'static [u8] {
    match status {
        WindowStatus::Ok => b"ok",
        WindowStatus::Straight => b"straight",
        WindowStatus::ClampedToMinChordError => b"clamped_to_min_chord_error",
        WindowStatus::LimitedByTolerance => b"limited_by_tolerance",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capability::{Capability, Resolved, Run};
    use crate::geometry::Vec3;
    use crate::segment::{SegmentCapability, SegmentRequest};
    use serde_json::json;

    /// A small deterministic generator (SplitMix64): the same random answers on every run.
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }

        /// Any float: every bit pattern (NaN, infinities, subnormals, -0), coordinates of the
        /// usual sizes, and round and short values.
        fn float(&mut self) -> f64 {
            match self.next() % 6 {
                0 => f64::from_bits(self.next()),
                1 => [0.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE, 5e-324, f64::MAX]
                    [(self.next() % 8) as usize],
                2 => (self.next() % 2_000_001) as f64 / 10.0 - 100_000.0,
                _ => (self.next() as f64 / u64::MAX as f64 - 0.5) * 10f64.powi((self.next() % 40) as i32 - 20),
            }
        }
    }

    fn answer(request: serde_json::Value, machine: Option<serde_json::Value>) -> SegmentAnswer {
        let request: SegmentRequest = serde_json::from_value(request).unwrap();
        let machine = machine.map(|machine| serde_json::from_value(machine).unwrap());
        let context = Resolved { tool: None, machine, material: None, other_tools: Vec::new() };
        let mut answer = SegmentCapability::solve(&request, context, &Run::default()).unwrap();
        answer.tool = request.tool.as_ref().and_then(|tool| match tool {
            crate::tool::ToolRef::Inline(tool) => Some(tool.clone()),
            crate::tool::ToolRef::Number(_) => None,
        });
        answer
    }

    fn assert_as_serde(answer: &SegmentAnswer) {
        let serde = serde_json::to_vec(answer).unwrap();
        let ours = to_json(answer.clone()).unwrap();
        assert!(
            ours == serde,
            "differs:\nours  {}\nserde {}",
            String::from_utf8_lossy(&ours),
            String::from_utf8_lossy(&serde)
        );
    }

    #[test]
    fn reference_answers_are_written_as_serde_writes_them() {
        let bspline = json!({"kind": "bspline", "degree": 3,
            "control_points": [[0, 0, 0], [10, 5, 1], [20, -5, 2], [30, 5, 1], [40, 0, 0]]});
        let polyline = json!({"kind": "polyline", "points": [[0, 0], [10, 0], [10, 10], [0, 10.5]]});
        let curves = [
            json!({"kind": "circle", "centre": [0, 0], "radius": 50}),
            json!({"kind": "arc", "centre": [1, 2], "radius": 20, "start_deg": 10, "end_deg": 200}),
            json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [400, 150]}),
            bspline,
            polyline,
        ];
        for curve in curves {
            for mode in ["window", "curve", "guarantee"] {
                let request = json!({"curve": curve, "feed": 6000, "block_time_ms": 4, "mode": mode,
                    "compare_tolerance": 0.01, "tolerance": 0.002});
                assert_as_serde(&answer(request, None));
            }
        }
        // With a machine (cycle time) and a tool whose name holds the marker's text.
        let machine =
            json!({"name": "m1", "block_time_ms": 2, "max_feed": 12000, "max_accel": 2000, "rapid_feed": 20000});
        let tool = json!({"kind": "flat", "radius": 3, "name": "\"windows\":[],\"points\":[],\"s\":[]"});
        let request = json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 5}, "feed": 3000,
            "machine": "m1", "tool": tool});
        let with_both = answer(request, Some(machine));
        assert!(with_both.machine.is_some() && with_both.tool.is_some() && with_both.cycle_time.is_some());
        assert_as_serde(&with_both);
    }

    #[test]
    fn short_copies_move_every_length_whole() {
        let source: Vec<u8> = (1..=LONGEST_NUMBER as u8).collect();
        for n in 1..=LONGEST_NUMBER {
            let mut target = [0_u8; LONGEST_NUMBER];
            copy_short(&mut target, &source[..n]);
            assert_eq!(&target[..n], &source[..n], "{n} bytes");
            assert!(target[n..].iter().all(|&byte| byte == 0), "{n} bytes: wrote past them");
        }
    }

    #[test]
    fn random_answers_are_written_as_serde_writes_them() {
        let mut random = Random(34);
        let template = answer(
            json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 50}, "feed": 6000, "block_time_ms": 4}),
            None,
        );
        let statuses = [
            WindowStatus::Ok,
            WindowStatus::Straight,
            WindowStatus::ClampedToMinChordError,
            WindowStatus::LimitedByTolerance,
        ];
        for round in 0..200 {
            let mut answer = template.clone();
            let count = (random.next() % 50) as usize;
            let dimension = 2 + (round % 2);
            let result = &mut answer.result;
            result.points = (0..count)
                .map(|_| CommandPoint::new(&Vec3::new(random.float(), random.float(), random.float()), dimension))
                .collect();
            result.s = (0..count).map(|_| random.float()).collect();
            result.windows = (0..random.next() % 5)
                .map(|_| SegmentWindow {
                    s_start: random.float(),
                    s_end: random.float(),
                    radius: (!random.next().is_multiple_of(3)).then(|| random.float()),
                    chord_error: random.float(),
                    rule_chord_error: random.float(),
                    status: statuses[(random.next() % 4) as usize],
                    blocks: [0, 1, usize::MAX, random.next() as usize][(random.next() % 4) as usize],
                })
                .collect();
            result.chord_error = random.float();
            assert_as_serde(&answer);
        }
    }
}
