//! Deburring with the block-time rule over HTTP: a stored machine (or a request's
//! `block_time_ms`) spaces the points so no block is shorter than feed × block time, the summary
//! reports the blocks, the machine's dialect is the G-code default, and jobs resolve the machine.

use kerf_tests::{TestApp, external_program, finished, json_with, poll_job, problem, rs274_moves};
use serde_json::{Value, json};

/// The tube request of [`kerf_cases::deburr::tube_request`] with `extra` fields.
fn request(extra: Value) -> Value {
    kerf_cases::with(kerf_cases::deburr::tube_request(), extra)
}

fn centre(point: &Value) -> [f64; 3] {
    let a = point["centre"].as_array().unwrap();
    [a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap()]
}

fn block_lengths(answer: &Value) -> Vec<f64> {
    let points = answer["points"].as_array().unwrap();
    points
        .windows(2)
        .map(|pair| {
            let (a, b) = (centre(&pair[0]), centre(&pair[1]));
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .collect()
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn a_stored_machine_spaces_the_points_by_its_block_time() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let machine = json!({"block_time_ms": 4, "max_feed": 6000, "dialect": "linuxcnc", "margin": 1.1});
    json_with(app.put_json("/api/v1/machines/mill-4ms", &machine).await, 201).await;

    // Without a block time the answer is the plain one: no block figures, no machine.
    let plain = json_with(app.post_json("/api/v1/deburr", &request(json!({"feed": 3000}))).await, 200).await;
    assert!(plain.get("machine").is_none() && plain["summary"].get("blocks").is_none());

    let body = request(json!({"machine": "mill-4ms", "feed": 3000}));
    let answer = json_with(app.post_json("/api/v1/deburr", &body).await, 200).await;
    let summary = &answer["summary"];
    assert_eq!(answer["machine"]["name"], "mill-4ms");
    assert_eq!(summary["block_time_ms"], 4.0);
    let block = 3000.0 * 4.0 / 60_000.0;
    assert_eq!(summary["block_length"], block);
    assert_eq!(summary["short_blocks"], 0, "{:?}", answer["warnings"]);
    let lengths = block_lengths(&answer);
    assert_eq!(summary["blocks"].as_u64().unwrap() as usize, lengths.len());
    assert!(lengths.iter().all(|l| *l >= 1.1 * block), "margin 1.1: every block at least 0.22 mm");
    assert!(summary["max_deviation"].as_f64().unwrap() <= 0.01);
    // Finer than the plain tolerance: more, shorter blocks, still digestible.
    assert!(summary["count"].as_u64().unwrap() > plain["summary"]["count"].as_u64().unwrap());
    let time = summary["estimated_time_s"].as_f64().unwrap();
    assert!(time >= lengths.len() as f64 * 0.004, "block-limited time {time}");

    // The request's block time overrides the machine's.
    let own = json_with(
        app.post_json("/api/v1/deburr", &request(json!({"machine": "mill-4ms", "feed": 3000, "block_time_ms": 1})))
            .await,
        200,
    )
    .await;
    assert_eq!(own["summary"]["block_time_ms"], 1.0);
    assert!(own["summary"]["blocks"].as_u64().unwrap() > summary["blocks"].as_u64().unwrap());

    // G-code: the machine's dialect by default; its moves are the JSON centres.
    let response = app
        .client
        .post(app.url("/api/v1/deburr?reference=centre"))
        .header("accept", "text/x-gcode")
        .json(&body)
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), 200);
    let program = response.text().await.unwrap();
    assert!(program.contains("G64 P0.0100") && !program.starts_with('%'), "linuxcnc from the machine");
    assert!(program.contains("(BLOCK TIME 4 MS MARGIN 1.1:"), "the header records the rule");
    if external_program("rs274", "the LinuxCNC G-code check").is_some() {
        let moves = rs274_moves(&program, app.directory(), "deburr_machine").expect("rs274 present");
        let feeds: Vec<[f64; 3]> = moves.iter().filter(|m| m.0).map(|m| m.1).collect();
        let centres: Vec<[f64; 3]> = answer["points"].as_array().unwrap().iter().map(centre).collect();
        // The loop's feed moves, in order, somewhere among the lead moves.
        let start =
            feeds.iter().position(|f| (0..3).all(|k| (f[k] - centres[1][k]).abs() <= 1e-4)).expect("loop start");
        for (index, want) in centres[1..].iter().enumerate() {
            let got = feeds[start + index];
            assert!((0..3).all(|k| (got[k] - want[k]).abs() <= 1e-4), "block {index}: {got:?} vs {want:?}");
        }
    }
    let fanuc = app
        .client
        .post(app.url("/api/v1/deburr?dialect=fanuc"))
        .header("accept", "text/x-gcode")
        .json(&body)
        .send()
        .await
        .unwrap();
    assert!(fanuc.text().await.unwrap().starts_with("%\n"), "the query wins");

    // Bad block-time input, unknown machine; the registry unchanged.
    let machines_before = json_with(app.get("/api/v1/machines").await, 200).await;
    for (extra, status, field, code) in [
        (json!({"block_time_ms": 0}), 422, "block_time_ms", "E_INPUT"),
        (json!({"block_time_ms": -4}), 422, "block_time_ms", "E_INPUT"),
        (json!({"block_time_ms": "4"}), 400, "block_time_ms", "E_JSON"),
        (json!({"machine": "no-such-control"}), 404, "machine", "E_NOT_FOUND"),
        (json!({"machine": 4}), 400, "machine", "E_JSON"),
    ] {
        let answer = problem(app.post_json("/api/v1/deburr", &request(extra.clone())).await, status).await;
        assert_eq!((&answer["code"], &answer["errors"][0]["path"]), (&json!(code), &json!(field)), "{extra}: {answer}");
    }
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await, machines_before, "registry unchanged");

    // A deburr job naming the machine resolves it at submission.
    let job = json!({"name": "deburr on mill-4ms", "operations": [
        {"operation": "deburr", "tool": 7, "machine": "mill-4ms", "feed": 3000,
         "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
         "hole": {"shape": "round", "radius": 8}, "edge": "outer", "cut_amount": 0.3}
    ]});
    let response = app
        .client
        .post(app.url("/api/v1/jobs"))
        .header("content-type", "application/json")
        .body(job.to_string())
        .send()
        .await
        .unwrap();
    let submitted = json_with(response, 202).await;
    let done = poll_job(&app.client, &app.base, submitted["id"].as_i64().unwrap(), 60, finished).await;
    assert_eq!(done["status"], "done", "{done}");
    assert_eq!(done["results"][0]["result"]["summary"]["blocks"], summary["blocks"]);
    assert_eq!(done["results"][0]["result"]["machine"]["name"], "mill-4ms");
}
