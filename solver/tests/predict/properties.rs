//! Property tests of the G-code reader and rewrite and of the node-correction rule: any text
//! reads to moves or a line-numbered error without panicking; a rewrite without edits is the
//! identity; edited end points read back as written; the node rule cancels the normal errors.

use kerf_solver::gcode::reader::{self, MoveEdit, MoveKind, ReadOptions};
use kerf_solver::predict::correct::{PassError, node_correction};
use proptest::prelude::*;

fn gcode_text() -> impl Strategy<Value = String> {
    let word = prop_oneof![
        Just("G0".to_owned()),
        Just("G1".to_owned()),
        Just("G2".to_owned()),
        Just("G3".to_owned()),
        Just("G90".to_owned()),
        Just("G91".to_owned()),
        Just("G20".to_owned()),
        Just("G21".to_owned()),
        Just("G18".to_owned()),
        Just("M3".to_owned()),
        Just("(NOTE)".to_owned()),
        Just("; tail".to_owned()),
        Just("%".to_owned()),
        Just("/".to_owned()),
        (prop::sample::select(vec!['X', 'Y', 'Z', 'I', 'J', 'K', 'R', 'F', 'S', 'N', 'P', 'Q']), -50.0f64..50.0)
            .prop_map(|(letter, value)| format!("{letter}{value:.3}")),
        "[ -~]{0,3}",
    ];
    prop::collection::vec(prop::collection::vec(word, 0..6).prop_map(|w| w.join(" ")), 0..20)
        .prop_map(|lines| lines.join("\n"))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn any_text_reads_or_fails_with_a_line_number(text in gcode_text()) {
        match reader::read(&text, "program", &ReadOptions::default()) {
            Ok(program) => {
                for m in &program.moves {
                    prop_assert!(m.line >= 1 && m.line <= program.line_count);
                    for v in m.to.iter().flatten() {
                        prop_assert!(v.is_finite());
                    }
                    if let Some(points) = m.points(0.01) {
                        prop_assert!(points.iter().flatten().all(|v| v.is_finite()));
                    }
                }
                let same = reader::rewrite(&text, &program, &[], "program").unwrap();
                prop_assert_eq!(same, text);
            }
            Err(error) => {
                prop_assert!(error.message().starts_with("line "), "{}", error.message());
                prop_assert_eq!(error.field(), Some("program"));
            }
        }
    }

    #[test]
    fn edited_end_points_read_back(
        offsets in prop::collection::vec(prop::array::uniform3(-0.05f64..0.05), 12),
        incremental in any::<bool>(),
        inch in any::<bool>(),
    ) {
        let body = if incremental {
            "G91\nG1 X1 F100\nG2 X1 Y1 I0 J1\nG1 Y1\nX-2 Y1 Z-1.5 (DOWN)\nG3 X-1 Y-1 R1\nG1 Y-2\nZ1.5\n"
        } else {
            "G1 X1 F100\nG2 X2 Y1 I0 J1\nG1 Y2\nX0 Y3 Z-0.5 (DOWN)\nG3 X-1 Y2 R1\nG1 Y0\nZ1\n"
        };
        let text = format!("{} G17 G90\nG0 X0 Y0 Z1\n{body}", if inch { "G20" } else { "G21" });
        let program = reader::read(&text, "program", &ReadOptions::default()).unwrap();
        let edits: Vec<MoveEdit> = program
            .moves
            .iter()
            .enumerate()
            .skip(1)
            .map(|(index, m)| {
                let to = m.to_xyz().unwrap();
                let d = offsets[index % offsets.len()];
                MoveEdit { index, to: [to[0] + d[0], to[1] + d[1], to[2] + d[2]], centre: None }
            })
            .collect();
        let out = reader::rewrite(&text, &program, &edits, "program").unwrap();
        prop_assert_eq!(out.lines().count(), text.lines().count());
        let again = reader::read(&out, "program", &ReadOptions::default()).unwrap();
        prop_assert_eq!(again.moves.len(), program.moves.len());
        let precision = if inch { 25.4 * 5e-5 } else { 5e-5 } * 4.0;
        for edit in &edits {
            let got = again.moves[edit.index].to_xyz().unwrap();
            for k in 0..3 {
                prop_assert!((got[k] - edit.to[k]).abs() <= precision, "move {}: {:?} vs {:?}", edit.index, got, edit.to);
            }
            prop_assert_eq!(
                matches!(again.moves[edit.index].kind, MoveKind::Arc { .. }),
                matches!(program.moves[edit.index].kind, MoveKind::Arc { .. })
            );
        }
    }

    #[test]
    fn the_node_rule_cancels_both_normal_errors_when_it_can(
        e1 in -0.05f64..0.05, e2 in -0.05f64..0.05,
        n1 in prop::array::uniform3(-1.0f64..1.0), n2 in prop::array::uniform3(-1.0f64..1.0),
    ) {
        let unit = |n: [f64; 3]| {
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            [n[0] / length, n[1] / length, n[2] / length]
        };
        prop_assume!((n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2]) > 0.01);
        prop_assume!((n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2]) > 0.01);
        let (n1, n2) = (unit(n1), unit(n2));
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        // One neighbour: the node moves by −e·n exactly.
        let (single, _) = node_correction(Some(PassError { error: e1, normal: n1 }), None);
        prop_assert!((dot(single, n1) + e1).abs() < 1e-12);
        // Two neighbours: no move along the chosen direction does better (least squares).
        let (c, ambiguous) = node_correction(
            Some(PassError { error: e1, normal: n1 }),
            Some(PassError { error: e2, normal: n2 }),
        );
        if !ambiguous {
            let residual = |c: [f64; 3]| (e1 + dot(c, n1)).powi(2) + (e2 + dot(c, n2)).powi(2);
            let best = residual(c);
            for scale in [0.9, 1.1, 0.5, 1.5] {
                prop_assert!(best <= residual([c[0] * scale, c[1] * scale, c[2] * scale]) + 1e-15);
            }
        }
    }
}
