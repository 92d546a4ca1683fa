//! Every reference case of `solver/tests/fixtures/deburr.json` (copied to `tests/fixtures/`): ball centres,
//! band edges and wedge angles at the sample points to 1e-6, and the tolerance algorithm's point
//! counts and parameter lists exactly (docs/spec/deburr.md §5.2).

use kerf_cases::{number, triple};
use kerf_solver::deburr::{self, DeburrRequest, Edge, Hole, Workpiece};
use kerf_solver::tool::{Tool, ToolKind, ToolRef};
use serde_json::Value;

const TOLERANCE: f64 = 1e-6;

fn cases() -> Vec<Value> {
    kerf_cases::fixture("deburr")["cases"].as_array().unwrap().clone()
}

fn assert_close(what: &str, got: f64, expected: f64) {
    assert!((got - expected).abs() <= TOLERANCE, "{what}: got {got}, expected {expected}");
}

fn assert_point(what: &str, got: [f64; 3], expected: [f64; 3]) {
    for axis in 0..3 {
        assert_close(&format!("{what}[{axis}]"), got[axis], expected[axis]);
    }
}

/// Builds the API request for a case: outer ridges on a tube, inner ridges on a bored block.
fn request(case: &Value) -> (DeburrRequest, Tool) {
    let inputs = &case["inputs"];
    let r1 = number(&inputs["R1"]);
    let origin = triple(&inputs["O_on_A1_at_hole_station"]);
    let arrangement = number(&inputs["arrangement_deg"]);
    let edge = if inputs["side"] == "outer" { Edge::Outer } else { Edge::Inner };
    let workpiece = match edge {
        Edge::Outer | Edge::Both => Workpiece::tube(origin, arrangement, r1 * 0.75, r1),
        Edge::Inner => Workpiece::BoreBlock {
            origin,
            arrangement_angle_deg: arrangement,
            bore_radius: r1,
            face_distance: Some(r1 + 20.0),
        },
    };
    let shape = &inputs["shape"];
    let hole_json = match shape["type"].as_str().unwrap() {
        "circle" => serde_json::json!({"shape": "round", "radius": shape["R2"]}),
        "slot" => {
            serde_json::json!({"shape": "slot", "radius": shape["R2"], "centre_distance": shape["Ls"]})
        }
        "rounded_rect" => serde_json::json!({
            "shape": "rounded_rect", "radius": shape["R2"],
            "centre_distance": [2.0 * number(&shape["a"]), 2.0 * number(&shape["b"])]
        }),
        other => panic!("unknown shape {other}"),
    };
    let mut hole: Hole = serde_json::from_value(hole_json).unwrap();
    hole.eccentricity = Some(number(&shape["f"]));
    hole.penetration_angle_deg = number(&inputs["penetration_deg"]);
    let tool = Tool::new(ToolKind::Ball, number(&inputs["tool_radius_D"]));
    let request = DeburrRequest {
        tool: ToolRef::Inline(tool.clone()),
        workpiece,
        hole: Some(hole),
        holes: None,
        pattern: None,
        edge,
        inner_tool: None,
        cut_amount: Some(number(&inputs["Q"])),
        width: None,
        tolerance: Some(number(&inputs["TA"])),
        method: deburr::Method::Tangent,
        start_deg: 0.0,
        direction: deburr::Direction::Ccw,
        feed: None,
        spindle_rpm: None,
        clearance: None,
        lead_distance: None,
        safe_z: None,
        machine: None,
        block_time_ms: None,
        verification: None,
        units: None,
    };
    (request, tool)
}

fn segment_name(reference: &str) -> String {
    reference.to_lowercase()
}

#[test]
fn sample_constructions_match() {
    for case in cases() {
        let (request, tool) = request(&case);
        let id = case["id"].as_str().unwrap();
        for sample in case["samples"].as_array().unwrap() {
            let segment = segment_name(sample["segment"].as_str().unwrap());
            let s = number(&sample["s"]);
            let got = deburr::construction_at(&request, &tool, &segment, s).unwrap();
            let at = format!("{id} {segment} s={s}");
            assert_point(&format!("{at} P"), got.target, triple(&sample["P"]));
            assert_point(&format!("{at} C"), got.centre, triple(&sample["C"]));
            assert_point(&format!("{at} u"), got.bisector, triple(&sample["u"]));
            assert_point(&format!("{at} G1"), got.band_edge_cylinder, triple(&sample["G1"]));
            assert_point(&format!("{at} G2"), got.band_edge_wall, triple(&sample["G2"]));
            assert_close(&format!("{at} beta"), got.wedge_angle_deg, number(&sample["beta_deg"]));
            assert_close(&format!("{at} L"), got.chord_depth, number(&sample["L"]));
            assert_close(&format!("{at} CL"), got.centre_offset, number(&sample["CL"]));
        }
    }
}

#[test]
fn tolerance_paths_match_counts_and_parameters() {
    for case in cases() {
        let (request, tool) = request(&case);
        let id = case["id"].as_str().unwrap();
        let path = &case["path"];
        let result = deburr::solve(&request, &tool).unwrap();
        assert_eq!(result.points.len() as u64, path["n_points_closed"].as_u64().unwrap(), "{id} closed count");
        assert_eq!(result.summary.count as u64, path["n_distinct"].as_u64().unwrap(), "{id} distinct count");

        // The parameter list of each segment, with its start shared with the previous segment's end.
        for name in path["segment_order"].as_array().unwrap() {
            let name = name.as_str().unwrap();
            let expected: Vec<f64> = path["segment_params"][name].as_array().unwrap().iter().map(number).collect();
            let lower = segment_name(name);
            let mut got: Vec<f64> = result.points.iter().filter(|p| p.segment == lower).map(|p| p.parameter).collect();
            if got.first() != Some(&0.0) {
                got.insert(0, 0.0);
            }
            // The first segment also carries the loop's start point (already at 0).
            got.dedup();
            assert_eq!(got, expected, "{id} {name} parameters");
        }

        for (index, first) in path["first_points"].as_array().unwrap().iter().enumerate() {
            let point = &result.points[index];
            assert_eq!(point.segment, segment_name(first["segment"].as_str().unwrap()), "{id} first {index}");
            assert_close(&format!("{id} first {index} s"), point.parameter, number(&first["s"]));
            assert_point(&format!("{id} first {index} C"), point.centre, triple(&first["C"]));
        }
        let last = result.points.last().unwrap();
        assert_point(&format!("{id} last C"), last.centre, triple(&path["last_point"]["C"]));
        assert_eq!(last.centre, result.points[0].centre, "{id} closed");

        let dense = number(&path["max_dev_dense_check"]);
        assert!(result.summary.max_deviation <= number(&case["inputs"]["TA"]) + 1e-12, "{id} deviation");
        assert!(
            (result.summary.max_deviation - dense).abs() < 0.1 * dense,
            "{id} deviation {} vs {dense}",
            result.summary.max_deviation
        );
    }
}
