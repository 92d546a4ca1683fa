//! Cycle time invariants on random paths: never shorter than every move at
//! its feed, never longer than stopping at every vertex, and the parts add up.

use kerf_solver::geometry::Vec3;
use kerf_solver::machine::cycle::{Dynamics, Step, cycle_time, s_curve_time, trapezoid_time};
use proptest::prelude::*;

fn steps() -> impl Strategy<Value = Vec<(f64, f64, f64, f64, u8)>> {
    prop::collection::vec((-50.0..50.0_f64, -50.0..50.0_f64, -5.0..5.0_f64, 60.0..12_000.0_f64, 0..3_u8), 1..40)
}

proptest! {
    #[test]
    fn bounded_by_the_feeds_and_by_stopping_everywhere(moves in steps(), accel in 50.0..5000.0_f64) {
        let dynamics = Dynamics { max_accel: accel, max_jerk: None, rapid_feed: 20_000.0, block_time_s: 0.0, tool_change_s: 3.0 };
        let path: Vec<Step> = moves
            .iter()
            .map(|&(x, y, z, feed, kind)| {
                let to = Vec3::new(x, y, z);
                if kind == 2 { Step::Rapid(to) } else { Step::Feed { to, feed, air: kind == 1 } }
            })
            .collect();
        let time = cycle_time(Vec3::zeros(), &path, &dynamics, 1);
        let (mut lower, mut upper) = (0.0, 0.0);
        let mut here = Vec3::zeros();
        for step in &path {
            let (to, speed) = match *step {
                Step::Rapid(to) => (to, 20_000.0 / 60.0),
                Step::Feed { to, feed, .. } => (to, feed / 60.0),
            };
            let length = (to - here).norm();
            lower += length / speed;
            upper += trapezoid_time(length, 0.0, 0.0, speed, accel);
            here = to;
        }
        let moving = time.cutting_s + time.air_s + time.rapid_s;
        prop_assert!(moving >= lower * (1.0 - 1e-12) - 1e-12, "{moving} < {lower}");
        prop_assert!(moving <= upper * (1.0 + 1e-12) + 1e-12, "{moving} > {upper}");
        prop_assert!((time.total_s - moving - 3.0).abs() <= 1e-9 * time.total_s.max(1.0));
    }

    /// A jerk limit only slows a path down: never faster than the trapezoid of the same
    /// acceleration, never slower than stopping at every vertex with S-curves.
    #[test]
    fn a_jerk_limit_lies_between_the_trapezoid_and_stopping_everywhere(
        moves in steps(),
        accel in 50.0..5000.0_f64,
        jerk in 100.0..1e6_f64,
    ) {
        let plain = Dynamics { max_accel: accel, max_jerk: None, rapid_feed: 20_000.0, block_time_s: 0.0, tool_change_s: 0.0 };
        let jerky = Dynamics { max_jerk: Some(jerk), ..plain };
        let path: Vec<Step> = moves
            .iter()
            .map(|&(x, y, z, feed, kind)| {
                let to = Vec3::new(x, y, z);
                if kind == 2 { Step::Rapid(to) } else { Step::Feed { to, feed, air: kind == 1 } }
            })
            .collect();
        let trapezoid = cycle_time(Vec3::zeros(), &path, &plain, 0).total_s;
        let s_curve = cycle_time(Vec3::zeros(), &path, &jerky, 0).total_s;
        let mut stopping = 0.0;
        let mut here = Vec3::zeros();
        for step in &path {
            let (to, speed) = match *step {
                Step::Rapid(to) => (to, 20_000.0 / 60.0),
                Step::Feed { to, feed, .. } => (to, feed / 60.0),
            };
            stopping += s_curve_time((to - here).norm(), 0.0, 0.0, speed, accel, jerk);
            here = to;
        }
        prop_assert!(s_curve >= trapezoid * (1.0 - 1e-9) - 1e-12, "{s_curve} < {trapezoid}");
        prop_assert!(s_curve <= stopping * (1.0 + 1e-9) + 1e-12, "{s_curve} > {stopping}");
    }
}
