//! The corrected program: a G-code input comes back with the same lines, block numbers,
//! comments and modal words and only coordinates changed (arcs still close); a path of points
//! becomes a complete program; iterations and the clamp behave (docs/spec/predict.md §3.14, §8).

use kerf_cases::predict::{bare_request, finishing_tool};
use kerf_solver::gcode::reader::{self, ReadOptions};
use kerf_solver::gcode::{Dialect, Reference, SpindleDirection, ToolCall};
use kerf_solver::predict::{
    self, CorrectionOptions, PassFlag, PassStatus, PathInput, PredictRequest, PrescribedDeflection, ProgramOptions,
};
use kerf_solver::stock::Stock;
use kerf_solver::tool::Tool;

const PROGRAM: &str = "%\nO0002 (CORRECT ME)\nN10 G21 G90 G17 G94\nN20 T1 M06\nN30 S8000 M03\n\
N40 G0 X-8 Y-0.8 Z20\nN50 G1 Z0 F1600 ; plunge outside the block\nN60 X28\nN70 Y-0.4\nN80 X-8\n\
N90 Y0\nN100 X28 (MIDDLE)\nN110 Y0.4\nN120 X-8\nN130 Y0.8\nN140 X28\nN150 G0 Z20\nN160 M05\nN170 M30\n%\n";

/// A flat block with a wall: raster lines along X; a prescribed deflection toward −Y and a
/// radius error give every line an error.
fn request(program: &str) -> (PredictRequest, Tool) {
    let tool = finishing_tool(3.0);
    let mut request = bare_request(
        &tool,
        Stock::Box { min: [0.0, -5.0, -10.0], max: [20.0, 5.0, 0.1] },
        PathInput::Gcode { program: program.to_owned() },
    );
    request.reference = Reference::Tip;
    request.deflection = Some(PrescribedDeflection { x: vec![0.004], y: vec![-0.006] });
    (request, tool)
}

fn options() -> ProgramOptions {
    ProgramOptions { dialect: Dialect::Fanuc, tool: ToolCall::Table(1), units: kerf_solver::units::Units::Mm }
}

/// The line without its coordinate words.
fn skeleton(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    let mut in_comment = false;
    while let Some(c) = chars.next() {
        if c == '(' || c == ';' {
            in_comment = true;
        }
        if !in_comment && "XYZIJKR".contains(c) {
            while chars.peek().is_some_and(|d| d.is_ascii_digit() || *d == '.' || *d == '-') {
                chars.next();
            }
            continue;
        }
        out.push(c);
    }
    out.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[test]
fn gcode_comes_back_with_only_coordinates_changed() {
    let (request, tool) = request(PROGRAM);
    let answer = predict::solve(&request, &tool, None).unwrap();
    assert!(answer.summary.predicted >= 3, "{:?}", answer.summary);
    assert!(answer.summary.max_correction > 0.0);
    let corrected = predict::corrected_program(&request, &answer, &options()).unwrap();
    assert_eq!(corrected.lines().count(), PROGRAM.lines().count());
    let mut changed = 0;
    for (old, new) in PROGRAM.lines().zip(corrected.lines()) {
        if old != new {
            changed += 1;
            assert_eq!(skeleton(old), skeleton(new), "{old:?} → {new:?}");
        }
    }
    assert!(changed >= 3);
    // Rapids stay byte for byte: only cutting moves change.
    for (old, new) in PROGRAM.lines().zip(corrected.lines()).filter(|(old, _)| old.contains(" G0 ")) {
        assert_eq!(old, new);
    }
    assert_eq!(PROGRAM.lines().filter(|l| l.contains(" G0 ")).count(), 2);
    // Every pass ends where the answer says, to the written precision.
    let read = reader::read(&corrected, "program", &ReadOptions::default()).unwrap();
    let feed_moves: Vec<_> = read.moves.iter().filter(|m| !matches!(m.kind, reader::MoveKind::Rapid)).collect();
    assert_eq!(feed_moves.len(), answer.passes.len());
    for (pass, read_move) in answer.passes.iter().zip(feed_moves) {
        let end = read_move.to_xyz().unwrap();
        for k in 0..3 {
            assert!((end[k] - pass.corrected[k]).abs() < 6e-5, "pass {}: {end:?} vs {:?}", pass.index, pass.corrected);
        }
        assert_eq!(Some(read_move.line), pass.line);
    }
    // The corrected middle line moves against the error: along its normal by about −e.
    let middle = &answer.passes[5];
    assert_eq!(middle.status, PassStatus::Ok);
    let n = middle.normal.unwrap();
    let along: f64 = (0..3).map(|k| middle.correction[k] * n[k]).sum();
    assert!((along + middle.error.unwrap()).abs() < 1e-9, "{along} vs {:?}", middle.error);
}

#[test]
fn corrected_arcs_still_close() {
    let program = "G21 G90 G17\nS8000 M03\nG0 X6 Y0 Z20\nG1 Z0 F1000\nG2 X-6 Y0 I-6 J0\nG2 X6 Y0 R6\n\
                   G1 X5.6\nG3 X-5.6 Y0 I-5.6 J0\nG3 X5.6 Y0 I5.6 J0\nG0 Z20\nM30\n";
    let (mut request, tool) = request(program);
    request.stock = Stock::Box { min: [-20.0, -20.0, -10.0], max: [20.0, 20.0, 0.1] };
    let answer = predict::solve(&request, &tool, None).unwrap();
    assert!(answer.summary.predicted > 10);
    let corrected = predict::corrected_program(&request, &answer, &options()).unwrap();
    let read = reader::read(&corrected, "program", &ReadOptions::default()).unwrap();
    assert_eq!(read.moves.len(), 8);
    for (line_index, (old, new)) in program.lines().zip(corrected.lines()).enumerate() {
        assert_eq!(skeleton(old), skeleton(new), "line {}", line_index + 1);
    }
    // Arc ends land on the corrected chord ends of their last chords.
    let original = reader::read(program, "program", &ReadOptions::default()).unwrap();
    for (moved, read_move) in read.moves.iter().zip(&original.moves) {
        if matches!(read_move.kind, reader::MoveKind::Arc { .. }) {
            let last_pass = answer.passes.iter().rev().find(|p| p.line == Some(read_move.line)).unwrap();
            let end = moved.to_xyz().unwrap();
            for (got, want) in end.iter().zip(last_pass.corrected) {
                assert!((got - want).abs() < 6e-5);
            }
        }
    }
}

#[test]
fn points_become_a_complete_program() {
    let tool = finishing_tool(3.0);
    let mut request = bare_request(
        &tool,
        Stock::Box { min: [0.0, -5.0, -10.0], max: [20.0, 5.0, 0.1] },
        PathInput::Points {
            points: (0..6)
                .map(|k| [if k % 2 == 0 { -8.0 } else { 28.0 }, 0.4 * f64::from(k / 2), 0.0])
                .flat_map(|p| [p, [if p[0] < 0.0 { 28.0 } else { -8.0 }, p[1], 0.0]])
                .collect(),
        },
    );
    request.reference = Reference::Tip;
    request.feed = Some(1600.0);
    request.spindle_rpm = Some(8000.0);
    let answer = predict::solve(&request, &tool, None).unwrap();
    let text = predict::corrected_program(&request, &answer, &options()).unwrap();
    assert!(text.starts_with("%\nO1000"));
    // The corrections move cutting points only: the rapids are those over the programmed points
    // (first and last at Y 0 and 0.8, the clearance 5 mm over z = 0), byte for byte.
    assert!(answer.summary.max_correction > 0.0);
    let rapids: Vec<&str> = text.lines().filter(|l| l.starts_with("G00 X")).collect();
    assert_eq!(rapids, ["G00 X-8.0000 Y0.0000 Z5.0000", "G00 X-8.0000 Y0.8000 Z5.0000"], "{text}");
    assert!(text.contains("S8000 M03"));
    assert!(text.contains("G01 X"));
    assert!(text.ends_with("M30\n%\n"));
    // A counter-clockwise spindle (which the prediction assumed) is started with M04.
    request.spindle_direction = Some(SpindleDirection::Ccw);
    let answer = predict::solve(&request, &tool, None).unwrap();
    let text = predict::corrected_program(&request, &answer, &options()).unwrap();
    assert!(text.contains("S8000 M04") && !text.contains("M03"), "{text}");
}

#[test]
fn iterations_and_the_clamp() {
    let (mut request, tool) = request(PROGRAM);
    request.correction = Some(CorrectionOptions { max_correction: None, iterations: Some(2) });
    let answer = predict::solve(&request, &tool, None).unwrap();
    assert_eq!(answer.summary.rounds.len(), 2);
    assert!(answer.passes[5].residual_error.is_some());
    request.correction = Some(CorrectionOptions { max_correction: Some(0.001), iterations: None });
    let clamped = predict::solve(&request, &tool, None).unwrap();
    assert!(clamped.summary.max_correction <= 0.001 + 1e-15);
    assert!(clamped.summary.clamped > 0);
    assert!(clamped.passes.iter().any(|p| p.flags.contains(&PassFlag::CorrectionClamped)));
}

#[test]
fn answers_are_deterministic_bytes() {
    let (request, tool) = request(PROGRAM);
    let a = serde_json::to_string(&predict::solve(&request, &tool, None).unwrap()).unwrap();
    let b = serde_json::to_string(&predict::solve(&request, &tool, None).unwrap()).unwrap();
    assert_eq!(a, b);
    assert!(!a.contains("NaN"));
}
