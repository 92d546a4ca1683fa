//! Deburring requests (`POST /api/v1/deburr`, a job's `deburr` operation).

use serde_json::{Value, json};

/// `hole` on `edge` of a tube of radii 30 and 50, stored tool 7, cut 0.3, tolerance 0.01.
pub fn request(hole: Value, edge: &str) -> Value {
    json!({
        "tool": 7,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 30, "outer_radius": 50},
        "hole": hole,
        "edge": edge,
        "cut_amount": 0.3,
        "tolerance": 0.01
    })
}

/// The outer edge of an R8 hole in a tube of radii 15 and 25 (as `examples/deburr-tube.toml`),
/// stored tool 7, cut 0.3, tolerance 0.01.
pub fn tube_request() -> Value {
    json!({
        "tool": 7,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 8}, "edge": "outer", "cut_amount": 0.3, "tolerance": 0.01
    })
}

/// Reference case 1 of docs/spec/deburr.md: the outer edge of an R10 hole in a tube of radii 40
/// and 50, cut 0.5, an inline ball end mill R3, every option at its default (92 points at
/// tolerance 0.01).
pub fn case_1() -> Value {
    json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
        "hole": {"shape": "round", "radius": 10}, "edge": "outer", "cut_amount": 0.5
    })
}

/// [`case_1`] solved slowly, to keep a worker busy for a while: the exact method at tolerance
/// 2e-6, with the tool's number 7.
pub fn long_request() -> Value {
    crate::with(
        case_1(),
        json!({"tool": {"kind": "ball", "radius": 3, "number": 7}, "tolerance": 2e-6, "method": "exact"}),
    )
}

/// A tube's holes (radius, penetration angle, axial position) deburred at `edge`: a tube of radii
/// 15 and 25, stored tool 7, cut 0.3.
pub fn holes_request(holes: &[(f64, f64, f64)], edge: &str) -> Value {
    let holes: Vec<_> = holes
        .iter()
        .map(|&(radius, angle, along)| {
            json!({"shape": "round", "radius": radius, "penetration_angle_deg": angle, "axial_position": along})
        })
        .collect();
    json!({
        "tool": 7, "edge": edge, "cut_amount": 0.3,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "holes": holes,
    })
}
