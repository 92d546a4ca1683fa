//! The engagement answer's JSON: the hand-written samples give exactly the
//! bytes `serde_json::to_vec` gives, for one path and for candidates side by side, with forces,
//! a machine's cycle time and blocks, flags and arc details.

use kerf_solver::capability::{Capability, Resolved, Run};
use kerf_solver::engagement::{EngagementCapability, EngagementRequest};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

fn same_bytes(body: Value, machine: Option<Value>) {
    let request: EngagementRequest = serde_json::from_value(body).unwrap();
    let mut tool = Tool::new(ToolKind::Flat, 5.0);
    tool.flutes = 3;
    let machine = machine.map(|m| serde_json::from_value(m).unwrap());
    let context = Resolved { tool, machine, material: None, other_tools: Vec::new() };
    let answer = EngagementCapability::solve(&request, context, &Run::default()).unwrap();
    let expected = serde_json::to_vec(&answer).unwrap();
    let ours = EngagementCapability::to_json(answer).unwrap();
    assert_eq!(String::from_utf8(ours).unwrap(), String::from_utf8(expected).unwrap());
}

#[test]
fn one_path_with_plunge_rapid_and_back_contact() {
    same_bytes(
        json!({
            "tool": 1, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
            "path": {"start": [20, 20], "segments": [
                {"type": "line", "to": [40, 20]},
                {"type": "line", "to": [30, 20]},
                {"type": "line", "to": [30, 60], "rapid": true},
                {"type": "arc", "to": [10, 40], "center": [10, 60], "dir": "ccw"},
                {"type": "line", "to": [-10, 30]}
            ]},
            "spindle_rpm": 6000, "feed_per_tooth": 0.04, "flute_counts": [1, 2, 5],
            "thickness_limit": 0.05, "step": 0.5, "radial_depth_max": 6, "radial_depth_min": 0.5,
            "axial_depth": 2
        }),
        None,
    );
}

#[test]
fn candidates_with_forces_and_a_machine() {
    same_bytes(
        json!({
            "tool": 1, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
            "paths": [
                {"name": "straight \"samples\":[]", "path": [[-10, 20], [70, 20]]},
                {"name": "zig-zag", "path": [[-10, 5], [70, 5], [70, 15], [-10, 15], [-10, 25], [70, 25]]},
                {"path": [[-10, 30], [35, 20], [70, 35]], "axial_depth": 3}
            ],
            "spindle_rpm": 8000, "feed_per_tooth": 0.05, "flute_counts": [2, 3, 4],
            "thickness_limit": 0.08, "step": 0.1, "kienzle": {"kc11": 1800, "mc": 0.25}, "axial_depth": 2,
            "feed_plan": {"target_thickness": 0.04, "max_feed": 3000}
        }),
        Some(json!({"name": "mill", "block_time_ms": 4, "max_feed": 12000, "max_accel": 2000})),
    );
}
