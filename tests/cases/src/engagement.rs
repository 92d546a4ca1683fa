//! Engagement requests (`POST /api/v1/engagement`).

use serde_json::{Value, json};

/// The request for an input block of the engagement fixture: its stock polygons (an empty
/// `holes` list left out, as a client would) and path pass unchanged, a flat end mill of
/// `radius`, the block's spindle speed and feed (per tooth, or `feed` at constant v_f).
pub fn fixture_request(stock: &Value, path: &Value, cutting: &Value, flutes: &Value, radius: f64) -> Value {
    let polygons: Vec<Value> = stock["polygons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let mut p = p.clone();
            if p["holes"].as_array().is_some_and(Vec::is_empty) {
                p.as_object_mut().unwrap().remove("holes");
            }
            p
        })
        .collect();
    let mut body = json!({
        "tool": {"kind": "flat", "radius": radius},
        "stock": {"polygons": polygons},
        "path": path,
        "spindle_rpm": cutting["spindle_rpm"],
        "flute_counts": flutes,
    });
    if cutting["feed_mode"] == "constant_vf" {
        body["feed"] = cutting["vf_mm_per_min"].clone();
    } else {
        body["feed_per_tooth"] = cutting["fz"].clone();
    }
    body
}
