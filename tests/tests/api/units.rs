//! Inch requests: converted to mm once at the edge, so an inch request answers the mm answer
//! divided by 25.4 in every length and feed (areas by 25.4²) and the same in everything else; its
//! program is written in G20 and moves as the mm program's (`rs274`); a machine's `units` is the
//! default of the requests that name it; a bad `units` is refused naming it.

use kerf_tests::{Store, TestApp, finished, json_with, poll_job, problem, rs274_moves};
use reqwest::multipart::{Form, Part};
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
    // the verification of a program, and verify (volumes keep the mm³ their names say)
    "resolution",
    "wall_tolerance",
    "depth",
    "outer_radius",
    "inner_radius",
    "flute_length",
    "stickout",
    // predict
    "error",
    "error_deflection",
    "error_shape",
    "generation_point",
    "deflection",
    "residual_error",
    "correction",
    "corrected",
    "merge_bound",
    "min_error",
    "max_error",
    "mean_error",
    "rms_error",
    "max_correction",
    "max_abs_error",
    "pixel_size",
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

/// Paths whose numbers are counts although their key names a length elsewhere (predict's
/// pixels per side).
const UNSCALED_AT: &[&str] = &["predict.summary.resolution"];

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
                    let at = format!("{path}.{key}");
                    let kind = if UNSCALED_AT.iter().any(|end| at.ends_with(end)) {
                        Kind::Same
                    } else {
                        kind_of(key, if matches!(kind, Kind::Length) { Kind::Length } else { Kind::Same })
                    };
                    assert_in_inch(&at, &inch[key.as_str()], &mm[key.as_str()], kind)
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
        (Value::String(inch), Value::String(mm)) => {
            // A sentence (a warning, a note) quotes its lengths in the answer's units.
            assert!(!quotes_mm(inch), "{path}: {inch:?} quotes mm");
            assert_eq!(sentence(inch), sentence(mm), "{path}: {inch:?} vs {mm:?}");
            0
        }
        _ => {
            assert_eq!(inch, mm, "{path}");
            0
        }
    }
}

/// Whether `text` gives a number in mm or mm/min.
fn quotes_mm(text: &str) -> bool {
    let bytes = text.as_bytes();
    text.match_indices("mm").any(|(at, _)| {
        let before = text[..at].trim_end_matches(' ');
        let after = bytes.get(at + 2).copied();
        before.ends_with(|c: char| c.is_ascii_digit()) && !after.is_some_and(|b| b.is_ascii_alphabetic())
    })
}

/// `text` without its numbers and with `in` read as `mm`: an inch sentence and its mm twin agree.
fn sentence(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let digit = |k: Option<usize>| k.and_then(|k| chars.get(k)).is_some_and(char::is_ascii_digit);
    let kept: Vec<char> = (0..chars.len())
        .filter(|&k| {
            let c = chars[k];
            !(c.is_ascii_digit()
                || (matches!(c, '.' | '-' | '+' | 'e') && (digit(k.checked_sub(1)) || digit(Some(k + 1)))))
        })
        .map(|k| chars[k])
        .collect();
    let word = |c: Option<&char>| c.is_some_and(|c| c.is_alphanumeric() && !matches!(c, '²' | '³'));
    let mut out = String::new();
    let mut k = 0;
    while k < kept.len() {
        let unit = kept[k] == 'i' && kept.get(k + 1) == Some(&'n');
        if unit && !word(k.checked_sub(1).and_then(|p| kept.get(p))) && !word(kept.get(k + 2)) {
            out.push_str("mm");
            k += 2;
        } else {
            out.push(kept[k]);
            k += 1;
        }
    }
    out
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
            if dialect == "linuxcnc" {
                // Blending within a tolerance, never `G64 P0` (no tolerance at all), and within
                // the mm program's where the inch program can say it.
                let tolerance =
                    |text: &str| -> f64 { line_with(text, "G64 P")["G64 P".len()..].trim().parse().unwrap() };
                let (inch_tolerance, mm_tolerance) = (tolerance(&inch_text), tolerance(&mm_text));
                assert!(inch_tolerance >= 1e-4, "{label}: G64 P{inch_tolerance}");
                assert!(
                    inch_tolerance <= (mm_tolerance / 25.4).max(1e-4) + 5e-5,
                    "{label}: {inch_tolerance} in vs {mm_tolerance} mm"
                );
            }
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

/// A predict request in units of `k` mm: a ball with a shape-error table and a modal stiffness
/// (N/mm, never scaled) over a box stock, cutting force coefficients (N/mm², never scaled) and a
/// G20 raster, which both twins read alike (a program keeps its own units).
fn predict_request(k: f64) -> Value {
    json!({"tool": {"kind": "ball", "radius": 0.125 * k, "flutes": 2,
                    "shape_error": [{"angle_deg": 0, "error": 0.00016 * k}, {"angle_deg": 45, "error": 0.00024 * k},
                                    {"angle_deg": 90, "error": 0.00035 * k}],
                    "stiffness": {"kind": "modal",
                                  "x": [{"stiffness": 3000, "frequency_hz": 1800, "damping_ratio": 0.04}],
                                  "y": [{"stiffness": 3000, "frequency_hz": 1800, "damping_ratio": 0.04}]}},
           "stock": {"kind": "box", "min": [-k, -k, -0.5 * k], "max": [k, k, 0.01 * k]},
           "path": {"kind": "gcode", "program": crate::predict::raster_program(5, 7, true)},
           "cutting": {"ktc": 2000, "krc": 800, "kac": 300},
           "correction": {"max_correction": 0.004 * k},
           "resolution": 64, "history": [3]})
}

/// The same prediction along points (in the request's units), written as a program by kerf.
fn predict_points_request(k: f64) -> Value {
    let mut request = predict_request(k);
    let points: Vec<[f64; 3]> = (0..9).map(|i| [(-0.15 + 0.0375 * f64::from(i)) * k, 0.0, 0.0]).collect();
    request["path"] = json!({"kind": "points", "points": points});
    request["feed"] = json!(60.0 * k);
    request["spindle_rpm"] = json!(8000);
    request["reference"] = json!("tip");
    request
}

/// A verify request in units of `k` mm with its program written in them: a flat end mill faces a
/// block, gouging the part below on one pass and leaving material on another.
fn verify_request(k: f64) -> Value {
    let moves: [(&str, [f64; 3], Option<f64>); 7] = [
        ("G0", [-0.25, 0.5, 0.25], None),
        ("G1", [-0.25, 0.5, -0.0625], Some(20.0)),
        ("G1", [2.25, 0.5, -0.0625], None),
        ("G1", [2.25, 1.0, -0.0625], None),
        ("G1", [1.0, 1.0, -0.125], None),
        ("G1", [-0.25, 1.0, -0.125], None),
        ("G0", [-0.25, 1.0, 0.25], None),
    ];
    let mut program =
        String::from(if k == 1.0 { "G20 G90 G17\nT1 M6\nS8000 M3\n" } else { "G21 G90 G17\nT1 M6\nS8000 M3\n" });
    for (word, [x, y, z], feed) in moves {
        program.push_str(&format!("{word} X{} Y{} Z{}", x * k, y * k, z * k));
        if let Some(feed) = feed {
            program.push_str(&format!(" F{}", feed * k));
        }
        program.push('\n');
    }
    program.push_str("M30\n");
    json!({"program": program,
           "tools": [{"number": 1, "kind": "flat", "radius": 0.125 * k, "flute_length": k, "stickout": 2.0 * k}],
           "stock": {"kind": "box", "min": [0, 0, -0.5 * k], "max": [2.0 * k, 2.0 * k, 0]},
           "part": {"kind": "box", "min": [0, 0, -0.5 * k], "max": [2.0 * k, 2.0 * k, -0.09375 * k]},
           "resolution": 0.03125 * k, "tolerance": 0.0004 * k, "allowance": 0.004 * k})
}

/// An inch prediction answers the mm prediction divided by 25.4 (the stiffness and the cutting
/// coefficients keep their N/mm units), a G-code path and a path of points alike; the program of
/// a path of points is written in G20 and its header quotes inches; a job answers the same.
#[tokio::test(flavor = "multi_thread")]
async fn an_inch_prediction_is_the_mm_prediction_divided_by_25_4() {
    let app = TestApp::spawn().await;
    for request in [predict_request as fn(f64) -> Value, predict_points_request] {
        let (inch, mm) = pair(request);
        let inch_answer = json_with(app.post_json("/api/v1/predict", &inch).await, 200).await;
        let mm_answer = json_with(app.post_json("/api/v1/predict", &mm).await, 200).await;
        assert_eq!(inch_answer["units"], "inch");
        assert!(mm_answer["summary"]["predicted"].as_u64().unwrap() > 5, "{mm_answer}");
        assert!(mm_answer["summary"]["rms_error"].as_f64().unwrap() > 1e-3, "{}", mm_answer["summary"]);
        let converted = assert_in_inch("predict", &inch_answer, &mm_answer, Kind::Same);
        assert!(converted > 100, "only {converted} lengths compared");
    }
    let (inch, mm) = pair(predict_points_request);
    let inch_program = app.post_text("/api/v1/predict/program?dialect=linuxcnc", &inch, 200).await;
    let mm_program = app.post_text("/api/v1/predict/program?dialect=linuxcnc", &mm, 200).await;
    assert!(inch_program.contains("\nG20 G17") && !inch_program.contains("G21"), "{inch_program}");
    assert!(mm_program.contains("\nG21 G17"), "{mm_program}");
    let header = inch_program
        .lines()
        .map(str::to_lowercase)
        .find(|line| line.contains("max correction"))
        .unwrap_or_else(|| panic!("{inch_program}"));
    assert!(header.contains(" in, predicted max error ") && !quotes_mm(&header), "{header}");

    let mut operation = inch.clone();
    operation["operation"] = json!("predict");
    let submitted = json_with(app.post_json("/api/v1/jobs", &json!({"operations": [operation]})).await, 202).await;
    let id = submitted["id"].as_i64().unwrap();
    let done = poll_job(&app.client, &app.base, id, 120, finished).await;
    assert_eq!(done["status"], "done", "{done}");
    let stored = &done["results"][0]["result"];
    let direct = json_with(app.post_json("/api/v1/predict", &inch).await, 200).await;
    assert_eq!(stored["units"], "inch");
    assert_eq!(stored["passes"], direct["passes"]);
    let program = app.get_text(&format!("/api/v1/jobs/{id}/gcode?operation=0"), 200).await;
    assert!(program.contains("G20"), "{program}");
}

/// A mesh stock's STL file is read in the request's units unless the stock names its own.
#[tokio::test(flavor = "multi_thread")]
async fn an_inch_stl_stock_is_read_in_inches() {
    let app = TestApp::spawn().await;
    let (inch, _) = pair(predict_request);
    let from_box = json_with(app.post_json("/api/v1/predict", &inch).await, 200).await;
    let form = |body: &Value, bytes: Vec<u8>| {
        Form::new()
            .part("request", Part::text(body.to_string()).mime_str("application/json").unwrap())
            .part("stock", Part::bytes(bytes).file_name("stock.stl"))
    };
    let mut body = inch.clone();
    body["stock"] = json!({"kind": "mesh"});
    let in_inches = crate::predict::box_stl_binary([-1.0, -1.0, -0.5], [1.0, 1.0, 0.01]);
    let response = app.client.post(app.url("/api/v1/predict")).multipart(form(&body, in_inches)).send().await.unwrap();
    let from_inches = json_with(response, 200).await;
    body["stock"] = json!({"kind": "mesh", "units": "mm"});
    let in_mm = crate::predict::box_stl_binary([-25.4, -25.4, -12.7], [25.4, 25.4, 0.254]);
    let response = app.client.post(app.url("/api/v1/predict")).multipart(form(&body, in_mm)).send().await.unwrap();
    let from_mm = json_with(response, 200).await;
    for from_mesh in [&from_inches, &from_mm] {
        assert_eq!(from_mesh["units"], "inch");
        let (a, b) = (from_box["passes"].as_array().unwrap(), from_mesh["passes"].as_array().unwrap());
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(b) {
            assert_eq!(p["status"], q["status"], "{p} vs {q}");
            if let (Some(x), Some(y)) = (p["error"].as_f64(), q["error"].as_f64()) {
                assert!((x - y).abs() <= 1e-6, "pass {}: {x} in vs {y} in", p["index"]);
            }
        }
    }
}

/// The inch verification of an inch program is the mm verification of its mm twin, its lengths
/// divided by 25.4 and its volumes the same mm³; its GLB mesh too, positions and `_DEVIATION` in
/// inches; as a job the same answer.
#[tokio::test(flavor = "multi_thread")]
async fn an_inch_verification_is_the_mm_verification_of_the_mm_twin() {
    let app = TestApp::spawn().await;
    let (inch, mm) = pair(verify_request);
    let inch_answer = json_with(app.post_json("/api/v1/verify", &inch).await, 200).await;
    let mm_answer = json_with(app.post_json("/api/v1/verify", &mm).await, 200).await;
    assert_eq!(inch_answer["units"], "inch");
    let kinds: Vec<&Value> = mm_answer["findings"].as_array().unwrap().iter().map(|f| &f["kind"]).collect();
    assert!(kinds.contains(&&json!("gouge")) && kinds.contains(&&json!("left_material")), "{mm_answer}");
    let converted = assert_in_inch("verify", &inch_answer, &mm_answer, Kind::Same);
    assert!(converted > 10, "only {converted} lengths compared");

    let glb = |body: Value| {
        let app = &app;
        async move {
            let response = app.client.post(app.url("/api/v1/verify?format=glb")).json(&body).send().await.unwrap();
            assert_eq!(response.status().as_u16(), 200);
            crate::verify_mesh::chunks(&response.bytes().await.unwrap())
        }
    };
    let (inch_json, inch_bin) = glb(inch.clone()).await;
    let (mm_json, mm_bin) = glb(mm).await;
    assert_eq!(inch_json["extras"]["verify"], inch_answer);
    for name in ["POSITION", "_DEVIATION"] {
        let inch_values = crate::verify_mesh::values(&inch_json, &inch_bin, name);
        let mm_values = crate::verify_mesh::values(&mm_json, &mm_bin, name);
        assert_eq!(inch_values.len(), mm_values.len(), "{name}");
        assert!(inch_values.len() > 100, "{name}");
        for (got, want) in inch_values.iter().zip(&mm_values) {
            assert!((got - want / 25.4).abs() <= 1e-6 * want.abs().max(1.0), "{name}: {got} in vs {want} mm");
        }
    }

    let mut operation = inch.clone();
    operation["operation"] = json!("verify");
    let submitted = json_with(app.post_json("/api/v1/jobs", &json!({"operations": [operation]})).await, 202).await;
    let id = submitted["id"].as_i64().unwrap();
    let done = poll_job(&app.client, &app.base, id, 60, finished).await;
    assert_eq!(done["status"], "done", "{done}");
    assert_eq!(done["results"][0]["result"]["findings"], inch_answer["findings"]);
}

/// A refusal and a warning of an inch request quote its lengths and feeds in inches.
#[tokio::test]
async fn an_inch_requests_refusals_and_warnings_read_inches() {
    let app = TestApp::spawn().await;
    // A tolerance below the smallest: the detail gives the limit and the value in inches.
    let mut body = segment_request(1.0);
    body["units"] = json!("inch");
    body["tolerance"] = json!(1e-9);
    let refused = problem(app.post_json("/api/v1/segment", &body).await, 422).await;
    let detail = refused["detail"].as_str().unwrap();
    assert!(detail.contains(" in (got 0.000000001000 in)") && !quotes_mm(detail), "{detail}");
    // A verify spacing over the memory limit: the stock's size in inches.
    let (mut inch, _) = pair(verify_request);
    inch["resolution"] = json!(0.00001);
    let refused = problem(app.post_json("/api/v1/verify", &inch).await, 422).await;
    let detail = refused["detail"].as_str().unwrap();
    assert!(detail.contains("over the stock's 2.0000 in × 2.0000 in") && !quotes_mm(detail), "{detail}");
    // A feed above the machine's: the warning in in/min.
    app.put_json("/api/v1/machines/slow", &json!({"block_time_ms": 4, "max_feed": 2540})).await;
    let mut body = segment_request(1.0);
    body["units"] = json!("inch");
    body["machine"] = json!("slow");
    body["feed"] = json!(150.0);
    let answer = json_with(app.post_json("/api/v1/segment", &body).await, 200).await;
    let warning = answer["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|w| w["code"] == "W_FEED_ABOVE_MACHINE_MAX")
        .unwrap_or_else(|| panic!("{answer}"));
    let message = warning["message"].as_str().unwrap();
    assert!(message.contains("feed 150.0 in/min is above the machine's max_feed 100.0 in/min"), "{message}");
}

/// The numbers a sentence quotes, each with its sign, decimals and exponent, and the step of its
/// last digit.
fn numbers(text: &str) -> Vec<(f64, f64)> {
    let bytes = text.as_bytes();
    let mut found = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let starts =
            bytes[at].is_ascii_digit() || (bytes[at] == b'-' && bytes.get(at + 1).is_some_and(u8::is_ascii_digit));
        let in_word = at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_');
        if !starts || in_word {
            at += 1;
            continue;
        }
        let mut end = at + 1;
        while end < bytes.len()
            && (bytes[end].is_ascii_digit()
                || (bytes[end] == b'.' && bytes.get(end + 1).is_some_and(u8::is_ascii_digit))
                || (bytes[end] == b'e' && bytes.get(end + 1).is_some_and(|b| b.is_ascii_digit() || *b == b'-')))
        {
            end += if bytes[end] == b'e' && bytes[end + 1] == b'-' { 2 } else { 1 };
        }
        let written = &text[at..end];
        let value: f64 = written.parse().unwrap_or_else(|_| panic!("{written:?} in {text:?}"));
        let (mantissa, exponent) = written.split_once('e').unwrap_or((written, "0"));
        let decimals = mantissa.split_once('.').map_or(0, |(_, fraction)| fraction.len());
        let exponent: i32 = exponent.parse().unwrap_or(0);
        found.push((value, 10f64.powi(exponent - i32::try_from(decimals).unwrap_or(0))));
        at = end;
    }
    found
}

/// A sentence of an inch answer quotes the numbers its twin in mm with the same numbers quotes:
/// every length and feed restated in inches reads as the request gave it, and one quoted in mm
/// (25.4 times the twin's) or bare shows.
fn assert_same_numbers(what: &str, inch: &str, mm: &str) {
    let (inch_numbers, mm_numbers) = (numbers(inch), numbers(mm));
    assert_eq!(inch_numbers.len(), mm_numbers.len(), "{what}: {inch:?} vs {mm:?}");
    for ((a, a_step), (b, b_step)) in inch_numbers.iter().zip(&mm_numbers) {
        // Equal to the last digit either writes.
        assert!((a - b).abs() <= a_step.max(*b_step), "{what}: {a} vs {b} in {inch:?} vs {mm:?}");
    }
    assert!(!quotes_mm(inch), "{what}: {inch:?} quotes mm");
}

/// A request of the tests above in units of `k` mm.
type Request = fn(f64) -> Value;

/// `request(1.0)` with `value` at `pointer`, in `units`.
fn changed(request: Request, pointer: &str, value: f64, units: &str) -> Value {
    let mut body = request(1.0);
    *body.pointer_mut(pointer).unwrap_or_else(|| panic!("{pointer}")) = json!(value);
    body["units"] = json!(units);
    body
}

/// Every refusal and warning of an inch request quotes its lengths and feeds as the request gave
/// them, in inches: a refusal checks the request in mm, and a length it quoted without its unit
/// would reach the machinist 25.4 times too large ("feed must be greater than 0 (got -76.2)" for
/// -3 in/min).
#[tokio::test]
async fn an_inch_requests_refusals_and_warnings_quote_its_own_numbers() {
    let app = TestApp::spawn().await;
    let bad: [(&str, Request, &str, f64); 16] = [
        ("contour", contour_request, "/feed", -3.0),
        ("contour", contour_request, "/loop_feed", -3.0),
        ("contour", contour_request, "/depths/step", -0.5),
        ("contour", contour_request, "/depths/bottom", 0.3),
        ("contour", contour_request, "/stock_allowance", 0.005),
        ("contour", contour_request, "/passes/1/allowance", 0.5),
        ("contour", contour_request, "/tool/radius", -0.125),
        ("deburr", deburr_request, "/holes/0/radius", -1.0),
        ("deburr", deburr_request, "/holes/0/radius", 1.2),
        ("deburr", deburr_request, "/workpiece/outer_radius", 0.5),
        ("deburr", deburr_request, "/tolerance", -0.001),
        ("engagement", engagement_request, "/feed_per_tooth", -0.002),
        ("engagement", engagement_request, "/thickness_limit", -0.1),
        ("engagement", engagement_request, "/tool/radius", -0.2),
        ("segment", segment_request, "/curve/semi_axes/0", -1.5),
        ("segment", segment_request, "/safe_z", -0.1),
    ];
    for (endpoint, request, pointer, value) in bad {
        let what = format!("{endpoint} {pointer} = {value}");
        let path = format!("/api/v1/{endpoint}");
        let inch = problem(app.post_json(&path, &changed(request, pointer, value, "inch")).await, 422).await;
        let mm = problem(app.post_json(&path, &changed(request, pointer, value, "mm")).await, 422).await;
        assert_eq!(inch["code"], mm["code"], "{what}: {inch} vs {mm}");
        assert_same_numbers(&what, inch["detail"].as_str().unwrap(), mm["detail"].as_str().unwrap());
    }
    let mut compared = 0;
    for (endpoint, request) in [
        ("segment", segment_request as fn(f64) -> Value),
        ("contour", contour_request),
        ("engagement", engagement_request),
        ("deburr", deburr_request),
    ] {
        let path = format!("/api/v1/{endpoint}");
        let mut inch = request(1.0);
        inch["units"] = json!("inch");
        let inch = json_with(app.post_json(&path, &inch).await, 200).await;
        let mm = json_with(app.post_json(&path, &request(1.0)).await, 200).await;
        let warnings = |answer: &Value| -> Vec<(String, String)> {
            answer["warnings"].as_array().map_or_else(Vec::new, |all| {
                all.iter()
                    .map(|w| (w["code"].as_str().unwrap().to_owned(), w["message"].as_str().unwrap().to_owned()))
                    .collect()
            })
        };
        for (code, message) in warnings(&inch) {
            // The twin warning of the same code about the same thing (`k = 3: …`): what the
            // answers recommend may differ, forces are not scaled.
            let about =
                |text: &str| text.strip_prefix("k = ").and_then(|rest| rest.split_once(':')).map(|(k, _)| k.to_owned());
            let twin = warnings(&mm).into_iter().find(|(other, text)| *other == code && about(text) == about(&message));
            if let Some((_, twin)) = twin {
                assert_same_numbers(&format!("{endpoint} {code}"), &message, &twin);
                compared += 1;
            }
        }
    }
    assert!(compared >= 5, "only {compared} warnings compared");
    // The G-code's least increment is 0.0001 of the program's unit: a chord error of 0.0002 in
    // (5.08 µm: blocks of 1.016 mm round a 25.4 mm circle) is within 5 increments of an inch
    // program, not of a mm program.
    let circle = |k: f64| json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": k}, "feed": 600.0 * k, "block_time_ms": 4});
    let mut inch = circle(1.0);
    inch["units"] = json!("inch");
    let mm = circle(25.4);
    let limited = |answer: &Value| {
        answer["warnings"]
            .as_array()
            .and_then(|all| all.iter().find(|w| w["code"] == "W_RESOLUTION_LIMITED"))
            .map(|w| w["message"].as_str().unwrap().to_owned())
    };
    let inch = json_with(app.post_json("/api/v1/segment", &inch).await, 200).await;
    let message = limited(&inch).unwrap_or_else(|| panic!("no W_RESOLUTION_LIMITED in {inch}"));
    let increment = message.split_once("of the G-code's ").and_then(|(_, rest)| rest.split_once(':')).unwrap().0;
    assert_eq!(increment.strip_suffix(" in").map(|number| number.parse::<f64>()), Some(Ok(0.0001)), "{message}");
    let mm = json_with(app.post_json("/api/v1/segment", &mm).await, 200).await;
    assert_eq!(limited(&mm), None, "{mm}");
    // A program's header comments: the job's lengths and feeds in the program's units (a
    // segmentation's chord errors have floors in mm, so its header is read for the feed).
    let mut inch = segment_request(1.0);
    inch["units"] = json!("inch");
    let program = app.post_text("/api/v1/segment?format=gcode", &inch, 200).await;
    assert!(program.contains("(BLOCK TIME 4 MS FEED 120.0 IN/MIN MARGIN 1 MIN CHORD ERROR"), "{program}");
    assert_eq!(line_with(&program, "(CHORD ERROR").matches(" IN").count(), 2, "{program}");
    for (endpoint, request) in
        [("contour", contour_request as Request), ("engagement", engagement_request), ("deburr", deburr_request)]
    {
        let path = format!("/api/v1/{endpoint}?format=gcode");
        let mut inch = request(1.0);
        inch["units"] = json!("inch");
        let inch = app.post_text(&path, &inch, 200).await;
        let mm = app.post_text(&path, &request(1.0), 200).await;
        let header = |program: &str| -> Vec<String> {
            program
                .lines()
                .skip_while(|line| !line.starts_with('('))
                .take_while(|line| line.starts_with('('))
                .map(str::to_owned)
                .collect()
        };
        let (inch_header, mm_header) = (header(&inch), header(&mm));
        assert!(inch_header.len() >= 3 && inch_header.len() == mm_header.len(), "{endpoint}: {inch}\nvs\n{mm}");
        for (inch_line, mm_line) in inch_header.iter().zip(&mm_header) {
            assert_same_numbers(&format!("{endpoint} program"), inch_line, mm_line);
        }
    }
}

/// The line of `program` that holds `text`.
fn line_with<'p>(program: &'p str, text: &str) -> &'p str {
    program.lines().find(|line| line.contains(text)).unwrap_or_else(|| panic!("no {text:?} in {program}"))
}

/// An inch program's header quotes inches where it quotes a length or a feed: the radius of an
/// inline tool the operator loads by hand, engagement's cutting and clearance heights and its feed
/// plan; the mm twin's quote mm.
#[tokio::test]
async fn an_inch_programs_header_reads_inches() {
    let app = TestApp::spawn().await;
    let (inch, mm) = pair(contour_request);
    let inch_program = app.post_text("/api/v1/contour?format=gcode", &inch, 200).await;
    let mm_program = app.post_text("/api/v1/contour?format=gcode", &mm, 200).await;
    let manual = "TOOL NOT IN THE TOOL TABLE";
    assert_eq!(line_with(&inch_program, manual), "(TOOL NOT IN THE TOOL TABLE: FLAT RADIUS 0.12500 IN)");
    assert_eq!(line_with(&mm_program, manual), "(TOOL NOT IN THE TOOL TABLE: FLAT RADIUS 3.1750 MM)");
    let (inch, mm) = pair(engagement_request);
    let inch_program = app.post_text("/api/v1/engagement?format=gcode", &inch, 200).await;
    let mm_program = app.post_text("/api/v1/engagement?format=gcode", &mm, 200).await;
    assert_eq!(line_with(&inch_program, "CUT Z"), "(CUT Z -0.080000 IN, CLEARANCE Z 0.20000 IN, CONTROL POINT TIP)");
    assert_eq!(line_with(&mm_program, "CUT Z"), "(CUT Z -2.0320 MM, CLEARANCE Z 5.0800 MM, CONTROL POINT TIP)");
    assert_eq!(
        line_with(&inch_program, "FEEDS HOLD"),
        "(FEEDS HOLD 0.002000 IN CHIP THICKNESS  TOOTH BASIS  FOR 4 FLUTES, MAX FEED 60.00 IN/MIN)"
    );
    assert_eq!(
        line_with(&mm_program, "FEEDS HOLD"),
        "(FEEDS HOLD 0.0508 MM CHIP THICKNESS  TOOTH BASIS  FOR 4 FLUTES, MAX FEED 1524 MM/MIN)"
    );
    assert_eq!(line_with(&inch_program, manual), "(TOOL NOT IN THE TOOL TABLE: FLAT RADIUS 0.20000 IN)");
    assert_eq!(line_with(&mm_program, manual), "(TOOL NOT IN THE TOOL TABLE: FLAT RADIUS 5.0800 MM)");
}

/// A deburr request in units of `k` mm whose inner edge a lollipop cutter cannot reach: its neck
/// would cut the hole wall, so it has an answer but no program.
fn blocked_deburr_request(k: f64) -> Value {
    json!({"tool": {"kind": "ball", "radius": 0.12 * k, "neck_radius": 0.11 * k},
           "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_diameter": 1.2 * k, "outer_radius": k},
           "holes": [{"shape": "round", "radius": 0.3 * k}],
           "edge": "inner", "width": 0.02 * k, "feed": 12.0 * k, "spindle_rpm": 8000})
}

/// Why an inch operation has no program quotes inches, at its endpoint and in its job; the mm
/// twin's quotes mm, in the same words.
#[tokio::test]
async fn an_inch_operations_reason_for_no_program_reads_inches() {
    let app = TestApp::spawn().await;
    let (inch, mm) = pair(blocked_deburr_request);
    let mut reasons = Vec::new();
    for body in [&inch, &mm] {
        let refused = problem(app.post_json("/api/v1/deburr?format=gcode", body).await, 422).await;
        assert_eq!(refused["code"], "E_NECK_COLLISION", "{refused}");
        let detail = refused["detail"].as_str().unwrap().to_owned();
        let mut operation = body.clone();
        operation["operation"] = json!("deburr");
        let job = json!({"operations": [operation]});
        let id = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await["id"].as_i64().unwrap();
        let done = poll_job(&app.client, &app.base, id, 60, finished).await;
        assert_eq!(done["status"], "done", "{done}");
        assert_eq!(done["results"][0]["gcode"], false, "{done}");
        let problem = done["results"][0]["gcode_problem"].as_str().unwrap_or_else(|| panic!("{done}"));
        assert_eq!(problem, format!("{detail} (E_NECK_COLLISION)"));
        reasons.push(detail);
    }
    assert_eq!(reasons[0], "the neck (radius 0.1100 in) would cut the hole wall: it is short of room by 0.03251 in");
    assert_eq!(reasons[1], "the neck (radius 2.794 mm) would cut the hole wall: it is short of room by 0.8258 mm");
}
