//! The materials library: the seeded materials, create, replace, read, list, delete,
//! bad names and values, survival across a restart; engagement requests and jobs that name a
//! material, and the preconditions of a write (`If-Match`, `If-None-Match`), on both stores.

use kerf_tests::{Store, TestApp, finished, json_with, poll_job, problem};
use serde_json::{Value, json};

/// The seeded materials, in name order, with their k_c1.1 (N/mm²), m_c and ISO group.
const SEEDED: [(&str, f64, f64, &str); 9] = [
    ("16MnCr5", 2100.0, 0.26, "P"),
    ("42CrMo4", 2500.0, 0.26, "P"),
    ("AlMg4.5Mn", 700.0, 0.25, "N"),
    ("AlSi10Mg", 700.0, 0.25, "N"),
    ("AlZnMgCu1.5", 800.0, 0.25, "N"),
    ("C45", 2220.0, 0.14, "P"),
    ("EN-GJL-250", 1150.0, 0.20, "K"),
    ("Ti6Al4V", 2110.0, 0.22, "S"),
    ("X5CrNi18-10", 2150.0, 0.20, "M"),
];

fn names(list: &Value) -> Vec<String> {
    list.as_array().unwrap().iter().map(|m| m["name"].as_str().unwrap().to_owned()).collect()
}

async fn seeded_materials_with_their_sources(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let list = json_with(app.get("/api/v1/materials").await, 200).await;
    assert_eq!(names(&list), SEEDED.map(|(name, ..)| name.to_owned()), "seeded and ordered by name");
    for (material, (name, kc11, mc, group)) in list.as_array().unwrap().iter().zip(SEEDED) {
        assert_eq!(material["kc11"].as_f64(), Some(kc11), "{name}");
        assert_eq!(material["mc"].as_f64(), Some(mc), "{name}");
        assert_eq!(material["iso_group"], group, "{name}");
        let description = material["description"].as_str().unwrap();
        assert!(description.contains("Source: "), "{name} names its source: {description}");
        assert!(description.chars().count() <= 500, "{name}");
    }
    assert_eq!(json_with(app.get("/api/v1/materials/C45").await, 200).await, list[5]);
}

async fn material_crud_and_restart(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let mine = json!({"kc11": 1780, "mc": 0.17, "radial_ratio": 0.4, "iso_group": "P",
                      "description": "S235JR, our supplier, measured 2026"});
    let created = json_with(app.put_json("/api/v1/materials/S235JR", &mine).await, 201).await;
    assert_eq!(
        created,
        json!({"name": "S235JR", "kc11": 1780.0, "mc": 0.17, "radial_ratio": 0.4, "iso_group": "P",
               "description": "S235JR, our supplier, measured 2026"})
    );
    assert_eq!(json_with(app.get("/api/v1/materials/S235JR").await, 200).await, created);
    // A replace stores the new record whole: what it leaves out is gone.
    let replaced =
        json_with(app.put_json("/api/v1/materials/S235JR", &json!({"kc11": 1800, "mc": 0.2})).await, 200).await;
    assert_eq!(replaced, json!({"name": "S235JR", "kc11": 1800.0, "mc": 0.2}));
    // Replacing a seeded material, with the name repeated in the body (a GET → edit → PUT).
    let mut c45 = json_with(app.get("/api/v1/materials/C45").await, 200).await;
    c45["kc11"] = json!(2300);
    assert_eq!(json_with(app.put_json("/api/v1/materials/C45", &c45).await, 200).await["kc11"], 2300.0);

    let list = json_with(app.get("/api/v1/materials").await, 200).await;
    assert_eq!(list.as_array().unwrap().len(), SEEDED.len() + 1);
    assert!(names(&list).windows(2).all(|pair| pair[0] < pair[1]), "ordered by name: {:?}", names(&list));

    app.restart().await;
    assert_eq!(json_with(app.get("/api/v1/materials").await, 200).await, list, "materials survive a restart");

    // A deleted seeded material stays deleted: seeding happens once, at the first start.
    assert_eq!(app.delete("/api/v1/materials/Ti6Al4V").await.status(), 204);
    assert_eq!(problem(app.get("/api/v1/materials/Ti6Al4V").await, 404).await["code"], "E_NOT_FOUND");
    problem(app.delete("/api/v1/materials/Ti6Al4V").await, 404).await;
    app.restart().await;
    problem(app.get("/api/v1/materials/Ti6Al4V").await, 404).await;
    assert_eq!(json_with(app.get("/api/v1/materials").await, 200).await.as_array().unwrap().len(), SEEDED.len());
    app.shutdown().await;
}

async fn bad_materials_are_refused_and_nothing_is_stored(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let before = json_with(app.get("/api/v1/materials").await, 200).await;
    let good = json!({"kc11": 1800, "mc": 0.25});
    let long_name = format!("/api/v1/materials/{}", "m".repeat(65));
    let with = |changes: Value| {
        let mut body = good.clone();
        body.as_object_mut().unwrap().extend(changes.as_object().unwrap().clone());
        body
    };
    // (what, path, body, status, field, code)
    let cases = vec![
        ("name with a space", "/api/v1/materials/a%20b", good.clone(), 422, "name", "E_INPUT"),
        ("name starting with a dot", "/api/v1/materials/.x", good.clone(), 422, "name", "E_INPUT"),
        ("name too long", long_name.as_str(), good.clone(), 422, "name", "E_INPUT"),
        ("body name differs", "/api/v1/materials/m1", with(json!({"name": "m2"})), 422, "name", "E_INPUT"),
        ("zero kc11", "/api/v1/materials/m1", with(json!({"kc11": 0})), 422, "kc11", "E_INPUT"),
        ("negative kc11", "/api/v1/materials/m1", with(json!({"kc11": -1800})), 422, "kc11", "E_INPUT"),
        ("kc11 in N/m²", "/api/v1/materials/m1", with(json!({"kc11": 1.8e9})), 422, "kc11", "E_INPUT"),
        ("mc of 1", "/api/v1/materials/m1", with(json!({"mc": 1})), 422, "mc", "E_INPUT"),
        ("negative mc", "/api/v1/materials/m1", with(json!({"mc": -0.1})), 422, "mc", "E_INPUT"),
        ("negative ratio", "/api/v1/materials/m1", with(json!({"radial_ratio": -1})), 422, "radial_ratio", "E_INPUT"),
        (
            "description too long",
            "/api/v1/materials/m1",
            with(json!({"description": "x".repeat(501)})),
            422,
            "description",
            "E_INPUT",
        ),
        (
            "line break in the description",
            "/api/v1/materials/m1",
            with(json!({"description": "a\nb"})),
            422,
            "description",
            "E_INPUT",
        ),
        ("missing mc", "/api/v1/materials/m1", json!({"kc11": 1800}), 400, "body", "E_JSON"),
        ("unknown field", "/api/v1/materials/m1", with(json!({"hardness": 200})), 400, "hardness", "E_JSON"),
        ("unknown ISO group", "/api/v1/materials/m1", with(json!({"iso_group": "Q"})), 400, "iso_group", "E_JSON"),
        ("string for a number", "/api/v1/materials/m1", with(json!({"kc11": "1800"})), 400, "kc11", "E_JSON"),
    ];
    let mut mismatches = Vec::new();
    for (what, path, body, status, field, code) in cases {
        let answer = problem(app.put_json(path, &body).await, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
    }
    assert_eq!(problem(app.get("/api/v1/materials/.x").await, 422).await["errors"][0]["path"], "name");
    assert_eq!(problem(app.delete("/api/v1/materials/a%20b").await, 422).await["errors"][0]["path"], "name");
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
    assert_eq!(json_with(app.get("/api/v1/materials").await, 200).await, before, "library unchanged");
}

/// A side-milling cut in a 4 kW spindle that the named material may exceed.
fn cut(material: Value) -> Value {
    let mut request = json!({
        "tool": {"kind": "flat", "radius": 5, "flutes": 4}, "spindle_rpm": 8000, "feed_per_tooth": 0.05,
        "flute_counts": [2, 4], "axial_depth": 5,
        "stock": {"polygon": [[0, 0], [100, 0], [100, 80], [0, 80]]},
        "path": [[-10, 77.5], [110, 77.5]]
    });
    request.as_object_mut().unwrap().extend(material.as_object().unwrap().clone());
    request
}

fn mean_torques(answer: &Value) -> Vec<f64> {
    answer["flutes"].as_array().unwrap().iter().map(|f| f["mean_torque_nm"].as_f64().unwrap()).collect()
}

async fn engagement_names_a_material(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    // The named material cuts exactly as its values given inline.
    let named = json_with(app.post_json("/api/v1/engagement", &cut(json!({"material": "42CrMo4"}))).await, 200).await;
    let inline = cut(json!({"kienzle": {"kc11": 2500, "mc": 0.26}}));
    let given = json_with(app.post_json("/api/v1/engagement", &inline).await, 200).await;
    assert_eq!(mean_torques(&named), mean_torques(&given));
    assert!(mean_torques(&named).iter().all(|t| *t > 0.0));
    assert_eq!(named["material"]["name"], "42CrMo4", "the answer says which values it used");
    assert_eq!(named["material"]["kc11"], 2500.0);
    assert!(given.get("material").is_none());
    // An aluminium needs less torque than the steel at the same cut.
    let aluminium =
        json_with(app.post_json("/api/v1/engagement", &cut(json!({"material": "AlMg4.5Mn"}))).await, 200).await;
    assert!(mean_torques(&aluminium)[0] < 0.5 * mean_torques(&named)[0]);
    // A replaced material gives its new values to the next request.
    json_with(app.put_json("/api/v1/materials/42CrMo4", &json!({"kc11": 5000, "mc": 0.26})).await, 200).await;
    let doubled = json_with(app.post_json("/api/v1/engagement", &cut(json!({"material": "42CrMo4"}))).await, 200).await;
    for (twice, once) in mean_torques(&doubled).iter().zip(mean_torques(&named)) {
        assert!((twice - 2.0 * once).abs() <= 1e-9 * twice, "{twice} vs 2 × {once}");
    }

    // (what, request, status, field, code)
    let cases = [
        ("unknown material", cut(json!({"material": "unobtainium"})), 404, "material", "E_NOT_FOUND"),
        ("badly named material", cut(json!({"material": "../etc"})), 404, "material", "E_NOT_FOUND"),
        (
            "both material and kienzle",
            cut(json!({"material": "C45", "kienzle": {"kc11": 2220, "mc": 0.14}})),
            422,
            "material",
            "E_INPUT",
        ),
        (
            "both, the material unknown",
            cut(json!({"material": "unobtainium", "kienzle": {"kc11": 2220, "mc": 0.14}})),
            422,
            "material",
            "E_INPUT",
        ),
        ("material as a number", cut(json!({"material": 45})), 400, "material", "E_JSON"),
        ("kienzle mc of 1", cut(json!({"kienzle": {"kc11": 2220, "mc": 1}})), 422, "kienzle.mc", "E_INPUT"),
        ("kienzle kc11 in N/m²", cut(json!({"kienzle": {"kc11": 2.2e9, "mc": 0.2}})), 422, "kienzle.kc11", "E_INPUT"),
    ];
    let mut mismatches = Vec::new();
    for (what, request, status, field, code) in cases {
        let answer = problem(app.post_json("/api/v1/engagement", &request).await, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
    }
    let mut without_depth = cut(json!({"material": "C45"}));
    without_depth.as_object_mut().unwrap().remove("axial_depth");
    let answer = problem(app.post_json("/api/v1/engagement", &without_depth).await, 422).await;
    assert_eq!(answer["errors"][0]["path"], "axial_depth");
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}

fn operation(request: Value) -> Value {
    let mut operation = json!({"operation": "engagement"});
    operation.as_object_mut().unwrap().extend(request.as_object().unwrap().clone());
    operation
}

async fn jobs_carry_their_materials(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    // One operation names a library material, one a material of the file (which goes before the
    // library's of the same name).
    let file = json!({
        "materials": [{"name": "C45", "kc11": 1000, "mc": 0.14, "description": "soft batch"}],
        "operations": [operation(cut(json!({"material": "X5CrNi18-10"}))), operation(cut(json!({"material": "C45"})))]
    });
    let submitted = json_with(app.post_json("/api/v1/jobs", &file).await, 202).await;
    let id = submitted["id"].as_i64().unwrap();
    // A later change in the library does not change the submitted job.
    json_with(app.put_json("/api/v1/materials/X5CrNi18-10", &json!({"kc11": 9000, "mc": 0.2})).await, 200).await;
    let job = poll_job(&app.client, &app.base, id, 60, finished).await;
    assert_eq!(job["status"], "done", "{job}");
    assert_eq!(job["results"][0]["result"]["material"]["kc11"], 2150.0, "resolved at submission");
    assert_eq!(
        job["results"][1]["result"]["material"],
        json!({"name": "C45", "kc11": 1000.0, "mc": 0.14,
        "description": "soft batch"})
    );
    let stainless =
        json_with(app.post_json("/api/v1/engagement", &cut(json!({"kienzle": {"kc11": 2150, "mc": 0.2}}))).await, 200)
            .await;
    assert_eq!(mean_torques(&job["results"][0]["result"]), mean_torques(&stainless));

    // Unknown names and bad values name the operation or the file's entry.
    let unknown = json!({"operations": [operation(cut(json!({"material": "unobtainium"})))]});
    let answer = problem(app.post_json("/api/v1/jobs", &unknown).await, 404).await;
    assert_eq!(answer["errors"][0]["path"], "operations[0].material");
    let bad = json!({"materials": [{"name": "soft", "kc11": 1000, "mc": 1.5}],
                     "operations": [operation(cut(json!({"material": "soft"})))]});
    let answer = problem(app.post_json("/api/v1/jobs", &bad).await, 422).await;
    assert_eq!(answer["errors"][0]["path"], "materials[0].mc");
    let nameless = json!({"materials": [{"kc11": 1000, "mc": 0.2}], "operations": [operation(cut(json!({})))]});
    let answer = problem(app.post_json("/api/v1/jobs", &nameless).await, 400).await;
    assert_eq!(answer["errors"][0]["path"], "materials[0].name");
    let twice = json!({"materials": [{"name": "a", "kc11": 1000, "mc": 0.2}, {"name": "a", "kc11": 900, "mc": 0.2}],
                       "operations": [operation(cut(json!({"material": "a"})))]});
    let answer = problem(app.post_json("/api/v1/jobs", &twice).await, 400).await;
    assert_eq!(answer["errors"][0]["path"], "materials[1].name");
}

async fn material_preconditions(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    super::tools::conditional_writes(
        &app,
        "/api/v1/materials/S235JR",
        &json!({"kc11": 1780, "mc": 0.17, "iso_group": "P"}),
        &json!({"kc11": 1800, "mc": 0.2}),
        &json!({"kc11": 1800, "mc": 0.2, "description": "measured"}),
    )
    .await;
    app.shutdown().await;
}

kerf_tests::on_both_stores!(
    seeded_materials_with_their_sources,
    material_crud_and_restart,
    bad_materials_are_refused_and_nothing_is_stored,
    engagement_names_a_material,
    jobs_carry_their_materials,
    material_preconditions,
);
