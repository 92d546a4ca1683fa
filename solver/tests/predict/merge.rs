//! Merging near-identical consecutive passes (`merge_similar_passes`, docs/spec/predict.md §3.2):
//! on random zig-zag finishing programs over inclined planes and boxes, every
//! merged pass's error differs from simulating it by at most its reported `merge_bound`, the
//! simulated passes are unchanged, and a long uniform program simulates far fewer passes.

use kerf_cases::predict::{bare_request, finishing_tool};
use kerf_solver::predict::{self, CuttingCoefficients, PathInput, Predict, PredictRequest};
use kerf_solver::stock::Stock;
use kerf_solver::tool::Tool;
use proptest::prelude::*;

/// A zig-zag raster of ball centres: `lines` lines of `steps` segments of `step` mm along the
/// plane's level direction, `pick` apart up the slope; coordinates rounded to `decimals` as a
/// post-processor writes them.
#[derive(Debug, Clone)]
struct Raster {
    slope_deg: f64,
    uphill_deg: f64,
    lines: usize,
    steps: usize,
    step: f64,
    pick: f64,
    decimals: usize,
    boxed: bool,
}

fn program(raster: &Raster, radius: f64) -> String {
    let (s, c) = raster.slope_deg.to_radians().sin_cos();
    let (sa, ca) = raster.uphill_deg.to_radians().sin_cos();
    let normal = [-s * ca, -s * sa, c];
    let uphill = [c * ca, c * sa, s];
    let level = [-sa, ca, 0.0];
    let mut text = String::from("G21 G90 G17\nS6000 M03\n");
    let d = raster.decimals;
    for line in 0..raster.lines {
        for k in 0..=raster.steps {
            let along = if line % 2 == 0 { k } else { raster.steps - k } as f64 * raster.step;
            let p: Vec<f64> =
                (0..3).map(|i| line as f64 * raster.pick * uphill[i] + along * level[i] + radius * normal[i]).collect();
            if line == 0 && k == 0 {
                text.push_str(&format!("G0 X{:.d$} Y{:.d$} Z{:.d$}\nG1 F1200\n", p[0], p[1], p[2] + 50.0));
                text.push_str(&format!("G1 Z{:.d$}\n", p[2]));
            } else {
                text.push_str(&format!("G1 X{:.d$} Y{:.d$} Z{:.d$}\n", p[0], p[1], p[2]));
            }
        }
    }
    text.push_str("G0 Z100\nM30\n");
    text
}

fn request(raster: &Raster) -> (PredictRequest, Tool) {
    let radius = 3.0;
    let tool = finishing_tool(radius);
    let (s, c) = raster.slope_deg.to_radians().sin_cos();
    let (sa, ca) = raster.uphill_deg.to_radians().sin_cos();
    let stock = if raster.boxed {
        Stock::Box { min: [-200.0, -200.0, -50.0], max: [200.0, 200.0, 0.2] }
    } else {
        Stock::Plane { point: [0.0, 0.0, 0.2 / c], normal: [-s * ca, -s * sa, c], min: [-200.0; 2], max: [200.0; 2] }
    };
    let mut request = bare_request(&tool, stock, PathInput::Gcode { program: program(raster, radius) });
    request.cutting = Some(CuttingCoefficients { ktc: 2000.0, krc: 800.0, kac: 300.0, kte: 0.0, kre: 0.0, kae: 0.0 });
    request.resolution = Some(64);
    request.edge_elements = Some(18);
    request.samples_per_revolution = Some(72);
    (request, tool)
}

fn merged(mut request: PredictRequest, tool: &Tool, tolerance: Option<f64>) -> Predict {
    request.merge_similar_passes = Some(true);
    request.merge_tolerance = tolerance;
    predict::solve(&request, tool, None).unwrap()
}

/// Every merged pass within its bound of the unmerged prediction; simulated passes unchanged.
fn check_against_unmerged(plain: &Predict, merged: &Predict) -> Result<usize, TestCaseError> {
    let mut count = 0;
    for (p, m) in plain.passes.iter().zip(&merged.passes) {
        prop_assert_eq!(p.status, m.status, "pass {}", p.index);
        match (m.merged_with, m.merge_bound) {
            (None, None) => {
                prop_assert_eq!(&p.error, &m.error, "simulated pass {}", p.index);
                prop_assert_eq!(&p.generation_point, &m.generation_point);
                prop_assert_eq!(&p.flags, &m.flags);
            }
            (Some(from), Some(bound)) => {
                count += 1;
                prop_assert!(merged.passes[from].merged_with.is_none());
                let (e, f) = (p.error.unwrap(), m.error.unwrap());
                prop_assert!(
                    (e - f).abs() <= bound + 1e-12,
                    "pass {} merged with {}: {} vs {} (bound {})",
                    p.index,
                    from,
                    f,
                    e,
                    bound
                );
                // Its own ball centre, not the simulated pass's.
                prop_assert!(m.centre != merged.passes[from].centre);
                let (cp, cm) = (p.centre.unwrap(), m.centre.unwrap());
                prop_assert!((0..3).all(|i| (cp[i] - cm[i]).abs() < 0.5), "{:?} vs {:?}", cp, cm);
            }
            other => prop_assert!(false, "pass {}: {:?}", p.index, other),
        }
    }
    let summary = merged.summary.merge.as_ref().unwrap();
    prop_assert_eq!(summary.merged, count);
    prop_assert_eq!(summary.simulated + summary.merged, merged.passes.len());
    Ok(count)
}

fn raster() -> impl Strategy<Value = Raster> {
    (
        0.0f64..35.0,
        0.0f64..360.0,
        2usize..4,
        30usize..90,
        0.15f64..0.6,
        0.3f64..0.8,
        prop::sample::select(vec![3, 4, 6]),
        any::<bool>(),
    )
        .prop_map(|(slope_deg, uphill_deg, lines, steps, step, pick, decimals, boxed)| Raster {
            slope_deg: if boxed { 0.0 } else { slope_deg },
            uphill_deg,
            lines,
            steps,
            step,
            pick,
            decimals,
            boxed,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn merged_errors_stay_within_the_reported_bound(raster in raster(), tolerance in 0.0001f64..0.003) {
        let (request, tool) = request(&raster);
        let plain = predict::solve(&request, &tool, None).unwrap();
        let merged = merged(request, &tool, Some(tolerance));
        check_against_unmerged(&plain, &merged)?;
    }
}

/// The deflection at the generation point swings with the rotation angle ψ_c, which moves with
/// the point's azimuth from pass to pass as the sample grid falls differently on each: on these
/// rasters a simulated pass's error differs from its neighbours' by 0.00019 mm (a swing repeating
/// every 4 passes, which the simulated passes 16 apart all miss) and by 0.00027 mm (one pass),
/// more than the generation point's resolution alone allows; the bound takes in how far e_D moves
/// over the rotation angles one sample spans.
#[test]
fn passes_whose_deflection_swings_with_the_rotation_angle_stay_within_the_bound() {
    let cases = [
        (
            Raster {
                slope_deg: 28.160853320689924,
                uphill_deg: 15.643667716190842,
                lines: 2,
                steps: 82,
                step: 0.15829053551174335,
                pick: 0.3,
                decimals: 4,
                boxed: false,
            },
            0.0007676043097126821,
            true,
        ),
        (
            Raster {
                slope_deg: 30.336212266898244,
                uphill_deg: 156.0799304114729,
                lines: 2,
                steps: 37,
                step: 0.5433734288798204,
                pick: 0.5853276931877036,
                decimals: 4,
                boxed: false,
            },
            0.001998796474983743,
            false,
        ),
    ];
    for (raster, tolerance, default_force_steps) in cases {
        let (mut request, tool) = request(&raster);
        if default_force_steps {
            request.edge_elements = None;
            request.samples_per_revolution = None;
        }
        let plain = predict::solve(&request, &tool, None).unwrap();
        let answer = merged(request, &tool, Some(tolerance));
        let swing = plain.passes.windows(2).skip(2).take(30).map(|w| (w[1].error.unwrap() - w[0].error.unwrap()).abs());
        assert!(swing.fold(0.0, f64::max) > 0.00018, "{raster:?}");
        check_against_unmerged(&plain, &answer).unwrap();
    }
}

/// A long uniform finishing program (three 120 mm lines of 0.25 mm segments over a flat box)
/// simulates a fraction of its passes (all but those within 2R of a line's end, which see the
/// turn, and every 16th), and the merged ones stay within their bounds.
#[test]
fn a_long_uniform_program_simulates_far_fewer_passes() {
    let raster = Raster {
        slope_deg: 0.0,
        uphill_deg: 90.0,
        lines: 3,
        steps: 480,
        step: 0.25,
        pick: 0.5,
        decimals: 4,
        boxed: true,
    };
    let (request, tool) = request(&raster);
    let plain = predict::solve(&request, &tool, None).unwrap();
    let answer = merged(request, &tool, None);
    let summary = answer.summary.merge.clone().unwrap();
    assert_eq!(summary.tolerance, 0.001);
    assert!(summary.simulated * 4 < answer.passes.len(), "{summary:?} of {} passes", answer.passes.len());
    let merged_count = check_against_unmerged(&plain, &answer).unwrap();
    assert_eq!(merged_count, summary.merged);
}

/// Off by default: no merge fields in the answer, byte for byte the same as before.
#[test]
fn merging_is_off_by_default() {
    let raster = Raster {
        slope_deg: 20.0,
        uphill_deg: 30.0,
        lines: 2,
        steps: 20,
        step: 0.3,
        pick: 0.5,
        decimals: 4,
        boxed: false,
    };
    let (request, tool) = request(&raster);
    let answer = predict::solve(&request, &tool, None).unwrap();
    let text = serde_json::to_string(&answer).unwrap();
    assert!(!text.contains("merge"), "{text}");
    let mut off = request.clone();
    off.merge_similar_passes = Some(false);
    assert_eq!(serde_json::to_string(&predict::solve(&off, &tool, None).unwrap()).unwrap(), text);
}

#[test]
fn bad_merge_tolerances_name_their_field() {
    let raster =
        Raster { slope_deg: 0.0, uphill_deg: 0.0, lines: 2, steps: 4, step: 0.5, pick: 0.5, decimals: 4, boxed: true };
    let (request, tool) = request(&raster);
    for bad in [0.0, -0.001, 0.2, f64::NAN, f64::INFINITY] {
        let mut r = request.clone();
        r.merge_similar_passes = Some(true);
        r.merge_tolerance = Some(bad);
        let error = predict::solve(&r, &tool, None).unwrap_err();
        assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("merge_tolerance")), "{bad}");
    }
    let mut r = request;
    r.merge_tolerance = Some(0.001);
    let error = predict::solve(&r, &tool, None).unwrap_err();
    assert_eq!(error.field(), Some("merge_tolerance"));
}
