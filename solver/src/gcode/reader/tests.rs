//! Unit tests of the reader and the rewrite (docs/spec/predict.md §8 corrected G-code).

use super::*;
use crate::error::ErrorCode;

fn read_ok(text: &str) -> ReadProgram {
    read(text, "program", &ReadOptions::default()).unwrap()
}

fn read_err(text: &str) -> SolverError {
    read(text, "program", &ReadOptions::default()).unwrap_err()
}

#[test]
fn reads_moves_with_lines_and_modal_state() {
    let program = read_ok(
        "%\nO1000 (TEST)\nN10 G21 G17 G90 G94\nN20 T3 M06\nN30 S6000 M03\n\
         N40 G00 X0 Y0 Z10 ; rapid\nN50 G01 Z-1 F300\nN60 X10\n/N70 Y5\nN80 G91 X1 Y1\nM30\n%\n",
    );
    let moves = &program.moves;
    assert_eq!(moves.len(), 5);
    assert_eq!(moves[0].line, 6);
    assert_eq!(moves[0].kind, MoveKind::Rapid);
    assert_eq!(moves[0].from, [None; 3]);
    assert_eq!(moves[0].to_xyz(), Some([0.0, 0.0, 10.0]));
    assert_eq!(moves[1].block_number, Some(50));
    assert_eq!(moves[1].modal.feed, Some(300.0));
    assert_eq!(moves[1].modal.spindle, Spindle::Clockwise);
    assert_eq!(moves[1].modal.spindle_rpm, Some(6000.0));
    assert_eq!(moves[1].modal.tool, Some(3));
    assert_eq!(moves[2].to_xyz(), Some([10.0, 0.0, -1.0]));
    assert_eq!(moves[3].line, 9);
    assert_eq!(moves[3].to_xyz(), Some([10.0, 5.0, -1.0]));
    assert_eq!(moves[4].to_xyz(), Some([11.0, 6.0, -1.0]));
    assert_eq!(moves[4].modal.distance, Distance::Incremental);
    let skipped = read(
        "G0 X0 Y0 Z0\n/G1 X5 F100\nG1 Y5 F100\n",
        "program",
        &ReadOptions { block_delete: true, ..ReadOptions::default() },
    )
    .unwrap();
    assert_eq!(skipped.moves.len(), 2);
    assert_eq!(skipped.moves[1].to_xyz(), Some([0.0, 5.0, 0.0]));
}

#[test]
fn inch_programs_are_converted_to_mm() {
    let program = read_ok("G20 G90\nG0 X1 Y2 Z0.5\nG1 X2 F10\nG2 X3 Y3 I0 J1\n");
    assert_eq!(program.moves[0].to_xyz(), Some([25.4, 50.8, 12.7]));
    assert_eq!(program.moves[1].modal.feed, Some(254.0));
    assert_eq!(program.moves[1].modal.units, Units::Inch);
    let MoveKind::Arc { centre, .. } = program.moves[2].kind else {
        panic!("not an arc");
    };
    assert!((centre[0] - 50.8).abs() < 1e-12 && (centre[1] - 76.2).abs() < 1e-12);
}

#[test]
fn arcs_by_centre_and_radius_agree_and_linearise_within_tolerance() {
    let by_centre = read_ok("G0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F100\n");
    let by_radius = read_ok("G0 X10 Y0 Z0\nG3 X0 Y10 R10 F100\n");
    let (MoveKind::Arc { centre: c1, .. }, MoveKind::Arc { centre: c2, .. }) =
        (by_centre.moves[1].kind, by_radius.moves[1].kind)
    else {
        panic!("not arcs");
    };
    assert!((0..3).all(|axis| (c1[axis] - c2[axis]).abs() < 1e-12));
    let points = by_centre.moves[1].points(0.001).unwrap();
    let mut previous = [10.0, 0.0, 0.0];
    for point in &points {
        assert!(((point[0]).hypot(point[1]) - 10.0).abs() < 1e-9);
        let mid = [(previous[0] + point[0]) / 2.0, (previous[1] + point[1]) / 2.0];
        assert!(10.0 - mid[0].hypot(mid[1]) <= 0.001 + 1e-12);
        previous = *point;
    }
    assert_eq!(*points.last().unwrap(), [0.0, 10.0, 0.0]);
    // Long arc with negative R, clockwise.
    let long = read_ok("G0 X10 Y0 Z0\nG2 X0 Y10 R-10 F100\n");
    let MoveKind::Arc { centre, .. } = long.moves[1].kind else {
        panic!("not an arc");
    };
    assert!(centre[0].abs() < 1e-9 && centre[1].abs() < 1e-9);
    let short_cw = read_ok("G0 X10 Y0 Z0\nG2 X0 Y10 R10 F100\n");
    let MoveKind::Arc { centre, .. } = short_cw.moves[1].kind else {
        panic!("not an arc");
    };
    assert!((centre[0] - 10.0).abs() < 1e-9 && (centre[1] - 10.0).abs() < 1e-9);
    // Full circle and a helix in the ZX plane.
    let full = read_ok("G0 X10 Y0 Z0\nG2 X10 Y0 I-10 J0 F100\n");
    assert!(full.moves[1].points(0.01).unwrap().len() > 50);
    let helix = read_ok("G18 G0 X10 Y0 Z0\nG3 X0 Y4 Z10 I-10 K0 F100\n");
    let points = helix.moves[1].points(0.01).unwrap();
    assert!((points[points.len() / 2][1] - 2.0).abs() < 0.2);
}

#[test]
fn bad_programs_are_refused_with_the_line_number() {
    let cases = [
        ("G0 X0 Y0 Z0\nG1 X1 Y1 Q\n", ErrorCode::GcodeSyntax, "line 2"),
        ("G0 X0 Y0 Z0\nG1 X1 (open\n", ErrorCode::GcodeSyntax, "line 2"),
        ("G0 X0 Y0 Z0\nG1 X1 X2 F1\n", ErrorCode::GcodeSyntax, "line 2"),
        ("G0 X0 Y0 Z0\n\nG41 D1 G1 X5 F100\n", ErrorCode::GcodeUnsupported, "line 3"),
        ("G81 X0 Y0 Z-1 R1 F100\n", ErrorCode::GcodeUnsupported, "line 1"),
        ("G0 X0 Y0 Z0\nG1 A10 F100\n", ErrorCode::GcodeUnsupported, "line 2"),
        ("#1=5\n", ErrorCode::GcodeUnsupported, "line 1"),
        ("G0 X10 Y0 Z0\nG2 X0 Y10 I-10 J1 F100\n", ErrorCode::ArcNotClosed, "line 2"),
        ("G0 X10 Y0 Z0\nG2 X-10 Y0 R5 F100\n", ErrorCode::ArcRadius, "line 2"),
        ("G2 X0 Y10 I-10 J0 F100\n", ErrorCode::GcodePosition, "line 1"),
        ("X10\n", ErrorCode::GcodeSyntax, "line 1"),
        ("G0 G1 X1\n", ErrorCode::GcodeSyntax, "line 1"),
        ("G1 X1 F-5\n", ErrorCode::GcodeSyntax, "line 1"),
        ("G0 X1 &\n", ErrorCode::GcodeSyntax, "line 1"),
        ("M98 P100\n", ErrorCode::GcodeUnsupported, "line 1"),
    ];
    for (text, code, line) in cases {
        let error = read_err(text);
        assert_eq!(error.code(), code, "{text}: {}", error.message());
        assert!(error.message().starts_with(line), "{text}: {}", error.message());
        assert_eq!(error.field(), Some("program"));
    }
    let limited =
        read("G0 X0\nG0 X1\nG0 X2\n", "program", &ReadOptions { max_lines: 2, ..ReadOptions::default() }).unwrap_err();
    assert_eq!(limited.code(), ErrorCode::TooManyLines);
}

#[test]
fn non_geometric_words_and_home_returns_do_not_move_the_tool() {
    let program =
        read_ok("G0 G54 G43 H1 X0 Y0 Z5\nG4 X2.5\nG10 L2 P1 X5\nG1 Z0 F100\nG91 G28 Z0\nG90 G0 X1\nG0 Y1 Z1\n");
    assert_eq!(program.moves.len(), 4);
    assert_eq!(program.moves[1].to_xyz(), Some([0.0, 0.0, 0.0]));
    assert_eq!(program.moves[2].from, [None; 3]);
    assert_eq!(program.moves[2].to, [Some(1.0), None, None]);
    assert_eq!(program.moves[3].from, [Some(1.0), None, None]);
    assert_eq!(program.moves[3].to_xyz(), Some([1.0, 1.0, 1.0]));
    let stopped = read_ok("G0 X0 Y0 Z0\nM30\nG0 X5\n");
    assert_eq!(stopped.moves.len(), 1);
    assert_eq!(stopped.line_count, 4);
}

#[test]
fn rewrite_changes_only_coordinates() {
    let text = "%\nN10 G90 G0 X0 Y0 Z5 (START)\nN20 G1 Z0.000 F300\nN30 X10. ; cut\nN40 Y5\nN50 G0 Z5\n%\n";
    let program = read_ok(text);
    let edits = [
        MoveEdit { index: 2, to: [10.0, 0.01, -0.002], centre: None },
        MoveEdit { index: 3, to: [10.0, 5.0, -0.001], centre: None },
    ];
    let out = rewrite(text, &program, &edits, "program").unwrap();
    assert_eq!(
        out,
        "%\nN10 G90 G0 X0 Y0 Z5 (START)\nN20 G1 Z0.000 F300\nN30 X10. Y0.0100 Z-0.0020 ; cut\nN40 Y5 Z-0.0010\nN50 G0 Z5\n%\n"
    );
    assert_eq!(out.lines().count(), text.lines().count());
    let reread = read_ok(&out);
    assert_eq!(reread.moves[2].to_xyz(), Some([10.0, 0.01, -0.002]));
    assert_eq!(reread.moves[4].to_xyz(), Some([10.0, 5.0, 5.0]));
}

#[test]
fn incremental_rewrite_keeps_later_end_points() {
    let text = "G90 G0 X0 Y0 Z0\nG91 G1 X10 F100\nX10\nX10\n";
    let program = read_ok(text);
    let edits = [MoveEdit { index: 2, to: [20.5, 0.0, 0.0], centre: None }];
    let out = rewrite(text, &program, &edits, "program").unwrap();
    assert_eq!(out, "G90 G0 X0 Y0 Z0\nG91 G1 X10 F100\nX10.5000\nX9.5000\n");
}

#[test]
fn rewritten_arcs_close_and_keep_their_format() {
    let text = "G0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F100\nG3 X-10 Y0 R10\n";
    let program = read_ok(text);
    let edits = [
        MoveEdit { index: 1, to: [0.0, 10.01, 0.0], centre: None },
        MoveEdit { index: 2, to: [-10.01, 0.0, 0.0], centre: Some([0.0, 0.0, 0.0]) },
    ];
    let out = rewrite(text, &program, &edits, "program").unwrap();
    let reread = read_ok(&out);
    assert_eq!(reread.moves[1].to_xyz(), Some([0.0, 10.01, 0.0]));
    assert_eq!(reread.moves[2].to_xyz(), Some([-10.01, 0.0, 0.0]));
    assert!(out.lines().nth(2).unwrap().contains('R'));
    let inch = "G20 G0 X1 Y0 Z0\nG1 X2 F10\n";
    let program = read_ok(inch);
    let out = rewrite(inch, &program, &[MoveEdit { index: 1, to: [50.8 + 0.254, 0.0, 0.0], centre: None }], "program")
        .unwrap();
    assert_eq!(out, "G20 G0 X1 Y0 Z0\nG1 X2.0100 F10\n");
}
