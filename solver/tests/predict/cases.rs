//! Reference cases A–G of `solver/tests/fixtures/predict.json` (copied to `tests/fixtures/`),
//! through the public API, to the tolerances stated there.

use kerf_cases::predict::bare_request;
use kerf_cases::{case, close, number, triple};
use std::f64::consts::PI;

use kerf_solver::predict::correct::{PassError, node_correction, polyline_corrections};
use kerf_solver::predict::dynamics::steady_state_deflection;
use kerf_solver::predict::shape::{Conversion, Section, shape_error_from_sections};
use kerf_solver::predict::{
    self, CuttingCoefficients, Method, PassFlag, PathInput, Predict, PredictRequest, PrescribedDeflection,
};
use kerf_solver::stock::Stock;
use kerf_solver::tool::{Mode, ShapeErrorPoint, Stiffness, Tool, ToolKind};
use serde_json::Value;

/// A program of separate straight passes (ball centres), linked by rapids at a safe height.
fn program(passes: &[([f64; 3], [f64; 3])], feed: f64) -> String {
    let mut text = String::from("(REFERENCE CASE)\nG21 G90 G17\nS6000 M03\n");
    for (start, end) in passes {
        text.push_str(&format!(
            "G0 X{:.9} Y{:.9} Z100\nG0 Z{:.9}\nG1 X{:.9} Y{:.9} Z{:.9} F{feed}\nG0 Z100\n",
            start[0], start[1], start[2], end[0], end[1], end[2]
        ));
    }
    text.push_str("M05\nM30\n");
    text
}

fn ball(radius: f64, table: Vec<ShapeErrorPoint>) -> Tool {
    let mut tool = Tool::new(ToolKind::Ball, radius);
    tool.shape_error = Some(table);
    tool
}

fn linear_table(at_0: f64, at_90: f64) -> Vec<ShapeErrorPoint> {
    vec![ShapeErrorPoint { angle_deg: 0.0, error: at_0 }, ShapeErrorPoint { angle_deg: 90.0, error: at_90 }]
}

fn request(
    tool: &Tool,
    stock: Stock,
    passes: &[([f64; 3], [f64; 3])],
    feed: f64,
    deflection: Option<PrescribedDeflection>,
    method: Method,
) -> PredictRequest {
    PredictRequest {
        deflection,
        method,
        ..bare_request(tool, stock, PathInput::Gcode { program: program(passes, feed) })
    }
}

/// D(ψ) = (−0.010 − 0.005 cos 2ψ, 0.003 sin 2ψ) at 1° steps (cases A, B).
fn deflection_ab() -> PrescribedDeflection {
    let psi = |k: usize| (k as f64).to_radians();
    PrescribedDeflection {
        x: (0..360).map(|k| -0.010 - 0.005 * (2.0 * psi(k)).cos()).collect(),
        y: (0..360).map(|k| 0.003 * (2.0 * psi(k)).sin()).collect(),
    }
}

fn plane_stock(case: &Value) -> Stock {
    let stock = &case["inputs"]["stock"];
    Stock::Plane {
        point: triple(&stock["plane_point"]),
        normal: triple(&stock["outward_normal"]),
        min: [number(&stock["footprint_x"][0]), number(&stock["footprint_y"][0])],
        max: [number(&stock["footprint_x"][1]), number(&stock["footprint_y"][1])],
    }
}

fn case_a_passes() -> Vec<([f64; 3], [f64; 3])> {
    (-25..=25)
        .map(|i| {
            let x = 0.5 * f64::from(i);
            ([x, -40.0, 5.0], [x, 40.0, 5.0])
        })
        .collect()
}

fn case_b_passes(case: &Value) -> Vec<([f64; 3], [f64; 3])> {
    let t = triple(&case["inputs"]["uphill_tangent_t_hat"]);
    let n = triple(&case["inputs"]["n_hat"]);
    let f = triple(&case["inputs"]["feed_f_hat"]);
    (-25..=25)
        .map(|i| {
            let at = |s: f64| {
                let mut p = [0.0; 3];
                for k in 0..3 {
                    p[k] = 0.5 * f64::from(i) * t[k] + 5.0 * n[k] + s * f[k];
                }
                p
            };
            (at(-40.0), at(40.0))
        })
        .collect()
}

/// Case A and B's tool feed: f_t · S · N_f.
const FEED_AB: f64 = 0.1 * 6000.0 * 2.0;

#[test]
fn case_a_flat_raster_generation_at_the_tip() {
    let case = case("predict", "A_");
    let expected = &case["expected"];
    let tolerances = &case["tolerances"];
    let tool = ball(5.0, linear_table(0.01, 0.01));
    for method in [Method::Sampling, Method::DepthBuffer] {
        let request = request(&tool, plane_stock(&case), &case_a_passes(), FEED_AB, Some(deflection_ab()), method);
        let answer = predict::solve(&request, &tool, None).unwrap();
        let pass = &answer.passes[25];
        assert_eq!(pass.line, Some(4 + 25 * 4 + 2));
        let centre = pass.centre.unwrap();
        close("O.y", centre[1], 0.0, 1e-9);
        close("theta_c", pass.contact_angle_deg.unwrap(), number(&expected["theta_c"]), number(&tolerances["theta_c"]));
        assert!(pass.azimuth_deg.is_none() && pass.rotation_angle_deg.is_none());
        assert!(pass.flags.contains(&PassFlag::AtTip), "{:?}", pass.flags);
        let normal = pass.normal.unwrap();
        let expected_normal = triple(&expected["normal"]);
        for k in 0..3 {
            close("normal", normal[k], expected_normal[k], number(&tolerances["normal"]));
        }
        close("e_D", pass.error_deflection.unwrap(), 0.0, 1e-12);
        close("e", pass.error.unwrap(), number(&expected["e"]), number(&tolerances["e"]));
        if method == Method::DepthBuffer {
            // The finished patch is p × f_t around the tip: 100–200 pixels.
            assert!((100..=200).contains(&pass.finished_count), "finished pixels {}", pass.finished_count);
        }
    }
}

#[test]
fn case_b_inclined_plane_rotation_sense() {
    let case = case("predict", "B_");
    let expected = &case["expected"];
    let tolerances = &case["tolerances"];
    let tool = ball(5.0, linear_table(0.005, 0.015));
    for method in [Method::Sampling, Method::DepthBuffer] {
        let request = request(&tool, plane_stock(&case), &case_b_passes(&case), FEED_AB, Some(deflection_ab()), method);
        let answer = predict::solve(&request, &tool, None).unwrap();
        let pass = &answer.passes[25];
        let centre = pass.centre.unwrap();
        let o = triple(&case["inputs"]["prediction"]["O"]);
        for k in 0..3 {
            close("O", centre[k], o[k], 1e-5);
        }
        let check = |what: &str, got: Option<f64>| {
            close(what, got.unwrap(), number(&expected[what]), number(&tolerances[what]));
        };
        check("theta_c", pass.contact_angle_deg);
        check("phi_c", pass.azimuth_deg);
        check("psi_c", pass.rotation_angle_deg);
        check("e_S", pass.error_shape);
        check("e_D", pass.error_deflection);
        check("e", pass.error);
        let normal = pass.normal.unwrap();
        let expected_normal = triple(&expected["normal"]);
        for k in 0..3 {
            close("normal", normal[k], expected_normal[k], number(&tolerances["normal"]));
        }
        // The wrong rotation sense would be far outside the tolerance.
        let wrong = number(&expected["wrong_rotation_sense_gives"]["e"]);
        assert!((pass.error.unwrap() - wrong).abs() > 10.0 * number(&tolerances["e"]));
        // M04 turns the generation instant to ψ = 45°.
        let mut ccw = request.clone();
        if let PathInput::Gcode { program } = &mut ccw.path {
            *program = program.replace("M03", "M04");
        }
        let reversed = predict::solve(&ccw, &tool, None).unwrap();
        close(
            "psi_c (M04)",
            reversed.passes[25].rotation_angle_deg.unwrap(),
            number(&expected["wrong_rotation_sense_gives"]["psi_c"]),
            0.5,
        );
        close(
            "e_D (M04)",
            reversed.passes[25].error_deflection.unwrap(),
            number(&expected["wrong_rotation_sense_gives"]["e_D"]),
            1e-4,
        );
    }
}

fn case_c_request(beta_deg: f64, method: Method, view_correction: bool) -> (PredictRequest, Tool, usize) {
    let table: Vec<ShapeErrorPoint> = (0..=90)
        .map(|k| ShapeErrorPoint { angle_deg: f64::from(k), error: 0.005 * f64::from(k).to_radians().sin() })
        .collect();
    let tool = ball(10.0, table);
    let beta = beta_deg.to_radians();
    let mut passes = Vec::new();
    let mut index = None;
    for k in -40..=40 {
        let b = beta + f64::from(k) * 0.0126;
        if b.abs() > PI / 2.0 {
            continue;
        }
        if k == 0 {
            index = Some(passes.len());
        }
        let (s, c) = b.sin_cos();
        passes.push(([60.0 * s, -40.0, 60.0 * c], [60.0 * s, 40.0, 60.0 * c]));
    }
    let mut request = request(
        &tool,
        Stock::Cylinder { start: [0.0, -30.0, 0.0], end: [0.0, 30.0, 0.0], radius: 50.2 },
        &passes,
        0.4 * 6000.0 * 2.0,
        Some(PrescribedDeflection { x: vec![0.020], y: vec![0.0] }),
        method,
    );
    request.view_correction = Some(view_correction);
    (request, tool, index.unwrap())
}

#[test]
fn case_c_convex_cylinder_below_rotated_and_sampled() {
    let case = case("predict", "C_");
    let tolerances = &case["tolerances"];
    for row in case["expected_rows"].as_array().unwrap() {
        let beta = number(&row["beta"]);
        let analytic = &row["analytic"];
        let theta = number(&analytic["theta_c"]);
        let e = number(&analytic["e"]);
        // From below, without view correction: within 0.2° up to 85°, pinned at the rim above.
        let (request, tool, index) = case_c_request(beta, Method::DepthBuffer, false);
        let below = predict::solve(&request, &tool, None).unwrap();
        let pass = &below.passes[index];
        let got = pass.contact_angle_deg.unwrap();
        if beta <= 85.0 {
            close(&format!("below θ at β={beta}"), got, theta, number(&tolerances["below_theta_c_for_beta_le_85"]));
            close(&format!("below φ at β={beta}"), pass.azimuth_deg.unwrap(), 180.0, number(&tolerances["phi_c"]));
        } else {
            close(&format!("rim θ at β={beta}"), got, 86.418, 0.05);
            assert!(pass.flags.contains(&PassFlag::RimLimited), "β={beta}: {:?}", pass.flags);
        }
        // With the view correction (default) the depth buffer stays within 0.1° up to 88°.
        let (request, tool, index) = case_c_request(beta, Method::DepthBuffer, true);
        let corrected = predict::solve(&request, &tool, None).unwrap();
        let pass = &corrected.passes[index];
        if beta >= 60.0 {
            assert!(pass.flags.contains(&PassFlag::ViewCorrected), "β={beta}: {:?}", pass.flags);
        }
        let tolerance = if beta >= 60.0 {
            number(&tolerances["rotated_theta_c"])
        } else {
            number(&tolerances["below_theta_c_for_beta_le_85"])
        };
        close(&format!("corrected θ at β={beta}"), pass.contact_angle_deg.unwrap(), theta, tolerance);
        close(&format!("corrected φ at β={beta}"), pass.azimuth_deg.unwrap(), 180.0, number(&tolerances["phi_c"]));
        close(&format!("corrected e at β={beta}"), pass.error.unwrap(), e, number(&tolerances["e"]));
        // Surface sampling: resolution-free, no view correction needed.
        let (request, tool, index) = case_c_request(beta, Method::Sampling, true);
        let sampled = predict::solve(&request, &tool, None).unwrap();
        let pass = &sampled.passes[index];
        close(&format!("sampled θ at β={beta}"), pass.contact_angle_deg.unwrap(), theta, 0.05);
        close(&format!("sampled φ at β={beta}"), pass.azimuth_deg.unwrap(), 180.0, number(&tolerances["phi_c"]));
        close(&format!("sampled e at β={beta}"), pass.error.unwrap(), e, number(&tolerances["e"]));
        close(&format!("ψ at β={beta}"), pass.rotation_angle_deg.unwrap(), number(&analytic["psi_c"]), 0.5);
    }
}

fn case_d_request(stiffness: Stiffness) -> (PredictRequest, Tool) {
    let case = case("predict", "B_");
    let mut tool = ball(5.0, linear_table(0.005, 0.015));
    tool.stiffness = Some(stiffness);
    let mut request = request(&tool, plane_stock(&case), &case_b_passes(&case), FEED_AB, None, Method::Sampling);
    request.cutting = Some(CuttingCoefficients { ktc: 2000.0, krc: 800.0, kac: 300.0, kte: 0.0, kre: 0.0, kae: 0.0 });
    request.samples_per_revolution = Some(720);
    request.edge_elements = Some(180);
    request.history = Some(vec![25]);
    (request, tool)
}

#[test]
fn case_d_force_and_dynamic_deflection_chain() {
    let case = case("predict", "D_");
    let expected = &case["expected"];
    let tolerances = &case["tolerances"];
    let mode = |m: &Value| Mode {
        stiffness: number(&m["k"]),
        frequency_hz: number(&m["fn"]),
        damping_ratio: number(&m["zeta"]),
    };
    let compliance = &case["inputs"]["compliance"];
    let (request, tool) = case_d_request(Stiffness::Modal {
        x: compliance["x"].as_array().unwrap().iter().map(mode).collect(),
        y: compliance["y"].as_array().unwrap().iter().map(mode).collect(),
    });
    let answer: Predict = predict::solve(&request, &tool, None).unwrap();
    let pass = &answer.passes[25];
    close("psi_c", pass.rotation_angle_deg.unwrap(), number(&expected["psi_c"]), 0.5);
    let history = pass.history.as_ref().unwrap();
    // Engaged intervals of ψ: where the force is non-zero.
    let engaged: Vec<f64> = history
        .force
        .iter()
        .enumerate()
        .filter(|(_, f)| f.iter().any(|v| v.abs() > 1e-12))
        .map(|(m, _)| m as f64 * history.step_deg)
        .collect();
    let interval_tolerance = number(&tolerances["engaged_interval_deg"]);
    for interval in expected["engaged_psi_intervals_deg"].as_array().unwrap() {
        let (lo, hi) = (number(&interval[0]), number(&interval[1]));
        let inside: Vec<f64> = engaged.iter().copied().filter(|psi| *psi >= lo - 10.0 && *psi <= hi + 10.0).collect();
        close("engagement start", inside[0], lo, interval_tolerance);
        close("engagement end", inside[inside.len() - 1], hi, interval_tolerance);
    }
    let peak = triple(&expected["F_peak_abs"]);
    for axis in 0..3 {
        let got = history.force.iter().map(|f| f[axis].abs()).fold(0.0, f64::max);
        close("F peak", got, peak[axis], number(&tolerances["F_peak_relative"]) * peak[axis]);
    }
    let e_d = number(&expected["e_D_dynamic"]);
    close("e_D dynamic", pass.error_deflection.unwrap(), e_d, number(&tolerances["e_D_dynamic_relative"]) * e_d);
    let d = triple(&expected["D_at_psi_c"]);
    let got = pass.deflection.unwrap();
    close("D_x(ψ_c)", got[0], d[0], 0.1 * d[0].abs());
    close("D_y(ψ_c)", got[1], d[1], 0.1 * d[1].abs());
    // Static stiffness: the force is zero at the tooth exit where the surface is generated.
    let (request, tool) = case_d_request(Stiffness::Static { x: 5000.0, y: 5000.0 });
    let answer = predict::solve(&request, &tool, None).unwrap();
    close("e_D static", answer.passes[25].error_deflection.unwrap(), 0.0, 2e-4);
}

#[test]
fn case_e_fft_matches_time_integration() {
    let case = case("predict", "E_");
    let expected = &case["expected"];
    let steps = 3600;
    let peak = 200.0;
    let force: Vec<f64> = (0..steps)
        .map(|k| {
            let phase = (k as f64 / (steps as f64 / 2.0)).fract();
            if phase < 0.3 { peak * (PI * phase / 0.3).sin() } else { 0.0 }
        })
        .collect();
    let mode = Mode { stiffness: 5000.0, frequency_hz: 1000.0, damping_ratio: 0.03 };
    let fft = steady_state_deflection(&force, 6000.0, &[mode]);
    let max = fft.iter().map(|d| d.abs()).fold(0.0, f64::max);
    close("max |D|", max, number(&expected["max_abs_D"]), 1e-5);
    let mean = fft.iter().sum::<f64>() / steps as f64;
    close("mean D", mean, number(&expected["mean_D"]), 1e-6);
    // RK4 over 40 revolutions from rest with the force held piecewise linear between samples.
    let omega_n = 2.0 * PI * mode.frequency_hz;
    let mass = mode.stiffness / (omega_n * omega_n);
    let damping = 2.0 * mode.damping_ratio * mass * omega_n;
    let period = 60.0 / 6000.0;
    let dt = period / steps as f64;
    let force_at = |t: f64| {
        let position = (t / dt).rem_euclid(steps as f64);
        let k = position.floor() as usize % steps;
        let frac = position - position.floor();
        (1.0 - frac) * force[k] + frac * force[(k + 1) % steps]
    };
    let derivative = |t: f64, x: f64, v: f64| (v, (force_at(t) - damping * v - mode.stiffness * x) / mass);
    let (mut x, mut v) = (0.0, 0.0);
    let mut last = vec![0.0; steps];
    for revolution in 0..40 {
        for (k, slot) in last.iter_mut().enumerate() {
            let t = (revolution * steps + k) as f64 * dt;
            if revolution == 39 {
                *slot = x;
            }
            let (k1x, k1v) = derivative(t, x, v);
            let (k2x, k2v) = derivative(t + dt / 2.0, x + dt / 2.0 * k1x, v + dt / 2.0 * k1v);
            let (k3x, k3v) = derivative(t + dt / 2.0, x + dt / 2.0 * k2x, v + dt / 2.0 * k2v);
            let (k4x, k4v) = derivative(t + dt, x + dt * k3x, v + dt * k3v);
            x += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
    }
    let difference = fft.iter().zip(&last).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(difference < number(&case["tolerances"]["difference"]), "FFT vs RK4: {difference}");
    for (angle, value) in expected["D_at_rotation_deg"].as_object().unwrap() {
        let k = (angle.parse::<f64>().unwrap() * 10.0).round() as usize;
        close(&format!("D at {angle}°"), fft[k], number(value), 1e-5);
    }
}

#[test]
fn case_f_node_correction_rule() {
    let case = case("predict", "F_");
    let expected = &case["expected"];
    let tolerance = number(&case["tolerances"]["offset"]);
    let error = |p: &Value| PassError { error: number(&p["e"]), normal: triple(&p["n"]) };
    let passes: Vec<Option<PassError>> =
        case["inputs"]["pass_errors"].as_array().unwrap().iter().map(|p| Some(error(p))).collect();
    let check = |got: &[[f64; 3]], want: &Value| {
        for (g, w) in got.iter().zip(want.as_array().unwrap()) {
            let w = triple(w);
            for k in 0..3 {
                close("offset", g[k], w[k], tolerance);
            }
        }
    };
    check(&polyline_corrections(&passes), &expected["node_offsets"]);
    let corner: Vec<Option<PassError>> =
        expected["corner_case"]["pass_errors"].as_array().unwrap().iter().map(|p| Some(error(p))).collect();
    check(&polyline_corrections(&corner), &expected["corner_case"]["node_offsets"]);
    let missing = vec![passes[0], None, passes[2]];
    check(&polyline_corrections(&missing), &expected["invalid_middle_pass"]["node_offsets"]);
    // Opposite errors on a straight line cancel: the node stays and is flagged.
    let up = PassError { error: 0.01, normal: [0.0, 0.0, 1.0] };
    let down = PassError { error: -0.01, normal: [0.0, 0.0, 1.0] };
    assert_eq!(node_correction(Some(up), Some(down)), ([0.0; 3], true));
}

#[test]
fn case_g_shape_error_from_sections() {
    let case = case("predict", "G_");
    let radius = 5.0;
    // Dense sections of the two measured envelopes: a ball of radius R + 0.010 about the
    // nominal centre, and the nominal profile widened by a run-out of 0.005.
    let nominal = |z: f64| (radius * radius - (radius - z) * (radius - z)).max(0.0).sqrt();
    let bigger = |z: f64| ((radius + 0.01).powi(2) - (radius - z) * (radius - z)).max(0.0).sqrt();
    let heights: Vec<f64> = (0..=20000).map(|k| f64::from(k) * radius / 20000.0).collect();
    let uniform: Vec<Section> = heights.iter().map(|&z| Section { height: z, radius: bigger(z) }).collect();
    let runout: Vec<Section> = heights.iter().map(|&z| Section { height: z, radius: nominal(z) + 0.005 }).collect();
    let tolerance = number(&case["tolerances"]["exact"]);
    for row in case["expected"].as_array().unwrap() {
        let angle = number(&row["theta_deg"]);
        for (key, sections) in [("uniform_radius_error_0.010", &uniform), ("runout_0.005", &runout)] {
            let exact = shape_error_from_sections(radius, sections, &[angle], Conversion::Exact).unwrap();
            close(&format!("exact δ {key} at {angle}"), exact[0].error, number(&row[key]["exact_delta"]), tolerance);
            let first = shape_error_from_sections(radius, sections, &[angle], Conversion::FirstOrder).unwrap();
            close(
                &format!("first-order δ {key} at {angle}"),
                first[0].error,
                number(&row[key]["first_order_delta"]),
                2e-6,
            );
        }
    }
}
