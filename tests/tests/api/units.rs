//! Inch requests: converted to mm once at the edge, so an inch request answers the mm answer
//! divided by 25.4 in every length and feed (areas by 25.4²) and the same in everything else; its
//! program is written in G20 and moves as the mm program's (`rs274`); a machine's `units` is the
//! default of the requests that name it; a bad `units` is refused naming it.

use kerf_tests::{Store, TestApp, finished, json_with, poll_job, problem, rs274_moves};
use serde_json::{Value, json};

/// Keys whose numbers (and arrays of numbers) are lengths or feeds in the answers compared here.
const LENGTHS: &[&str] = &[
    // segment
    "chord_error",
    "min_window_chord_error",
    "s_start",
    "s_end",
    "radius",
    "rule_chord_error",
    "points",
    "s",
    "block_length",
    "min_block_length",
    "max_block_length",
    "last_block_length",
    "path_length",
    "max_deviation",
    "curve_length",
    "min_radius",
    "feed_limit",
    "tolerance_feed",
    "feed",
    "min_chord_error",
    "tolerance",
    "max_accel",
    "max_jerk",
    "max_feed",
    "plunge_feed",
    "rapid_feed",
    // contour
    "z",
    "to",
    "vertex",
    "cl_point",
    "leg",
    "exit_end",
    "entry_start",
    "centre",
    "far_corner",
    "length",
    "clearance",
    "target",
    "left_depth",
    "overcut_depth",
    "allowance",
    "offset",
    "start",
    "cut_length",
    "leg_length",
    "loop_length",
    "relief_length",
    "gouge_min_clearance",
    "stock_min_clearance",
    "tool_radius",
    "feed_length",
    "loop_feed",
    "safe_z",
    "lead",
    "finest_arc_tolerance",
    // engagement
    "polygon",
    "position",
    "radial_depth",
    "mean_chip_thickness",
    "thickness",
    "feed_per_tooth",
    "max_thickness",
    "mean_thickness",
    "min_thickness",
    "median_thickness",
    "thickness_margin",
    "thickness_limit",
    "multi_tooth_intervals",
    "step",
    "engaged_intervals",
    "max_engaged_at_s",
    "max_radial_depth",
    "axial_depth",
    "target_thickness",
    "from_s",
    "to_s",
    "feed_range",
    // deburr
    "tip",
    "centre_offset",
    "cut_amount",
    "width",
    "true_width_min",
    "true_width_max",
    "swept_width_min",
    "swept_width_max",
    "max_exact_offset",
    "safe_centre_z",
    "axial_position",
    "travel",
    "request_order_travel",
    // the verification of a program (volumes keep the mm³ their names say)
    "resolution",
    "wall_tolerance",
    "depth",
];

/// Keys whose numbers are areas.
const AREAS: &[&str] = &["left_area", "overcut_area"];

/// Keys whose numbers are volumes (per minute).
const VOLUMES: &[&str] = &["mrr", "max_mrr"];

/// How a number at a key compares: as a length (÷ 25.4), an area (÷ 25.4²) or unchanged.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Same,
    Length,
    Area,
    Volume,
}

/// Keys whose numbers are never converted, even inside a length's object (deburr's `points`).
const UNSCALED: &[&str] = &["parameter"];

fn kind_of(key: &str, inherited: Kind) -> Kind {
    if key.ends_with("_deg") || UNSCALED.contains(&key) {
        Kind::Same
    } else if LENGTHS.contains(&key) {
        Kind::Length
    } else if AREAS.contains(&key) {
        Kind::Area
    } else if VOLUMES.contains(&key) {
        Kind::Volume
    } else {
        inherited
    }
}

/// Every number of `inch` is that of `mm` converted as its key says, within 1e-9 relative; every
/// other value is equal. Returns how many numbers were converted.
fn assert_in_inch(path: &str, inch: &Value, mm: &Value, kind: Kind) -> usize {
    match (inch, mm) {
        (Value::Object(inch), Value::Object(mm)) => {
            let mut keys: Vec<&String> = inch.keys().filter(|key| *key != "units").collect();
            keys.sort();
            let mut mm_keys: Vec<&String> = mm.keys().filter(|key| *key != "units").collect();
            mm_keys.sort();
            assert_eq!(keys, mm_keys, "{path}: keys");
            keys.iter()
                .map(|key| {
                    let kind = kind_of(key, if matches!(kind, Kind::Length) { Kind::Length } else { Kind::Same });
                    assert_in_inch(&format!("{path}.{key}"), &inch[key.as_str()], &mm[key.as_str()], kind)
                })
                .sum()
        }
        (Value::Array(inch), Value::Array(mm)) => {
            assert_eq!(inch.len(), mm.len(), "{path}: length");
            inch.iter().zip(mm).enumerate().map(|(k, (a, b))| assert_in_inch(&format!("{path}[{k}]"), a, b, kind)).sum()
        }
        (Value::Number(inch), Value::Number(mm)) => {
            let (inch, mm) = (inch.as_f64().unwrap(), mm.as_f64().unwrap());
            let want = match kind {
                Kind::Same => mm,
                Kind::Length => mm / 25.4,
                Kind::Area => mm / 25.4 / 25.4,
                Kind::Volume => mm / 25.4 / 25.4 / 25.4,
            };
            assert!((inch - want).abs() <= 1e-9 * want.abs().max(1e-12), "{path}: {inch} in vs {mm} mm ({kind:?})");
            usize::from(!matches!(kind, Kind::Same))
        }
        _ => {
            assert_eq!(inch, mm, "{path}");
            0
        }
    }
}

/// A segment request with its lengths in units of `k` mm (1 for mm values written as inches,
/// 25.4 for the same in mm): an ellipse cut in guarantee mode with a tolerance and a comparison.
fn segment_request(k: f64) -> Value {
    json!({"curve": {"kind": "ellipse", "centre": [0.5 * k, 0.25 * k], "semi_axes": [1.5 * k, 0.6 * k]},
           "feed": 120.0 * k, "block_time_ms": 4, "mode": "guarantee", "tolerance": 0.002 * k,
           "compare_tolerance": 0.001 * k, "safe_z": 0.25 * k, "spindle_rpm": 9000})
}

/// A contour request in units of `k` mm: an arrow with an inline tool, loops, a dogbone, two passes.
fn contour_request(k: f64) -> Value {
    let outline: Vec<[f64; 2]> = [[0.0, 0.4], [1.6, 0.4], [1.6, 0.0], [3.2, 1.0], [1.6, 2.0], [1.6, 1.6], [0.0, 1.6]]
        .iter()
        .map(|[x, y]| [x * k, y * k])
        .collect();
    json!({"tool": {"kind": "flat", "radius": 0.125 * k, "flutes": 3}, "contour": outline, "side": "outside",
           "depths": {"top": 0, "bottom": -0.08 * k, "step": 0.04 * k},
           "corner_loop": {"style": "arc"}, "inside_corner_relief": "dogbone",
           "feed": 30.0 * k, "loop_feed": 80.0 * k, "stock_allowance": 0.02 * k, "spindle_rpm": 8000,
           "passes": [{"allowance": 0.012 * k, "join": "round"}, {"allowance": 0}], "block_time_ms": 2})
}

/// An engagement request in units of `k` mm: a slot, an arc and a side cut through a plate with
/// an inline tool, forces from inline Kienzle values (N/mm², never scaled), a feed plan and a block
/// time.
fn engagement_request(k: f64) -> Value {
    json!({"tool": {"kind": "flat", "radius": 0.2 * k, "flutes": 3, "helix_deg": 30},
           "stock": {"polygon": [[0, 0], [2.4 * k, 0], [2.4 * k, 1.6 * k], [0, 1.6 * k]]},
           "path": {"start": [-0.4 * k, 0.8 * k], "segments": [
               {"type": "line", "to": [1.2 * k, 0.8 * k]},
               {"type": "arc", "to": [1.6 * k, 1.2 * k], "center": [1.2 * k, 1.2 * k], "dir": "ccw"},
               {"type": "line", "to": [1.6 * k, 2.0 * k]}]},
           "spindle_rpm": 8000, "feed_per_tooth": 0.002 * k, "flute_counts": [2, 3, 4],
           "thickness_limit": 0.1 * k, "time_limit_s": 60, "step": 0.01 * k,
           "axial_depth": 0.08 * k, "clearance": 0.2 * k, "kienzle": {"kc11": 1700, "mc": 0.25},
           "feed_plan": {"target_thickness": 0.002 * k, "max_feed": 60.0 * k, "min_block_length": 0.02 * k},
           "block_time_ms": 4})
}

/// A deburr request in units of `k` mm: both ridges of a round hole and a slot in a tube, inline
/// ball tools, the exact method and a block time.
fn deburr_request(k: f64) -> Value {
    json!({"tool": {"kind": "ball", "radius": 0.12 * k}, "inner_tool": {"kind": "ball", "radius": 0.08 * k},
           "workpiece": {"kind": "tube", "origin": [0.1 * k, 0.2 * k, 0], "inner_diameter": 1.2 * k, "outer_radius": k},
           "holes": [{"shape": "round", "radius": 0.3 * k},
                     {"shape": "slot", "radius": 0.2 * k, "centre_distance": 0.3 * k, "penetration_angle_deg": 45,
                      "axial_position": 1.5 * k}],
           "edge": "both", "width": 0.02 * k, "tolerance": 0.0005 * k, "method": "exact", "feed": 12.0 * k,
           "clearance": 0.2 * k, "lead_distance": 0.04 * k, "spindle_rpm": 8000, "block_time_ms": 2})
}

/// A mm program (G21) of 0.1 mm G01 steps along a quarter circle of radius 20 mm at 3000 mm/min.
fn dense_arc_program() -> String {
    let mut text = String::from("G21 G17 G90\nG00 X20. Y0. Z5.\nG01 Z-1. F300\nG01 X20. Y0. F3000\n");
    for k in 1..=314 {
        let angle = f64::from(k) * 0.005;
        text.push_str(&format!("X{:.4} Y{:.4}\n", 20.0 * angle.cos(), 20.0 * angle.sin()));
    }
    text.push_str("G00 Z5.\nM30\n");
    text
}

/// A resegment request in inch keeps its program's G21 and reads its tolerances in inch: its
/// answer is the mm twin's with the deviation and chord error divided by 25.4, its program the
/// same text.
#[tokio::test]
async fn resegment_reads_its_tolerances_in_inch_and_keeps_the_programs_units() {
    let app = TestApp::spawn().await;
    let request = |k: f64| json!({"program": dense_arc_program(), "block_time_ms": 4, "tolerance": 0.0002 * k, "min_chord_error": 0.00004 * k});
    let (inch, mm) = pair(request);
    let inch_answer = json_with(app.post_json("/api/v1/resegment", &inch).await, 200).await;
    let mm_answer = json_with(app.post_json("/api/v1/resegment", &mm).await, 200).await;
    assert_eq!(inch_answer["units"], "inch");
    assert!(mm_answer["max_deviation"].as_f64().unwrap() > 0.0, "{mm_answer}");
    assert!(mm_answer["before"]["short_blocks"].as_u64().unwrap() > 100, "{mm_answer}");
    assert_eq!(assert_in_inch("resegment", &inch_answer, &mm_answer, Kind::Same), 2);
    let inch_program = app.post_text("/api/v1/resegment?format=gcode", &inch, 200).await;
    let mm_program = app.post_text("/api/v1/resegment?format=gcode", &mm, 200).await;
    assert_eq!(inch_program, mm_program);
    assert!(inch_program.contains("G21") && !inch_program.contains("G20"), "{inch_program}");
}

/// `body` in inch (`units: inch`) and its mm twin.
fn pair(request: fn(f64) -> Value) -> (Value, Value) {
    let mut inch = request(1.0);
    inch["units"] = json!("inch");
    (inch, request(25.4))
}

#[tokio::test]
async fn inch_answers_are_the_mm_answers_divided_by_25_4() {
    let app = TestApp::spawn().await;
    for (endpoint, request) in [
        ("segment", segment_request as fn(f64) -> Value),
        ("contour", contour_request),
        ("engagement", engagement_request),
        ("deburr", deburr_request),
    ] {
        let (inch, mm) = pair(request);
        let inch_answer = json_with(app.post_json(&format!("/api/v1/{endpoint}"), &inch).await, 200).await;
        let mm_answer = json_with(app.post_json(&format!("/api/v1/{endpoint}"), &mm).await, 200).await;
        assert_eq!(inch_answer["units"], "inch", "{endpoint}");
        assert_eq!(mm_answer["units"], "mm", "{endpoint}");
        let converted = assert_in_inch(endpoint, &inch_answer, &mm_answer, Kind::Same);
        assert!(converted > 50, "{endpoint}: only {converted} lengths compared");
    }
}

#[tokio::test]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn inch_programs_move_as_the_mm_programs_in_rs274() {
    let app = TestApp::spawn().await;
    for (endpoint, query, request) in [
        ("segment", "", segment_request as fn(f64) -> Value),
        ("contour", "&arcs=g2g3", contour_request),
        ("contour", "", contour_request),
        ("engagement", "", engagement_request),
        ("deburr", "", deburr_request),
    ] {
        let (inch, mm) = pair(request);
        for dialect in ["linuxcnc", "fanuc", "haas"] {
            let url = format!("/api/v1/{endpoint}?format=gcode&dialect={dialect}{query}");
            let inch_text = app.post_text(&url, &inch, 200).await;
            let mm_text = app.post_text(&url, &mm, 200).await;
            assert!(inch_text.contains("G20 ") && !inch_text.contains("G21"), "{inch_text}");
            assert!(mm_text.contains("G21 ") && !mm_text.contains("G20"), "{mm_text}");
            let label = format!("{endpoint}_{dialect}{}", query.replace(['&', '='], "_"));
            let inch_moves = rs274_moves(&inch_text, app.directory(), &format!("{label}_inch")).expect("rs274");
            let mm_moves = rs274_moves(&mm_text, app.directory(), &format!("{label}_mm")).expect("rs274");
            assert_eq!(inch_moves.len(), mm_moves.len(), "{label}: move count");
            assert!(inch_moves.iter().filter(|m| m.0).count() > 10, "{label}");
            for (index, (got, want)) in inch_moves.iter().zip(&mm_moves).enumerate() {
                assert_eq!(got.0, want.0, "{label}: move {index} kind");
                // rs274 reports each program in its own units: the inch one within 0.0001 in of
                // the mm one's.
                let close = (0..3).all(|axis| (got.1[axis] - want.1[axis] / 25.4).abs() <= 1e-4);
                assert!(close, "{label}: move {index}: {got:?} in vs {want:?} mm");
            }
        }
    }
}

#[tokio::test]
async fn every_post_writes_inch_programs_in_its_own_words() {
    let app = TestApp::spawn().await;
    let (inch, _) = pair(segment_request);
    for (dialect, word) in [
        ("fanuc", "\nG20 G17"),
        ("haas", "\nG20 G17"),
        ("linuxcnc", "\nG20 G17"),
        ("grbl", "\nG20 G17"),
        ("sinumerik", "\nG700 G17"),
        ("heidenhain_iso", "%KERF1001 G70 *"),
        ("heidenhain", "BEGIN PGM KERF1001 INCH"),
    ] {
        let text = app.post_text(&format!("/api/v1/segment?format=gcode&dialect={dialect}"), &inch, 200).await;
        assert!(text.contains(word), "{dialect}: {text}");
        assert!(!text.contains("G21") && !text.contains("G71") && !text.contains("KERF1001 MM"), "{dialect}: {text}");
        // The clearance plane, 0.25 in, with 4 decimals.
        assert!(text.contains("Z0.2500") || text.contains("Z+0.2500"), "{dialect}: {text}");
    }
}

#[tokio::test]
async fn a_bad_units_value_is_refused_naming_units() {
    let app = TestApp::spawn().await;
    for (endpoint, mut body) in
        [("segment", segment_request(1.0)), ("contour", contour_request(1.0)), ("engagement", engagement_request(1.0))]
    {
        body["units"] = json!("furlong");
        let response = app.post_json(&format!("/api/v1/{endpoint}"), &body).await;
        let status = response.status().as_u16();
        assert!(status == 400 || status == 422, "{endpoint}: {status}");
        let problem = problem(response, status).await;
        assert!(problem.to_string().contains("units"), "{endpoint}: {problem}");
    }
    let response =
        app.put_json("/api/v1/machines/bad", &json!({"block_time_ms": 4, "max_feed": 5000, "units": "cm"})).await;
    let status = response.status().as_u16();
    assert!(status == 400 || status == 422, "machine: {status}");
    let problem = problem(response, status).await;
    assert!(problem.to_string().contains("units"), "machine: {problem}");
}

async fn machine_units_are_stored_and_are_the_requests_default(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let haas = json!({"block_time_ms": 4, "max_feed": 5080, "dialect": "haas", "units": "inch"});
    let created = json_with(app.put_json("/api/v1/machines/vf2", &haas).await, 201).await;
    assert_eq!(created["units"], "inch");
    app.restart().await;
    let read = json_with(app.get("/api/v1/machines/vf2").await, 200).await;
    assert_eq!(read["units"], "inch");
    assert_eq!(read["max_feed"], 5080.0, "the profile's own values stay in mm/min");

    // A request naming the machine is read in inch; one that says mm is read in mm.
    let mut inch = segment_request(1.0);
    inch["machine"] = json!("vf2");
    let mut mm = segment_request(25.4);
    mm["machine"] = json!("vf2");
    mm["units"] = json!("mm");
    let inch_answer = json_with(app.post_json("/api/v1/segment", &inch).await, 200).await;
    let mm_answer = json_with(app.post_json("/api/v1/segment", &mm).await, 200).await;
    assert_eq!(inch_answer["units"], "inch");
    assert_eq!(inch_answer["machine"]["max_feed"], 200.0, "the echoed machine in inch/min");
    assert_in_inch("segment", &inch_answer, &mm_answer, Kind::Same);
    let program = app.post_text("/api/v1/segment?format=gcode", &inch, 200).await;
    assert!(program.starts_with("%\nO01001") && program.contains("\nG20 G17"), "{program}");

    // A deburr request naming it is read in inch too, its stored tool staying in mm.
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let mut deburr = deburr_request(1.0);
    deburr["tool"] = json!(7);
    deburr["machine"] = json!("vf2");
    let answer = json_with(app.post_json("/api/v1/deburr", &deburr).await, 200).await;
    assert_eq!(answer["units"], "inch");
    assert_eq!(answer["tool"]["radius"], 3.0 / 25.4, "the echoed tool in inch");

    // Resegment reads its tolerances in the machine's units (its program keeps its own G21).
    let resegment = json!({"program": dense_arc_program(), "block_time_ms": 4, "machine": "vf2"});
    let answer = json_with(app.post_json("/api/v1/resegment", &resegment).await, 200).await;
    assert_eq!(answer["units"], "inch");

    // Back to mm: the column and the profile follow.
    let metric = json!({"block_time_ms": 4, "max_feed": 5080, "dialect": "haas"});
    json_with(app.put_json("/api/v1/machines/vf2", &metric).await, 200).await;
    let read = json_with(app.get("/api/v1/machines/vf2").await, 200).await;
    assert!(read.get("units").is_none(), "{read}");
    let answer = json_with(app.post_json("/api/v1/segment", &inch).await, 200).await;
    assert_eq!(answer["units"], "mm");
}

kerf_tests::on_both_stores!(machine_units_are_stored_and_are_the_requests_default);

#[tokio::test]
async fn a_job_operation_in_inch_stores_the_inch_answer_and_program() {
    let app = TestApp::spawn().await;
    let (inch, _) = pair(segment_request);
    let mut operation = inch.clone();
    operation["operation"] = json!("segment");
    let job = json!({"operations": [operation]});
    let submitted = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await;
    let id = submitted["id"].as_i64().unwrap();
    let done = poll_job(&app.client, &app.base, id, 60, finished).await;
    assert_eq!(done["status"], "done", "{done}");
    let direct = json_with(app.post_json("/api/v1/segment", &inch).await, 200).await;
    let stored = &done["results"][0]["result"];
    assert_eq!(stored["units"], "inch", "{done}");
    assert_eq!(stored["points"], direct["points"]);
    let program = app.get_text(&format!("/api/v1/jobs/{id}/gcode?operation=0"), 200).await;
    assert!(program.contains("\nG20 G17"), "{program}");
}
