//! Cancellation through the seam: every capability's solve and program writer, run on a large
//! input with the cancel flag raised a few milliseconds in, returns `E_CANCELLED` within 100 ms
//! (of its thread's CPU time) of the raise (a timed-out request, a cancelled job and a stopping server free their solver slot
//! at once), also when raised early or late in the work (engagement: in the contact, the samples'
//! forces, the flute statistics).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use kerf_cases::predict;
use kerf_cases::split::{context, contour_context, contour_request, deburr_context, deburr_request};
use kerf_solver::SolverError;
use kerf_solver::capability::{self, Capability, Control, OutputOptions, Purpose, Resolved, Run, resolve};
use kerf_solver::contour::{ContourCapability, LoopsRequest};
use kerf_solver::deburr::DeburrCapability;
use kerf_solver::engagement::EngagementCapability;
use kerf_solver::error::ErrorCode;
use kerf_solver::gcode::Arcs;
use kerf_solver::predict::{Method, PredictCapability};
use kerf_solver::segment::{SegmentCapability, SegmentRequest};
use kerf_solver::tool::Tool;
use serde_json::json;

use crate::inline::Inline;

/// When the flag is raised after the work started.
const RAISE_AFTER: Duration = Duration::from_millis(20);
/// The most CPU time the work may spend after the raise. CPU time, not wall time, so that a
/// machine busy with other work does not fail the test; it ticks in 10 ms steps.
const BOUND: Duration = Duration::from_millis(100);
/// The most wall time the work may take after the raise, however busy the machine.
const WALL_BOUND: Duration = Duration::from_secs(5);

/// CPU time (user and system) of thread `task` of this process, from `/proc`.
fn thread_cpu(task: &str) -> Duration {
    let stat = std::fs::read_to_string(format!("/proc/self/task/{task}/stat")).expect("thread stat");
    let fields: Vec<&str> = stat.rsplit_once(") ").expect("stat fields").1.split(' ').collect();
    let ticks: u64 = fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap();
    // USER_HZ is 100 on Linux.
    Duration::from_millis(ticks * 10)
}

/// This thread's id, as `/proc/self/task` names it.
fn this_thread() -> String {
    let link = std::fs::read_link("/proc/thread-self").expect("/proc/thread-self");
    link.file_name().unwrap().to_string_lossy().into_owned()
}

/// What the work did after the cancel flag was raised.
struct AfterRaise {
    cpu: Duration,
    wall: Duration,
}

/// Runs `work` with a cancel flag raised `raise_after` in; what it spent after the raise, and
/// what it returned.
fn cancel_during<T: Send>(
    raise_after: Duration,
    work: impl FnOnce(Control<'_>) -> Result<T, SolverError> + Send,
) -> (AfterRaise, Result<T, SolverError>) {
    let flag = AtomicBool::new(false);
    let (task_sender, task) = std::sync::mpsc::channel();
    let (read_sender, read) = std::sync::mpsc::channel();
    std::thread::scope(|scope| {
        let flag = &flag;
        let running = scope.spawn(move || {
            let me = this_thread();
            task_sender.send(me.clone()).unwrap();
            let result = work(Control { progress: None, cancel: Some(flag) });
            let ended = Instant::now();
            // The thread stays until its CPU time at the raise is read, so work that ended
            // first (a busy machine may wake the raise late) is told apart from a missing thread.
            read.recv().unwrap();
            (ended, thread_cpu(&me), result)
        });
        let task = task.recv().unwrap();
        std::thread::sleep(raise_after);
        let (raised, cpu_at_raise) = (Instant::now(), thread_cpu(&task));
        flag.store(true, Ordering::Relaxed);
        read_sender.send(()).unwrap();
        let (ended, cpu_at_end, result) = running.join().expect("the work does not panic");
        let after =
            AfterRaise { cpu: cpu_at_end.saturating_sub(cpu_at_raise), wall: ended.saturating_duration_since(raised) };
        (after, result)
    })
}

/// `work` ended with `E_CANCELLED` within [`BOUND`] of CPU time after a raise [`RAISE_AFTER`] in.
fn stops<T: Send>(what: &str, work: impl FnOnce(Control<'_>) -> Result<T, SolverError> + Send) {
    stops_raised_after(what, RAISE_AFTER, work);
}

/// `work` ended with `E_CANCELLED` within [`BOUND`] of CPU time after a raise `raise_after` in
/// (and was still running then: an input too small to outlast the raise proves nothing).
fn stops_raised_after<T: Send>(
    what: &str,
    raise_after: Duration,
    work: impl FnOnce(Control<'_>) -> Result<T, SolverError> + Send,
) {
    let (after, result) = cancel_during(raise_after, work);
    let Err(error) = result else {
        assert!(after.wall > Duration::ZERO, "{what} finished before the cancel flag was raised: use a larger input");
        panic!("{what} ran to its end, {:?} of CPU after the cancel flag was raised", after.cpu);
    };
    assert_eq!(error.code(), ErrorCode::Cancelled, "{what}: {error:?}");
    assert!(after.cpu <= BOUND, "{what} ran on for {:?} of CPU after the cancel flag was raised", after.cpu);
    assert!(after.wall <= WALL_BOUND, "{what} ran on for {:?} after the cancel flag was raised", after.wall);
}

/// `C`'s solve of `request` for `purpose`, under `control`.
fn solve<C: Capability>(
    request: &C::Request,
    context: Resolved<C::Tool>,
    purpose: Purpose,
    control: Control<'_>,
) -> Result<C::Answer, SolverError> {
    C::solve(request, context, &Run { control, purpose, ..Run::default() })
}

/// `C`'s program of an answer, under `control`.
fn program<C: Capability>(
    request: &C::Request,
    answer: &C::Answer,
    output: &OutputOptions,
    control: Control<'_>,
) -> Result<String, SolverError> {
    capability::program::<C>(request, answer, output, control)
}

fn segment_request() -> SegmentRequest {
    // A large ellipse at a tiny chord error: hundreds of thousands of blocks.
    serde_json::from_value(json!({
        "curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [1000, 625]},
        "feed": 1000, "block_time_ms": 0.5, "mode": "curve", "tolerance": 1e-6,
    }))
    .unwrap()
}

#[test]
fn segment_solve_and_program_stop() {
    let request = segment_request();
    let none = || Resolved { tool: None::<Tool>, machine: None, material: None, other_tools: Vec::new() };
    stops("segment solve", |control| solve::<SegmentCapability>(&request, none(), Purpose::Program, control));
    let answer = solve::<SegmentCapability>(&request, none(), Purpose::Program, Control::default()).unwrap();
    stops("segment program", |control| {
        program::<SegmentCapability>(&request, &answer, &OutputOptions::default(), control)
    });
}

#[test]
fn contour_solve_and_program_stop() {
    // Layers enough that the faster writer still writes their program for longer than the
    // raise; the program alone (its verification would cut it within the solve).
    let request = contour_request(6_000, json!({"tolerance": 0.0005, "verification": {"enabled": false}}));
    stops("contour solve", |control| {
        solve::<ContourCapability>(&request, contour_context(false), Purpose::Program, control)
    });
    let answer =
        solve::<ContourCapability>(&request, contour_context(false), Purpose::Program, Control::default()).unwrap();
    for arcs in [Arcs::Chords, Arcs::G2g3] {
        let output = OutputOptions { arcs: Some(arcs), ..OutputOptions::default() };
        // With arcs the program is a few blocks a layer: raised early.
        stops_raised_after(&format!("contour program ({arcs:?})"), Duration::from_millis(5), |control| {
            program::<ContourCapability>(&request, &answer, &output, control)
        });
    }
}

#[test]
fn contour_loops_stop() {
    // A star of 100 000 points: a loop at every other one.
    let path: Vec<[f64; 2]> = (0..100_000)
        .map(|k| {
            let angle = std::f64::consts::TAU * f64::from(k) / 100_000.0;
            let radius = if k % 2 == 0 { 5000.0 } else { 4999.0 };
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect();
    let request: LoopsRequest = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 0.5}, "path": path, "tolerance": 0.0005,
    }))
    .unwrap();
    let tool = Tool::new(kerf_solver::tool::ToolKind::Flat, 0.5);
    stops("contour loops", |control| request.solve(tool, control));
}

#[test]
fn deburr_solve_and_program_stop() {
    // The most holes a request may have, at a fine tolerance: its program takes tens of
    // milliseconds to write even in a debug build, so it is raised early.
    let holes: Vec<(f64, f64, f64)> = (0..100).map(|k| (4.0, 90.0, 20.0 * f64::from(k))).collect();
    let request = deburr_request(&holes, "both", json!({"tolerance": 3e-6}));
    stops("deburr solve", |control| {
        solve::<DeburrCapability>(&request, deburr_context(Some(2.0), false), Purpose::Program, control)
    });
    let answer =
        solve::<DeburrCapability>(&request, deburr_context(Some(2.0), false), Purpose::Program, Control::default())
            .unwrap();
    stops_raised_after("deburr program", Duration::from_millis(5), |control| {
        program::<DeburrCapability>(&request, &answer, &OutputOptions::default(), control)
    });
}

#[test]
fn predict_solve_and_program_stop() {
    let (request, tool, _) = predict::raster_request(60.0, 0.1, 0.1, Method::Sampling, 64);
    stops("predict solve", |control| solve::<PredictCapability>(&request, context(&tool), Purpose::Program, control));
}

#[test]
fn a_long_contour_stops_while_planned() {
    // 200 000 vertices (the limit), one layer: the time goes into planning the passes.
    let contour: Vec<[f64; 2]> = (0..200_000)
        .map(|k| {
            let angle = std::f64::consts::TAU * f64::from(k) / 200_000.0;
            let radius = if k % 2 == 0 { 5000.0 } else { 4999.5 };
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect();
    let request = contour_request(1, json!({"contour": contour}));
    stops("contour plan", |control| {
        solve::<ContourCapability>(&request, contour_context(false), Purpose::Program, control)
    });
}

#[test]
fn gcode_reading_stops() {
    let text: String = (0..2_000_000).map(|k| format!("G01 X{}.5 Y1 Z0 F600\n", k % 1000)).collect();
    stops("G-code reading", |control| {
        kerf_solver::gcode::reader::read_cancellable(
            &text,
            "path.program",
            &kerf_solver::gcode::reader::ReadOptions { max_lines: 3_000_000, ..Default::default() },
            control,
        )
    });
}

/// A flat end with a helix slotting 220 mm at a 0.05 mm step (4 400 samples), 8 flute counts
/// with Kienzle forces, a feed plan and a block time: seconds of work after the contact, most of
/// it the forces of every flute count at every sample.
fn large_engagement_request() -> serde_json::Value {
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

#[test]
fn engagement_solve_stops_early_and_late() {
    let request = serde_json::from_value(large_engagement_request()).expect("a valid request");
    // Early (in the contact), later (in the samples' forces) and later still.
    for raise_after_ms in [5, 30, 300] {
        let context: Resolved<Tool> = resolve(EngagementCapability::refs(&request), &Inline).expect("inline tool");
        stops_raised_after(
            &format!("engagement solve, raised after {raise_after_ms} ms"),
            Duration::from_millis(raise_after_ms),
            |control| solve::<EngagementCapability>(&request, context, Purpose::Json, control),
        );
    }
}
