//! Test support, shared by the solver's tests, the loopback tests, the benches and the cost
//! model: the reference cases of the specs (`solver/tests/fixtures/`, one file per capability), the few
//! helpers every test reads them with, and the requests the tests build, one builder per request
//! shape (a module per capability), so no test file keeps its own copy.
//!
//! The JSON builders return the body as the API takes it; a solver test parses the same body
//! into the request type (`serde_json::from_value`), so both kinds of test solve the same request.

use serde_json::Value;

pub mod contour;
pub mod deburr;
pub mod engagement;
pub mod predict;
pub mod split;

/// `body` with the top-level fields of `extra` set (added or replaced).
///
/// # Panics
/// When `extra` is not an object.
#[must_use]
pub fn with(mut body: Value, extra: Value) -> Value {
    for (key, value) in extra.as_object().expect("extra fields are an object") {
        body[key] = value.clone();
    }
    body
}

/// `request` as operation `name` of a job file (`{"operation": name, ...request}`).
#[must_use]
pub fn operation(name: &str, request: Value) -> Value {
    with(serde_json::json!({"operation": name}), request)
}

/// The fixture `name` (`deburr`, `segment`, `contour`, `engagement`, `predict`).
///
/// # Panics
/// When the file is missing or not JSON: a broken fixture is a broken test.
pub fn fixture(name: &str) -> Value {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../solver/tests/fixtures/{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|error| panic!("{}: {error}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|error| panic!("{}: {error}", path.display()))
}

/// The case of fixture `name` whose `id` is `id`, else the one whose `id` starts with it, from
/// its `cases`, `reference_cases` or `unit_checks`.
///
/// # Panics
/// When no case matches.
pub fn case(name: &str, id: &str) -> Value {
    let all = fixture(name);
    let cases: Vec<&Value> =
        ["cases", "reference_cases", "unit_checks"].iter().filter_map(|list| all[*list].as_array()).flatten().collect();
    let id_of = |case: &Value| case["id"].as_str().unwrap_or_default().to_owned();
    cases
        .iter()
        .find(|case| id_of(case) == id)
        .or_else(|| cases.iter().find(|case| id_of(case).starts_with(id)))
        .map(|case| (*case).clone())
        .unwrap_or_else(|| panic!("{name}: no case {id}"))
}

/// A JSON number.
///
/// # Panics
/// When it is not a number.
pub fn number(value: &Value) -> f64 {
    value.as_f64().unwrap_or_else(|| panic!("not a number: {value}"))
}

/// A JSON `[x, y, z]`.
pub fn triple(value: &Value) -> [f64; 3] {
    [number(&value[0]), number(&value[1]), number(&value[2])]
}

/// Asserts `got` is within `tolerance` of `expected`, naming `what`.
///
/// # Panics
/// When it is not.
pub fn close(what: &str, got: f64, expected: f64, tolerance: f64) {
    // 1e-12 absorbs the last bit of a value printed to the fixture's precision.
    assert!((got - expected).abs() <= tolerance + 1e-12, "{what}: got {got}, expected {expected} ± {tolerance}");
}
