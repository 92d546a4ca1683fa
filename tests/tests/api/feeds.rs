//! Feeds near the stock: the programs of segment, contour, deburr and predict, read back with
//! the service's own G-code reader, never move at a feed above the planned cutting feed where
//! the tool is within its radius of the part, and a machine's `max_feed` caps the request's feed
//! (with `W_FEED_ABOVE_MACHINE_MAX` saying from what to what), never raising it.

use kerf_solver::gcode::reader::{MoveKind, ReadOptions, read};
use kerf_tests::{TestApp, json_with, rs274_moves};
use serde_json::{Value, json};

/// The machine's max feed, below every feed the requests ask for.
const MACHINE_MAX: f64 = 600.0;
/// The requested cutting feed, above the machine's.
const REQUESTED: f64 = 2400.0;
/// Tool radius of every request, mm.
const RADIUS: f64 = 3.0;

/// What a program's moves show about its feeds.
#[derive(Debug)]
struct Feeds {
    /// The largest F of any feed move (G01/G02/G03).
    largest: f64,
    /// The largest F of any feed move that passes within the tool radius of the part.
    largest_near: f64,
    /// The F of each plunge (a G01 straight down the tool axis).
    plunges: Vec<f64>,
}

/// Reads `program` with the service's reader and sorts its feed moves by `near` (whether a point
/// lies within the tool radius of the part); straight moves are sampled every 0.1 mm, arcs by
/// chords of 1 µm sagitta.
fn feeds(program: &str, near: impl Fn([f64; 3]) -> bool) -> Feeds {
    let read = read(program, "program", &ReadOptions::default()).expect("the program reads");
    let mut found = Feeds { largest: 0.0, largest_near: 0.0, plunges: Vec::new() };
    for step in read.moves.iter().filter(|m| m.kind != MoveKind::Rapid) {
        let (Some(from), Some(to)) = (step.from_xyz(), step.to_xyz()) else { continue };
        let feed = step.modal.feed.expect("every feed move has a feed");
        found.largest = found.largest.max(feed);
        let points = match step.kind {
            MoveKind::Linear => {
                let length = (0..3).map(|k| (to[k] - from[k]).powi(2)).sum::<f64>().sqrt();
                let count = (length / 0.1).ceil().max(1.0) as usize;
                (0..=count)
                    .map(|i| {
                        let t = i as f64 / count as f64;
                        [0, 1, 2].map(|k| from[k] + t * (to[k] - from[k]))
                    })
                    .collect()
            }
            _ => step.points(1e-3).expect("an arc from a known point"),
        };
        if points.iter().any(|p| near(*p)) {
            found.largest_near = found.largest_near.max(feed);
        }
        if step.kind == MoveKind::Linear && from[0] == to[0] && from[1] == to[1] && to[2] < from[2] {
            found.plunges.push(feed);
        }
    }
    found
}

/// Distance from `(x, y)` to the closed polygon's boundary, 0 inside it.
fn polygon_distance(polygon: &[[f64; 2]], x: f64, y: f64) -> f64 {
    let mut inside = false;
    let mut distance = f64::INFINITY;
    for (i, a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let t = (((x - a[0]) * dx + (y - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        distance = distance.min((x - a[0] - t * dx).hypot(y - a[1] - t * dy));
        if (a[1] > y) != (b[1] > y) && x < a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            inside = !inside;
        }
    }
    if inside { 0.0 } else { distance }
}

fn codes(answer: &Value) -> Vec<&str> {
    answer["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect()
}

/// Posts `body` to `path` for its JSON answer and its G-code program (LinuxCNC dialect).
async fn answer_and_program(app: &TestApp, path: &str, body: &Value) -> (Value, String) {
    let answer = json_with(app.post_json(path, body).await, 200).await;
    let program = app.post_text(&format!("{path}?format=gcode&dialect=linuxcnc"), body, 200).await;
    (answer, program)
}

/// Asserts the feed rules of one capability's program: nothing above `cutting`, the largest feed
/// near the part is `cutting`, plunges at most `plunge`.
fn assert_feeds(name: &str, program: &str, found: &Feeds, cutting: f64, plunge: f64) {
    assert!(
        found.largest <= cutting + 1e-9,
        "{name}: a move at F{} above the cutting feed {cutting}\n{program}",
        found.largest
    );
    assert!(
        (found.largest_near - cutting).abs() <= 1e-9,
        "{name}: the largest feed near the part is F{}, not the cutting feed {cutting}\n{program}",
        found.largest_near
    );
    assert!(!found.plunges.is_empty(), "{name}: the program enters\n{program}");
    for feed in &found.plunges {
        assert!(*feed <= plunge + 1e-9, "{name}: an entry at F{feed} above the plunge feed {plunge}\n{program}");
    }
}

#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
#[tokio::test(flavor = "multi_thread")]
async fn a_machine_caps_every_feed_near_the_stock() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": RADIUS})).await;
    app.register_tool(7, &json!({"kind": "ball", "radius": RADIUS})).await;
    let machine = json!({"block_time_ms": 1, "max_feed": MACHINE_MAX, "dialect": "linuxcnc"});
    json_with(app.put_json("/api/v1/machines/slow", &machine).await, 201).await;
    let capped = |answer: &Value, name: &str| {
        let warning = answer["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|w| w["code"] == "W_FEED_ABOVE_MACHINE_MAX")
            .unwrap_or_else(|| panic!("{name}: no W_FEED_ABOVE_MACHINE_MAX in {:?}", codes(answer)));
        let message = warning["message"].as_str().unwrap();
        assert!(message.contains("capped from 2400 mm/min to 600"), "{name}: {message}");
    };

    // Segment: a circle of radius 20 at Z −2, the part is the curve itself.
    let body = json!({"curve": {"kind": "circle", "centre": [0, 0, -2], "radius": 20}, "feed": REQUESTED,
                      "machine": "slow", "tool": 3});
    let (answer, program) = answer_and_program(&app, "/api/v1/segment", &body).await;
    capped(&answer, "segment");
    assert_eq!(answer["feed"], MACHINE_MAX, "the answer's feed is the program's");
    let found = feeds(&program, |p| (p[0].hypot(p[1]) - 20.0).hypot(p[2] + 2.0) <= RADIUS);
    assert_feeds("segment", &program, &found, MACHINE_MAX, MACHINE_MAX / 2.0);
    rs274_moves(&program, app.directory(), "feeds_segment");

    // Contour: the outside of a rectangle 80 × 60 from Z 0 down to −4.
    let rectangle = [[0.0, 0.0], [80.0, 0.0], [80.0, 60.0], [0.0, 60.0]];
    let body = json!({"tool": 3, "contour": rectangle, "side": "outside", "depths": {"top": 0, "bottom": -4, "step": 2},
                      "feed": REQUESTED, "loop_feed": 3000, "plunge_feed": 1800, "machine": "slow"});
    let (answer, program) = answer_and_program(&app, "/api/v1/contour", &body).await;
    capped(&answer, "contour");
    let messages: Vec<&str> =
        answer["warnings"].as_array().unwrap().iter().filter_map(|w| w["message"].as_str()).collect();
    for said in ["loop_feed capped from 3000 mm/min to 600", "plunge_feed capped from 1800 mm/min to 600"] {
        assert!(messages.iter().any(|m| m.contains(said)), "contour: no \"{said}\" in {messages:?}");
    }
    assert_eq!(answer["summary"]["loop_feed"], MACHINE_MAX, "the answer's loop feed is the program's");
    let found = feeds(&program, |p| {
        polygon_distance(&rectangle, p[0], p[1]).hypot(p[2].max(0.0)) <= RADIUS && p[2] >= -4.0 - RADIUS
    });
    assert_feeds("contour", &program, &found, MACHINE_MAX, MACHINE_MAX);
    rs274_moves(&program, app.directory(), "feeds_contour");

    // Deburr: the outer edge of a hole in a tube; the part is where the ball's centre cuts.
    let body = kerf_cases::with(kerf_cases::deburr::tube_request(), json!({"machine": "slow", "feed": REQUESTED}));
    let (answer, program) = answer_and_program(&app, "/api/v1/deburr", &body).await;
    capped(&answer, "deburr");
    assert_eq!(answer["summary"]["feed"], MACHINE_MAX, "the answer's feed is the program's");
    let centres: Vec<[f64; 3]> = answer["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [0, 1, 2].map(|k| p["centre"][k].as_f64().unwrap()))
        .collect();
    let found = feeds(&program, |p| {
        centres.iter().any(|c| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt() <= RADIUS)
    });
    assert!(found.largest <= MACHINE_MAX + 1e-9, "deburr: a move at F{} over the machine's\n{program}", found.largest);
    assert!(
        (found.largest_near - MACHINE_MAX).abs() <= 1e-9,
        "deburr: F{} near the part\n{program}",
        found.largest_near
    );
    rs274_moves(&program, app.directory(), "feeds_deburr");

    // Predict takes no machine: its program keeps the request's feed, and nothing runs faster.
    let points: Vec<[f64; 3]> = (0..=16).map(|i| [-4.0 + 0.5 * f64::from(i), 0.0, 0.0]).collect();
    let mut body = crate::predict::raster_request(crate::predict::finishing_tool(), 1, 2);
    body["path"] = json!({"kind": "points", "points": points});
    body["feed"] = json!(1600);
    body["spindle_rpm"] = json!(8000);
    body["tool"]["number"] = json!(3);
    let (_, program) = answer_and_program(&app, "/api/v1/predict", &body).await;
    // The box stock from −20 to 20 in X and Y, −10 to 0.25 in Z.
    let found = feeds(&program, |p| {
        let outside = [p[0].abs() - 20.0, p[1].abs() - 20.0, (p[2] - 0.25).max(-10.0 - p[2])].map(|d| d.max(0.0));
        outside.iter().map(|d| d * d).sum::<f64>().sqrt() <= RADIUS
    });
    assert_feeds("predict", &program, &found, 1600.0, 1600.0);
    rs274_moves(&program, app.directory(), "feeds_predict");
}

/// A machine never raises a feed: a request below its max feed keeps its own, without a warning.
#[tokio::test(flavor = "multi_thread")]
async fn a_machine_never_raises_a_feed() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": RADIUS})).await;
    let machine = json!({"block_time_ms": 1, "max_feed": 12000, "dialect": "linuxcnc"});
    json_with(app.put_json("/api/v1/machines/fast", &machine).await, 201).await;
    let body = json!({"tool": 3, "contour": [[0, 0], [80, 0], [80, 60], [0, 60]], "side": "outside",
                      "depths": {"top": 0, "bottom": -2, "step": 2}, "feed": REQUESTED, "machine": "fast"});
    let (answer, program) = answer_and_program(&app, "/api/v1/contour", &body).await;
    assert!(!codes(&answer).contains(&"W_FEED_ABOVE_MACHINE_MAX"), "{:?}", codes(&answer));
    let found = feeds(&program, |_| true);
    assert_eq!(found.largest, REQUESTED, "{program}");
    let body = kerf_cases::with(kerf_cases::deburr::tube_request(), json!({"machine": "fast", "feed": REQUESTED}));
    app.register_tool(7, &json!({"kind": "ball", "radius": RADIUS})).await;
    let answer = json_with(app.post_json("/api/v1/deburr", &body).await, 200).await;
    assert_eq!(answer["summary"]["feed"], REQUESTED);
    assert!(!codes(&answer).contains(&"W_FEED_ABOVE_MACHINE_MAX"), "{:?}", codes(&answer));
}

/// A program never writes a spindle speed as `S0` (it writes whole rpm) nor a feed as `F0` (it
/// writes 0.1 mm/min, or 0.1 in/min in inch): such a request is refused at the field it came from,
/// for every capability that writes a program; the least values that write are kept.
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
#[tokio::test(flavor = "multi_thread")]
async fn a_spindle_speed_or_feed_a_program_would_write_as_zero_is_refused_at_its_field() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": RADIUS})).await;
    app.register_tool(7, &json!({"kind": "ball", "radius": RADIUS})).await;
    let rectangle = [[0.0, 0.0], [80.0, 0.0], [80.0, 60.0], [0.0, 60.0]];
    let points: Vec<[f64; 3]> = (0..=16).map(|i| [-4.0 + 0.5 * f64::from(i), 0.0, 0.0]).collect();
    let mut predict = crate::predict::raster_request(crate::predict::finishing_tool(), 1, 2);
    predict["path"] = json!({"kind": "points", "points": points});
    predict["tool"]["number"] = json!(3);
    // Each capability's request with a spindle speed and a feed field set by the case.
    let requests: Vec<(&str, Value, &str)> = vec![
        (
            "/api/v1/segment",
            json!({"curve": {"kind": "circle", "centre": [0, 0, -2], "radius": 20}, "tool": 3, "block_time_ms": 1,
                   "min_chord_error": 0.01}),
            "feed",
        ),
        (
            "/api/v1/contour",
            json!({"tool": 3, "contour": rectangle, "side": "outside", "depths": {"top": 0, "bottom": -2, "step": 2}}),
            "feed",
        ),
        ("/api/v1/deburr", kerf_cases::deburr::tube_request(), "feed"),
        (
            "/api/v1/engagement",
            json!({"tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
                   "path": [[-10, 20], [70, 20]], "flute_counts": [2], "axial_depth": 2}),
            "feed_per_tooth",
        ),
        ("/api/v1/predict", predict, "feed"),
    ];
    for (path, body, feed_field) in &requests {
        // A feed per tooth of 0.0001 mm on two flutes: 0.6 mm/min at 3000 rpm.
        let feed = if *feed_field == "feed" { 1000.0 } else { 0.1 };
        let slow = if *feed_field == "feed" { 0.01 } else { 0.000_001 };
        let with =
            |rpm: f64, feed: f64| kerf_cases::with(body.clone(), json!({"spindle_rpm": rpm, (*feed_field): feed}));
        for (case, request, field, said) in [
            ("spindle 0.3 rpm", with(0.3, feed), "spindle_rpm", "S0"),
            ("a feed of 0.01 mm/min", with(3000.0, slow), *feed_field, "F0"),
        ] {
            for query in ["?format=gcode", "?format=gcode&dialect=heidenhain"] {
                let refused = kerf_tests::problem(app.post_json(&format!("{path}{query}"), &request).await, 422).await;
                assert_eq!(refused["code"], "E_INPUT", "{path}{query}, {case}: {refused}");
                assert_eq!(refused["errors"][0]["path"], field, "{path}{query}, {case}: {refused}");
                let detail = refused["detail"].as_str().unwrap();
                assert!(detail.contains(said), "{path}{query}, {case}: {detail}");
            }
        }
    }

    // The least values that write are written: 0.6 rpm as S1; a contour feed of 0.2 mm/min as
    // F0.2 and its plunges at half of it as F0.1; half of 0.08 mm/min is refused as a plunge's.
    let (path, body, _) = &requests[1];
    let least = kerf_cases::with(body.clone(), json!({"spindle_rpm": 0.6, "feed": 0.2}));
    let program = app.post_text(&format!("{path}?format=gcode&dialect=linuxcnc"), &least, 200).await;
    for word in ["S1 M03", " F0.2", " F0.1"] {
        assert!(program.contains(word), "no {word:?} in\n{program}");
    }
    rs274_moves(&program, app.directory(), "feeds_least");
    let plunge = kerf_cases::with(body.clone(), json!({"feed": 0.08}));
    let refused = kerf_tests::problem(app.post_json(&format!("{path}?format=gcode"), &plunge).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "feed", "{refused}");
    assert!(refused["detail"].as_str().unwrap().contains("a plunge's feed of 0.04 mm/min"), "{refused}");

    // An inch program writes 0.1 in/min: 0.02 in/min is refused, in inches.
    let inch = kerf_cases::with(
        body.clone(),
        json!({"units": "inch", "tool": {"kind": "flat", "radius": 0.125}, "contour": [[0, 0], [3, 0], [3, 2], [0, 2]],
               "depths": {"top": 0, "bottom": -0.1, "step": 0.1}, "feed": 0.02}),
    );
    let refused = kerf_tests::problem(app.post_json(&format!("{path}?format=gcode"), &inch).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "feed", "{refused}");
    let detail = refused["detail"].as_str().unwrap();
    assert!(detail.contains("in/min") && !detail.contains("mm/min"), "{detail}");
    // The JSON answer of a contour cuts its program (the verification): refused the same way.
    let slow_spindle = kerf_cases::with(body.clone(), json!({"spindle_rpm": 0.3, "feed": 1000}));
    let refused = kerf_tests::problem(app.post_json(path, &slow_spindle).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "spindle_rpm", "{refused}");
}

/// A program is never written above the machine's `max_spindle_rpm` (its control would clamp
/// the speed under the same feeds: a thicker chip than planned): contour, deburr and segment
/// refuse such a request at `spindle_rpm`, engagement its program (and an answer whose
/// verification cuts it); engagement's analysis without a program still answers the limit as
/// its own (no flute count recommended at that speed).
#[tokio::test(flavor = "multi_thread")]
async fn a_spindle_speed_above_the_machines_max_is_refused_for_every_program() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": RADIUS})).await;
    app.register_tool(7, &json!({"kind": "ball", "radius": RADIUS})).await;
    let machine = json!({"block_time_ms": 1, "max_feed": 12000, "max_spindle_rpm": 8000});
    json_with(app.put_json("/api/v1/machines/small", &machine).await, 201).await;
    let requests = [
        (
            "/api/v1/segment",
            json!({"curve": {"kind": "circle", "centre": [0, 0, -2], "radius": 20}, "tool": 3, "feed": 1000}),
        ),
        (
            "/api/v1/contour",
            json!({"tool": 3, "contour": [[0, 0], [80, 0], [80, 60], [0, 60]], "side": "outside",
                   "depths": {"top": 0, "bottom": -2, "step": 2}, "feed": 1000}),
        ),
        ("/api/v1/deburr", kerf_cases::deburr::tube_request()),
    ];
    for (path, body) in &requests {
        let fast = kerf_cases::with(body.clone(), json!({"machine": "small", "spindle_rpm": 12000}));
        for query in ["", "?format=gcode"] {
            let refused = kerf_tests::problem(app.post_json(&format!("{path}{query}"), &fast).await, 422).await;
            assert_eq!(refused["errors"][0]["path"], "spindle_rpm", "{path}{query}: {refused}");
            let detail = refused["detail"].as_str().unwrap();
            assert!(detail.contains("max_spindle_rpm 8000 rpm"), "{path}{query}: {detail}");
        }
        let at_most = kerf_cases::with(body.clone(), json!({"machine": "small", "spindle_rpm": 8000}));
        let program = app.post_text(&format!("{path}?format=gcode"), &at_most, 200).await;
        assert!(program.contains("S8000 M03"), "{path}: {program}");
        // The defaults' 6000 rpm is within it.
        let default = kerf_cases::with(body.clone(), json!({"machine": "small"}));
        json_with(app.post_json(path, &default).await, 200).await;
    }

    let engagement = json!({"tool": {"kind": "flat", "radius": 5},
                            "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
                            "path": [[-10, 20], [70, 20]], "flute_counts": [2, 3], "feed_per_tooth": 0.02,
                            "spindle_rpm": 12000, "machine": "small"});
    let answer = json_with(app.post_json("/api/v1/engagement", &engagement).await, 200).await;
    assert_eq!(answer["recommended"], json!([]), "{answer}");
    assert_eq!(answer["flutes"][0]["over_limits"][0]["limit"], "spindle_speed", "{answer}");
    let programmed = kerf_cases::with(engagement, json!({"axial_depth": 2}));
    let refused = kerf_tests::problem(app.post_json("/api/v1/engagement?format=gcode", &programmed).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "spindle_rpm", "{refused}");
    assert!(refused["detail"].as_str().unwrap().contains("max_spindle_rpm 8000 rpm"), "{refused}");
    // With a_p the answer's verification cuts that program: refused the same way.
    let refused = kerf_tests::problem(app.post_json("/api/v1/engagement", &programmed).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "spindle_rpm", "{refused}");
}
