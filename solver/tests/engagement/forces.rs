//! Spindle torque and power from Kienzle's law (docs/spec/engagement.md §11 items 4, 5, 9)
//! against closed forms: full slotting gives k·k_c1.1·a_p·f_z^(1−m_c)·R·I(1−m_c)/(2π) with
//! I(a) = ∫₀^π sin^a, side milling the same integral over the engaged arc; P = 2πNM/60; the
//! helix keeps the mean and only smooths the peak; the spindle limits warn and cap the feed
//! plan; the tooth-passing frequency is checked against the tool's natural frequencies.

use std::f64::consts::{PI, TAU};

use kerf_solver::engagement::{self, EngagementRequest, EngagementSolution, FeedLimit, PathEngagement, Physics};
use kerf_solver::machine::SpindleLimits;
use kerf_solver::material::{self, Kienzle};
use kerf_solver::tool::{Mode, Stiffness, Tool, ToolKind};
use proptest::prelude::*;
use serde_json::{Value, json};

const RADIUS: f64 = 5.0;
const KC11: f64 = 1800.0;
const RPM: f64 = 3000.0;
const FZ: f64 = 0.05;
const AP: f64 = 2.0;

/// ∫ over [from, to] ⊂ [0, π] of sin^a by the midpoint rule after θ = from + (to − from)·u²
/// near a zero of sin: independent of the solver's table.
fn sin_power_integral(a: f64, from: f64, to: f64) -> f64 {
    let n = 400_000;
    let h = (to - from) / f64::from(n);
    (0..n).map(|i| (from + (f64::from(i) + 0.5) * h).sin().max(0.0).powf(a) * h).sum()
}

fn tool(helix_deg: Option<f64>) -> Tool {
    let mut tool = Tool::new(ToolKind::Flat, RADIUS);
    tool.flutes = 4;
    tool.helix_deg = helix_deg;
    tool
}

/// A full slot through the block [0, 50] × [−20, 20] from its edge: every sample after the
/// first (a plunge, left out of the statistics) cuts [0°, 180°].
fn slot(mc: f64, flutes: &[u32]) -> Value {
    json!({
        "tool": 1, "stock": {"polygon": [[0, -20], [50, -20], [50, 20], [0, 20]]},
        "path": [[0, 0], [45, 0]], "spindle_rpm": RPM, "feed_per_tooth": FZ, "flute_counts": flutes,
        "step": 0.25, "axial_depth": AP, "kienzle": {"kc11": KC11, "mc": mc},
    })
}

fn solve_body(body: Value, tool: &Tool, physics: &Physics) -> Result<PathEngagement, kerf_solver::error::SolverError> {
    let request: EngagementRequest = serde_json::from_value(body).unwrap();
    engagement::solve_in(&request, tool, None, physics, kerf_solver::capability::Control::default()).map(|answer| {
        match answer {
            EngagementSolution::Single(result) => *result,
            EngagementSolution::Comparison(_) => panic!("single path expected"),
        }
    })
}

fn solve(body: Value) -> PathEngagement {
    solve_body(body, &tool(None), &Physics::default()).unwrap()
}

fn close_rel(what: &str, got: f64, expected: f64, relative: f64) {
    assert!((got - expected).abs() <= relative * expected.abs(), "{what}: got {got}, expected {expected}");
}

#[test]
fn full_slot_mean_torque_is_the_closed_form() {
    let flutes = [1, 2, 3, 4, 6];
    for mc in [0.0, 0.17, 0.25, 0.4] {
        let a = 1.0 - mc;
        let integral = sin_power_integral(a, 0.0, PI);
        let result = solve(slot(mc, &flutes));
        for flute in &result.flutes {
            let k = f64::from(flute.flute_count);
            // N·mm → N·m.
            let expected = k * KC11 * AP * FZ.powf(a) * RADIUS * integral / TAU / 1000.0;
            close_rel(&format!("mc {mc} k {k} mean torque"), flute.mean_torque_nm.unwrap(), expected, 0.005);
            // Far tighter than the 0.5 % a machinist needs: the table is exact to about 1e-9.
            close_rel(&format!("mc {mc} k {k} mean torque, tight"), flute.mean_torque_nm.unwrap(), expected, 1e-6);
        }
        if mc == 0.0 {
            // a = 1: I = 2 exactly, M = k·k_c·a_p·f_z·R/π.
            let k4 = &result.flutes[3];
            close_rel("mc 0 analytic", k4.mean_torque_nm.unwrap(), 4.0 * KC11 * AP * FZ * RADIUS / PI / 1000.0, 1e-9);
        }
    }
}

#[test]
fn full_slot_peak_torque_is_the_largest_tooth_sum() {
    // One tooth: the peak is at θ = 90°, R·k_c·a_p·f_z^a. Two teeth in a slot: always one tooth
    // on [0°, 180°], also R·k_c·a_p·f_z^a. Four teeth: two 90° apart, at 45° and 135° at best.
    let mc = 0.25;
    let a = 1.0 - mc;
    let result = solve(slot(mc, &[1, 2, 4]));
    let unit = RADIUS * KC11 * AP * FZ.powf(a) / 1000.0;
    let expected = [unit, unit, unit * 2.0 * (PI / 4.0).sin().powf(a)];
    for (flute, want) in result.flutes.iter().zip(expected) {
        close_rel(&format!("k {} peak", flute.flute_count), flute.peak_torque_nm.unwrap(), want, 1e-9);
        assert!(flute.peak_torque_nm.unwrap() >= flute.mean_torque_nm.unwrap());
    }
}

/// The resultant of k teeth at phase β in a full slot, per k_c·a_p·f_z^a, cw: each tooth
/// at θ on [0°, 180°] pushes with sin^a θ·[(−sin θ, cos θ) + ratio·(−cos θ, −sin θ)].
fn slot_resultant(a: f64, ratio: f64, flutes: u32, phase: f64) -> f64 {
    let (mut x, mut y) = (0.0, 0.0);
    for j in 0..flutes {
        let theta = (phase + 360.0 * f64::from(j) / f64::from(flutes)).rem_euclid(360.0);
        if theta <= 180.0 {
            let (s, c) = theta.to_radians().sin_cos();
            let w = s.max(0.0).powf(a);
            x += w * (-s - ratio * c);
            y += w * (c - ratio * s);
        }
    }
    x.hypot(y)
}

#[test]
fn full_slot_peak_force_is_the_largest_resultant() {
    let mc = 0.25;
    let a = 1.0 - mc;
    for ratio in [0.0, 0.3, 0.6] {
        let mut body = slot(mc, &[1, 2, 3, 4, 5]);
        body["kienzle"]["radial_ratio"] = json!(ratio);
        let result = solve(body);
        assert_eq!(result.forces.as_ref().unwrap().radial_ratio, ratio);
        let unit = KC11 * AP * FZ.powf(a);
        for flute in &result.flutes {
            let k = flute.flute_count;
            let scan = (0..=200_000)
                .map(|i| slot_resultant(a, ratio, k, 360.0 / f64::from(k) * f64::from(i) / 200_000.0))
                .fold(0.0, f64::max);
            close_rel(&format!("ratio {ratio} k {k} peak force"), flute.peak_force_n.unwrap(), unit * scan, 1e-5);
            if k == 1 {
                // One tooth: |F| = F_t·√(1 + ratio²), largest at θ = 90°.
                close_rel("k 1 closed", flute.peak_force_n.unwrap(), unit * (1.0 + ratio * ratio).sqrt(), 1e-9);
            }
        }
    }
    // Without radial_ratio the default applies.
    let forces = solve(slot(mc, &[2])).forces.unwrap();
    assert_eq!(forces.radial_ratio, material::DEFAULT_RADIAL_RATIO);
}

#[test]
fn side_milling_quarter_diameter_is_the_integral_over_the_engaged_arc() {
    // a_e = D/4 along the top edge of the block: climb milling over [0°, 60°] travelling +X
    // with the material on the right, conventional over [120°, 180°] travelling −X.
    let mc = 0.22;
    let a = 1.0 - mc;
    let integral = sin_power_integral(a, 0.0, PI / 3.0);
    let y = 20.0 + RADIUS - RADIUS / 2.0;
    for (path, arc) in [(json!([[-10, y], [60, y]]), [0.0, 60.0]), (json!([[60, y], [-10, y]]), [120.0, 180.0])] {
        let mut body = slot(mc, &[1, 3, 4]);
        body["path"] = path;
        let result = solve(body);
        let steady: Vec<_> = result.samples.iter().filter(|s| s.position[0] > 10.0 && s.position[0] < 40.0).collect();
        assert!(steady.len() > 100);
        for sample in steady {
            assert!((sample.radial_depth - RADIUS / 2.0).abs() < 1e-6, "a_e {}", sample.radial_depth);
            assert_eq!(sample.arcs.len(), 1);
            assert!((sample.arcs[0][0] - arc[0]).abs() < 1e-6 && (sample.arcs[0][1] - arc[1]).abs() < 1e-6);
            for (column, k) in [1.0, 3.0, 4.0].into_iter().enumerate() {
                let expected = k * KC11 * AP * FZ.powf(a) * RADIUS * integral / TAU / 1000.0;
                close_rel(&format!("s {} k {k}", sample.s), sample.torque_nm[column], expected, 1e-6);
            }
        }
    }
}

#[test]
fn power_is_two_pi_n_torque_over_sixty() {
    let result = solve(slot(0.25, &[2, 4]));
    for sample in &result.samples {
        for (torque, power) in sample.torque_nm.iter().zip(&sample.power_kw) {
            close_rel("sample power", *power, TAU * RPM * torque / 60.0 / 1000.0, 1e-12);
        }
    }
    for flute in &result.flutes {
        close_rel(
            "mean power",
            flute.mean_power_kw.unwrap(),
            TAU * RPM * flute.mean_torque_nm.unwrap() / 60_000.0,
            1e-12,
        );
        close_rel(
            "peak power",
            flute.peak_power_kw.unwrap(),
            TAU * RPM * flute.peak_torque_nm.unwrap() / 60_000.0,
            1e-12,
        );
        assert!((flute.tooth_passing_hz.unwrap() - RPM * f64::from(flute.flute_count) / 60.0).abs() < 1e-9);
    }
}

#[test]
fn helix_lag_is_two_ap_tan_helix_over_d() {
    let helix: f64 = 35.0;
    let result = solve_body(slot(0.25, &[4]), &tool(Some(helix)), &Physics::default()).unwrap();
    let forces = result.forces.unwrap();
    let expected = (2.0 * AP * helix.to_radians().tan() / (2.0 * RADIUS)).to_degrees();
    assert!((forces.helix_lag_deg - expected).abs() < 1e-12, "{} vs {expected}", forces.helix_lag_deg);
    let straight = solve(slot(0.25, &[4])).forces.unwrap();
    assert_eq!(straight.helix_lag_deg, 0.0);
}

/// The same slot as two candidate paths, the second with its own a_p.
fn slot_pair(request_depth: Option<f64>, own_depth: Value) -> Value {
    let mut body = slot(0.25, &[2, 4]);
    let path = body.as_object_mut().unwrap().remove("path").unwrap();
    body["paths"] =
        json!([{"name": "request's a_p", "path": path}, {"name": "own a_p", "path": path, "axial_depth": own_depth}]);
    match request_depth {
        Some(depth) => body["axial_depth"] = json!(depth),
        None => drop(body.as_object_mut().unwrap().remove("axial_depth")),
    }
    body
}

fn solve_pair(body: Value, tool: &Tool) -> Result<Vec<PathEngagement>, kerf_solver::error::SolverError> {
    let request: EngagementRequest = serde_json::from_value(body).unwrap();
    engagement::solve_in(&request, tool, None, &Physics::default(), kerf_solver::capability::Control::default()).map(
        |answer| match answer {
            EngagementSolution::Comparison(comparison) => comparison.candidates,
            EngagementSolution::Single(_) => panic!("candidates expected"),
        },
    )
}

#[test]
fn a_path_with_its_own_axial_depth() {
    // Torque is linear in the chip width a_p (no helix): twice the depth, twice the torque and
    // removal rate; the helix lag 2a_p·tan λ/D doubles too.
    let helix: f64 = 30.0;
    for (tool, lag_per_mm) in [(tool(None), 0.0), (tool(Some(helix)), (helix.to_radians().tan() / RADIUS).to_degrees())]
    {
        let pair = solve_pair(slot_pair(Some(AP), json!(2.0 * AP)), &tool).unwrap();
        let (shallow, deep) = (&pair[0], &pair[1]);
        let (a, b) = (shallow.forces.as_ref().unwrap(), deep.forces.as_ref().unwrap());
        assert_eq!((a.axial_depth, b.axial_depth), (AP, 2.0 * AP));
        assert!(
            (a.helix_lag_deg - AP * lag_per_mm).abs() < 1e-12
                && (b.helix_lag_deg - 2.0 * AP * lag_per_mm).abs() < 1e-12
        );
        for (x, y) in shallow.flutes.iter().zip(&deep.flutes) {
            let (once, twice) = (x.mean_torque_nm.unwrap(), y.mean_torque_nm.unwrap());
            close_rel("mean torque at 2·a_p", twice, 2.0 * once, 1e-12);
            close_rel("power at 2·a_p", y.mean_power_kw.unwrap(), 2.0 * x.mean_power_kw.unwrap(), 1e-12);
        }
        close_rel("removal rate at 2·a_p", deep.max_mrr.unwrap(), 2.0 * shallow.max_mrr.unwrap(), 1e-12);
    }
    // Every path may bring its own a_p instead of the request; a path with none then has none.
    let own = solve_pair(slot_pair(None, json!(3.0)), &tool(None));
    let error = own.unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("axial_depth")));
    let mut both_own = slot_pair(None, json!(3.0));
    both_own["paths"][0]["axial_depth"] = json!(1.5);
    let pair = solve_pair(both_own, &tool(None)).unwrap();
    assert_eq!(pair.iter().map(|c| c.forces.as_ref().unwrap().axial_depth).collect::<Vec<_>>(), [1.5, 3.0]);
    for bad in [json!(-1.0), json!(0.0), json!(1e9)] {
        let error = solve_pair(slot_pair(Some(AP), bad.clone()), &tool(None)).unwrap_err();
        assert_eq!(error.field(), Some("paths[1].axial_depth"), "{bad}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// The helix spreads each tooth over its lag: the torque averaged over the tooth phase is
    /// unchanged and its peak can only fall (it is a window mean of the straight-flute torque).
    #[test]
    fn helix_keeps_the_mean_and_never_raises_the_peak(
        helix in 5.0_f64..60.0,
        offset in -9.0_f64..9.0,
        flutes in 1_u32..7,
        mc in 0.1_f64..0.4,
        ccw in any::<bool>(),
    ) {
        let mut body = slot(mc, &[flutes]);
        body["path"] = json!([[-10, offset + 20.0], [60, offset + 20.0]]);
        body["step"] = json!(1.0);
        if ccw {
            body["spindle_direction"] = json!("ccw");
        }
        let straight = solve_body(body.clone(), &tool(None), &Physics::default()).unwrap();
        let helical = solve_body(body, &tool(Some(helix)), &Physics::default()).unwrap();
        for (a, b) in straight.samples.iter().zip(&helical.samples) {
            prop_assert!((a.torque_nm[0] - b.torque_nm[0]).abs() <= 1e-12 * a.torque_nm[0].max(1.0));
            prop_assert!(b.peak_torque_nm[0] <= a.peak_torque_nm[0] * (1.0 + 1e-9) + 1e-12);
            prop_assert!(b.peak_torque_nm[0] >= b.torque_nm[0] * (1.0 - 1e-9));
            // The resultant is a window mean of the straight-flute resultant too.
            prop_assert!(b.peak_force_n[0] <= a.peak_force_n[0] * (1.0 + 1e-6) + 1e-9);
        }
    }

    /// Torque grows as f_z^(1−m_c) and linearly with a_p and k_c1.1.
    #[test]
    fn torque_scales_with_feed_depth_and_material(scale in 0.2_f64..5.0, mc in 0.0_f64..0.5) {
        let base = solve(slot(mc, &[3]));
        let mut body = slot(mc, &[3]);
        body["feed_per_tooth"] = json!(FZ * scale);
        body["axial_depth"] = json!(AP * scale);
        body["kienzle"]["kc11"] = json!(KC11 * scale);
        let scaled = solve(body);
        let factor = scale.powf(1.0 - mc) * scale * scale;
        let (m0, m1) = (base.flutes[0].mean_torque_nm.unwrap(), scaled.flutes[0].mean_torque_nm.unwrap());
        prop_assert!((m1 - m0 * factor).abs() <= 1e-9 * m1);
        let (p0, p1) = (base.flutes[0].peak_torque_nm.unwrap(), scaled.flutes[0].peak_torque_nm.unwrap());
        prop_assert!((p1 - p0 * factor).abs() <= 1e-9 * p1);
    }
}

#[test]
fn over_the_power_limit_warns_and_the_capped_plan_brings_it_under() {
    let limit = 0.5;
    let physics =
        Physics { material: None, spindle: SpindleLimits { spindle_power_kw: Some(limit), spindle_torque_nm: None } };
    let mut body = slot(0.25, &[4]);
    // A thick target chip and a high machine feed: only the spindle can limit the plan.
    body["feed_plan"] = json!({"target_thickness": 1.0, "max_feed": 100_000, "flute_count": 4});
    let result = solve_body(body.clone(), &tool(None), &physics).unwrap();
    let nominal = result.flutes[0].mean_power_kw.unwrap();
    assert!(nominal > limit * 1.5, "the test needs a path well over the limit: {nominal} kW");
    assert!(result.warnings.iter().any(|w| w.code == "W_SPINDLE_POWER"), "{:?}", result.warnings);
    assert!(!result.warnings.iter().any(|w| w.code == "W_SPINDLE_TORQUE"));
    let plan = result.feed_plan.unwrap();
    let cutting: Vec<_> = plan.blocks.iter().filter(|b| b.to_s > 0.5).collect();
    assert!(!cutting.is_empty());
    for block in &cutting {
        assert_eq!(block.limited_by, Some(FeedLimit::Power), "{block:?}");
        // Re-run the path at the block's feed: its power is at the limit, not above.
        let mut rerun = body.clone();
        rerun.as_object_mut().unwrap().remove("feed_per_tooth");
        rerun.as_object_mut().unwrap().remove("feed_plan");
        rerun["feed"] = json!(block.feed.unwrap());
        let capped = solve_body(rerun, &tool(None), &physics).unwrap();
        let power = capped.flutes[0].mean_power_kw.unwrap();
        assert!(power <= limit, "capped power {power} kW");
        // Rounded down to whole mm/min only: within 1 % of the limit.
        assert!(power >= 0.99 * limit, "capped power {power} kW far below the limit");
        assert!(!capped.warnings.iter().any(|w| w.code == "W_SPINDLE_POWER"));
    }
}

#[test]
fn torque_limit_caps_at_low_speed() {
    // At 300 rpm a 10 kW spindle allows 318 N·m; its 1 N·m torque rating binds instead.
    let physics = Physics {
        material: None,
        spindle: SpindleLimits { spindle_power_kw: Some(10.0), spindle_torque_nm: Some(1.0) },
    };
    let mut body = slot(0.25, &[4]);
    body["spindle_rpm"] = json!(300);
    body["feed_plan"] = json!({"target_thickness": 1.0, "max_feed": 100_000, "flute_count": 4});
    let result = solve_body(body, &tool(None), &physics).unwrap();
    assert!(result.warnings.iter().any(|w| w.code == "W_SPINDLE_TORQUE"));
    assert!(!result.warnings.iter().any(|w| w.code == "W_SPINDLE_POWER"));
    let plan = result.feed_plan.unwrap();
    assert!(plan.blocks.iter().filter(|b| b.to_s > 0.5).all(|b| b.limited_by == Some(FeedLimit::Torque)));
    let forces = result.forces.unwrap();
    assert_eq!((forces.spindle_power_kw, forces.spindle_torque_nm), (Some(10.0), Some(1.0)));
}

#[test]
fn tooth_passing_near_a_natural_frequency_warns() {
    // N = 3000 rpm: k = 4 passes teeth at 200 Hz.
    for (natural, warned) in [(205.0, true), (195.0, true), (212.0, false), (150.0, false)] {
        let mut tool = tool(None);
        let mode = Mode { stiffness: 5000.0, frequency_hz: natural, damping_ratio: 0.05 };
        tool.stiffness = Some(Stiffness::Modal { x: vec![mode], y: vec![Mode { frequency_hz: 900.0, ..mode }] });
        let result = solve_body(slot(0.25, &[4]), &tool, &Physics::default()).unwrap();
        let warning = result.warnings.iter().any(|w| w.code == "W_TOOTH_PASSING");
        assert_eq!(warning, warned, "natural {natural} Hz");
        assert_eq!(result.forces.unwrap().natural_frequencies_hz, vec![natural, 900.0]);
    }
}

#[test]
fn material_is_resolved_by_the_caller() {
    let mut body = slot(0.25, &[4]);
    body.as_object_mut().unwrap().remove("kienzle");
    body["material"] = json!("C45");
    let error = solve_body(body.clone(), &tool(None), &Physics::default()).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("material")));
    let physics = Physics {
        material: Some(Kienzle { kc11: KC11, mc: 0.25, radial_ratio: None }),
        spindle: SpindleLimits::default(),
    };
    let named = solve_body(body, &tool(None), &physics).unwrap();
    let inline = solve(slot(0.25, &[4]));
    assert_eq!(named.flutes, inline.flutes);
}

#[test]
fn bad_physics_inputs_name_their_field() {
    let cases = [
        (json!({"kienzle": {"kc11": -1, "mc": 0.2}}), "kienzle.kc11"),
        (json!({"kienzle": {"kc11": 1800, "mc": 1.0}}), "kienzle.mc"),
        (json!({"kienzle": {"kc11": 1800, "mc": -0.1}}), "kienzle.mc"),
        (json!({"kienzle": {"kc11": 1800, "mc": 0.2, "radial_ratio": -0.5}}), "kienzle.radial_ratio"),
        (json!({"material": "C45"}), "material"),
    ];
    for (extra, field) in cases {
        let mut body = slot(0.25, &[4]);
        for (key, value) in extra.as_object().unwrap() {
            body[key] = value.clone();
        }
        let error = solve_body(body, &tool(None), &Physics::default()).unwrap_err();
        assert_eq!(error.field(), Some(field), "{error:?}");
    }
    let mut body = slot(0.25, &[4]);
    body.as_object_mut().unwrap().remove("axial_depth");
    let error = solve_body(body, &tool(None), &Physics::default()).unwrap_err();
    assert_eq!(error.field(), Some("axial_depth"));
    let limits =
        Physics { material: None, spindle: SpindleLimits { spindle_power_kw: Some(0.0), spindle_torque_nm: None } };
    let error = solve_body(slot(0.25, &[4]), &tool(None), &limits).unwrap_err();
    assert_eq!(error.field(), Some("spindle_power_kw"));
}

#[test]
fn without_kienzle_the_answer_has_no_force_fields() {
    let mut body = slot(0.25, &[4]);
    body.as_object_mut().unwrap().remove("kienzle");
    let physics =
        Physics { material: None, spindle: SpindleLimits { spindle_power_kw: Some(0.01), spindle_torque_nm: None } };
    let result = solve_body(body, &tool(None), &physics).unwrap();
    let text = serde_json::to_string(&result).unwrap();
    for key in ["torque_nm", "power_kw", "force_n", "forces", "tooth_passing_hz", "W_SPINDLE"] {
        assert!(!text.contains(key), "{key} in an answer without kienzle");
    }
}

/// The chip per f_z at tool angle θ (degrees) from the geometry: the edge point's distance ρ
/// from the path's centre over r_path, times sin θ.
fn edge_ratio(position: [f64; 2], heading_deg: f64, centre: [f64; 2], theta: f64) -> f64 {
    let (t, th) = (heading_deg.to_radians(), theta.to_radians());
    let (tangent, right) = ([t.cos(), t.sin()], [t.sin(), -t.cos()]);
    let q = [
        position[0] + RADIUS * (th.cos() * right[0] + th.sin() * tangent[0]),
        position[1] + RADIUS * (th.cos() * right[1] + th.sin() * tangent[1]),
    ];
    let rho = (q[0] - centre[0]).hypot(q[1] - centre[1]);
    let r_path = (position[0] - centre[0]).hypot(position[1] - centre[1]);
    rho / r_path * th.sin().max(0.0)
}

#[test]
fn arc_feed_correction_uses_the_feed_at_the_edge() {
    // Widening a Ø30 hole (left by an earlier circle of radius 10) by 1 mm: the tool centre
    // runs a ccw half circle of radius 11, the material outside the turn (climb, right).
    let mc = 0.25;
    let body = |correct: bool| {
        json!({
            "tool": 1, "stock": {"polygon": [[-40, -40], [40, -40], [40, 40], [-40, 40]],
                "previous_cuts": [{"path": {"start": [10, 0], "segments": [
                    {"type": "arc", "to": [10, 0], "center": [0, 0], "dir": "ccw"}]}, "radius": RADIUS}]},
            "path": {"start": [11, 0], "segments": [{"type": "arc", "to": [-11, 0], "center": [0, 0], "dir": "ccw"}]},
            "spindle_rpm": RPM, "feed_per_tooth": FZ, "flute_counts": [1, 3], "step": 0.2,
            "axial_depth": AP, "kienzle": {"kc11": KC11, "mc": mc}, "arc_feed_correction": correct,
        })
    };
    let plain = solve(body(false));
    let corrected = solve(body(true));
    let mut checked = 0;
    for (a, b) in plain.samples.iter().zip(&corrected.samples) {
        let angle = b.position[1].atan2(b.position[0]).to_degrees();
        if !(60.0..150.0).contains(&angle) {
            continue;
        }
        checked += 1;
        assert_eq!(a.arcs, b.arcs);
        let [from, to] = b.arcs[0];
        assert!(from >= -1e-9 && to < 90.0, "{:?}", b.arcs);
        // Thickest chip of one tooth: the largest geometric ratio over the arc, densely.
        let n = 20_000;
        let dense: Vec<f64> = (0..=n)
            .map(|i| {
                edge_ratio(b.position, b.heading_deg, [0.0, 0.0], from + (to - from) * f64::from(i) / f64::from(n))
            })
            .collect();
        let peak = dense.iter().copied().fold(0.0, f64::max);
        close_rel("corrected H k=1", b.thickness[0], FZ * peak, 1e-4);
        // Outside the turn the edge runs faster than the centre: (11 + 5)/11 at the wall.
        assert!(b.thickness[0] > a.thickness[0] * 1.3, "{} vs {}", b.thickness[0], a.thickness[0]);
        // Phase-mean torque: R·k_c·a_p·f_z^a/(2π)·∫ (c·sin)^a over the arc, by the midpoint rule.
        let width = (to - from).to_radians() / f64::from(n);
        let integral: f64 = (0..n)
            .map(|i| {
                let theta = from + (to - from) * (f64::from(i) + 0.5) / f64::from(n);
                edge_ratio(b.position, b.heading_deg, [0.0, 0.0], theta).powf(1.0 - mc) * width
            })
            .sum();
        let expected = KC11 * AP * FZ.powf(1.0 - mc) * RADIUS * integral / TAU / 1000.0;
        close_rel("corrected torque k=1", b.torque_nm[0], expected, 1e-4);
    }
    assert!(checked > 50);
    // Straight paths are not touched by the switch.
    let mut straight = slot(mc, &[3]);
    let unswitched = solve(straight.clone());
    straight["arc_feed_correction"] = json!(true);
    let switched = solve(straight);
    assert_eq!(unswitched.samples, switched.samples);
}

/// ∫₀^a_p r(z)·sin^(−m_c)κ(z) dz for a corner radius r_c (R ball), directly in z after
/// z = a_p·u² (the integrand has a z^(−m_c/2) singularity at the tip): independent of the
/// solver's κ substitution and tables.
fn torque_width(radius: f64, corner: f64, depth: f64, mc: f64) -> f64 {
    let n = 400_000;
    (0..n)
        .map(|i| {
            let u = (f64::from(i) + 0.5) / f64::from(n);
            let z = depth * u * u;
            let (r, sin_kappa) = if z < corner {
                let s = (corner * corner - (corner - z) * (corner - z)).sqrt() / corner;
                (radius - corner + corner * s, s)
            } else {
                (radius, 1.0)
            };
            r * sin_kappa.powf(-mc) * 2.0 * depth * u / f64::from(n)
        })
        .sum()
}

#[test]
fn ball_and_bull_ends_integrate_chip_and_lever_arm_over_the_height() {
    let mut ball = tool(None);
    ball.kind = ToolKind::Ball;
    let mut bull = tool(None);
    bull.kind = ToolKind::Bull;
    bull.corner_radius = Some(2.0);
    for mc in [0.0, 0.25] {
        let a = 1.0 - mc;
        let integral = sin_power_integral(a, 0.0, PI);
        for (label, end, corner, depth) in
            [("ball a_p = R", &ball, RADIUS, RADIUS), ("ball a_p < R", &ball, RADIUS, 2.0), ("bull", &bull, 2.0, 4.0)]
        {
            let mut body = slot(mc, &[2, 4]);
            body["axial_depth"] = json!(depth);
            let result = solve_body(body, end, &Physics::default()).unwrap();
            // Every height band's section cuts its whole front half here: the same as the full
            // radius's arcs, now computed per band (no W_FORCE_MODEL).
            assert!(!result.warnings.iter().any(|w| w.code == "W_FORCE_MODEL"), "{label}: per height");
            let width = torque_width(RADIUS, corner, depth, mc);
            for flute in &result.flutes {
                let k = f64::from(flute.flute_count);
                let expected = k * KC11 * width * FZ.powf(a) * integral / TAU / 1000.0;
                close_rel(&format!("{label} mc {mc} k {k}"), flute.mean_torque_nm.unwrap(), expected, 1e-4);
            }
        }
    }
    // m_c = 0: the spindle's work per turn is k_c·k·f_z times the slot's cross-section A, so
    // M = k·k_c·f_z·A/(2π): a half disc πR²/2 for the ball at a_p = R, 2R·a_p less the two
    // corners' (1 − π/4)·r_c² for the bull.
    let check = |end: &Tool, depth: f64, area: f64| {
        let mut body = slot(0.0, &[4]);
        body["axial_depth"] = json!(depth);
        let result = solve_body(body, end, &Physics::default()).unwrap();
        let expected = 4.0 * KC11 * FZ * area / TAU / 1000.0;
        close_rel(&format!("{:?} cross-section", end.kind), result.flutes[0].mean_torque_nm.unwrap(), expected, 1e-6);
    };
    check(&ball, RADIUS, PI * RADIUS * RADIUS / 2.0);
    check(&bull, 4.0, 2.0 * RADIUS * 4.0 - 2.0 * (1.0 - PI / 4.0) * 4.0);
    // A flat end has no warning and R·a_p.
    let flat = solve(slot(0.25, &[2]));
    assert!(!flat.warnings.iter().any(|w| w.code == "W_FORCE_MODEL"));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// Wherever the capped plan runs, the spindle's phase-mean power and torque at the block's
    /// feed stay within the machine's ratings (checked on every sample of the block from its
    /// own torque at the nominal feed, scaled by (f_block/f_nominal)^(1−m_c)).
    #[test]
    fn capped_plan_never_exceeds_the_spindle(
        power in 0.05_f64..2.0,
        torque in 0.2_f64..5.0,
        offset in -6.0_f64..6.0,
        corner in 15.0_f64..45.0,
        rpm in 800.0_f64..6000.0,
        mc in 0.1_f64..0.35,
    ) {
        let physics = Physics {
            material: None,
            spindle: SpindleLimits { spindle_power_kw: Some(power), spindle_torque_nm: Some(torque) },
        };
        let mut body = slot(mc, &[3]);
        body["spindle_rpm"] = json!(rpm);
        body["step"] = json!(0.5);
        body["path"] = json!([[-10, offset], [corner, offset], [corner, 30]]);
        body["feed_plan"] = json!({"target_thickness": 1.0, "max_feed": 50_000, "flute_count": 3});
        let result = solve_body(body, &tool(None), &physics).unwrap();
        let plan = result.feed_plan.clone().unwrap();
        let nominal_feed = result.flutes[0].feed;
        for block in &plan.blocks {
            let feed = block.feed.unwrap();
            for sample in result.samples.iter().filter(|s| s.s >= block.from_s - 1e-9 && s.s <= block.to_s + 1e-9) {
                let scaled = sample.torque_nm[0] * (feed / nominal_feed).powf(1.0 - mc);
                let scaled_power = TAU * rpm * scaled / 60_000.0;
                prop_assert!(scaled <= torque * (1.0 + 1e-9), "s {}: {} N·m > {}", sample.s, scaled, torque);
                prop_assert!(scaled_power <= power * (1.0 + 1e-9), "s {}: {} kW > {}", sample.s, scaled_power, power);
            }
        }
    }
}
