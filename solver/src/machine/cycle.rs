//! The cycle time a control would take (docs/spec/api.md, Machines; docs/spec/engagement.md §11
//! item 7): every move runs a trapezoidal feed
//! profile limited by its feed and the machine's acceleration, stopping at sharp vertices and
//! where rapids begin and end; a block never takes less than the block time; rapids run at the
//! rapid feed; a tool change adds its time. The breakdown separates cutting, air (feed moves the
//! capability knows to be out of the material: corner loops, leads), rapid and tool change.
//!
//! With a jerk limit (`max_jerk`) every change of speed is an S-curve instead: the acceleration
//! ramps up at the jerk, holds at `max_accel` if the change is large enough, and ramps down, so a
//! change by Δv takes Δv/a + a/j (or 2√(Δv/j) when a is never reached) and covers the mean of
//! the two speeds times that time. Each change starts and ends at zero acceleration (a
//! junction is passed at constant speed), which is how jerk-limited look-ahead is usually
//! planned and errs on the long side.
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
    /// Largest path jerk, mm/s³ (> 0): S-curve speed changes; `None`: trapezoids.
    pub max_jerk: Option<f64>,
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
    /// The jerk used, mm/s³, when the machine has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_jerk: Option<f64>,
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

/// Time and length of a jerk-limited change of speed from `from` to `to` (mm/s) with at most
/// `accel` and `jerk`, starting and ending at zero acceleration: (s, mm).
pub fn s_curve_change(from: f64, to: f64, accel: f64, jerk: f64) -> (f64, f64) {
    let change = (to - from).abs();
    let time =
        if change >= accel * accel / jerk { change / accel + accel / jerk } else { 2.0 * (change / jerk).sqrt() };
    (time, 0.5 * (from + to) * time)
}

/// The highest speed an S-curve reaches from `from` (mm/s) within `length` mm: the inverse of
/// [`s_curve_change`]'s length, in closed form (a cubic while the acceleration stays below
/// `accel`, a quadratic once it holds there).
pub fn s_curve_reach(from: f64, length: f64, accel: f64, jerk: f64) -> f64 {
    if length <= 0.0 {
        return from;
    }
    // Below a/j·a of change: length = (2v + Δ)·√(Δ/j); with s = √Δ, s³ + 2v·s − length·√j = 0.
    let (p, q) = (2.0 * from, length * jerk.sqrt());
    let s = if p <= 1e-12 * q.cbrt().powi(2) {
        q.cbrt()
    } else {
        let k = (p / 3.0).sqrt();
        2.0 * k * ((1.5 * q / (p * k)).asinh() / 3.0).sinh()
    };
    let knee = accel * accel / jerk;
    if s * s < knee {
        return from + s * s;
    }
    // Beyond: length = (2v + Δ)/2·(Δ/a + a/j), a quadratic in Δ.
    let b = 2.0 * from + knee;
    let c = 2.0 * from * knee - 2.0 * length * accel;
    from + 0.5 * (-b + (b * b - 4.0 * c).max(0.0).sqrt())
}

/// Time to run `length` mm entering at `entry`, leaving at `exit`, cruising at most at `cruise`
/// (mm/s) with S-curve speed changes (acceleration `accel`, jerk `jerk`): up to the cruise speed
/// and down again, or, on a move too short for that, up to the peak speed whose two changes fill
/// the move (found by bisection). The entry and exit speeds must be reachable.
pub fn s_curve_time(length: f64, entry: f64, exit: f64, cruise: f64, accel: f64, jerk: f64) -> f64 {
    if length <= 0.0 {
        return 0.0;
    }
    let both = |peak: f64| {
        let (up_t, up_l) = s_curve_change(entry, peak, accel, jerk);
        let (down_t, down_l) = s_curve_change(peak, exit, accel, jerk);
        (up_t + down_t, up_l + down_l)
    };
    let (time, used) = both(cruise);
    if used <= length {
        return time + (length - used) / cruise;
    }
    let (mut low, mut high) = (entry.max(exit), cruise);
    for _ in 0..200 {
        let middle = 0.5 * (low + high);
        if both(middle).1 <= length {
            low = middle;
        } else {
            high = middle;
        }
        if high - low <= 1e-13 * high {
            break;
        }
    }
    let (time, used) = both(low);
    time + if low > 0.0 { (length - used).max(0.0) / low } else { 0.0 }
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
    // The speed reachable from `speed` within `length`: by the acceleration alone, or the S-curve.
    let reach = |speed: f64, length: f64| match dynamics.max_jerk {
        None => (speed * speed + 2.0 * accel * length).sqrt(),
        Some(jerk) => s_curve_reach(speed, length, accel, jerk),
    };
    for i in (0..count).rev() {
        junction[i] = junction[i].min(reach(junction[i + 1], lengths[i]));
    }
    for i in 0..count {
        junction[i + 1] = junction[i + 1].min(reach(junction[i], lengths[i]));
    }
    let mut time = CycleTime { max_accel: accel, max_jerk: dynamics.max_jerk, ..CycleTime::default() };
    for i in 0..count {
        let t = match dynamics.max_jerk {
            None => trapezoid_time(lengths[i], junction[i], junction[i + 1], cruise[i], accel),
            Some(jerk) => s_curve_time(lengths[i], junction[i], junction[i + 1], cruise[i], accel, jerk),
        };
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
        Dynamics { max_accel: 500.0, max_jerk: None, rapid_feed: 30_000.0, block_time_s: 0.0, tool_change_s: 0.0 };

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

    /// Rest to rest over `length` at cruise `v` (mm/s), acceleration `a` and jerk `j`: the
    /// textbook seven-phase S-curve (and its shorter forms), written out case by case.
    fn s_curve_closed_form(length: f64, v: f64, a: f64, j: f64) -> f64 {
        // Reaching v: with a held (v ≥ a²/j) in v/a + a/j, else in 2√(v/j); the distance is
        // v/2 times that time.
        let to_cruise = if v >= a * a / j { v / a + a / j } else { 2.0 * (v / j).sqrt() };
        if length >= v * to_cruise {
            return length / v + to_cruise;
        }
        // Too short to cruise: up to the peak p and down, length = p·t(p).
        if length >= 2.0 * a * a * a / (j * j) {
            // p ≥ a²/j: length = p(p/a + a/j) → p² + (a²/j)p − a·length = 0.
            let k = a * a / j;
            let peak = 0.5 * (-k + (k * k + 4.0 * a * length).sqrt());
            2.0 * (peak / a + a / j)
        } else {
            // p < a²/j: length = 2p√(p/j) → t = 4√(p/j) = 4·(length/(2j))^(1/3).
            4.0 * (length / (2.0 * j)).cbrt()
        }
    }

    #[test]
    fn a_line_with_jerk_takes_the_s_curve() {
        // 6000 mm/min = 100 mm/s at 500 mm/s²: a²/j = 25 mm/s at j = 10 000, so the acceleration
        // holds at a; at j = 1000 (a²/j = 250 mm/s > 100) it never reaches a.
        for jerk in [10_000.0, 1000.0, 200.0] {
            let dynamics = Dynamics { max_jerk: Some(jerk), ..DYNAMICS };
            for length in [200.0, 25.0, 10.0, 1.0, 0.05, 0.001] {
                let time = cycle_time(Vec3::zeros(), &[feed(length, 0.0, 6000.0)], &dynamics, 0);
                let expected = s_curve_closed_form(length, 100.0, 500.0, jerk);
                assert!(
                    (time.total_s - expected).abs() < 1e-9 * expected.max(1.0),
                    "{jerk} {length}: {} vs {expected}",
                    time.total_s
                );
                let trapezoid = closed_form(length, 100.0, 500.0);
                assert!(time.total_s > trapezoid, "jerk only slows the line down");
                assert_eq!(time.max_jerk, Some(jerk));
            }
            // Split into collinear pieces the line never stops between them; a speed change
            // spread over pieces starts a new S-curve at each junction, so it may take longer.
            let pieces: Vec<Step> = (1..=20).map(|k| feed(10.0 * f64::from(k), 0.0, 6000.0)).collect();
            let time = cycle_time(Vec3::zeros(), &pieces, &dynamics, 0);
            let whole = s_curve_closed_form(200.0, 100.0, 500.0, jerk);
            let stopping = 20.0 * s_curve_closed_form(10.0, 100.0, 500.0, jerk);
            assert!(time.total_s >= whole - 1e-9 && time.total_s < 0.5 * stopping, "{jerk}: pieces {}", time.total_s);
        }
        // A very large jerk gives the trapezoid back.
        let stiff = Dynamics { max_jerk: Some(1e12), ..DYNAMICS };
        let time = cycle_time(Vec3::zeros(), &[feed(100.0, 0.0, 6000.0)], &stiff, 0);
        assert!((time.total_s - closed_form(100.0, 100.0, 500.0)).abs() < 1e-6);
    }

    #[test]
    fn without_jerk_the_trapezoid_is_unchanged() {
        let square =
            [feed(40.0, 0.0, 3000.0), feed(40.0, 40.0, 3000.0), feed(0.0, 40.0, 3000.0), feed(0.0, 0.0, 3000.0)];
        let time = cycle_time(Vec3::zeros(), &square, &DYNAMICS, 0);
        assert!((time.total_s - 4.0 * closed_form(40.0, 50.0, 500.0)).abs() < 1e-12);
        assert_eq!(time.max_jerk, None);
        let with_jerk = cycle_time(Vec3::zeros(), &square, &Dynamics { max_jerk: Some(2000.0), ..DYNAMICS }, 0);
        let expected = 4.0 * s_curve_closed_form(40.0, 50.0, 500.0, 2000.0);
        assert!((with_jerk.total_s - expected).abs() < 1e-9, "{} vs {expected}", with_jerk.total_s);
    }

    #[test]
    fn the_reach_inverts_the_change() {
        for (from, accel, jerk) in
            [(0.0, 500.0, 1000.0), (30.0, 500.0, 10_000.0), (5.0, 100.0, 50.0), (200.0, 2000.0, 1e6)]
        {
            for length in [1e-4, 0.01, 1.0, 10.0, 1000.0] {
                let to = s_curve_reach(from, length, accel, jerk);
                let (_, covered) = s_curve_change(from, to, accel, jerk);
                assert!((covered - length).abs() < 1e-9 * length.max(1.0), "{from} {length}: {covered}");
            }
        }
    }
}
