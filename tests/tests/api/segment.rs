//! `POST /api/v1/segment` over HTTP: the patent's experiment (case A) and cases B and C, every
//! curve kind, machine defaults and overrides, G-code through `rs274` for both dialects, and a
//! table of bad requests that leave the database unchanged.

use kerf_cases::{case, close, number};
use kerf_tests::{TestApp, external_program, json_with, problem, rs274_moves};
use serde_json::{Value, json};

fn points(answer: &Value) -> Vec<Vec<f64>> {
    answer["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect())
        .collect()
}

fn check_points(what: &str, got: &[Vec<f64>], expected: &Value) {
    let expected = expected.as_array().unwrap();
    assert_eq!(got.len(), expected.len(), "{what}: count");
    for (index, (point, want)) in got.iter().zip(expected).enumerate() {
        for axis in 0..2 {
            close(&format!("{what}[{index}][{axis}]"), point[axis], number(&want[axis]), 1e-6);
        }
    }
}

fn check_ends(answer: &Value, expected: &Value) {
    let all = points(answer);
    let first = expected["first_points"].as_array().unwrap().len();
    let last = expected["last_points"].as_array().unwrap().len();
    check_points("first points", &all[..first], &expected["first_points"]);
    check_points("last points", &all[all.len() - last..], &expected["last_points"]);
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

/// What every answer must satisfy: counts agree, no short block except span ends, the largest
/// deviation within the largest window chord error, block lengths as reported.
fn check_answer(what: &str, answer: &Value) {
    let all = points(answer);
    assert_eq!(answer["blocks"].as_u64().unwrap() as usize, all.len() - 1, "{what}: blocks");
    assert_eq!(answer["s"].as_array().unwrap().len(), all.len(), "{what}: s per point");
    assert_eq!(answer["short_blocks"], 0, "{what}: short blocks");
    let deviation = number(&answer["max_deviation"]);
    assert!(deviation <= number(&answer["chord_error"]) * (1.0 + 1e-6) + 1e-12, "{what}: deviation {deviation}");
    let shortest = all.windows(2).map(|p| distance(&p[0], &p[1])).fold(f64::INFINITY, f64::min);
    assert!(shortest <= number(&answer["min_block_length"]) + 1e-12, "{what}: shortest block");
    let block_time = number(&answer["block_length"]);
    close(what, block_time, number(&answer["feed"]) * number(&answer["block_time_ms"]) / 60_000.0, 1e-12);
}

async fn segment(app: &TestApp, body: &Value) -> Value {
    json_with(app.post_json("/api/v1/segment", body).await, 200).await
}

#[tokio::test(flavor = "multi_thread")]
async fn patent_experiment_case_a_over_http() {
    let app = TestApp::spawn().await;
    let case = case("segment", "A");
    let expected = &case["expected"];
    let body = json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 50},
                      "feed": 10000, "block_time_ms": 4, "mode": "window", "margin": 1.0,
                      "min_chord_error": 0.0, "compare_tolerance": 0.01});
    let answer = segment(&app, &body).await;
    check_answer("case A", &answer);
    close("C_ep", number(&answer["chord_error"]), 0.001_111_123_5, 5e-11);
    close("C_ep (fixture)", number(&answer["chord_error"]), number(&expected["Cep_mm"]), 1e-13);
    assert_eq!(answer["blocks"], 472);
    check_ends(&answer, expected);
    close("shortest block", number(&answer["min_block_length"]), number(&expected["chord_length_mm"]), 1e-9);
    close("last block", number(&answer["last_block_length"]), number(&expected["last_chord_mm"]), 1e-6);
    close("block-limited time", number(&answer["estimated_time_s"]), 1.888, 5e-4);
    assert_eq!(answer["short_end_blocks"], 1);
    assert!(answer["windows"].as_array().unwrap().iter().all(|w| w["status"] == "ok"));
    // Side by side: the same circle at a plain 0.01 mm.
    let fixed = &answer["comparison"];
    assert_eq!(fixed["blocks"], case["baselines"]["fixed_0.01mm"]["blocks"]);
    close("fixed chord", number(&fixed["min_block_length"]), 1.999_9, 1e-4);
    assert_eq!(fixed["short_blocks"], 0);
    eprintln!(
        "patent experiment over HTTP: rule C_ep {:.10} mm, {} blocks, shortest {:.6} mm, short {}, last {:.6} mm, \
         max deviation {:.10} mm, {:.4} s; fixed 0.01 mm: {} blocks, shortest {:.6} mm, short {}, max deviation \
         {:.6} mm, {:.4} s",
        number(&answer["chord_error"]),
        answer["blocks"],
        number(&answer["min_block_length"]),
        answer["short_blocks"],
        number(&answer["last_block_length"]),
        number(&answer["max_deviation"]),
        number(&answer["estimated_time_s"]),
        fixed["blocks"],
        number(&fixed["min_block_length"]),
        fixed["short_blocks"],
        number(&fixed["max_deviation"]),
        number(&fixed["estimated_time_s"]),
    );
    // A fixed 0.0005 mm starves the control: blocks shorter than one block time.
    let mut fine = body.clone();
    fine["compare_tolerance"] = json!(0.0005);
    let starved = segment(&app, &fine).await;
    assert_eq!(starved["comparison"]["blocks"], 703);
    assert!(starved["comparison"]["short_blocks"].as_u64().unwrap() > 600);

    // Determinism: byte-identical answers.
    let once = app.client.post(app.url("/api/v1/segment")).json(&body).send().await.unwrap().bytes().await.unwrap();
    let again = app.client.post(app.url("/api/v1/segment")).json(&body).send().await.unwrap().bytes().await.unwrap();
    assert_eq!(once, again);
}

#[tokio::test(flavor = "multi_thread")]
async fn cases_b_and_c_over_http() {
    let app = TestApp::spawn().await;
    let ellipse = json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 50], "start_deg": 0, "end_deg": 90});
    let case_b = case("segment", "B");
    let answer = segment(
        &app,
        &json!({"curve": ellipse, "feed": 10000, "block_time_ms": 4, "margin": 1.1, "mode": "curve", "rule": "extremes"}),
    )
    .await;
    check_answer("case B", &answer);
    close("C_ep", number(&answer["chord_error"]), number(&case_b["expected"]["Cep_mm"]), 1e-12);
    assert_eq!(answer["blocks"], case_b["expected"]["blocks_total_greedy"]);
    assert_eq!(answer["windows"].as_array().unwrap().len(), 1);
    check_ends(&answer, &case_b["expected"]);

    let case_c = case("segment", "C");
    let answer = segment(
        &app,
        &json!({"curve": ellipse, "feed": 12000, "block_time_ms": 4, "margin": 1.05, "min_chord_error": 0.001,
                "window": 5, "compare_tolerance": 0.001}),
    )
    .await;
    check_answer("case C", &answer);
    assert_eq!(answer["blocks"], case_c["expected"]["blocks_total"]);
    let windows = answer["windows"].as_array().unwrap();
    assert_eq!(windows.len() as u64, case_c["expected"]["windows"].as_u64().unwrap());
    let clamped = windows.iter().filter(|w| w["status"] == "clamped_to_min_chord_error").count();
    assert_eq!(clamped as u64, case_c["expected"]["windows_clamped_to_Cemin"].as_u64().unwrap());
    close("first window radius", number(&windows[0]["radius"]), 25.325_135_169, 1e-6);
    check_ends(&answer, &case_c["expected"]);
    // The fixed 0.001 mm baseline starves the control on 70 blocks.
    assert_eq!(answer["comparison"]["blocks"], 145);
    assert_eq!(answer["comparison"]["short_blocks"], 70);
}

/// A request for `curve` at 6000 mm/min and 4 ms, with the margin of 1.1 that absorbs curvature
/// growing inside a window (with 1.0 the 3-point radius lets some blocks come out a few per cent
/// short, which the answer reports as `W_BLOCK_TIME_VIOLATION`).
fn at_6000(curve: Value) -> Value {
    json!({"curve": curve, "feed": 6000, "block_time_ms": 4, "margin": 1.1})
}

#[tokio::test(flavor = "multi_thread")]
async fn every_curve_kind() {
    let app = TestApp::spawn().await;
    // Circle, clockwise from 90°, in a plane at z = 5.
    let answer = segment(
        &app,
        &at_6000(json!({"kind": "circle", "centre": [10, 20, 5], "radius": 30, "start_deg": 90, "direction": "cw"})),
    )
    .await;
    check_answer("circle", &answer);
    let all = points(&answer);
    assert!(all.iter().all(|p| p.len() == 3 && (p[2] - 5.0).abs() < 1e-12));
    assert!(distance(&all[0], &[10.0, 50.0, 5.0]) < 1e-9 && distance(all.last().unwrap(), &[10.0, 50.0, 5.0]) < 1e-9);
    assert!(all[1][0] > 10.0, "clockwise from the top goes to +x");

    // Arc: a quarter, with its figures against the exact NURBS quarter circle below.
    let arc = segment(
        &app,
        &at_6000(
            json!({"kind": "arc", "centre": [0, 0], "radius": 50, "start_deg": 0, "end_deg": 90, "direction": "ccw"}),
        ),
    )
    .await;
    check_answer("arc", &arc);
    let arc_points = points(&arc);
    assert!(distance(arc_points.last().unwrap(), &[0.0, 50.0]) < 1e-9);
    assert!(arc_points.iter().all(|p| p.len() == 2 && (p[0].hypot(p[1]) - 50.0).abs() < 1e-9));

    // Ellipse, rotated, full turn.
    let answer = segment(
        &app,
        &at_6000(json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [40, 15], "rotation_deg": 30})),
    )
    .await;
    check_answer("ellipse", &answer);
    let radii: Vec<f64> = answer["windows"].as_array().unwrap().iter().filter_map(|w| w["radius"].as_f64()).collect();
    let (low, high) = radii.iter().fold((f64::INFINITY, 0.0_f64), |(l, h), r| (l.min(*r), h.max(*r)));
    assert!(low < 6.0 && high > 90.0, "radius from b²/a = 5.6 to a²/b = 107: {low} … {high}");

    // NURBS: the exact quarter circle of the arc above gives the same chord error and blocks.
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let nurbs = segment(
        &app,
        &at_6000(json!({"kind": "bspline", "degree": 2, "control_points": [[50, 0], [50, 50], [0, 50]],
                        "weights": [1, half, 1], "knots": [0, 0, 0, 1, 1, 1]})),
    )
    .await;
    check_answer("nurbs", &nurbs);
    close("nurbs chord error", number(&nurbs["chord_error"]), number(&arc["chord_error"]), 1e-9);
    assert_eq!(nurbs["blocks"], arc["blocks"]);
    for (got, want) in points(&nurbs).iter().zip(&arc_points) {
        assert!(distance(got, want) < 1e-6, "{got:?} vs {want:?}");
    }

    // A clamped uniform cubic B-spline in 3-D (default knots).
    let answer = segment(
        &app,
        &at_6000(json!({"kind": "bspline", "degree": 3,
                        "control_points": [[0, 0, 0], [40, 0, 2], [40, 40, 4], [0, 40, 6], [0, 80, 8], [40, 80, 10]]})),
    )
    .await;
    check_answer("bspline", &answer);
    let all = points(&answer);
    assert!(distance(&all[0], &[0.0, 0.0, 0.0]) < 1e-12 && distance(all.last().unwrap(), &[40.0, 80.0, 10.0]) < 1e-9);

    // Dense polylines: a 2-D circle sampled every ~0.02 mm gives the circle's own chord error.
    let samples: Vec<Value> = (0..=15_708)
        .map(|k| {
            let t = k as f64 / 15_708.0 * std::f64::consts::FRAC_PI_2;
            json!([50.0 * t.cos(), 50.0 * t.sin()])
        })
        .collect();
    let answer = segment(&app, &at_6000(json!({"kind": "polyline", "points": samples}))).await;
    check_answer("polyline 2-D", &answer);
    close(
        "polyline chord error",
        number(&answer["chord_error"]),
        number(&arc["chord_error"]),
        0.02 * number(&arc["chord_error"]),
    );
    assert!(points(&answer).iter().all(|p| p.len() == 2));

    // A 3-D helix R20, 5 mm pitch: three coordinates out, z rising.
    let helix: Vec<Value> = (0..=6000)
        .map(|k| {
            let t = k as f64 / 1000.0;
            json!([20.0 * t.cos(), 20.0 * t.sin(), 5.0 * t / std::f64::consts::TAU])
        })
        .collect();
    let answer = segment(&app, &at_6000(json!({"kind": "polyline", "points": helix}))).await;
    check_answer("polyline 3-D", &answer);
    let all = points(&answer);
    assert!(all.iter().all(|p| p.len() == 3));
    assert!(all.windows(2).all(|p| p[1][2] > p[0][2]), "z rises along the helix");
    // Helix curvature radius r(1 + (p/2πr)²) = 20.03 mm.
    let radius = number(&answer["min_radius"]);
    assert!((radius - 20.03).abs() < 0.1, "helix radius {radius}");
}

#[tokio::test(flavor = "multi_thread")]
async fn machine_defaults_and_overrides() {
    let app = TestApp::spawn().await;
    let machine =
        json!({"block_time_ms": 4, "max_feed": 10000, "dialect": "linuxcnc", "margin": 1.1, "min_chord_error": 0.001});
    json_with(app.put_json("/api/v1/machines/hsc", &machine).await, 201).await;
    let circle = json!({"kind": "circle", "centre": [0, 0], "radius": 50});

    // The machine's values are the defaults: feed = max_feed, its block time, margin and clamp.
    let answer = segment(&app, &json!({"curve": circle, "machine": "hsc"})).await;
    check_answer("machine defaults", &answer);
    assert_eq!(answer["machine"]["name"], "hsc");
    assert_eq!((&answer["feed"], &answer["block_time_ms"]), (&json!(10000.0), &json!(4.0)));
    assert_eq!((&answer["margin"], &answer["min_chord_error"]), (&json!(1.1), &json!(0.001)));
    close("C_ep with k_f 1.1", number(&answer["chord_error"]), 0.001_344_5, 1e-6);
    assert!(answer["warnings"].as_array().unwrap().iter().all(|w| w["code"] != "W_FEED_ABOVE_MACHINE_MAX"));

    // The request overrides each of them; a feed below the machine's is kept.
    let answer = segment(
        &app,
        &json!({"curve": circle, "machine": "hsc", "feed": 6000, "block_time_ms": 2, "margin": 1.0, "min_chord_error": 0.0}),
    )
    .await;
    assert_eq!((&answer["feed"], &answer["block_time_ms"]), (&json!(6000.0), &json!(2.0)));
    assert_eq!((&answer["margin"], &answer["min_chord_error"]), (&json!(1.0), &json!(0.0)));
    // h = 6000·2/120000 = 0.1 mm on R50.
    close("C_ep overridden", number(&answer["chord_error"]), 0.01 / (50.0 + (2500.0_f64 - 0.01).sqrt()), 1e-12);
    assert!(answer["warnings"].as_array().unwrap().iter().all(|w| w["code"] != "W_FEED_ABOVE_MACHINE_MAX"));

    // A feed above the machine's is capped to it, never the other way, and the answer says so.
    let answer = segment(&app, &json!({"curve": circle, "machine": "hsc", "feed": 12000, "block_time_ms": 2})).await;
    assert_eq!(answer["feed"], json!(10000.0));
    let capped = answer["warnings"].as_array().unwrap().iter().find(|w| w["code"] == "W_FEED_ABOVE_MACHINE_MAX");
    let message = capped.expect("W_FEED_ABOVE_MACHINE_MAX")["message"].as_str().unwrap();
    assert!(message.contains("capped from 12000 mm/min to 10000"), "{message}");

    // The clamp of the machine applies where the rule asks for less (large radius).
    let answer = segment(
        &app,
        &json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 500}, "machine": "hsc", "feed": 3000}),
    )
    .await;
    assert!(answer["windows"].as_array().unwrap().iter().all(|w| w["status"] == "clamped_to_min_chord_error"));
    close("clamped", number(&answer["chord_error"]), 0.001, 1e-15);

    // G-code: the machine's dialect unless the query names one.
    let program = |query: &'static str| {
        let request = json!({"curve": circle, "machine": "hsc"});
        let url = app.url(&format!("/api/v1/segment{query}"));
        let client = app.client.clone();
        async move {
            let response = client.post(url).header("accept", "text/x-gcode").json(&request).send().await.unwrap();
            assert_eq!(response.status(), 200);
            response.text().await.unwrap()
        }
    };
    let own = program("").await;
    assert!(own.contains("G64 P") && !own.starts_with('%'), "linuxcnc from the machine:\n{own}");
    let fanuc = program("?dialect=fanuc").await;
    assert!(fanuc.starts_with("%\nO1001") && !fanuc.contains("G64"), "fanuc asked for:\n{fanuc}");

    // After the machine is deleted, naming it is a 404 on `machine`.
    assert_eq!(app.delete("/api/v1/machines/hsc").await.status(), 204);
    let answer =
        problem(app.post_json("/api/v1/segment", &json!({"curve": circle, "machine": "hsc"})).await, 404).await;
    assert_eq!(answer["errors"][0]["path"], "machine");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn programs_pass_rs274_and_match_json() {
    if external_program("rs274", "the LinuxCNC G-code check").is_none() {
        return;
    }
    let app = TestApp::spawn().await;
    app.register_tool(4, &json!({"kind": "flat", "radius": 3})).await;
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let requests = [
        (
            "circle_a",
            json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 50}, "feed": 10000, "block_time_ms": 4, "tool": 4}),
        ),
        (
            "ellipse_c",
            json!({"curve": {"kind": "ellipse", "centre": [10, -5, -2], "semi_axes": [100, 50], "end_deg": 90},
                   "feed": 12000, "block_time_ms": 4, "margin": 1.05, "min_chord_error": 0.001, "window": 5,
                   "tool": {"kind": "ball", "radius": 2}}),
        ),
        (
            "nurbs_3d",
            json!({"curve": {"kind": "bspline", "degree": 2, "control_points": [[50, 0, 1], [50, 50, 3], [0, 50, 5]],
                              "weights": [1, half, 1]}, "feed": 3000, "block_time_ms": 2, "tool": 4, "spindle_rpm": 12000}),
        ),
    ];
    for (name, body) in requests {
        let answer = segment(&app, &body).await;
        let expected: Vec<[f64; 3]> =
            points(&answer).iter().map(|p| [p[0], p[1], p.get(2).copied().unwrap_or(0.0)]).collect();
        for dialect in ["fanuc", "linuxcnc"] {
            let url = app.url(&format!("/api/v1/segment?format=gcode&dialect={dialect}"));
            let response = app.client.post(url).json(&body).send().await.unwrap();
            assert_eq!(response.status(), 200, "{name} {dialect}");
            assert!(response.headers()["content-type"].to_str().unwrap().starts_with("text/x-gcode"));
            let program = response.text().await.unwrap();
            let label = format!("segment_{name}_{dialect}");
            let moves = rs274_moves(&program, app.directory(), &label).expect("rs274 present");
            let feeds: Vec<[f64; 3]> = moves.iter().filter(|m| m.0).map(|m| m.1).collect();
            // The first feed move plunges to the curve start; then one per block.
            assert_eq!(feeds.len(), expected.len(), "{label}: one feed move per point");
            for (index, (got, want)) in feeds.iter().zip(&expected).enumerate() {
                assert!(distance(got, want) <= 1e-4 * 3f64.sqrt(), "{label}: point {index} {got:?} vs {want:?}");
            }
            // The plunge to the start at half the feed (no plunge feed given), then the feed.
            let mut g01 = program.lines().filter(|l| l.starts_with("G01"));
            let feed = answer["feed"].as_f64().unwrap();
            let (plunge, first_block) = (g01.next().unwrap(), g01.next().unwrap());
            assert!(plunge.ends_with(&format!("F{:.0}", feed * 0.5)), "{label}: F word of the plunge: {plunge}");
            assert!(first_block.ends_with(&format!("F{feed:.0}")), "{label}: F word on the first block: {first_block}");
            let f_words = program.lines().filter(|l| l.starts_with("G01") && l.contains(" F")).count();
            assert_eq!(f_words, 2, "{label}: modal feed");
            if name == "ellipse_c" {
                assert!(program.contains("M00"), "an inline tool without a number stops for a manual change");
            } else {
                assert!(program.contains("T4 M06") && program.contains("G43 H4"), "{label}");
            }
        }
    }
}

/// A valid request to start each bad case from.
fn valid() -> Value {
    json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 50}, "feed": 10000, "block_time_ms": 4})
}

fn with(path: &[&str], value: Value) -> Value {
    let mut body = valid();
    let mut slot = &mut body;
    for key in &path[..path.len() - 1] {
        slot = &mut slot[*key];
    }
    slot[path[path.len() - 1]] = value;
    body
}

fn without(key: &str) -> Value {
    let mut body = valid();
    body.as_object_mut().unwrap().remove(key);
    body
}

fn curve(curve: Value) -> Value {
    with(&["curve"], curve)
}

/// (what, body, status, field, code)
fn bad_cases() -> Vec<(&'static str, Value, u16, &'static str, &'static str)> {
    let line2 = |points: Value| json!({"kind": "polyline", "points": points});
    let spline = |extra: Value| {
        let mut c = json!({"kind": "bspline", "degree": 2, "control_points": [[0, 0], [10, 10], [20, 0], [30, 10]]});
        for (k, v) in extra.as_object().unwrap() {
            c[k] = v.clone();
        }
        c
    };
    vec![
        ("zero feed", with(&["feed"], json!(0)), 422, "feed", "E_INPUT"),
        ("negative feed", with(&["feed"], json!(-100)), 422, "feed", "E_INPUT"),
        ("zero block time", with(&["block_time_ms"], json!(0)), 422, "block_time_ms", "E_INPUT"),
        ("negative block time", with(&["block_time_ms"], json!(-4)), 422, "block_time_ms", "E_INPUT"),
        ("no feed and no machine", without("feed"), 422, "feed", "E_INPUT"),
        ("no block time and no machine", without("block_time_ms"), 422, "block_time_ms", "E_INPUT"),
        ("feed beyond f64", with(&["feed"], json!("placeholder")), 400, "feed", "E_JSON"),
        ("huge radius", with(&["curve", "radius"], json!(1e300)), 422, "curve.radius", "E_INPUT"),
        ("huge centre", with(&["curve", "centre"], json!([1e300, 0])), 422, "curve.centre[0]", "E_INPUT"),
        ("huge feed", with(&["feed"], json!(1e300)), 422, "feed", "E_INFEASIBLE_FEED_FOR_RADIUS"),
        ("tiny block time", with(&["block_time_ms"], json!(1e-300)), 422, "min_chord_error", "E_TOO_MANY_BLOCKS"),
        ("zero radius", with(&["curve", "radius"], json!(0)), 422, "curve.radius", "E_INPUT"),
        (
            "arc without sweep",
            curve(json!({"kind": "arc", "centre": [0, 0], "radius": 5, "start_deg": 30, "end_deg": 30})),
            422,
            "curve.end_deg",
            "E_DEGENERATE_CURVE",
        ),
        (
            "flat ellipse",
            curve(json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [5, 0]})),
            422,
            "curve.semi_axes[1]",
            "E_INPUT",
        ),
        ("polyline of one point", curve(line2(json!([[1, 1]]))), 422, "curve.points", "E_DEGENERATE_CURVE"),
        (
            "polyline of one repeated point",
            curve(line2(json!([[1, 1], [1, 1], [1, 1]]))),
            422,
            "curve.points",
            "E_DEGENERATE_CURVE",
        ),
        ("polyline mixing 2-D and 3-D", curve(line2(json!([[0, 0], [1, 1, 1]]))), 422, "curve.points[1]", "E_INPUT"),
        ("a point with four axes", with(&["curve", "centre"], json!([0, 0, 0, 0])), 422, "curve.centre", "E_INPUT"),
        (
            "spline with coinciding control points",
            curve(json!({"kind": "bspline", "degree": 2, "control_points": [[1, 1], [1, 1], [1, 1]]})),
            422,
            "curve.control_points",
            "E_DEGENERATE_CURVE",
        ),
        (
            "knots of the wrong count",
            curve(spline(json!({"knots": [0, 0, 0, 1, 1, 1]}))),
            422,
            "curve.knots",
            "E_INPUT",
        ),
        (
            "decreasing knots",
            curve(spline(json!({"knots": [0, 0, 0, 0.7, 1, 1, 0.9]}))),
            422,
            "curve.knots[6]",
            "E_INPUT",
        ),
        ("unclamped knots", curve(spline(json!({"knots": [0, 1, 2, 3, 4, 5, 6]}))), 422, "curve.knots[1]", "E_INPUT"),
        ("degree 6", curve(spline(json!({"degree": 6}))), 422, "curve.degree", "E_INPUT"),
        ("too few control points", curve(spline(json!({"degree": 4}))), 422, "curve.control_points", "E_INPUT"),
        ("negative weight", curve(spline(json!({"weights": [1, -1, 1, 1]}))), 422, "curve.weights[1]", "E_INPUT"),
        (
            "feed infeasible for the radius",
            with(&["curve", "radius"], json!(0.3)),
            422,
            "feed",
            "E_INFEASIBLE_FEED_FOR_RADIUS",
        ),
        ("margin below 1", with(&["margin"], json!(0.9)), 422, "margin", "E_INPUT"),
        ("rule in window mode", with(&["rule"], json!("max")), 422, "rule", "E_INPUT"),
        ("zero window", with(&["window"], json!(0)), 422, "window", "E_INPUT"),
        ("unreachable tolerance", with(&["tolerance"], json!(1e-9)), 422, "tolerance", "E_INPUT"),
        ("negative compare tolerance", with(&["compare_tolerance"], json!(-0.01)), 422, "compare_tolerance", "E_INPUT"),
        ("clearance below the curve", with(&["safe_z"], json!(-1)), 422, "safe_z", "E_INPUT"),
        (
            "inline tool with zero radius",
            with(&["tool"], json!({"kind": "ball", "radius": 0})),
            422,
            "tool.radius",
            "E_INPUT",
        ),
        ("unknown machine", with(&["machine"], json!("no-such-control")), 404, "machine", "E_NOT_FOUND"),
        ("unknown tool", with(&["tool"], json!(4242)), 404, "tool", "E_NOT_FOUND"),
        ("unknown field", with(&["colour"], json!("red")), 400, "colour", "E_JSON"),
        ("unknown curve field", with(&["curve", "colour"], json!("red")), 400, "curve", "E_JSON"),
        ("unknown curve kind", with(&["curve", "kind"], json!("spiral")), 400, "curve.kind", "E_JSON"),
        ("unknown mode", with(&["mode"], json!("fast")), 400, "mode", "E_JSON"),
        ("string for a number", with(&["feed"], json!("10000")), 400, "feed", "E_JSON"),
        ("missing curve", without("curve"), 400, "body", "E_JSON"),
    ]
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_segment_requests() {
    let app = TestApp::spawn().await;
    app.register_tool(4, &json!({"kind": "flat", "radius": 3})).await;
    json_with(app.put_json("/api/v1/machines/hsc", &json!({"block_time_ms": 4, "max_feed": 10000})).await, 201).await;
    let tools_before = json_with(app.get("/api/v1/tools").await, 200).await;
    let machines_before = json_with(app.get("/api/v1/machines").await, 200).await;
    let mut mismatches = Vec::new();
    for (what, body, status, field, code) in bad_cases() {
        let response = if what == "feed beyond f64" {
            let text = valid().to_string().replace("10000", "1e999");
            app.client
                .post(app.url("/api/v1/segment"))
                .header("content-type", "application/json")
                .body(text)
                .send()
                .await
                .unwrap()
        } else {
            app.post_json("/api/v1/segment", &body).await
        };
        let answer = problem(response, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
        if what == "feed infeasible for the radius" {
            let detail = answer["detail"].as_str().unwrap();
            assert!(detail.contains("largest feasible feed is 9000 mm/min"), "{detail}");
        }
    }
    // The query is checked too.
    for (query, field) in [("?dialect=mazak", "dialect"), ("?format=pdf", "format"), ("?colour=red", "colour")] {
        let answer = problem(app.post_json(&format!("/api/v1/segment{query}"), &valid()).await, 400).await;
        assert_eq!(answer["errors"][0]["path"], field);
    }
    let raw = app.client.post(app.url("/api/v1/segment")).body("{}").send().await.unwrap();
    problem(raw, 415).await;
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await, tools_before, "tools unchanged");
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await, machines_before, "machines unchanged");
}

async fn submit(app: &TestApp, body: String, media_type: &str) -> reqwest::Response {
    app.client.post(app.url("/api/v1/jobs")).header("content-type", media_type).body(body).send().await.unwrap()
}

async fn run_job(app: &TestApp, body: String, media_type: &str) -> Value {
    let submitted = json_with(submit(app, body, media_type).await, 202).await;
    kerf_tests::poll_job(&app.client, &app.base, submitted["id"].as_i64().unwrap(), 60, kerf_tests::finished).await
}

#[tokio::test(flavor = "multi_thread")]
async fn jobs_carry_machines_from_the_file_or_the_registry() {
    let app = TestApp::spawn().await;
    let circle = json!({"kind": "circle", "centre": [0, 0], "radius": 50});
    // A machine in the file is used before the registry's machine of the same name.
    json_with(app.put_json("/api/v1/machines/hsc", &json!({"block_time_ms": 8, "max_feed": 5000})).await, 201).await;
    let in_file = json!({
        "name": "file machine",
        "machines": [{"name": "hsc", "block_time_ms": 4, "max_feed": 10000, "dialect": "linuxcnc"}],
        "operations": [{"operation": "segment", "machine": "hsc", "curve": circle}]
    });
    let job = run_job(&app, in_file.to_string(), "application/json").await;
    assert_eq!(job["status"], "done", "{job}");
    let result = &job["results"][0]["result"];
    assert_eq!(
        (&result["feed"], &result["block_time_ms"], &result["blocks"]),
        (&json!(10000.0), &json!(4.0), &json!(472))
    );
    let id = job["id"].as_i64().unwrap();
    let program = app.get(&format!("/api/v1/jobs/{id}/gcode")).await.text().await.unwrap();
    assert!(program.contains("G01 X49.9956 Y0.6667 Z0.0000"), "{program}");

    // A machine only in the registry is resolved at submission and stored with the job.
    let from_registry = "name = \"registry machine\"\n[[operations]]\noperation = \"segment\"\nmachine = \"hsc\"\n\
                         curve = { kind = \"circle\", centre = [0, 0], radius = 50 }\n"
        .to_owned();
    let job = run_job(&app, from_registry.clone(), "application/toml").await;
    assert_eq!(job["status"], "done", "{job}");
    assert_eq!(
        (&job["results"][0]["result"]["feed"], &job["results"][0]["result"]["block_time_ms"]),
        (&json!(5000.0), &json!(8.0))
    );
    // The same file after the machine changed is a different job, not the earlier result.
    json_with(app.put_json("/api/v1/machines/hsc", &json!({"block_time_ms": 4, "max_feed": 5000})).await, 200).await;
    let submitted = json_with(submit(&app, from_registry.clone(), "application/toml").await, 202).await;
    assert_ne!(submitted["id"], job["id"]);
    // Without the machine, the submission is refused naming the operation's field.
    assert_eq!(app.delete("/api/v1/machines/hsc").await.status(), 204);
    let answer = problem(submit(&app, from_registry, "application/toml").await, 404).await;
    assert_eq!(answer["errors"][0]["path"], "operations[0].machine");

    // Bad machines in a file, and NaN (TOML has it; JSON has not) reaching the solver.
    let good_op = "[[operations]]\noperation = \"segment\"\nmachine = \"m\"\ncurve = { kind = \"circle\", centre = [0, 0], radius = 50 }\n";
    let cases = [
        ("[[machines]]\nblock_time_ms = 4\nmax_feed = 1000\n", 400, "machines[0].name"),
        ("[[machines]]\nname = \"m\"\nblock_time_ms = 0\nmax_feed = 1000\n", 422, "machines[0].block_time_ms"),
        ("[[machines]]\nname = \"m\"\nblock_time_ms = nan\nmax_feed = 1000\n", 400, "machines[0].block_time_ms"),
        ("[[machines]]\nname = \"a b\"\nblock_time_ms = 4\nmax_feed = 1000\n", 422, "machines[0].name"),
        (
            "[[machines]]\nname = \"m\"\nblock_time_ms = 4\nmax_feed = 1000\n[[machines]]\nname = \"m\"\nblock_time_ms = 2\nmax_feed = 1000\n",
            400,
            "machines[1].name",
        ),
        ("[[machines]]\nname = \"m\"\nblock_time_ms = 4\nmax_feed = 1000\naxes = 5\n", 400, "machines[0].axes"),
        ("[[machines]]\nname = \"other\"\nblock_time_ms = 4\nmax_feed = 1000\n", 404, "operations[0].machine"),
    ];
    for (machines, status, field) in cases {
        let answer = problem(submit(&app, format!("{machines}{good_op}"), "application/toml").await, status).await;
        assert_eq!(answer["errors"][0]["path"], field, "{machines}: {answer}");
    }
    // TOML has nan and inf, JSON has not: refused at submission with the line and field.
    let circle = "curve = { kind = \"circle\", centre = [0, 0], radius = 50 }";
    let cases = [
        (format!("feed = nan\nblock_time_ms = 4\n{circle}"), "operations[0].feed", "line 3,"),
        (format!("feed = 1000\nblock_time_ms = -inf\n{circle}"), "operations[0].block_time_ms", "line 4,"),
        (
            "feed = 1000\nblock_time_ms = 4\ncurve = { kind = \"circle\", centre = [0, +nan], radius = 5e1 }"
                .to_owned(),
            "operations[0].curve.centre[1]",
            "line 5,",
        ),
    ];
    for (fields, field, line) in cases {
        let text = format!("[[operations]]\noperation = \"segment\"\n{fields}\n");
        let answer = problem(submit(&app, text, "application/toml").await, 400).await;
        assert_eq!(answer["errors"][0]["path"], field, "{answer}");
        assert!(answer["detail"].as_str().unwrap().starts_with(line), "{answer}");
    }
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await, json!([]), "registry unchanged");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn segment_page_plots_compares_and_uses_a_machine() {
    let app = TestApp::spawn().await;
    let Some(result) = crate::browser::run_scenario(&app, "segment", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["segments"], 472, "{result}");
    // R50 at 12 000 mm/min with k_f 1.1: blocks of 0.88 mm, 357 of them with the remainder.
    assert!(result["machineBlocks"].as_u64().unwrap() < 472, "{result}");
    // The machine the page registered is gone again.
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await, json!([]));
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn jobs_page_shows_segment_results() {
    let app = TestApp::spawn().await;
    let example = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/segment-machine.toml");
    let Some(result) = crate::browser::run_scenario(&app, "jobs", &[example.to_str().unwrap()]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["plots"], 6, "plan, chord error and block length per operation: {result}");
}

#[tokio::test(flavor = "multi_thread")]
async fn guarantee_mode_from_the_request_or_the_machine_leaves_no_short_block() {
    let app = TestApp::spawn().await;
    let quarter = json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 50], "end_deg": 90});
    let window = json_with(
        app.post_json("/api/v1/segment", &json!({"curve": quarter, "feed": 10000, "block_time_ms": 4})).await,
        200,
    )
    .await;
    assert!(window["short_blocks"].as_u64().unwrap() > 0, "the patent's windows leave short blocks");
    let asked = json!({"curve": quarter, "feed": 10000, "block_time_ms": 4, "mode": "guarantee"});
    let guaranteed = json_with(app.post_json("/api/v1/segment", &asked).await, 200).await;
    assert_eq!(guaranteed["short_blocks"], 0, "guarantee mode");
    // A machine whose mode is guarantee makes it the default of requests naming it.
    let machine = json!({"block_time_ms": 4, "max_feed": 10000, "mode": "guarantee"});
    json_with(app.put_json("/api/v1/machines/no-starving", &machine).await, 201).await;
    let named = json!({"curve": quarter, "machine": "no-starving"});
    let from_machine = json_with(app.post_json("/api/v1/segment", &named).await, 200).await;
    assert_eq!(from_machine["short_blocks"], 0, "the machine's guarantee mode");
    assert_eq!(from_machine["points"], guaranteed["points"]);
}
