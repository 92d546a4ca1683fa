//! `POST /api/v1/contour` and `POST /api/v1/contour/loops` over HTTP: the three reference
//! contours of docs/spec/contour.md (C1–C3) to the fixture's 1e-6, G-code of both dialects through
//! LinuxCNC's `rs274` with its end points equal to the JSON moves, a table of bad requests with
//! the database unchanged, the JSON move limit, and byte-identical answers.

use kerf_cases::contour::{circle, pocket_request, reference};
use kerf_cases::{case, number, triple};
use kerf_tests::{TestApp, assert_moves_match, external_program, finished, json_with, poll_job, problem, rs274_moves};
use serde_json::{Value, json};

const TOLERANCE: f64 = 1e-6;

fn pair(value: &Value) -> [f64; 2] {
    [number(&value[0]), number(&value[1])]
}

fn close_pair(what: &str, got: &Value, expected: &Value) {
    let (got, expected) = (pair(got), pair(expected));
    let distance = ((got[0] - expected[0]).powi(2) + (got[1] - expected[1]).powi(2)).sqrt();
    assert!(distance <= 1.5 * TOLERANCE, "{what}: got {got:?}, expected {expected:?}");
}

fn close(what: &str, got: &Value, expected: f64) {
    let got = number(got);
    assert!((got - expected).abs() <= TOLERANCE, "{what}: got {got}, expected {expected}");
}

pub async fn app_with_tools() -> TestApp {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3, "name": "D6 flat end mill"})).await;
    app.register_tool(4, &json!({"kind": "ball", "radius": 2})).await;
    app.register_tool(5, &json!({"kind": "bull", "radius": 4, "corner_radius": 1})).await;
    app
}

/// Every end point of the answer's moves in machining order: (feed move, point).
fn answer_moves(answer: &Value, lift: f64) -> Vec<(bool, [f64; 3])> {
    answer["layers"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|layer| layer["moves"].as_array().unwrap().iter())
        .map(|step| {
            let mut to = triple(&step["to"]);
            to[2] += lift;
            (step["kind"] != "rapid", to)
        })
        .collect()
}

#[tokio::test(flavor = "multi_thread")]
async fn reference_contours_over_http() {
    let app = app_with_tools().await;
    for id in ["C1", "C2", "C3"] {
        let case = case("contour", id);
        let answer = json_with(app.post_json("/api/v1/contour", &reference(id)).await, 200).await;
        let expected_passes = case["expected"]["passes"].as_array().unwrap();
        let final_pass = expected_passes.last().unwrap();
        assert_eq!(answer["tool"]["kind"], "flat");
        assert_eq!(answer["summary"]["layers"], 1, "{id}");
        assert_eq!(answer["summary"]["passes"], expected_passes.len(), "{id}");
        assert_eq!(answer["layers"][0]["z"], 0.0);

        // Corners of the final pass, in request order, matched by vertex.
        let corners = answer["corners"].as_array().unwrap();
        assert_eq!(corners.len(), final_pass["corners"].as_array().unwrap().len(), "{id} corners");
        for want in final_pass["corners"].as_array().unwrap() {
            let vertex = pair(&want["V"]);
            let got = corners
                .iter()
                .find(|c| {
                    let v = pair(&c["vertex"]);
                    (v[0] - vertex[0]).abs() < 1e-5 && (v[1] - vertex[1]).abs() < 1e-5
                })
                .unwrap_or_else(|| panic!("{id}: no corner at {vertex:?}"));
            let what = |name: &str| format!("{id} corner {vertex:?} {name}");
            close(&what("alpha"), &got["angle_deg"], number(&want["alpha_deg"]));
            close(&what("phi"), &got["turn_deg"], number(&want["phi_deg"]));
            let convex = want["convex"].as_bool().unwrap();
            assert_eq!(got["convexity"], if convex { "convex" } else { "concave" }, "{}", what("convexity"));
            close_pair(&what("P"), &got["cl_point"], &want["P"]);
            let action = match want["action"].as_str().unwrap() {
                "loop_arc" => "loop_arc",
                "loop_par" => "loop_parallelogram",
                "reflex" => "reflex",
                other => panic!("unexpected action {other}"),
            };
            assert_eq!(got["action"], action, "{}", what("action"));
            assert_eq!(got["looped"], want.get("loop").is_some(), "{}", what("looped"));
            if let Some(want_loop) = want.get("loop") {
                let got_loop = &got["corner_loop"];
                close(&what("L"), &got_loop["leg"], number(&want_loop["L"]));
                close_pair(&what("A"), &got_loop["exit_end"], &want_loop["A"]);
                close_pair(&what("B"), &got_loop["entry_start"], &want_loop["B"]);
                if want_loop["type"] == "arc" {
                    close(&what("rho"), &got_loop["radius"], number(&want_loop["rho"]));
                    close_pair(&what("C"), &got_loop["centre"], &want_loop["C"]);
                    close(&what("sweep"), &got_loop["sweep_deg"], number(&want_loop["sweep_deg"]));
                } else {
                    close_pair(&what("M"), &got_loop["far_corner"], &want_loop["M"]);
                }
            }
            if let Some(area) = want.get("inside_corner_leftover_area_final") {
                close(&what("material left"), &got["material"]["left_area"], number(area));
            } else {
                assert_eq!(got["material"]["left_area"], 0.0, "{}", what("nothing left at a convex corner"));
            }
        }

        // Per pass: offset, start and the lengths by element kind.
        let passes = answer["passes"].as_array().unwrap();
        for (got, want) in passes.iter().zip(expected_passes) {
            let what = |name: &str| format!("{id} pass {} {name}", want["pass_index"]);
            close(&what("offset"), &got["offset"], number(&want["offset"]));
            close_pair(&what("start"), &got["start"], &want["start"]);
            let by_kind = &want["length_by_kind"];
            let length = |kind: &str| by_kind.get(kind).map_or(0.0, number);
            close(&what("cut"), &got["cut_length"], length("cut"));
            close(&what("legs"), &got["leg_length"], length("exit") + length("entry"));
            close(&what("loops"), &got["loop_length"], length("loop"));
        }

        // The final pass runs through every looped corner point twice: into the loop and back.
        let moves = answer_moves(&answer, 0.0);
        for corner in corners.iter().filter(|c| c["looped"] == true) {
            let p = pair(&corner["cl_point"]);
            let visits = moves
                .iter()
                .filter(|(feed, to)| *feed && (to[0] - p[0]).abs() < 1e-9 && (to[1] - p[1]).abs() < 1e-9)
                .count();
            assert!(visits >= 2, "{id}: corner point {p:?} passed {visits} times");
        }
        assert!(answer["layers"][0]["moves"].as_array().unwrap().iter().any(|m| m["kind"] == "loop"));
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn pocket_with_layers_loops_and_relief() {
    let app = app_with_tools().await;
    let answer = json_with(app.post_json("/api/v1/contour", &pocket_request()).await, 200).await;
    assert_eq!(answer["tool"]["number"], 3);
    let layers = answer["layers"].as_array().unwrap();
    let heights: Vec<f64> = layers.iter().map(|l| number(&l["z"])).collect();
    assert_eq!(heights, vec![-2.0, -4.0, -6.0]);
    // Every layer starts and ends at the clearance plane.
    let safe_z = number(&answer["summary"]["safe_z"]);
    for layer in layers {
        let moves = layer["moves"].as_array().unwrap();
        assert_eq!(number(&moves.last().unwrap()["to"][2]), safe_z);
        assert!(moves.iter().filter(|m| m["kind"] != "rapid").all(|m| number(&m["to"][2]) == number(&layer["z"])));
    }
    let corners = answer["corners"].as_array().unwrap();
    let action = |index: usize| corners.iter().find(|c| c["index"] == index).unwrap()["action"].as_str().unwrap();
    // The pocket's corners get dogbones; the wedge's tip at (40, 40) protrudes into the pocket
    // and gets a loop.
    for index in [0, 1, 2, 6] {
        assert_eq!(action(index), "dogbone", "corner {index}");
    }
    assert_eq!(action(4), "loop_arc");
    let relief = corners.iter().find(|c| c["index"] == 0).unwrap();
    assert!(number(&relief["material"]["left_area"]) < 1e-9, "the dogbone reaches the vertex");
    assert!(number(&relief["material"]["overcut_area"]) > 0.0, "a dogbone cuts beyond the faces");
    assert!(layers[0]["moves"].as_array().unwrap().iter().any(|m| m["kind"] == "loop" && m["feed"] == 1500.0));
    assert_eq!(answer["summary"]["moves"], layers.iter().map(|l| l["moves"].as_array().unwrap().len()).sum::<usize>());
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn gcode_of_both_dialects_matches_the_json_moves() {
    if external_program("rs274", "the LinuxCNC G-code check").is_none() {
        return;
    }
    let app = app_with_tools().await;
    let mut ball = reference("C3");
    ball["tool"] = json!(4);
    ball["depths"] = json!({"top": 0, "bottom": -3, "step": 1.5});
    let mut blocks = pocket_request();
    blocks["block_time_ms"] = json!(4);
    let jobs = [
        ("pocket", pocket_request(), 0.0),
        ("pocket_block_time", blocks, 0.0),
        ("c3_ball", ball, 2.0),
        ("c2_inline", reference("C2"), 0.0),
    ];
    for (name, body, centre_height) in jobs {
        let answer = json_with(app.post_json("/api/v1/contour", &body).await, 200).await;
        for dialect in ["fanuc", "linuxcnc"] {
            for reference in ["tip", "centre"] {
                let url = app.url(&format!("/api/v1/contour?dialect={dialect}&reference={reference}"));
                let response = app.client.post(url).header("accept", "text/x-gcode").json(&body).send().await.unwrap();
                assert_eq!(response.status(), 200, "{name} {dialect} {reference}");
                assert!(response.headers()["content-type"].to_str().unwrap().starts_with("text/x-gcode"));
                let program = response.text().await.unwrap();
                let label = format!("contour_{name}_{dialect}_{reference}");
                let mut interpreted = rs274_moves(&program, app.directory(), &label).expect("rs274 present");
                // First the length-offset traverse to the clearance plane, last the final retract.
                interpreted.remove(0);
                interpreted.pop();
                let lift = if reference == "centre" { centre_height } else { 0.0 };
                let expected = answer_moves(&answer, lift);
                assert_moves_match(&label, &interpreted, &expected);
                if dialect == "linuxcnc" {
                    assert!(program.contains("G64 P"), "{label}: blending tolerance");
                } else {
                    assert!(program.starts_with("%\nO1000"), "{label}: Fanuc program number");
                }
                if name == "c2_inline" {
                    assert!(program.contains("M00"), "an inline tool without a number stops for a manual change");
                }
            }
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn answers_are_byte_identical() {
    let app = app_with_tools().await;
    let mut blocks = pocket_request();
    blocks["block_time_ms"] = json!(4);
    for body in [pocket_request(), reference("C2"), blocks] {
        let mut answers = Vec::new();
        for accept in ["application/json", "application/json", "text/x-gcode", "text/x-gcode"] {
            let response =
                app.client.post(app.url("/api/v1/contour")).header("accept", accept).json(&body).send().await.unwrap();
            assert_eq!(response.status(), 200);
            answers.push(response.bytes().await.unwrap());
        }
        assert_eq!(answers[0], answers[1], "JSON");
        assert_eq!(answers[2], answers[3], "G-code");
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn json_answers_are_limited_and_gcode_goes_further() {
    let app = app_with_tools().await;
    // About 606 moves in each of 1 000 layers: over the JSON limit, within the G-code limit.
    // Without the contour's own verification, which would cut those 1 000 layers on its model
    // (nine tenths of the request's time in a debug build, near the 30 s synchronous limit on a
    // loaded machine) and is not what this checks.
    let body = json!({
        "tool": 3, "contour": circle(600), "side": "outside",
        "depths": {"top": 0, "bottom": -100, "step": 0.1}, "feed": 800,
        "verification": {"enabled": false}
    });
    let refused = problem(app.post_json("/api/v1/contour", &body).await, 422).await;
    assert_eq!(refused["code"], "E_TOO_MANY_MOVES");
    assert_eq!(refused["errors"][0]["path"], "depths.step");
    let detail = refused["detail"].as_str().unwrap();
    assert!(detail.contains("500000") && detail.contains("G-code") && detail.contains("job"), "{detail}");

    let program = app.post_text("/api/v1/contour?format=gcode", &body, 200).await;
    let blocks = program.lines().filter(|l| l.starts_with("G01") || l.starts_with("G00")).count();
    assert!(blocks > 500_000, "{blocks} blocks");
    assert!(program.ends_with("M30\n%\n"));
}

/// A valid request to start each bad case from (tool 3, an outer profile in three layers).
fn valid() -> Value {
    json!({
        "tool": 3,
        "contour": [[0, 0], [40, 0], [40, 30], [0, 30]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -6, "step": 2},
        "corner_loop": {"style": "arc"},
        "feed": 800
    })
}

/// `valid()` with the fields of `changes` replaced (nested objects replaced whole).
fn with(changes: Value) -> Value {
    let mut body = valid();
    for (key, value) in changes.as_object().unwrap() {
        body[key] = value.clone();
    }
    body
}

fn without(key: &str) -> Value {
    let mut body = valid();
    body.as_object_mut().unwrap().remove(key);
    body
}

/// (what, path and query, body, expected status, field path, code)
type Case = (&'static str, &'static str, Value, u16, &'static str, &'static str);

fn contour_cases() -> Vec<Case> {
    let notch = json!([[0, 0], [30, 0], [30, 20], [17, 20], [17, 10], [14, 10], [14, 20], [0, 20]]);
    let neck = json!([
        [0, 0],
        [40, 0],
        [40, 30],
        [21.5, 30],
        [21.5, 20],
        [30, 20],
        [30, 5],
        [10, 5],
        [10, 20],
        [18.5, 20],
        [18.5, 30],
        [0, 30]
    ]);
    let r2 = json!({"kind": "flat", "radius": 2});
    let url = "/api/v1/contour";
    let gcode = "/api/v1/contour?format=gcode";
    vec![
        (
            "self-intersecting polygon",
            url,
            with(json!({"contour": [[0, 0], [10, 10], [10, 0], [0, 10]]})),
            422,
            "contour[2]",
            "E_SELF_INTERSECTION",
        ),
        ("fewer than 3 points", url, with(json!({"contour": [[0, 0], [10, 0]]})), 422, "contour", "E_DEGENERATE"),
        ("no points", url, with(json!({"contour": []})), 422, "contour", "E_DEGENERATE"),
        (
            "duplicate points",
            url,
            with(json!({"contour": [[0, 0], [20, 0], [10, 10], [20, 20], [0, 20], [10, 10]]})),
            422,
            "contour[5]",
            "E_DUPLICATE_POINT",
        ),
        (
            "zero area",
            url,
            with(json!({"contour": [[0, 0], [10, 0], [20, 0], [5, 0]]})),
            422,
            "contour",
            "E_DEGENERATE",
        ),
        (
            "clockwise contour",
            url,
            with(json!({"contour": [[0, 0], [0, 30], [40, 30], [40, 0]]})),
            422,
            "contour",
            "E_ORIENTATION",
        ),
        (
            "null coordinate",
            url,
            with(json!({"contour": [[0, 0], [40, 0], [40, null], [0, 30]]})),
            400,
            "contour[2][1]",
            "E_JSON",
        ),
        (
            "point with three coordinates",
            url,
            with(json!({"contour": [[0, 0, 0], [40, 0], [40, 30]]})),
            400,
            "contour[0]",
            "E_JSON",
        ),
        (
            "tool too big for a notch",
            url,
            with(json!({"contour": notch, "tool": r2})),
            422,
            "contour[4]",
            "E_OFFSET_COLLAPSE",
        ),
        (
            "tool too big for a neck",
            url,
            with(json!({"contour": neck, "tool": r2})),
            422,
            "contour[3]",
            "E_OFFSET_SELF_INTERSECTION",
        ),
        (
            "tool too big for a pocket",
            url,
            with(json!({"contour": [[0, 0], [3, 0], [3, 3], [0, 3]], "side": "inside"})),
            422,
            "contour[0]",
            "E_OFFSET_COLLAPSE",
        ),
        (
            "bottom above top",
            url,
            with(json!({"depths": {"top": 0, "bottom": 5, "step": 1}})),
            422,
            "depths.bottom",
            "E_INPUT",
        ),
        ("zero step", url, with(json!({"depths": {"top": 0, "bottom": -5, "step": 0}})), 422, "depths.step", "E_INPUT"),
        (
            "negative step",
            url,
            with(json!({"depths": {"top": 0, "bottom": -5, "step": -1}})),
            422,
            "depths.step",
            "E_INPUT",
        ),
        (
            "too many layers",
            url,
            with(json!({"depths": {"top": 0, "bottom": -100, "step": 0.001}})),
            422,
            "depths.step",
            "E_TOO_MANY_LAYERS",
        ),
        ("zero feed", url, with(json!({"feed": 0})), 422, "feed", "E_INPUT"),
        ("zero block time", url, with(json!({"block_time_ms": 0})), 422, "block_time_ms", "E_INPUT"),
        ("negative block time", url, with(json!({"block_time_ms": -4})), 422, "block_time_ms", "E_INPUT"),
        ("block time as a string", url, with(json!({"block_time_ms": "4"})), 400, "block_time_ms", "E_JSON"),
        ("negative loop feed", url, with(json!({"loop_feed": -5})), 422, "loop_feed", "E_INPUT"),
        (
            "loop radius limits crossed",
            url,
            with(json!({"corner_loop": {"style": "arc", "min_radius": 3, "max_radius": 1}})),
            422,
            "corner_loop.min_radius",
            "E_INPUT",
        ),
        (
            "allowances growing inwards",
            url,
            with(json!({"passes": [{"allowance": 0.2}, {"allowance": 0.5}]})),
            422,
            "passes[1].allowance",
            "E_INPUT",
        ),
        (
            "override of no corner",
            url,
            with(json!({"corner_overrides": [{"index": 9, "loop": false}]})),
            422,
            "corner_overrides[0].index",
            "E_INPUT",
        ),
        ("unknown tool", url, with(json!({"tool": 4242})), 404, "tool", "E_NOT_FOUND"),
        (
            "inline tool with zero radius",
            url,
            with(json!({"tool": {"kind": "flat", "radius": 0}})),
            422,
            "tool.radius",
            "E_INPUT",
        ),
        ("unknown tool kind", url, with(json!({"tool": {"kind": "drill", "radius": 3}})), 400, "tool.kind", "E_JSON"),
        ("unknown top-level field", url, with(json!({"colour": "red"})), 400, "colour", "E_JSON"),
        (
            "unknown field in depths",
            url,
            with(json!({"depths": {"top": 0, "bottom": -6, "step": 2, "middle": -3}})),
            400,
            "depths.middle",
            "E_JSON",
        ),
        (
            "unknown field in corner_loop",
            url,
            with(json!({"corner_loop": {"style": "arc", "size": 2}})),
            400,
            "corner_loop.size",
            "E_JSON",
        ),
        (
            "unknown loop style",
            url,
            with(json!({"corner_loop": {"style": "star"}})),
            400,
            "corner_loop.style",
            "E_JSON",
        ),
        ("unknown side", url, with(json!({"side": "middle"})), 400, "side", "E_JSON"),
        ("missing feed", url, without("feed"), 400, "body", "E_JSON"),
        ("string for a number", url, with(json!({"feed": "800"})), 400, "feed", "E_JSON"),
        ("bad dialect", "/api/v1/contour?format=gcode&dialect=mazak", valid(), 400, "dialect", "E_QUERY"),
        ("unknown query parameter", "/api/v1/contour?units=inch", valid(), 400, "units", "E_QUERY"),
        ("tilted walls as G-code", gcode, with(json!({"tilt_deg": 5})), 422, "tilt_deg", "E_TILT_NEEDS_5_AXIS"),
        (
            "huge JSON answer",
            url,
            with(json!({"contour": circle(600), "depths": {"top": 0, "bottom": -100, "step": 0.1}})),
            422,
            "depths.step",
            "E_TOO_MANY_MOVES",
        ),
        (
            "huge program",
            gcode,
            with(json!({"contour": circle(20_000), "depths": {"top": 0, "bottom": -100, "step": 0.25}})),
            422,
            "depths.step",
            "E_TOO_MANY_MOVES",
        ),
        ("too many points", url, with(json!({"contour": circle(200_001)})), 422, "contour", "E_TOO_MANY_POINTS"),
    ]
}

fn loops_cases() -> Vec<Case> {
    let url = "/api/v1/contour/loops";
    let square = json!([[-1, -1], [21, -1], [21, 21], [-1, 21]]);
    // 200 corners turning 1.8° each, every one looped with about 3 500 chords: over 500 000 moves.
    let polygon: Vec<[f64; 2]> = (0..200)
        .map(|k| {
            let angle = std::f64::consts::TAU * k as f64 / 200.0;
            [500.0 * angle.cos(), 500.0 * angle.sin()]
        })
        .collect();
    vec![
        ("fewer than 3 points", url, json!({"tool": 3, "path": [[0, 0], [1, 0]]}), 422, "path", "E_DEGENERATE"),
        (
            "repeated points only",
            url,
            json!({"tool": 3, "path": [[0, 0], [0, 0], [1, 0], [1, 0]]}),
            422,
            "path",
            "E_DEGENERATE",
        ),
        ("unknown tool", url, json!({"tool": 4242, "path": square}), 404, "tool", "E_NOT_FOUND"),
        (
            "inline tool with negative radius",
            url,
            json!({"tool": {"kind": "flat", "radius": -1}, "path": square}),
            422,
            "tool.radius",
            "E_INPUT",
        ),
        (
            "turn threshold of 180°",
            url,
            json!({"tool": 3, "path": square, "threshold": 180}),
            422,
            "threshold",
            "E_INPUT",
        ),
        ("negative tolerance", url, json!({"tool": 3, "path": square, "tolerance": -1}), 422, "tolerance", "E_INPUT"),
        ("unknown detection mode", url, json!({"tool": 3, "path": square, "detect": "magic"}), 400, "detect", "E_JSON"),
        ("unknown field", url, json!({"tool": 3, "path": square, "side": "left"}), 400, "side", "E_JSON"),
        (
            "G-code asked for",
            "/api/v1/contour/loops?format=gcode",
            json!({"tool": 3, "path": square}),
            400,
            "format",
            "E_QUERY",
        ),
        (
            "huge answer",
            url,
            json!({"tool": 3, "path": polygon, "threshold": 1, "tolerance": 1e-6}),
            422,
            "path",
            "E_TOO_MANY_MOVES",
        ),
    ]
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_requests_name_the_field_and_change_nothing() {
    let app = app_with_tools().await;
    let tools_before = json_with(app.get("/api/v1/tools").await, 200).await;
    let jobs_before = json_with(app.get("/api/v1/jobs").await, 200).await;
    let mut mismatches = Vec::new();
    for (what, url, body, status, field, code) in contour_cases().into_iter().chain(loops_cases()) {
        let response = app.post_json(url, &body).await;
        if response.status() != status {
            let text = response.text().await.unwrap();
            mismatches.push(format!("{what}: expected {status}, got {}", &text[..text.len().min(300)]));
            continue;
        }
        let answer = problem(response, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await, tools_before, "tool table unchanged");
    assert_eq!(json_with(app.get("/api/v1/jobs").await, 200).await, jobs_before, "no job created");
}

#[tokio::test(flavor = "multi_thread")]
async fn loops_on_an_existing_path_repeat_the_contour_loops() {
    let app = app_with_tools().await;
    // C1's final pass: the square's offset by r = 1, travelled counter-clockwise from S (the
    // middle of edge 0), material on the left.
    let contour = json_with(app.post_json("/api/v1/contour", &reference("C1")).await, 200).await;
    let body = json!({
        "tool": {"kind": "flat", "radius": 1},
        "path": [[10, -1], [21, -1], [21, 21], [-1, 21], [-1, -1]],
        "material_side": "left",
        "corner_loop": {"style": "arc", "radius": 1}
    });
    let looped = json_with(app.post_json("/api/v1/contour/loops", &body).await, 200).await;
    assert_eq!(looped["tool"]["radius"], 1.0);
    let points = looped["points"].as_array().unwrap();
    assert_eq!(points.iter().filter(|p| p["looped"] == true).count(), 4);
    assert_eq!(points[0]["corner"], false, "S lies on a straight edge");
    assert!(number(&looped["max_abs_cross"]) < 1e-9 && number(&looped["min_dot"]) > 1.0 - 1e-9, "claim 10");

    // The same moves as the contour's pass from S round to S, kind for kind.
    let pass: Vec<(String, [f64; 2])> = contour["layers"][0]["moves"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["kind"] == "cut" || m["kind"] == "loop")
        .map(|m| (m["kind"].as_str().unwrap().to_owned(), [number(&m["to"][0]), number(&m["to"][1])]))
        .collect();
    let moves = looped["moves"].as_array().unwrap();
    assert_eq!(moves.len(), pass.len(), "move count");
    for (index, (got, (kind, to))) in moves.iter().zip(&pass).enumerate() {
        assert_eq!(got["kind"], kind.as_str(), "move {index}");
        let at = pair(&got["to"]);
        assert!((at[0] - to[0]).abs() < 1e-9 && (at[1] - to[1]).abs() < 1e-9, "move {index}: {at:?} vs {to:?}");
    }

    // The patent's curvature rule (claim 8) is undefined on vertical chords and says so;
    // identical requests answer the same bytes.
    let mut patent = body.clone();
    patent["detect"] = json!("patent_curvature");
    let answer = json_with(app.post_json("/api/v1/contour/loops", &patent).await, 200).await;
    let codes: Vec<&str> = answer["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"W_DETECT_UNDEFINED") && codes.contains(&"W_DETECT_DISAGREE"), "{codes:?}");
    let once =
        app.client.post(app.url("/api/v1/contour/loops")).json(&body).send().await.unwrap().bytes().await.unwrap();
    let twice =
        app.client.post(app.url("/api/v1/contour/loops")).json(&body).send().await.unwrap().bytes().await.unwrap();
    assert_eq!(once, twice);
}

#[tokio::test(flavor = "multi_thread")]
async fn jobs_store_what_fits_and_refusals_name_the_field() {
    let app = app_with_tools().await;
    let submit = |job: Value| {
        app.client.post(app.url("/api/v1/jobs")).header("content-type", "application/json").body(job.to_string()).send()
    };
    // About 606 000 moves: the program has them all, the stored JSON the layers that fit.
    let mut big = json!({
        "operation": "contour", "tool": 3, "contour": circle(600), "side": "outside",
        "depths": {"top": 0, "bottom": -100, "step": 0.1}, "feed": 800
    });
    let submitted = json_with(submit(json!({"name": "big", "operations": [big.clone()]})).await.unwrap(), 202).await;
    let job = poll_job(&app.client, &app.base, submitted["id"].as_i64().unwrap(), 120, finished).await;
    assert_eq!(job["status"], "done", "{}", &job.to_string()[..job.to_string().len().min(500)]);
    let result = &job["results"][0]["result"];
    let total = result["summary"]["moves"].as_u64().unwrap() as usize;
    assert!(total > 500_000);
    let stored: usize = result["layers"].as_array().unwrap().iter().map(|l| l["moves"].as_array().unwrap().len()).sum();
    assert!(stored <= 500_000 && stored > 400_000, "{stored} moves stored");
    assert_eq!(result["layers"].as_array().unwrap().len(), 1000, "every layer is listed");
    assert!(result["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "W_MOVES_NOT_STORED"));
    let program = app.get(&format!("/api/v1/jobs/{}/gcode", submitted["id"])).await.text().await.unwrap();
    let blocks = program.lines().filter(|l| l.starts_with("G01") || l.starts_with("G00")).count();
    assert_eq!(blocks, total + 2, "the length-offset block, every move and the final retract");

    // A contour the solver refuses fails the job with the field at fault.
    big["contour"] = json!([[0, 0], [10, 10], [10, 0], [0, 10]]);
    let submitted = json_with(submit(json!({"operations": [big]})).await.unwrap(), 202).await;
    let job = poll_job(&app.client, &app.base, submitted["id"].as_i64().unwrap(), 60, finished).await;
    assert_eq!(job["status"], "failed");
    assert_eq!(job["error"]["errors"][0]["path"], "operations[0].contour[2]");
    assert_eq!(job["error"]["code"], "E_SELF_INTERSECTION");
}

#[tokio::test(flavor = "multi_thread")]
async fn block_time_rule_chooses_the_arc_chords_and_reports_the_blocks() {
    let app = app_with_tools().await;
    let plain = json_with(app.post_json("/api/v1/contour", &reference("C1")).await, 200).await;
    assert!(plain["summary"].get("blocks").is_none(), "no block figures without a block time");
    let mut body = reference("C1");
    body["block_time_ms"] = json!(4);
    let ruled = json_with(app.post_json("/api/v1/contour", &body).await, 200).await;
    let blocks = &ruled["summary"]["blocks"];
    // 800 mm/min on a 4 ms control: blocks of at least 0.05333 mm.
    let block_length = 800.0 * 4.0 / 60_000.0;
    close("block length", &blocks["block_length"], block_length);
    assert_eq!(blocks["block_time_ms"], 4.0);
    assert_eq!(blocks["short_blocks"], 0, "{}", ruled["warnings"]);
    assert!(number(&blocks["min_block_length"]) >= block_length * (1.0 - 1e-9));
    let feed_moves = answer_moves(&ruled, 0.0).iter().filter(|m| m.0).count();
    assert_eq!(blocks["blocks"], feed_moves);
    assert!(number(&blocks["estimated_time_s"]) >= number(&ruled["summary"]["estimated_time_s"]));
    // The loops are chorded finer than the 0.01 mm tolerance (the rule's chord error for ρ = 1
    // at 800 mm/min and 4 ms is 0.000356 mm), so there are more loop moves than without the rule.
    let finest = number(&blocks["finest_arc_tolerance"]);
    assert!((finest - 0.000_355_6).abs() < 1e-7, "{finest}");
    let loops = |answer: &Value| {
        answer["layers"][0]["moves"].as_array().unwrap().iter().filter(|m| m["kind"] == "loop").count()
    };
    assert!(loops(&ruled) > 2 * loops(&plain), "{} vs {}", loops(&ruled), loops(&plain));
    // The corners, loops and material are those of the plain answer.
    assert_eq!(ruled["corners"], plain["corners"]);

    // A feed the 1 mm legs cannot keep up with is reported, not refused.
    body["feed"] = json!(10_000);
    body["block_time_ms"] = json!(10);
    let fast = json_with(app.post_json("/api/v1/contour", &body).await, 200).await;
    let codes: Vec<&str> = fast["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(
        codes.contains(&"W_BLOCK_TIME_VIOLATION") && codes.contains(&"W_CHORD_ERROR_EXCEEDS_TOLERANCE"),
        "{codes:?}"
    );
    assert!(fast["summary"]["blocks"]["short_blocks"].as_u64().unwrap() > 0);
}

/// A named machine gives the block time (and margin) of the rule, its dialect is the G-code
/// default, the request's `block_time_ms` wins over it, and jobs resolve it like the endpoint.
#[tokio::test(flavor = "multi_thread")]
async fn a_named_machine_gives_the_block_time_and_dialect() {
    let app = app_with_tools().await;
    let mut body = reference("C1");
    body["machine"] = json!("mill-4ms");
    let unknown = problem(app.post_json("/api/v1/contour", &body).await, 404).await;
    assert_eq!(unknown["errors"][0]["path"], "machine");

    let machine = json!({"block_time_ms": 4, "max_feed": 600, "dialect": "linuxcnc"});
    json_with(app.put_json("/api/v1/machines/mill-4ms", &machine).await, 201).await;
    let from_machine = json_with(app.post_json("/api/v1/contour", &body).await, 200).await;
    assert_eq!(from_machine["machine"]["block_time_ms"], 4.0);
    assert_eq!(from_machine["summary"]["blocks"]["block_time_ms"], 4.0);
    let codes: Vec<&str> =
        from_machine["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"W_FEED_ABOVE_MACHINE_MAX"), "feed 800 over the machine's 600: {codes:?}");
    // The machine caps feed 800 to its 600: the program is that of feed 600.
    let mut explicit = reference("C1");
    explicit["block_time_ms"] = json!(4);
    explicit["feed"] = json!(600);
    let explicit = json_with(app.post_json("/api/v1/contour", &explicit).await, 200).await;
    assert_eq!(from_machine["layers"], explicit["layers"], "the machine's block time chords as the request's");

    body["block_time_ms"] = json!(10);
    let overridden = json_with(app.post_json("/api/v1/contour", &body).await, 200).await;
    assert_eq!(overridden["summary"]["blocks"]["block_time_ms"], 10.0);

    let program = app.post_text("/api/v1/contour?format=gcode", &body, 200).await;
    assert!(!program.starts_with('%') && program.contains("G64"), "linuxcnc from the machine:\n{program}");

    let mut operation = body.clone();
    operation["operation"] = json!("contour");
    let job = json!({"operations": [operation]});
    let response =
        app.client.post(app.url("/api/v1/jobs")).header("content-type", "application/json").body(job.to_string());
    let submitted = json_with(response.send().await.unwrap(), 202).await;
    let job = poll_job(&app.client, &app.base, submitted["id"].as_i64().unwrap(), 60, finished).await;
    assert_eq!(job["status"], "done", "{job}");
    let result = &job["results"][0]["result"];
    assert_eq!(result["machine"]["name"], "mill-4ms");
    assert_eq!(result["layers"], overridden["layers"], "the job's answer is the endpoint's");
}
