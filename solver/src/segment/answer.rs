//! What a segment request answers (docs/spec/api.md, Segment; docs/spec/segment.md §1.3 outputs and §6 reports).

use std::ops::Index;

use serde::{Serialize, Serializer};

use crate::error::Warning;
use crate::geometry::Vec3;
use crate::machine::stats::BlockStats;

/// A command point, `[x, y]` or `[x, y, z]` like the curve, and written to JSON as that array.
///
/// The coordinates are held inline: a long curve has about 100 000 points, and a `Vec<f64>` each
/// would cost as many small allocations (and frees) per solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandPoint {
    /// x, y, z; the coordinates past `dimension` are 0 (so `to_vec3` puts a 2-D point at z = 0
    /// and the derived equality compares only the point's own coordinates).
    coordinates: [f64; 3],
    /// How many coordinates the point has: 2 or 3, the curve's.
    dimension: usize,
}

impl CommandPoint {
    /// The first `dimension` coordinates of `point` (at most 3).
    pub(crate) fn new(point: &Vec3, dimension: usize) -> Self {
        let dimension = dimension.min(3);
        let mut coordinates = [0.0; 3];
        coordinates[..dimension].copy_from_slice(&[point.x, point.y, point.z][..dimension]);
        Self { coordinates, dimension }
    }

    /// The coordinates, `[x, y]` or `[x, y, z]`.
    pub fn as_slice(&self) -> &[f64] {
        &self.coordinates[..self.dimension]
    }

    /// How many coordinates the point has: 2 or 3, like the curve.
    pub fn dimension(&self) -> usize {
        self.dimension
    }

    /// The point in space (a 2-D curve's at z = 0).
    pub fn to_vec3(&self) -> Vec3 {
        let [x, y, z] = self.coordinates;
        Vec3::new(x, y, z)
    }
}

/// `point[axis]`: x, y or (3-D only) z.
impl Index<usize> for CommandPoint {
    type Output = f64;

    fn index(&self, axis: usize) -> &f64 {
        &self.as_slice()[axis]
    }
}

/// As the array of its coordinates, the JSON a `Vec<f64>` had.
impl Serialize for CommandPoint {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.as_slice())
    }
}

/// How a window's chord error was chosen (docs/spec/segment.md §2.7, §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum WindowStatus {
    /// On (or with margins just above) the chord-error surface.
    Ok,
    /// Straight (r = ∞): chord error 0, the chord runs to the end of the straight (E1).
    Straight,
    /// Raised to `min_chord_error` (embodiment 6, E5).
    ClampedToMinChordError,
    /// Lowered to the accuracy bound `tolerance`: blocks here are shorter than the rule wants (E4).
    LimitedByTolerance,
}

/// A stretch of the curve cut with one chord error.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct SegmentWindow {
    /// Arc length where the window starts, mm.
    pub s_start: f64,
    /// Arc length where it ends, mm (its last chord may run past it, see docs/spec/segment.md §2.9).
    pub s_end: f64,
    /// Radius of curvature the chord error came from, mm (null where straight).
    pub radius: Option<f64>,
    /// Chord error the window was cut with, mm.
    pub chord_error: f64,
    /// The rule's chord error C_ep before the accuracy bound, mm.
    pub rule_chord_error: f64,
    /// Why this chord error.
    pub status: WindowStatus,
    /// Blocks that start in this window.
    pub blocks: usize,
}

/// The same curve cut with a plain fixed chord error (`compare_tolerance`), for comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from engagement's comparison of paths in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = SegmentComparison))]
pub struct Comparison {
    /// The fixed chord error, mm.
    pub tolerance: f64,
    /// Largest distance of the curve from its chord, mm.
    pub max_deviation: f64,
    /// Block figures of that cut.
    #[serde(flatten)]
    pub stats: BlockStats,
}

/// The answer: the command points, their windows, block figures, warnings.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct SegmentSolution {
    /// The whole-curve chord error, or the largest window value, mm.
    pub chord_error: f64,
    /// The smallest window value, mm.
    pub min_window_chord_error: f64,
    /// Windows in order along the curve (one for `mode: curve`).
    pub windows: Vec<SegmentWindow>,
    /// The command points in order, `[x, y]` or `[x, y, z]` like the curve; the first is the curve
    /// start, the last its end. Consecutive points are one G01 block.
    // Documented as the arrays of numbers it is written as.
    #[cfg_attr(feature = "schema", schema(value_type = Vec<Vec<f64>>))]
    pub points: Vec<CommandPoint>,
    /// Arc length of each point along the curve, mm.
    pub s: Vec<f64>,
    /// Block figures at the feed and block time.
    #[serde(flatten)]
    pub stats: BlockStats,
    /// Largest distance of the target curve from its chord, mm.
    pub max_deviation: f64,
    /// Arc length of the target curve, mm.
    pub curve_length: f64,
    /// Smallest radius of curvature the chord error was computed from, mm (null where the curve
    /// is straight).
    pub min_radius: Option<f64>,
    /// Largest feed at which one block still fits the smallest radius, mm/min (E3).
    pub feed_limit: Option<f64>,
    /// With `tolerance`: the largest feed at which the rule's chord error stays within it
    /// everywhere, so every block is feed × block time long at that accuracy, mm/min (E4).
    pub tolerance_feed: Option<f64>,
    /// Feed used, mm/min.
    pub feed: f64,
    /// Block time used, ms.
    pub block_time_ms: f64,
    /// Margin k_f used.
    pub margin: f64,
    /// Lower bound C_emin used, mm.
    pub min_chord_error: f64,
    /// The fixed-tolerance cut of `compare_tolerance`, side by side.
    pub comparison: Option<Comparison>,
    /// Everything worth knowing that did not stop the computation.
    pub warnings: Vec<Warning>,
    /// Header lines for the G-code program.
    #[serde(skip)]
    pub(crate) description: Vec<String>,
    /// Spindle speed for the program, rpm.
    #[serde(skip)]
    pub(crate) spindle_rpm: f64,
    /// Clearance plane for the program.
    #[serde(skip)]
    pub(crate) safe_z: f64,
    /// The circle or arc the curve is, for a program that writes it as G02/G03 (`None` for
    /// ellipses, polylines and NURBS: they stay chords).
    #[serde(skip)]
    pub(crate) circle: Option<super::shape::Arc>,
}

/// Most bytes one command point takes in memory while the answer is built: the cut's vertex and
/// deviation, the position copied for the block statistics, the command point and its arc length.
pub(crate) const POINT_MEMORY_BYTES: u64 = (std::mem::size_of::<super::cut::Vertex>()
    + std::mem::size_of::<Option<f64>>()
    + std::mem::size_of::<Vec3>()
    + std::mem::size_of::<CommandPoint>()
    + std::mem::size_of::<f64>()) as u64;

/// Most bytes one command point takes as JSON: `[x,y,z],` in `points` and its `s`, each number at
/// its longest (24 characters; checked by `point_json_is_within_its_bound`).
pub(crate) const POINT_JSON_BYTES: u64 = 128;

/// Most bytes one command point takes in a program: one `G01`/`G02` line with three coordinates
/// and an arc centre of up to `-1000000.0000` (the coordinate range) and a feed word.
pub(crate) const POINT_PROGRAM_BYTES: u64 = 128;

/// Most bytes one command point takes for `purpose`: in memory, plus its JSON, its program, or for
/// a job both.
pub(crate) fn point_bound(purpose: crate::capability::Purpose) -> u64 {
    use crate::capability::Purpose;
    POINT_MEMORY_BYTES
        + match purpose {
            Purpose::Json => POINT_JSON_BYTES,
            Purpose::Program => POINT_PROGRAM_BYTES,
            Purpose::Job => POINT_JSON_BYTES + POINT_PROGRAM_BYTES,
        }
}

/// Most bytes one window takes in memory and as JSON, every number at its longest (checked by
/// `window_json_is_within_its_bound`).
pub(crate) const WINDOW_BYTES: u64 = 512;

#[cfg(test)]
mod budget_tests {
    use super::*;

    /// The longest number serde writes (ryu).
    const LONGEST: f64 = -2.225_073_858_507_201_4e-308;

    #[test]
    fn point_json_is_within_its_bound() {
        let point = CommandPoint::new(&Vec3::new(LONGEST, LONGEST, LONGEST), 3);
        // The point and its arc length, each with the comma that separates it from the next.
        let json = serde_json::to_vec(&point).unwrap().len() + serde_json::to_vec(&LONGEST).unwrap().len() + 2;
        assert!(json as u64 <= POINT_JSON_BYTES, "{json} bytes");
    }

    #[test]
    fn window_json_is_within_its_bound() {
        let window = SegmentWindow {
            s_start: LONGEST,
            s_end: LONGEST,
            radius: Some(LONGEST),
            chord_error: LONGEST,
            rule_chord_error: LONGEST,
            status: WindowStatus::ClampedToMinChordError,
            blocks: usize::MAX,
        };
        let json = serde_json::to_vec(&window).unwrap().len() + 1;
        assert!((json + std::mem::size_of::<SegmentWindow>()) as u64 <= WINDOW_BYTES, "{json} bytes");
    }
}
