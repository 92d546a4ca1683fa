//! The low-angle pass exclusion of claim 8 (docs/spec/predict.md §3.4): with `exclusion_deg` a
//! pass whose finished surface lies only at contact angles up to θ_x is not predicted. On a
//! flat raster with ball R = 3, 0.1 mm deep and 0.4 mm apart, the middle line owns the floor
//! between the scallops (θ_max = asin(0.2/3) = 3.82°) and the outer lines their side walls up to
//! the stock top (θ_max = asin(√(3² − 2.9²)/3) = 14.8°); the pixel of the global view (R/32)
//! blurs each by at most one pixel.

use kerf_cases::predict::{bare_request, finishing_tool};
use kerf_solver::predict::{self, PassStatus, PathInput, PredictRequest};
use kerf_solver::stock::Stock;
use kerf_solver::tool::Tool;

fn flat_case(exclusion: Option<f64>) -> (PredictRequest, Tool) {
    let tool = finishing_tool(3.0);
    let program = "%\nO0001 (FLAT)\nN1 G21 G90 G17\nN2 T1 M06\nN3 S8000 M03\nN4 G0 X-10 Y0 Z20\n\
                   N5 G1 Z3.0 F1600\nN6 X30\nN7 Y0.4\nN8 X-10\nN9 Y0.8\nN10 X30 (LAST)\nN11 G0 Z20\nN12 M30\n%\n";
    let mut request = bare_request(
        &tool,
        Stock::Box { min: [0.0, -5.0, -10.0], max: [20.0, 5.0, 0.1] },
        PathInput::Gcode { program: program.to_owned() },
    );
    request.reference = kerf_solver::gcode::Reference::Centre;
    request.exclusion_deg = exclusion;
    (request, tool)
}

/// Statuses of the three cutting lines (passes 1, 3, 5).
fn line_statuses(exclusion: Option<f64>) -> (predict::Predict, [PassStatus; 3]) {
    let (request, tool) = flat_case(exclusion);
    let answer = predict::solve(&request, &tool, None).unwrap();
    let statuses = [answer.passes[1].status, answer.passes[3].status, answer.passes[5].status];
    (answer, statuses)
}

#[test]
fn thresholds_around_the_closed_form_angles() {
    let (plain, all) = line_statuses(None);
    assert_eq!(all, [PassStatus::Ok; 3]);
    assert_eq!(plain.summary.skipped_small_angle, None);
    let skipped = PassStatus::SkippedSmallAngle;
    // Below every θ_max (the middle line's is at least asin((0.2 − R/32)/3) = 2.0°).
    assert_eq!(line_statuses(Some(1.9)).1, [PassStatus::Ok; 3]);
    // Above the middle line's 3.82°, below the outer lines' 14.8° less a pixel (13.0°).
    let (answer, statuses) = line_statuses(Some(4.0));
    assert_eq!(statuses, [PassStatus::Ok, skipped, PassStatus::Ok]);
    assert_eq!(answer.summary.skipped_small_angle, Some(1));
    assert_eq!(line_statuses(Some(12.5)).1, [PassStatus::Ok, skipped, PassStatus::Ok]);
    // Above all of them.
    let (answer, statuses) = line_statuses(Some(15.0));
    assert_eq!(statuses, [skipped; 3]);
    assert_eq!(answer.summary.skipped_small_angle, Some(3));
    assert_eq!(answer.summary.predicted, 0);
    // The moves that cut nothing (plunge and step-overs in the air) own no pixel: their own
    // statuses come from the prediction as before.
    for index in [0, 2, 4] {
        assert_eq!(answer.passes[index].status, plain.passes[index].status);
    }
}

#[test]
fn skipping_leaves_the_other_passes_unchanged() {
    let (plain, _) = line_statuses(None);
    let (excluded, _) = line_statuses(Some(4.0));
    for index in [1, 5] {
        assert_eq!(plain.passes[index], excluded.passes[index]);
    }
    assert!(excluded.passes[3].error.is_none());
}

#[test]
fn threshold_outside_zero_to_ninety_is_refused() {
    for bad in [-1.0, 90.5, f64::NAN] {
        let (request, tool) = flat_case(Some(bad));
        let error = predict::solve(&request, &tool, None).unwrap_err();
        assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("exclusion_deg")));
    }
}

/// With `exclusion_shape_error` an excluded pass keeps its status but gets e_S from the same
/// generation point as a full prediction; here (no force model) e = e_S for every pass, so the
/// excluded passes carry exactly the plain prediction's numbers, and the path is corrected the
/// same way.
#[test]
fn excluded_passes_get_their_shape_error_when_asked() {
    let (plain, _) = line_statuses(None);
    let (mut request, tool) = flat_case(Some(15.0));
    request.exclusion_shape_error = Some(true);
    let answer = predict::solve(&request, &tool, None).unwrap();
    assert_eq!(answer.summary.skipped_small_angle, Some(3));
    for index in [1, 3, 5] {
        let (p, e) = (&plain.passes[index], &answer.passes[index]);
        assert_eq!(e.status, PassStatus::SkippedSmallAngle);
        assert_eq!(p.status, PassStatus::Ok);
        assert!(e.error_shape.is_some());
        assert_eq!(e.error_shape, p.error_shape, "pass {index}");
        assert_eq!(e.error, e.error_shape);
        assert_eq!(e.error_deflection, None);
        assert_eq!(e.contact_angle_deg, p.contact_angle_deg);
        assert_eq!(e.normal, p.normal);
        assert_eq!(e.generation_point, p.generation_point);
        assert_eq!(e.correction, p.correction);
    }
    // Without the switch the same passes carry nothing and the path is not moved there.
    let (skipped, _) = line_statuses(Some(15.0));
    for index in [1, 3, 5] {
        assert_eq!(skipped.passes[index].error_shape, None);
        assert_eq!(skipped.passes[index].correction, [0.0; 3]);
    }
}

/// With a force model the excluded pass's e_S equals the full prediction's e_S, and e_D is left
/// out (not computed) rather than zero.
#[test]
fn excluded_shape_error_matches_the_full_prediction_with_force() {
    let tool = finishing_tool(3.0);
    let (mut request, _) = flat_case(Some(15.0));
    request.cutting =
        Some(predict::CuttingCoefficients { ktc: 2000.0, krc: 800.0, kac: 300.0, kte: 0.0, kre: 0.0, kae: 0.0 });
    let mut full = request.clone();
    full.exclusion_deg = None;
    let full = predict::solve(&full, &tool, None).unwrap();
    request.exclusion_shape_error = Some(true);
    let excluded = predict::solve(&request, &tool, None).unwrap();
    for index in [1, 3, 5] {
        let (f, e) = (&full.passes[index], &excluded.passes[index]);
        assert!(f.error_deflection.is_some());
        assert_eq!(e.error_shape, f.error_shape, "pass {index}");
        assert_eq!(e.contact_angle_deg, f.contact_angle_deg);
        assert_eq!((e.error_deflection, e.error, e.deflection), (None, e.error_shape, None));
    }
}

#[test]
fn shape_error_switch_without_threshold_is_refused() {
    let (mut request, tool) = flat_case(None);
    request.exclusion_shape_error = Some(true);
    let error = predict::solve(&request, &tool, None).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("exclusion_shape_error")));
    // Off without a threshold is the default and accepted.
    request.exclusion_shape_error = Some(false);
    assert!(predict::solve(&request, &tool, None).is_ok());
}
