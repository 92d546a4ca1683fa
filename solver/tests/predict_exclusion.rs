//! The low-angle pass exclusion of claim 8 (error-prediction.md §3.4): with `exclusion_deg` a
//! pass whose finished surface lies only at contact angles up to θ_x is not predicted. On a
//! flat raster with ball R = 3, 0.1 mm deep and 0.4 mm apart, the middle line owns the floor
//! between the scallops (θ_max = asin(0.2/3) = 3.82°) and the outer lines their side walls up to
//! the stock top (θ_max = asin(√(3² − 2.9²)/3) = 14.8°); the pixel of the global view (R/32)
//! blurs each by at most one pixel.

mod predict_support;

use kerf_solver::predict::{self, PassStatus, PathInput, PredictRequest, Stock};
use kerf_solver::tool::Tool;
use predict_support::{bare_request, finishing_tool};

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
