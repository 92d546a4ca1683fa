//! Invariants of the prediction (docs/spec/predict.md §6.7): turning or moving the whole case
//! leaves θ_c and e unchanged (φ_c turns with it); doubling the resolution moves θ_c by less
//! than the reference tolerance; the depth buffer and the surface sampling agree within 0.2° up
//! to 85°; the answer does not depend on the thread count.

use kerf_cases::predict::{PATENT, inclined_case, inclined_case_with};
use kerf_solver::predict::{self, Method, PredictedPass};
use proptest::prelude::*;

fn middle(request: &kerf_solver::predict::PredictRequest, tool: &kerf_solver::tool::Tool) -> PredictedPass {
    let answer = predict::solve(request, tool, None).unwrap();
    answer.passes[5].clone()
}

fn angle_difference(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn turning_and_moving_the_case_changes_nothing(
        slope in 5.0f64..70.0,
        uphill in 0.0f64..360.0,
        turn in 1u32..360,
        shift in prop::array::uniform3(-200.0f64..200.0),
    ) {
        let turn = f64::from(turn);
        let (request, tool) = inclined_case(slope, uphill, 0.0, [0.0; 3], Method::Sampling);
        let base = middle(&request, &tool);
        let (request, tool) = inclined_case(slope, uphill, turn, shift, Method::Sampling);
        let moved = middle(&request, &tool);
        prop_assert_eq!(base.status, moved.status);
        let (t0, t1) = (base.contact_angle_deg.unwrap(), moved.contact_angle_deg.unwrap());
        prop_assert!((t0 - t1).abs() < 1e-4, "θ {t0} vs {t1}");
        prop_assert!((t0 - slope).abs() < 0.05, "θ {t0} vs slope {slope}");
        let (e0, e1) = (base.error.unwrap(), moved.error.unwrap());
        prop_assert!((e0 - e1).abs() < 1e-7, "e {e0} vs {e1}");
        prop_assert!(base.error_deflection.unwrap().abs() > 0.0);
        let dphi = angle_difference(moved.azimuth_deg.unwrap(), base.azimuth_deg.unwrap() + turn);
        prop_assert!(dphi.abs() < 1e-4, "φ turned by {dphi}");
    }

    /// Sampling under case B's conditions; the depth buffer under the patent's (case C), where
    /// N = 512 resolves the finished patch (§6.5); tolerances of cases B and C.
    #[test]
    fn doubling_the_resolution_moves_the_contact_angle_little(slope in 5.0f64..85.0, uphill in 0.0f64..360.0) {
        for (conditions, method, tolerance) in [
            (kerf_cases::predict::FINE, Method::Sampling, 0.02),
            (PATENT, Method::DepthBuffer, 0.15),
        ] {
            let (mut request, tool) = inclined_case_with(conditions, slope, uphill, 0.0, [0.0; 3], method);
            request.resolution = Some(512);
            let coarse = middle(&request, &tool).contact_angle_deg.unwrap();
            request.resolution = Some(1024);
            let fine = middle(&request, &tool).contact_angle_deg.unwrap();
            prop_assert!((coarse - fine).abs() < tolerance, "{method:?}: {coarse} vs {fine}");
        }
    }

    /// Under the patent's conditions (§6.5: N = 512 resolves the patch).
    #[test]
    fn depth_buffer_and_sampling_agree_up_to_85_degrees(slope in 0.0f64..85.0, uphill in 0.0f64..360.0) {
        let (request, tool) = inclined_case_with(PATENT, slope, uphill, 0.0, [0.0; 3], Method::Sampling);
        let sampled = middle(&request, &tool);
        let (request, tool) = inclined_case_with(PATENT, slope, uphill, 0.0, [0.0; 3], Method::DepthBuffer);
        let buffered = middle(&request, &tool);
        let (a, b) = (sampled.contact_angle_deg.unwrap(), buffered.contact_angle_deg.unwrap());
        prop_assert!((a - b).abs() < 0.2, "sampling {a} vs depth buffer {b} at slope {slope}");
        prop_assert!((a - slope).abs() < 0.2, "sampling {a} vs slope {slope}");
    }
}

#[test]
fn answers_do_not_depend_on_the_thread_count() {
    let (mut request, tool) = inclined_case(35.0, 20.0, 0.0, [0.0; 3], Method::Sampling);
    request.pass_range = None;
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| predict::solve(&request, &tool, None).unwrap())
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    assert!(one.summary.predicted >= 9, "{:?}", one.summary);
}
