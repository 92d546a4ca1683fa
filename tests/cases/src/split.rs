//! Requests for the split tests and the cost-model measurement (`tests/load/cost_model.rs`):
//! engagement candidates, a contour of some layers, a tube's holes, typed with the context the
//! server would resolve; and parts' outputs kept as JSON text, as the job store keeps them (CBOR
//! there).

use kerf_solver::capability::{PartSink, PartSource, Resolved};
use kerf_solver::contour::ContourRequest;
use kerf_solver::deburr::DeburrRequest;
use kerf_solver::engagement::EngagementRequest;
use kerf_solver::machine::MachineProfile;
use kerf_solver::tool::Tool;
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::json;

/// Parts' outputs as JSON text, as the job store keeps them.
#[derive(Default)]
pub struct Texts(pub Vec<String>, pub usize);

impl PartSink for Texts {
    fn put<T: Serialize>(&mut self, value: &T) -> Result<(), kerf_solver::SolverError> {
        self.0.push(serde_json::to_string(value).unwrap());
        Ok(())
    }
}

impl PartSource for Texts {
    fn count(&self) -> usize {
        self.0.len()
    }

    fn next_part<T: DeserializeOwned>(&mut self) -> Option<Result<T, kerf_solver::SolverError>> {
        let text = self.0.get(self.1)?;
        self.1 += 1;
        Some(Ok(serde_json::from_str(text).unwrap()))
    }
}

/// The context of `tool` alone: no machine, material or other tools.
pub fn context(tool: &Tool) -> Resolved<Tool> {
    Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() }
}

/// Three candidate paths through a 60 × 40 mm block, cut by a 4-flute Ø10 end mill at 2 mm a_p
/// with Kienzle forces, on a machine with a block time and accelerations (blocks, cycle time).
pub fn engagement_request(step: f64) -> (EngagementRequest, Tool, MachineProfile) {
    let request = serde_json::from_value(serde_json::json!({
        "tool": 1, "machine": "mill",
        "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "paths": [
            {"name": "straight", "path": [[-10, 20], [70, 20]]},
            {"name": "zig-zag", "path": [[-10, 5], [70, 5], [70, 15], [-10, 15], [-10, 25], [70, 25]]},
            {"name": "deeper", "path": [[-10, 30], [35, 20], [70, 35]], "axial_depth": 3},
        ],
        "spindle_rpm": 8000, "feed_per_tooth": 0.05, "flute_counts": [2, 3, 4],
        "thickness_limit": 0.08, "step": step, "kienzle": {"kc11": 1800, "mc": 0.25}, "axial_depth": 2,
        "candidate": 1,
    }))
    .unwrap();
    let mut tool = Tool::new(kerf_solver::tool::ToolKind::Flat, 5.0);
    tool.flutes = 4;
    let machine = serde_json::from_value(serde_json::json!({
        "name": "mill", "block_time_ms": 4, "max_feed": 12000, "max_accel": 2000, "dialect": "linuxcnc"
    }))
    .unwrap();
    (request, tool, machine)
}

/// A flat end mill of `radius`.
pub fn flat(radius: f64) -> Tool {
    Tool::new(kerf_solver::tool::ToolKind::Flat, radius)
}

/// The arrow island of `examples/contour-arrow.toml` ([`crate::contour::arrow_request`]),
/// `layers` layers deep, with `extra` fields.
pub fn contour_request(layers: usize, extra: serde_json::Value) -> ContourRequest {
    serde_json::from_value(crate::with(crate::contour::arrow_request(layers), extra)).unwrap()
}

pub fn contour_context(machine: bool) -> Resolved<Tool> {
    let machine = machine.then(|| {
        serde_json::from_value(json!({
            "name": "mill", "block_time_ms": 2, "max_feed": 12000, "max_accel": 2000, "dialect": "linuxcnc"
        }))
        .unwrap()
    });
    Resolved { tool: flat(3.0), machine, material: None, other_tools: Vec::new() }
}

/// A ball end mill of `radius`.
pub fn ball(radius: f64) -> Tool {
    Tool::new(kerf_solver::tool::ToolKind::Ball, radius)
}

/// A tube's holes (radius, penetration angle, axial position) deburred at `edge`
/// ([`crate::deburr::holes_request`]), with `extra` fields.
pub fn deburr_request(holes: &[(f64, f64, f64)], edge: &str, extra: serde_json::Value) -> DeburrRequest {
    serde_json::from_value(crate::with(crate::deburr::holes_request(holes, edge), extra)).unwrap()
}

pub fn deburr_context(inner: Option<f64>, machine: bool) -> Resolved<Tool> {
    let machine = machine.then(|| {
        serde_json::from_value(json!({"name": "mill", "block_time_ms": 2, "max_feed": 6000, "max_accel": 1000}))
            .unwrap()
    });
    Resolved { tool: ball(3.0), machine, material: None, other_tools: inner.map(ball).into_iter().collect() }
}
