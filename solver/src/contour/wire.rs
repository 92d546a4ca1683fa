//! The contour answer as JSON, byte for byte what `serde_json::to_vec` writes, but cheaper: the
//! layers' moves, nearly all of a large answer, are written by hand straight into one pre-sized
//! buffer; the rest (tool, corners, passes, summary, warnings) still goes through serde.
//!
//! Derived serialisation pays per move for escaping every key, the enum's name and growing the
//! buffer by doubling; here the keys are constants and the numbers use the formatter
//! `serde_json` uses (`zmij` for floats), so the text is identical.

use super::answer::{ContourLayer, ContourMove, MoveKind};
use super::capability::ContourAnswer;
use crate::wire::float;

/// What `serde_json` writes for the answer whose layers were taken out.
const EMPTY_LAYERS: &[u8] = b"\"layers\":[]";

/// A generous estimate of one move's text, bytes (the buffer only needs to be about right: it
/// still grows if the moves are longer).
const MOVE_BYTES: usize = 80;

/// Bytes of a layer besides its moves: `{"z":…,"moves":[]},`.
const LAYER_BYTES: usize = 48;

/// The answer as JSON, exactly as `serde_json::to_vec(&answer)` would write it.
///
/// # Errors
/// When serde cannot write the answer's other fields.
pub(crate) fn to_json(mut answer: ContourAnswer) -> serde_json::Result<Vec<u8>> {
    let layers = std::mem::take(&mut answer.result.layers);
    let rest = serde_json::to_vec(&answer)?;
    // The key is written once, and no string can hold the unescaped quotes of the marker; a key
    // `layers` elsewhere (none today) leaves the answer to serde.
    let [mark] = crate::wire::marks(&rest, EMPTY_LAYERS)[..] else {
        answer.result.layers = layers;
        return serde_json::to_vec(&answer);
    };
    let moves: usize = layers.iter().map(|layer| layer.moves.len()).sum();
    let mut out = Vec::with_capacity(rest.len() + layers.len() * LAYER_BYTES + moves * MOVE_BYTES);
    // Up to and with `"layers":`, then the array in place of `[]`.
    let array = mark + EMPTY_LAYERS.len() - 2;
    out.extend_from_slice(&rest[..array]);
    write_layers(&mut out, &layers);
    out.extend_from_slice(&rest[mark + EMPTY_LAYERS.len()..]);
    Ok(out)
}

/// `layers` as a JSON array.
///
/// Layers repeat one another's moves at another height, and a layer's moves share a few heights
/// and feeds. A move's text is three pieces, each copied from its counterpart in the layer before
/// (counted from the end, as the first layer's first moves differ) when the values it is written
/// from are the same, else written: the head (the comma before it, kind, x and y), the z, and the
/// tail (the feed and the closing brace; written whenever either has a tool axis). Copies of
/// pieces that lie one after another there are made as one, so a stretch of moves differing only
/// in height is copied in runs between its heights. Heights and feeds are formatted once each
/// ([`Numbers`]). Copying text of the same values gives the same text.
pub(crate) fn write_layers(out: &mut Vec<u8>, layers: &[ContourLayer]) {
    let mut previous: Vec<Written> = Vec::new();
    let mut current: Vec<Written> = Vec::new();
    let mut numbers = Numbers::default();
    out.push(b'[');
    for (index, layer) in layers.iter().enumerate() {
        if index > 0 {
            out.push(b',');
        }
        out.extend_from_slice(b"{\"z\":");
        float(out, layer.z);
        out.extend_from_slice(b",\"moves\":[");
        let skipped = previous.len().checked_sub(layer.moves.len());
        let mut copies = Copies::default();
        for (index, step) in layer.moves.iter().enumerate() {
            let written = Written::of(step, index > 0);
            let twin = skipped.and_then(|skipped| previous.get(index + skipped));
            let start = copies.end(out);
            match twin.filter(|twin| twin.same_head(&written)) {
                Some(twin) => copies.copy(out, twin.start, twin.z_start),
                None => {
                    copies.flush(out);
                    if index > 0 {
                        out.push(b',');
                    }
                    out.extend_from_slice(kind_prefix(step.kind));
                    float(out, step.to[0]);
                    out.push(b',');
                    float(out, step.to[1]);
                    out.push(b',');
                }
            }
            let z_start = copies.end(out);
            match twin.filter(|twin| twin.z == written.z) {
                Some(twin) => copies.copy(out, twin.z_start, twin.z_end),
                None => {
                    copies.flush(out);
                    numbers.write(out, step.to[2]);
                }
            }
            let z_end = copies.end(out);
            match twin.filter(|twin| twin.same_tail(&written)) {
                Some(twin) => copies.copy(out, twin.z_end, twin.end),
                None => {
                    copies.flush(out);
                    out.push(b']');
                    if let Some(feed) = step.feed {
                        out.extend_from_slice(b",\"feed\":");
                        numbers.write(out, feed);
                    }
                    if let Some(axis) = &step.axis {
                        out.extend_from_slice(b",\"axis\":[");
                        triple(out, axis);
                    }
                    out.push(b'}');
                }
            }
            current.push(Written { start, z_start, z_end, end: copies.end(out), ..written });
        }
        copies.flush(out);
        out.extend_from_slice(b"]}");
        std::mem::swap(&mut previous, &mut current);
        current.clear();
    }
    out.push(b']');
}

/// A range of the output waiting to be copied to its end: the next range that starts where it
/// ends joins it, anything else written first flushes it.
#[derive(Default)]
struct Copies {
    from: usize,
    to: usize,
}

impl Copies {
    /// Where the output ends once the waiting copy is made.
    fn end(&self, out: &[u8]) -> usize {
        out.len() + (self.to - self.from)
    }

    /// Copies `from..to` of the output to its end (later, joined with what follows it there).
    fn copy(&mut self, out: &mut Vec<u8>, from: usize, to: usize) {
        if self.to != from || self.from == self.to {
            self.flush(out);
            self.from = from;
        }
        self.to = to;
    }

    fn flush(&mut self, out: &mut Vec<u8>) {
        if self.to > self.from {
            out.extend_from_within(self.from..self.to);
        }
        self.from = 0;
        self.to = 0;
    }
}

/// Where a move's text lies in the output (from the comma before it, the start of its z, the end
/// of its z, its end), and the values it was written from.
#[derive(Clone, Copy)]
struct Written {
    /// Whether a comma precedes it (not the first move of its layer).
    comma: bool,
    kind: MoveKind,
    x: u64,
    y: u64,
    z: u64,
    /// The feed's bits, `None` without one.
    feed: Option<u64>,
    /// Whether its tail is the feed alone (no tool axis).
    tail_plain: bool,
    start: usize,
    z_start: usize,
    z_end: usize,
    end: usize,
}

impl Written {
    fn of(step: &ContourMove, comma: bool) -> Self {
        Self {
            comma,
            kind: step.kind,
            x: step.to[0].to_bits(),
            y: step.to[1].to_bits(),
            z: step.to[2].to_bits(),
            feed: step.feed.map(f64::to_bits),
            tail_plain: step.axis.is_none(),
            start: 0,
            z_start: 0,
            z_end: 0,
            end: 0,
        }
    }

    /// Whether `other`'s text up to its z is this one's.
    fn same_head(&self, other: &Self) -> bool {
        self.comma == other.comma && self.kind == other.kind && self.x == other.x && self.y == other.y
    }

    /// Whether `other`'s text after its z is this one's (both without a tool axis).
    fn same_tail(&self, other: &Self) -> bool {
        self.tail_plain && other.tail_plain && self.feed == other.feed
    }
}

/// The text of the last few distinct numbers written through it (a layer's heights and feeds).
#[derive(Default)]
struct Numbers {
    entries: [(u64, [u8; 32], usize); 4],
    filled: usize,
    next: usize,
}

impl Numbers {
    fn write(&mut self, out: &mut Vec<u8>, value: f64) {
        let bits = value.to_bits();
        if let Some((_, text, length)) = self.entries[..self.filled].iter().find(|(b, _, _)| *b == bits) {
            out.extend_from_slice(&text[..*length]);
            return;
        }
        let from = out.len();
        float(out, value);
        let written = &out[from..];
        let mut text = [0u8; 32];
        text[..written.len()].copy_from_slice(written);
        self.entries[self.next] = (bits, text, written.len());
        self.next = (self.next + 1) % self.entries.len();
        self.filled = (self.filled + 1).min(self.entries.len());
    }
}

fn kind_prefix(kind: MoveKind) -> &'static [u8] {
    match kind {
        MoveKind::Cut => b"{\"kind\":\"cut\",\"to\":[",
        MoveKind::Loop => b"{\"kind\":\"loop\",\"to\":[",
        MoveKind::Link => b"{\"kind\":\"link\",\"to\":[",
        MoveKind::Rapid => b"{\"kind\":\"rapid\",\"to\":[",
    }
}

/// Three numbers and the closing bracket of their array.
fn triple(out: &mut Vec<u8>, values: &[f64; 3]) {
    float(out, values[0]);
    out.push(b',');
    float(out, values[1]);
    out.push(b',');
    float(out, values[2]);
    out.push(b']');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capability::{Capability, Resolved, Run};
    use crate::contour::{ContourCapability, ContourRequest};
    use crate::tool::{Tool, ToolKind};
    use proptest::prelude::*;

    /// Floats serde writes in every form: integral, shortest round trip, exponents, signed zero,
    /// not finite (`null`).
    fn number() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<f64>(),
            -1e6f64..1e6,
            prop::sample::select(vec![
                0.0,
                -0.0,
                1200.0,
                0.1 + 0.2,
                1e21,
                -1e-7,
                5e-324,
                f64::MAX,
                -2.225_073_858_507_201_4e-308,
                f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ]),
        ]
    }

    fn step() -> impl Strategy<Value = ContourMove> {
        (
            prop::sample::select(vec![MoveKind::Cut, MoveKind::Loop, MoveKind::Link, MoveKind::Rapid]),
            [number(), number(), number()],
            prop::option::of(number()),
            prop::option::of([number(), number(), number()]),
        )
            .prop_map(|(kind, to, feed, axis)| ContourMove { kind, to, feed, axis: axis.map(Box::new) })
    }

    fn layers() -> impl Strategy<Value = Vec<ContourLayer>> {
        prop::collection::vec(
            (number(), prop::collection::vec(step(), 0..12)).prop_map(|(z, moves)| ContourLayer {
                z,
                moves,
                arcs: Vec::new(),
            }),
            0..6,
        )
    }

    /// Layers that repeat a first one's moves at other heights, with some moves dropped from the
    /// front, some of another kind or place, some with other heights and feeds.
    fn repeated_layers() -> impl Strategy<Value = Vec<ContourLayer>> {
        (
            prop::collection::vec(step(), 1..16),
            prop::collection::vec(
                (number(), 0usize..4, prop::collection::vec((0u8..8, step()), 16), prop::option::of(number())),
                1..6,
            ),
        )
            .prop_map(|(base, copies)| {
                copies
                    .into_iter()
                    .map(|(z, skip, changes, feed)| {
                        let moves = base
                            .iter()
                            .zip(&changes)
                            .skip(skip.min(base.len() - 1))
                            .map(|(step, (change, other))| {
                                let mut step = step.clone();
                                match change {
                                    0 => step.kind = other.kind,
                                    1 => step.to[0] = other.to[0],
                                    2 => step.to[1] = other.to[1],
                                    3 => step.feed = feed,
                                    4 => step.to[2] = other.to[2],
                                    _ => step.to[2] = z,
                                }
                                step
                            })
                            .collect();
                        ContourLayer { z, moves, arcs: Vec::new() }
                    })
                    .collect()
            })
    }

    fn request(side: &str, tilt: Option<f64>) -> ContourRequest {
        let mut body = serde_json::json!({
            "tool": {"kind": "flat", "radius": 1.5, "name": "a \"layers\":[] tool"},
            "contour": [[0, 0], [40, 0], [40, 30], [25, 30], [20, 12], [15, 30], [0, 30]],
            "side": side, "depths": {"top": 0, "bottom": -3, "step": 1},
            "corner_loop": {"style": "arc"}, "feed": 800, "loop_feed": 1500
        });
        if let Some(tilt) = tilt {
            body["tilt_deg"] = serde_json::json!(tilt);
        }
        serde_json::from_value(body).unwrap()
    }

    fn solved(request: &ContourRequest) -> ContourAnswer {
        let crate::tool::ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        let context = Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() };
        ContourCapability::solve(request, context, &Run::default()).unwrap()
    }

    #[test]
    fn solved_answers_are_written_as_serde_writes_them() {
        for (side, tilt) in [("inside", None), ("outside", None), ("outside", Some(3.0))] {
            let answer = solved(&request(side, tilt));
            assert!(answer.result.summary.moves > 50);
            assert_eq!(to_json(answer.clone()).unwrap(), serde_json::to_vec(&answer).unwrap(), "{side} {tilt:?}");
        }
    }

    proptest! {
        #[test]
        fn random_moves_are_written_as_serde_writes_them(layers in prop_oneof![layers(), repeated_layers()]) {
            let mut answer = solved(&request("outside", None));
            answer.result.layers = layers;
            prop_assert_eq!(
                String::from_utf8(to_json(answer.clone()).unwrap()).unwrap(),
                String::from_utf8(serde_json::to_vec(&answer).unwrap()).unwrap()
            );
        }
    }

    #[test]
    fn a_string_holding_the_marker_does_not_move_the_moves() {
        let mut answer = solved(&request("outside", None));
        answer.tool = Tool::new(ToolKind::Flat, 1.5);
        answer.result.warnings.insert(0, crate::error::Warning::new("W_TEST", "\"layers\":[]"));
        assert_eq!(to_json(answer.clone()).unwrap(), serde_json::to_vec(&answer).unwrap());
    }
}
