//! Probes for the external programs the tests need (LinuxCNC's `rs274`, Chromium and its driver,
//! PostgreSQL, openssl, schemathesis) where the tests look for them, and sets `kerf_has_<name>` for each one
//! found: a test that needs a missing one is `ignored` in cargo's summary, with the reason, instead
//! of passing without having run. Under `KERF_REQUIRE_EXTERNAL=1` every flag is set, so such a
//! test runs and fails. One warning line lists what will not run and how to install it.

// The build script uses only part of the lookups the tests share with it.
#[allow(dead_code)]
#[path = "src/external.rs"]
mod external;

fn main() {
    for variable in external::ENVIRONMENT {
        println!("cargo::rerun-if-env-changed={variable}");
    }
    let required = external::required();
    let mut missing = Vec::new();
    for program in external::EXTERNALS {
        println!("cargo::rustc-check-cfg=cfg(kerf_has_{})", program.name);
        let (found, watched) = external::probe(program);
        for path in watched.0 {
            println!("cargo::rerun-if-changed={}", path.display());
        }
        if found || required {
            println!("cargo::rustc-cfg=kerf_has_{}", program.name);
        } else {
            missing.push(program.reason());
        }
    }
    if !missing.is_empty() {
        println!(
            "cargo::warning=the tests that need these are ignored, not run: {} (KERF_REQUIRE_EXTERNAL=1 runs them, failing)",
            missing.join("; ")
        );
    }
}
