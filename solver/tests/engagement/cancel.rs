//! Cancellation: a large engagement request run through the capability seam stops within 100 ms
//! of its cancel flag being raised, wherever its work is (contact, samples and forces, flute
//! statistics, feed plan, program blocks), so a request past its time limit frees its solver slot.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use kerf_solver::capability::{Capability, Control, Lookup, Resolved, Run, resolve};
use kerf_solver::engagement::EngagementCapability;
use kerf_solver::machine::MachineProfile;
use kerf_solver::material::Material;
use kerf_solver::tool::Tool;
use serde_json::{Value, json};

/// No registry: the request carries its tool inline.
struct Inline;

impl Lookup for Inline {
    fn tool(&self, _number: u32) -> Option<Tool> {
        None
    }
    fn machine(&self, _name: &str) -> Option<MachineProfile> {
        None
    }
    fn material(&self, _name: &str) -> Option<Material> {
        None
    }
}

/// A flat end with a helix slotting 220 mm at a 0.05 mm step (4 400 samples), 8 flute counts
/// with Kienzle forces, a feed plan and a block time: seconds of work after the contact, most of
/// it the forces of every flute count at every sample.
fn large() -> Value {
    json!({
        "tool": {"kind": "flat", "radius": 5, "flutes": 4, "helix_deg": 30},
        "stock": {"polygon": [[0, -20], [200, -20], [200, 20], [0, 20]]},
        "path": [[-10, 0], [210, 0]],
        "spindle_rpm": 6000, "feed_per_tooth": 0.05, "flute_counts": [1, 2, 3, 4, 5, 6, 7, 8],
        "thickness_limit": 0.2, "time_limit_s": 5000, "step": 0.05, "axial_depth": 3,
        "kienzle": {"kc11": 1800, "mc": 0.25},
        "feed_plan": {"target_thickness": 0.05, "max_feed": 5000},
        "block_time_ms": 2,
    })
}

/// Runs `body` with the cancel flag raised after `after`; the time from the raise to the return
/// and whether the run ended in `E_CANCELLED`.
fn cancelled_after(body: &Value, after: Duration) -> (Duration, Option<String>) {
    let request = serde_json::from_value(body.clone()).expect("a valid request");
    let context: Resolved<Tool> = resolve(EngagementCapability::refs(&request), &Inline).expect("inline tool");
    let flag = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let run = Run { control: Control { progress: None, cancel: Some(&flag) }, ..Run::default() };
            let outcome = EngagementCapability::solve(&request, context, &run);
            (Instant::now(), outcome.err().map(|e| e.code().as_str().to_owned()))
        });
        std::thread::sleep(after);
        let raised = Instant::now();
        flag.store(true, Ordering::Relaxed);
        let (ended, code) = worker.join().expect("the solver does not panic");
        (ended.saturating_duration_since(raised), code)
    })
}

#[test]
fn a_large_request_stops_within_100_ms_of_the_cancel_flag() {
    let body = large();
    // Early (in the contact), later (in the samples' forces) and later still.
    for after_ms in [5, 30, 300] {
        let (late, code) = cancelled_after(&body, Duration::from_millis(after_ms));
        assert_eq!(
            code.as_deref(),
            Some("E_CANCELLED"),
            "raised after {after_ms} ms, it ran to the end, {late:?} after the raise"
        );
        assert!(late < Duration::from_millis(100), "raised after {after_ms} ms, it returned {late:?} later");
    }
}
