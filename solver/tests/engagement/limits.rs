//! The recommendation holds every limit kerf computes (docs/spec/engagement.md §5.9): a flute
//! count over the machine's spindle torque, power or speed, or its max feed, is never
//! recommended and says which limit it misses and by how much; the feed plan and the program are
//! for the recommended (or chosen) flute count; a machine's max feed caps the plan's, never
//! raises it; out of contact the plan runs at the nominal feed, not the machine's maximum.

use kerf_solver::capability::Control;
use kerf_solver::engagement::{
    self, EngagementRequest, EngagementSolution, FeedLimit, FluteLimit, PathEngagement, Physics,
};
use kerf_solver::machine::{MachineProfile, SpindleLimits};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

fn tool() -> Tool {
    let mut tool = Tool::new(ToolKind::Flat, 5.0);
    tool.flutes = 2;
    tool
}

/// A full slot from outside the block, flute counts 1–8, generous chip and time limits (every
/// count meets them), Kienzle forces at a_p 2 mm and a feed plan.
fn slot() -> Value {
    json!({
        "tool": 1, "stock": {"polygon": [[0, -20], [50, -20], [50, 20], [0, 20]]},
        "path": [[-10, 0], [45, 0]], "spindle_rpm": 3000, "feed_per_tooth": 0.05,
        "flute_counts": [1, 2, 3, 4, 5, 6, 7, 8], "thickness_limit": 1.0, "time_limit_s": 1000,
        "step": 0.25, "axial_depth": 2, "kienzle": {"kc11": 1800, "mc": 0.25},
        "feed_plan": {"target_thickness": 0.05},
    })
}

fn machine(extra: Value) -> MachineProfile {
    let mut body = json!({"block_time_ms": 2, "max_feed": 12000});
    body.as_object_mut().unwrap().extend(extra.as_object().unwrap().clone());
    serde_json::from_value(body).unwrap()
}

fn solve(body: Value, machine: &MachineProfile, spindle: SpindleLimits) -> PathEngagement {
    let request: EngagementRequest = serde_json::from_value(body).unwrap();
    let physics = Physics { material: None, spindle };
    match engagement::solve_in(&request, &tool(), Some(machine), &physics, Control::default()).unwrap() {
        EngagementSolution::Single(result) => *result,
        EngagementSolution::Comparison(_) => panic!("single path expected"),
    }
}

fn codes(result: &PathEngagement) -> Vec<&str> {
    result.warnings.iter().map(|w| w.code).collect()
}

/// The highest phase-mean torque over the engaged samples of each flute column.
fn highest_torques(result: &PathEngagement) -> Vec<f64> {
    (0..result.flutes.len())
        .map(|column| {
            result.samples.iter().map(|s| s.torque_nm.get(column).copied().unwrap_or(0.0)).fold(0.0, f64::max)
        })
        .collect()
}

#[test]
fn a_flute_count_over_the_spindle_torque_is_never_recommended() {
    let free = solve(slot(), &machine(json!({})), SpindleLimits::default());
    assert_eq!(free.recommended.first(), Some(&8), "without a spindle limit the fastest, 8 flutes");
    let torques = highest_torques(&free);
    // A limit between the torques of 4 and 5 flutes.
    let limit = 0.5 * (torques[3] + torques[4]);
    let spindle = SpindleLimits { spindle_power_kw: None, spindle_torque_nm: Some(limit) };
    let limited = solve(slot(), &machine(json!({})), spindle);
    for (flute, torque) in limited.flutes.iter().zip(highest_torques(&limited)) {
        let over = flute.over_limits.iter().find(|o| o.limit == FluteLimit::SpindleTorque);
        if torque > limit {
            assert!(!flute.recommended, "k = {} at {torque} N·m over {limit}", flute.flute_count);
            let over = over.expect("the torque limit is named");
            assert!((over.value - torque).abs() < 1e-9 && over.allowed == limit, "{over:?}");
        } else {
            assert!(flute.recommended && over.is_none(), "k = {}", flute.flute_count);
        }
    }
    assert_eq!(limited.recommended.first(), Some(&4), "{:?}", limited.recommended);
    // The plan and the program are for the recommended 4 flutes, and say so.
    assert_eq!(limited.program_flute_count, 4);
    assert_eq!(limited.feed_plan.as_ref().unwrap().flute_count, 4);
    assert!(codes(&limited).contains(&"W_PROGRAM_FLUTE_COUNT"), "{:?}", codes(&limited));
    // A flute count chosen in the feed plan wins over the recommendation.
    let mut chosen = slot();
    chosen["feed_plan"]["flute_count"] = json!(2);
    let chosen = solve(chosen, &machine(json!({})), spindle);
    assert_eq!((chosen.program_flute_count, chosen.feed_plan.as_ref().unwrap().flute_count), (2, 2));
    assert!(!codes(&chosen).contains(&"W_PROGRAM_FLUTE_COUNT"));
}

#[test]
fn the_spindle_power_speed_and_the_machine_feed_bound_the_recommendation_too() {
    let free = solve(slot(), &machine(json!({})), SpindleLimits::default());
    let power = free.flutes[2].mean_power_kw.unwrap() * 1.001;
    let spindle = SpindleLimits { spindle_power_kw: Some(power), spindle_torque_nm: None };
    let limited = solve(slot(), &machine(json!({})), spindle);
    for flute in &limited.flutes {
        let over = flute.over_limits.iter().any(|o| o.limit == FluteLimit::SpindlePower);
        assert_eq!(flute.recommended, !over, "k = {}: {:?}", flute.flute_count, flute.over_limits);
    }
    assert!(limited.recommended.iter().all(|&k| k < 4), "{:?}", limited.recommended);
    // 3000 rpm × 0.05 mm × k: 5 flutes need 750 mm/min, over a machine's 700.
    let slow = solve(slot(), &machine(json!({"max_feed": 700})), SpindleLimits::default());
    assert_eq!(slow.recommended.first(), Some(&4), "{:?}", slow.recommended);
    let over = &slow.flutes[4].over_limits;
    assert_eq!((over[0].limit, over[0].value, over[0].allowed), (FluteLimit::MachineFeed, 750.0, 700.0));
    // A spindle speed over the machine's: no flute count, and the reason names the speed.
    let fast = solve(slot(), &machine(json!({"max_spindle_rpm": 2000})), SpindleLimits::default());
    assert!(fast.recommended.is_empty());
    let why = fast.warnings.iter().find(|w| w.code == "W_NO_RECOMMENDATION").expect("W_NO_RECOMMENDATION");
    assert!(why.message.contains("spindle speed 3000 rpm > 2000 rpm"), "{}", why.message);
}

#[test]
fn a_machine_caps_the_plan_feed_and_never_raises_it() {
    let mut body = slot();
    body["feed_plan"]["max_feed"] = json!(2000);
    let capped_by_user = solve(body.clone(), &machine(json!({})), SpindleLimits::default());
    assert_eq!(capped_by_user.feed_plan.as_ref().unwrap().max_feed, 2000.0);
    assert!(capped_by_user.feed_plan.as_ref().unwrap().feed_range[1] <= 2000.0);
    body["feed_plan"]["max_feed"] = json!(20000);
    let lowered = solve(body, &machine(json!({})), SpindleLimits::default());
    assert_eq!(lowered.feed_plan.as_ref().unwrap().max_feed, 12000.0);
    assert!(codes(&lowered).contains(&"W_FEED_ABOVE_MACHINE_MAX"));
}

#[test]
fn out_of_contact_the_plan_runs_at_the_nominal_feed() {
    // A thinner target chip than f_z: the slot is planned below the nominal feed.
    let mut body = slot();
    body["feed_plan"] = json!({"target_thickness": 0.03, "max_feed": 12000});
    let result = solve(body, &machine(json!({})), SpindleLimits::default());
    let plan = result.feed_plan.as_ref().unwrap();
    let nominal = 3000.0 * 0.05 * f64::from(result.program_flute_count);
    let cutting = 3000.0 * 0.03 * f64::from(result.program_flute_count);
    // The first 5 mm are in the air: the tool touches the block at x = −5.
    for block in &plan.blocks {
        if block.to_s <= 5.0 - 1e-9 {
            assert_eq!((block.feed, block.limited_by), (Some(nominal), Some(FeedLimit::Air)), "{block:?}");
        } else {
            assert!(block.feed.unwrap() <= cutting, "{block:?} in contact above {cutting}");
        }
    }
    assert!(plan.blocks.iter().any(|b| b.limited_by == Some(FeedLimit::Air)), "{:?}", plan.blocks);
    assert!(plan.blocks.iter().all(|b| b.feed.unwrap() <= nominal), "{:?}", plan.blocks);
}
