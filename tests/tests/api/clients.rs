//! Clients generated from the served OpenAPI document by tools no one here wrote
//! (openapi-python-client; openapi-typescript with openapi-fetch; @hey-api/openapi-ts) run the
//! shop workflow against the real service: `clients/generate` fails on any generator warning
//! (how these tools say they dropped an operation, a response or a schema), every operation of
//! the document must be in the generated code, and each workflow in `clients/` goes through the
//! generated client only (tools, machine, deburr JSON and G-code, segment, contour, engagement,
//! predict, a job file submitted and followed, its program and outputs.zip).

use std::path::{Path, PathBuf};

use kerf_tests::{TestApp, external_program, json_with, missing_message};

fn clients_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../clients")
}

/// Runs `program` with `arguments` in `folder`, with `path_first` first on `PATH`; fails the test
/// with its output unless it succeeds. Returns its standard output.
async fn run(program: &Path, arguments: &[&str], folder: &Path, path_first: &Path) -> String {
    let path = std::env::var_os("PATH").unwrap_or_default();
    let mut folders = vec![path_first.to_path_buf()];
    folders.extend(std::env::split_paths(&path));
    let output = tokio::process::Command::new(program)
        .args(arguments)
        .current_dir(folder)
        .env("PATH", std::env::join_paths(folders).expect("PATH joins"))
        .env("NO_COLOR", "1")
        .output()
        .await
        .unwrap_or_else(|error| panic!("{} runs: {error}", program.display()));
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "{} {arguments:?} failed:\n{stdout}\n{}",
        program.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    stdout
}

/// The served document's operationIds.
async fn operation_ids(app: &TestApp) -> Vec<String> {
    let document = json_with(app.get("/api/v1/openapi.json").await, 200).await;
    let mut ids = Vec::new();
    for item in document["paths"].as_object().unwrap().values() {
        for operation in item.as_object().unwrap().values() {
            ids.push(operation["operationId"].as_str().unwrap().to_owned());
        }
    }
    assert!(ids.len() > 30, "{ids:?}");
    ids
}

/// `get_job_program` as `getJobProgram`.
fn camel_case(id: &str) -> String {
    let mut words = id.split('_');
    let first = words.next().unwrap_or_default().to_owned();
    words.fold(first, |mut name, word| {
        let mut letters = word.chars();
        if let Some(letter) = letters.next() {
            name.extend(letter.to_uppercase());
            name.push_str(letters.as_str());
        }
        name
    })
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_openapi_python_client),
    ignore = "openapi-python-client not found: pip install -r tests/requirements.txt"
)]
async fn the_generated_python_client_runs_the_shop_workflow() {
    let Some(generator) = external_program("openapi-python-client", "the generated Python client") else {
        return;
    };
    let venv = generator.parent().expect("a folder").to_path_buf();
    let app = TestApp::spawn().await;
    let clients = clients_folder();
    let document = app.url("/api/v1/openapi.json");
    run(&clients.join("generate"), &[&document, "python"], &clients, &venv).await;
    let api = clients.join("python/generated/kerf_client/api");
    for id in operation_ids(&app).await {
        let generated = std::fs::read_dir(&api)
            .unwrap()
            .any(|tag| tag.is_ok_and(|tag| tag.path().join(format!("{id}.py")).is_file()));
        assert!(generated, "operation {id} is missing from the Python client");
    }
    let output = run(&venv.join("python3"), &["python/workflow.py", &app.base], &clients, &venv).await;
    assert!(output.contains("python workflow:"), "{output}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_typescript_clients),
    ignore = "node or the TypeScript client generators not found: apt-get install npm; npm ci --prefix clients/typescript"
)]
async fn the_generated_typescript_clients_run_the_shop_workflow() {
    let node = external_program("node", "the generated TypeScript clients");
    assert!(
        kerf_tests::external::typescript_clients(),
        "{}",
        missing_message("the TypeScript client generators", "the generated TypeScript clients")
    );
    let Some(node) = node else { return };
    let node_folder = node.parent().expect("a folder").to_path_buf();
    let app = TestApp::spawn().await;
    let clients = clients_folder();
    let typescript = clients.join("typescript");
    let document = app.url("/api/v1/openapi.json");
    run(&clients.join("generate"), &[&document, "typescript"], &clients, &node_folder).await;
    let sdk = std::fs::read_to_string(typescript.join("generated/hey/sdk.gen.ts")).unwrap();
    let schema = std::fs::read_to_string(typescript.join("generated/schema.d.ts")).unwrap();
    for id in operation_ids(&app).await {
        assert!(
            sdk.contains(&format!("export const {} ", camel_case(&id))),
            "operation {id} is missing from hey-api's SDK"
        );
        assert!(schema.contains(&format!("    {id}: {{")), "operation {id} is missing from openapi-typescript's types");
    }
    let bin = typescript.join("node_modules/.bin");
    // The workflows are checked against the generated types first: a wrong type is a failure.
    run(&bin.join("tsc"), &["-p", "."], &typescript, &node_folder).await;
    for (workflow, says) in [("workflow-fetch.ts", "openapi-fetch workflow:"), ("workflow-hey.ts", "hey-api workflow:")]
    {
        let output = run(&bin.join("tsx"), &[workflow, &app.base], &typescript, &node_folder).await;
        assert!(output.contains(says), "{output}");
    }
}
