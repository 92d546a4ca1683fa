//! The cycle time a control would take (issue 15, item 4): every move runs a trapezoidal feed
//! profile limited by its feed and the machine's acceleration, stopping at sharp vertices and
//! where rapids begin and end; a block never takes less than the block time; rapids run at the
//! rapid feed; a tool change adds its time. The breakdown separates cutting, air (feed moves the
//! capability knows to be out of the material: corner loops, leads), rapid and tool change.
//!
//! Velocity planning is the usual look-ahead: junction speeds start at the smaller of the two
//! feeds (0 at a sharp vertex, a feed change to or from a rapid, and the path's ends), then a
//! backward and a forward pass cap each junction at what the acceleration allows over the move
//! next to it (v² ≤ u² + 2aL). Each move then takes the closed-form time of its trapezoid (or
//! triangle) between its entry and exit speeds.

use serde::Serialize;

use crate::geometry::Vec3;

/// A vertex turning more than this stops the tool (degrees): corners of a contour, not the few
/// degrees between the chords of an arc.
pub const SHARP_TURN_DEG: f64 = 10.0;

/// What the machine allows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dynamics {
    /// Largest path acceleration, mm/s² (> 0).
    pub max_accel: f64,
    /// Feed of rapids, mm/min (> 0).
    pub rapid_feed: f64,
    /// Block processing time, s (0 when unknown).
    pub block_time_s: f64,
    /// Time of one tool change, s.
    pub tool_change_s: f64,
}

/// One move for the time estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// A rapid to the point.
    Rapid(Vec3),
    /// A feed move to the point at `feed` mm/min; `air` when it is known to cut nothing.
    Feed {
        /// End point.
        to: Vec3,
        /// Feed, mm/min.
        feed: f64,
        /// Out of the material.
        air: bool,
    },
}

/// The estimated cycle time and its parts, s.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct CycleTime {
    /// Everything, s.
    pub total_s: f64,
    /// Feed moves in the material, s.
    pub cutting_s: f64,
    /// Feed moves in the air (loops, leads), s.
    pub air_s: f64,
    /// Rapids, s.
    pub rapid_s: f64,
    /// Tool changes, s.
    pub tool_change_s: f64,
    /// The acceleration used, mm/s².
    pub max_accel: f64,
}

/// Time to run `length` mm entering at `entry`, leaving at `exit`, cruising at most at `cruise`
/// (mm/s) with acceleration `accel`: a trapezoid, or a triangle when the move is too short to
/// reach the cruise speed. The entry and exit speeds must be reachable (the planner ensures it).
pub fn trapezoid_time(length: f64, entry: f64, exit: f64, cruise: f64, accel: f64) -> f64 {
    if length <= 0.0 {
        return 0.0;
    }
    let speed_up = (cruise * cruise - entry * entry) / (2.0 * accel);
    let slow_down = (cruise * cruise - exit * exit) / (2.0 * accel);
    if speed_up + slow_down <= length {
        (cruise - entry) / accel + (cruise - exit) / accel + (length - speed_up - slow_down) / cruise
    } else {
        let peak = ((2.0 * accel * length + entry * entry + exit * exit) / 2.0).sqrt();
        (peak - entry).max(0.0) / accel + (peak - exit).max(0.0) / accel
    }
}

/// The cycle time of `steps` starting at `start`, with `tool_changes` tool changes.
pub fn cycle_time(start: Vec3, steps: &[Step], dynamics: &Dynamics, tool_changes: usize) -> CycleTime {
    let accel = dynamics.max_accel;
    let rapid = dynamics.rapid_feed / 60.0;
    // Per move: length, cruise speed (mm/s), direction, kind (0 cutting, 1 air, 2 rapid).
    let mut lengths = Vec::with_capacity(steps.len());
    let mut cruise = Vec::with_capacity(steps.len());
    let mut directions = Vec::with_capacity(steps.len());
    let mut kinds = Vec::with_capacity(steps.len());
    let mut here = start;
    for step in steps {
        let (to, speed, kind) = match *step {
            Step::Rapid(to) => (to, rapid, 2),
            Step::Feed { to, feed, air } => (to, feed / 60.0, usize::from(air)),
        };
        let delta = to - here;
        lengths.push(delta.norm());
        cruise.push(speed.max(1e-9));
        directions.push(delta.try_normalize(1e-12));
        kinds.push(kind);
        here = to;
    }
    let count = steps.len();
    // Junction speed before move i (index i) and after the last move (index count).
    let mut junction = vec![0.0; count + 1];
    let sharp = SHARP_TURN_DEG.to_radians().cos();
    for i in 1..count {
        let smooth = match (directions[i - 1], directions[i]) {
            (Some(a), Some(b)) => a.dot(&b) >= sharp,
            _ => false,
        };
        let same_kind = (kinds[i - 1] == 2) == (kinds[i] == 2);
        junction[i] = if smooth && same_kind { cruise[i - 1].min(cruise[i]) } else { 0.0 };
    }
    for i in (0..count).rev() {
        junction[i] = junction[i].min((junction[i + 1] * junction[i + 1] + 2.0 * accel * lengths[i]).sqrt());
    }
    for i in 0..count {
        junction[i + 1] = junction[i + 1].min((junction[i] * junction[i] + 2.0 * accel * lengths[i]).sqrt());
    }
    let mut time = CycleTime { max_accel: accel, ..CycleTime::default() };
    for i in 0..count {
        let t = trapezoid_time(lengths[i], junction[i], junction[i + 1], cruise[i], accel);
        let t = if kinds[i] == 2 || lengths[i] <= 0.0 { t } else { t.max(dynamics.block_time_s) };
        match kinds[i] {
            0 => time.cutting_s += t,
            1 => time.air_s += t,
            _ => time.rapid_s += t,
        }
    }
    time.tool_change_s = dynamics.tool_change_s * tool_changes as f64;
    time.total_s = time.cutting_s + time.air_s + time.rapid_s + time.tool_change_s;
    time
}

/// The cycle time of a program's tool path (chords, not arcs: an arc counts as its chord) from
/// its first point: rapids at the rapid feed, straight moves down the tool axis in the air at
/// `plunge_feed` of their feed ([`crate::gcode::plunge_feed`], as the post writes them), every
/// other feed move cutting. `None` for an empty path.
pub fn path_cycle_time(
    path: &crate::path::Toolpath,
    dynamics: &Dynamics,
    plunge_feed: Option<f64>,
    tool_changes: usize,
) -> Option<CycleTime> {
    use crate::path::Motion;
    let start = path.moves.first()?.to;
    let mut here = start;
    let steps: Vec<Step> = path
        .moves
        .iter()
        .map(|step| {
            let to = step.to;
            let from = std::mem::replace(&mut here, to);
            match step.motion {
                Motion::Rapid => Step::Rapid(to),
                Motion::Linear { feed } | Motion::Arc { feed, .. } => {
                    let down = to.z < from.z && (to.x - from.x).abs() <= 1e-9 && (to.y - from.y).abs() <= 1e-9;
                    if down {
                        Step::Feed { to, feed: crate::gcode::plunge_feed(feed, plunge_feed), air: true }
                    } else {
                        Step::Feed { to, feed, air: false }
                    }
                }
            }
        })
        .collect();
    Some(cycle_time(start, &steps, dynamics, tool_changes))
}

#[cfg(test)]
mod tests {
    use super::*;

    const DYNAMICS: Dynamics =
        Dynamics { max_accel: 500.0, rapid_feed: 30_000.0, block_time_s: 0.0, tool_change_s: 0.0 };

    fn feed(x: f64, y: f64, feed: f64) -> Step {
        Step::Feed { to: Vec3::new(x, y, 0.0), feed, air: false }
    }

    /// Rest to rest over `length` at cruise `v` (mm/s) and acceleration `a`.
    fn closed_form(length: f64, v: f64, a: f64) -> f64 {
        if length >= v * v / a { length / v + v / a } else { 2.0 * (length / a).sqrt() }
    }

    #[test]
    fn a_line_takes_the_trapezoid_or_the_triangle() {
        // 6000 mm/min = 100 mm/s; at 500 mm/s² the tool needs 10 mm to reach it and 10 to stop.
        for (length, expected) in [(100.0, 100.0 / 100.0 + 100.0 / 500.0), (10.0, 2.0 * (10.0_f64 / 500.0).sqrt())] {
            let time = cycle_time(Vec3::zeros(), &[feed(length, 0.0, 6000.0)], &DYNAMICS, 0);
            assert!((time.total_s - expected).abs() < 1e-12, "{length}: {} vs {expected}", time.total_s);
            assert!((time.total_s - closed_form(length, 100.0, 500.0)).abs() < 1e-12);
            assert_eq!(time.cutting_s, time.total_s);
        }
        // Split into collinear pieces the line takes the same time: no stop between them.
        let pieces: Vec<Step> = (1..=20).map(|k| feed(5.0 * f64::from(k), 0.0, 6000.0)).collect();
        let time = cycle_time(Vec3::zeros(), &pieces, &DYNAMICS, 0);
        assert!((time.total_s - closed_form(100.0, 100.0, 500.0)).abs() < 1e-9, "{}", time.total_s);
    }

    #[test]
    fn a_square_stops_at_its_four_corners() {
        let side = 40.0;
        let square =
            [feed(side, 0.0, 3000.0), feed(side, side, 3000.0), feed(0.0, side, 3000.0), feed(0.0, 0.0, 3000.0)];
        let time = cycle_time(Vec3::zeros(), &square, &DYNAMICS, 0);
        let expected = 4.0 * closed_form(side, 50.0, 500.0);
        assert!((time.total_s - expected).abs() < 1e-12, "{} vs {expected}", time.total_s);
    }

    #[test]
    fn rapids_block_time_and_tool_changes_add_up() {
        let dynamics = Dynamics { block_time_s: 0.5, tool_change_s: 7.0, ..DYNAMICS };
        let steps = [
            Step::Rapid(Vec3::new(0.0, 0.0, 50.0)),
            Step::Feed { to: Vec3::new(0.0, 0.0, 0.0), feed: 600.0, air: true },
            feed(1.0, 0.0, 600.0),
        ];
        let time = cycle_time(Vec3::new(0.0, 0.0, 100.0), &steps, &dynamics, 1);
        assert!((time.rapid_s - closed_form(50.0, 500.0, 500.0)).abs() < 1e-12);
        assert!((time.air_s - closed_form(50.0, 10.0, 500.0)).abs() < 1e-12);
        // One millimetre at 10 mm/s takes 0.12 s, less than the 0.5 s block time.
        assert!((time.cutting_s - 0.5).abs() < 1e-12);
        assert_eq!(time.tool_change_s, 7.0);
        assert!((time.total_s - (time.rapid_s + time.air_s + time.cutting_s + 7.0)).abs() < 1e-12);
    }
}
