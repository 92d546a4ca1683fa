//! Test support, shared by the solver's case tests and the loopback tests: the reference cases of
//! `../shared/cases` (copied to `solver/tests/fixtures/`) and the few helpers every test reads
//! them with, so no test file keeps its own copy.

use serde_json::Value;

/// The fixture `name` (`deburr`, `chord`, `corners`, `engagement`, `error-prediction`).
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
