//! Contour requests (`POST /api/v1/contour`, a job's `contour` operation).

use serde_json::{Value, json};

use crate::number;

/// The request of a reference case of the contour fixture (docs/spec/contour.md, C1–C3): an
/// inline flat tool of the case's radius, one layer at z = 0, conventional milling (σ = +1, the
/// cases' convention), the case's passes and the loop style of its loop passes.
///
/// # Panics
/// When a pass has a join the cases do not use.
pub fn reference_request(case: &Value) -> Value {
    let inputs = &case["inputs"];
    let mut corner_loop = json!({"max_angle_deg": 180.0 - number(&inputs["phi_min_deg"])});
    let passes: Vec<Value> = inputs["passes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|pass| match pass["join"].as_str().unwrap() {
            "loop_arc" => {
                corner_loop["style"] = json!("arc");
                corner_loop["radius"] = pass["rho"].clone();
                json!({"allowance": pass["delta"], "loop": true})
            }
            "loop_par" => {
                corner_loop["style"] = json!("parallelogram");
                corner_loop["leg"] = pass["L"].clone();
                json!({"allowance": pass["delta"], "loop": true})
            }
            "round" => json!({"allowance": pass["delta"], "loop": false, "join": "round"}),
            other => panic!("unknown join {other}"),
        })
        .collect();
    // The fixture rounds its inputs to 1e-6; where the spec gives a vertex exactly (C2's
    // (18 + √3, 1 + 6√3)), the exact value, so derived angles match to 1e-6 degrees too.
    let exact = [18.0 + 3f64.sqrt(), 1.0 + 6.0 * 3f64.sqrt()];
    let contour: Vec<[f64; 2]> = inputs["contour"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let p = [number(&p[0]), number(&p[1])];
            if (p[0] - exact[0]).abs() < 1e-6 && (p[1] - exact[1]).abs() < 1e-6 { exact } else { p }
        })
        .collect();
    json!({
        "tool": {"kind": "flat", "radius": number(&inputs["tool_radius"])},
        "contour": contour,
        "side": "outside",
        "direction": "conventional",
        "depths": {"top": 1.0, "bottom": 0.0, "step": 1.0},
        "corner_loop": corner_loop,
        "passes": passes,
        "feed": 800,
    })
}

/// [`reference_request`] of the case `id` (`C1`, `C2`, `C3`).
pub fn reference(id: &str) -> Value {
    reference_request(&crate::case("contour", id))
}

/// A pocket whose top wall has a wedge of material reaching into it (a 53° tip at (40, 40)):
/// three layers, a loop at the tip, dogbone relief in the inside corners, stored tool 3 (flat R3).
pub fn pocket_request() -> Value {
    json!({
        "tool": 3,
        "contour": [[0, 0], [80, 0], [80, 60], [50, 60], [40, 40], [30, 60], [0, 60]],
        "side": "inside",
        "depths": {"top": 0, "bottom": -6, "step": 2},
        "corner_loop": {"style": "arc"},
        "inside_corner_relief": "dogbone",
        "feed": 800,
        "loop_feed": 1500,
        "stock_allowance": 0.5,
        "passes": [{"allowance": 0.3, "join": "round"}, {"allowance": 0}]
    })
}

/// The arrow island of `examples/contour-arrow.toml`, `layers` layers of 1 mm deep, stored tool 3.
pub fn arrow_request(layers: usize) -> Value {
    json!({
        "tool": 3,
        "contour": [[0, 10], [40, 10], [40, 0], [80, 25], [40, 50], [40, 40], [0, 40]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -(layers as f64), "step": 1},
        "corner_loop": {"style": "arc"}, "inside_corner_relief": "dogbone",
        "feed": 800, "loop_feed": 2000, "stock_allowance": 0.5, "spindle_rpm": 8000,
        "passes": [{"allowance": 0.3, "join": "round"}, {"allowance": 0}],
    })
}

/// A circle of `points` vertices with radius 30: no corner turns enough for a loop.
pub fn circle(points: usize) -> Vec<[f64; 2]> {
    (0..points)
        .map(|k| {
            let angle = std::f64::consts::TAU * k as f64 / points as f64;
            [30.0 * angle.cos(), 30.0 * angle.sin()]
        })
        .collect()
}
