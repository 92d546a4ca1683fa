//! The deployment files in `deploy/` mirror the tested topology and say only what the binary
//! accepts: every command line in the Dockerfile, compose.yaml and kubernetes.yaml, with the
//! `KERF_*` variables set beside it turned into the flags they stand for, parses with the real
//! command-line parser (`Cli::try_parse_from`), and every `KERF_*` variable is one a flag reads.
//! Each kerf container runs the image of this release (an explicit tag and pull policy) as a
//! non-root user on a read-only root file system, without capabilities or privilege escalation,
//! within resource limits; on Kubernetes a PodDisruptionBudget covers each Deployment, liveness
//! is `/healthz` and readiness `/readyz`. (What is checked is these files' keys, read as YAML: no
//! Kubernetes schema validator or cluster runs here.) The toolchain the workspace declares and the
//! Dockerfile builds with is at least what every locked package needs (`cargo metadata`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::{CommandFactory, Parser};
use kerf_server::cli::{Cli, Command};
use yaml_rust2::{Yaml, YamlLoader};

fn deploy(name: &str) -> String {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The workspace's version: the image tag the deployment files run.
fn release() -> String {
    let manifest: toml::Table = toml::from_str(
        &std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../Cargo.toml")).expect("Cargo.toml"),
    )
    .expect("Cargo.toml is TOML");
    manifest["workspace"]["package"]["version"].as_str().expect("workspace version").to_owned()
}

/// The flag that reads environment variable `variable` in `subcommand`'s options.
fn flag_for(subcommand: &str, variable: &str) -> (String, bool) {
    let command = Cli::command();
    let options = command.find_subcommand(subcommand).unwrap_or_else(|| panic!("no subcommand {subcommand}"));
    let argument = options
        .get_arguments()
        .find(|argument| argument.get_env().is_some_and(|env| env == variable))
        .unwrap_or_else(|| panic!("`kerf {subcommand}` reads no variable {variable}"));
    let long = argument.get_long().expect("environment options have a long flag");
    (format!("--{long}"), !argument.get_action().takes_values())
}

/// Parses `kerf ARGUMENTS` with `environment` as the flags it stands for; returns the command.
fn parses(label: &str, arguments: &[String], environment: &BTreeMap<String, String>) -> Command {
    let subcommand = arguments.first().map_or("serve", String::as_str);
    let mut line = vec!["kerf".to_owned()];
    line.extend(arguments.iter().cloned());
    for (variable, value) in environment {
        if !variable.starts_with("KERF_") {
            continue;
        }
        let (flag, switch) = flag_for(subcommand, variable);
        assert!(!line.contains(&flag), "{label}: {variable} and {flag} both given");
        line.push(flag);
        if !switch {
            line.push(value.clone());
        }
    }
    match Cli::try_parse_from(&line) {
        Ok(cli) => cli.command.unwrap_or(Command::Serve(cli.serve)),
        Err(error) => panic!("{label}: `{}` is refused:\n{error}", line.join(" ")),
    }
}

fn strings(yaml: &Yaml) -> Vec<String> {
    yaml.as_vec()
        .map(|items| items.iter().map(|item| item.as_str().expect("a string").to_owned()).collect())
        .unwrap_or_default()
}

fn text(yaml: &Yaml) -> String {
    match yaml {
        Yaml::String(s) | Yaml::Real(s) => s.clone(),
        Yaml::Integer(n) => n.to_string(),
        Yaml::Boolean(b) => b.to_string(),
        other => panic!("not a scalar: {other:?}"),
    }
}

/// A compose service with its `<<` merge key applied.
fn merged(service: &Yaml) -> yaml_rust2::yaml::Hash {
    let mut hash = service["<<"].as_hash().cloned().unwrap_or_default();
    for (key, value) in service.as_hash().expect("a service is a mapping") {
        if key.as_str() != Some("<<") {
            hash.insert(key.clone(), value.clone());
        }
    }
    hash
}

#[test]
fn dockerfile_runs_the_binary_with_flags_it_accepts() {
    let dockerfile = deploy("Dockerfile");
    let instruction = |name: &str| -> Vec<String> {
        let line = dockerfile.lines().find(|l| l.starts_with(&format!("{name} "))).unwrap_or_else(|| panic!("{name}"));
        serde_json::from_str(&line[name.len() + 1..]).unwrap_or_else(|e| panic!("{name} in exec form: {e}"))
    };
    assert_eq!(dockerfile.matches("\nFROM ").count() + usize::from(dockerfile.starts_with("FROM ")), 2, "two stages");
    assert_eq!(instruction("ENTRYPOINT"), [Cli::command().get_name()], "the image runs the binary");
    assert!(dockerfile.contains("--bin kerf") && dockerfile.contains("target/release/kerf"), "builds and copies it");
    let user = dockerfile.lines().rev().find_map(|l| l.strip_prefix("USER ")).expect("the image names its user");
    let ids: Vec<u32> = user.split(':').map(|id| id.trim().parse().expect("a numeric user")).collect();
    assert!(
        ids.iter().all(|&id| id != 0),
        "the image runs as a numeric non-root user (runAsNonRoot checks it): {user}"
    );
    let command = parses("Dockerfile CMD", &instruction("CMD"), &BTreeMap::new());
    assert!(matches!(command, Command::Serve(_)));
}

#[test]
fn compose_mirrors_the_tested_topology() {
    let documents = YamlLoader::load_from_str(&deploy("compose.yaml")).expect("compose.yaml is YAML");
    let services = documents[0]["services"].as_hash().expect("services");
    let (mut api_nodes, mut workers) = (0, 0);
    for (name, service) in services {
        let name = name.as_str().unwrap();
        let service = merged(service);
        let image = service.get(&Yaml::from_str("image")).map(text).unwrap_or_default();
        if !image.starts_with("kerf") {
            assert!(image.starts_with("postgres"), "{name}: only kerf and PostgreSQL ({image})");
            continue;
        }
        assert_eq!(image, format!("kerf:{}", release()), "{name}: the image of this release");
        let key = |key: &str| service.get(&Yaml::from_str(key)).cloned().unwrap_or(Yaml::BadValue);
        assert_eq!(text(&key("pull_policy")), "build", "{name}: built here, never pulled");
        assert_eq!(key("read_only").as_bool(), Some(true), "{name}: read-only root file system");
        assert_eq!(strings(&key("cap_drop")), ["ALL"], "{name}: no capabilities");
        assert!(strings(&key("security_opt")).contains(&"no-new-privileges:true".to_owned()), "{name}");
        let user = text(&key("user"));
        assert!(user.split(':').all(|id| id.parse::<u32>().is_ok_and(|id| id != 0)), "{name}: non-root, not {user}");
        let limits = &key("deploy")["resources"]["limits"];
        assert!(!limits["cpus"].is_badvalue() && !limits["memory"].is_badvalue(), "{name}: CPU and memory limits");
        let arguments = strings(service.get(&Yaml::from_str("command")).expect("a command"));
        let environment: BTreeMap<String, String> = service
            .get(&Yaml::from_str("environment"))
            .and_then(Yaml::as_hash)
            .map(|env| env.iter().map(|(k, v)| (text(k), text(v))).collect())
            .unwrap_or_default();
        assert!(environment["KERF_DATABASE"].starts_with("postgres://"), "{name}: on PostgreSQL");
        match parses(name, &arguments, &environment) {
            Command::Serve(serve) => {
                assert_eq!(serve.job_workers, Some(0), "{name}: API nodes leave the jobs to the workers");
                api_nodes += 1;
            }
            Command::Worker(worker) => {
                assert!(worker.metrics_bind.is_some(), "{name}: workers expose their metrics");
                workers += 1;
            }
            Command::Run(_) | Command::Migrate(_) | Command::Jobs(_) => {
                panic!("{name}: kerf {arguments:?} is not a service")
            }
        }
    }
    assert_eq!((api_nodes, workers), (2, 1), "two API nodes and a (scaled) worker service");
}

#[test]
fn kubernetes_example_mirrors_the_tested_topology() {
    let documents = YamlLoader::load_from_str(&deploy("kubernetes.yaml")).expect("kubernetes.yaml is YAML");
    let mut kinds = Vec::new();
    let (mut api, mut worker) = (false, false);
    let budgets: Vec<&Yaml> = documents.iter().filter(|d| text(&d["kind"]) == "PodDisruptionBudget").collect();
    for document in &documents {
        let kind = text(&document["kind"]);
        kinds.push(kind.clone());
        if kind != "Deployment" {
            continue;
        }
        let name = text(&document["metadata"]["name"]);
        let labels = &document["spec"]["template"]["metadata"]["labels"];
        assert!(
            budgets.iter().any(|budget| {
                let selector = budget["spec"]["selector"]["matchLabels"].as_hash().expect("a budget selects by labels");
                selector.iter().all(|(label, value)| labels[text(label).as_str()] == *value)
            }),
            "{name}: a PodDisruptionBudget selects its pods"
        );
        let pod = &document["spec"]["template"]["spec"];
        assert_eq!(pod["securityContext"]["runAsNonRoot"].as_bool(), Some(true), "{name}: runAsNonRoot");
        for container in pod["containers"].as_vec().expect("containers") {
            assert_eq!(text(&container["image"]), format!("kerf:{}", release()), "{name}: the image of this release");
            let policy = text(&container["imagePullPolicy"]);
            assert!(["IfNotPresent", "Always", "Never"].contains(&policy.as_str()), "{name}: pull policy {policy}");
            for (bound, resource) in
                [("requests", "cpu"), ("requests", "memory"), ("limits", "cpu"), ("limits", "memory")]
            {
                let value = &container["resources"][bound][resource];
                assert!(!value.is_badvalue(), "{name}: resources.{bound}.{resource}");
            }
            let security = &container["securityContext"];
            assert_eq!(security["allowPrivilegeEscalation"].as_bool(), Some(false), "{name}: privilege escalation");
            assert_eq!(security["readOnlyRootFilesystem"].as_bool(), Some(true), "{name}: read-only root");
            assert_eq!(strings(&security["capabilities"]["drop"]), ["ALL"], "{name}: capabilities dropped");
            assert_eq!(text(&container["livenessProbe"]["httpGet"]["path"]), "/healthz", "{name}: liveness");
            assert_eq!(text(&container["readinessProbe"]["httpGet"]["path"]), "/readyz", "{name}: readiness");
            let mut arguments = strings(&container["command"]);
            if arguments.first().is_some_and(|first| first == "kerf") {
                arguments.remove(0);
            }
            arguments.extend(strings(&container["args"]));
            let environment: BTreeMap<String, String> = container["env"]
                .as_vec()
                .map(|env| {
                    env.iter()
                        .map(|item| {
                            // A value from a Secret stands for the URL the Secret holds.
                            let value =
                                item["value"].as_str().map_or("postgres://from-the-secret/kerf", |v| v).to_owned();
                            (text(&item["name"]), value)
                        })
                        .collect()
                })
                .unwrap_or_default();
            match parses(&name, &arguments, &environment) {
                Command::Serve(serve) => {
                    assert_eq!(serve.job_workers, Some(0), "{name}: the API runs no jobs");
                    api = true;
                }
                Command::Worker(options) => {
                    assert!(options.metrics_bind.is_some(), "{name}: workers expose their metrics");
                    worker = true;
                }
                Command::Run(_) | Command::Migrate(_) | Command::Jobs(_) => {
                    panic!("{name}: kerf {arguments:?} is not a service")
                }
            }
        }
    }
    assert!(api && worker, "an API Deployment and a worker Deployment");
    assert!(kinds.iter().any(|k| k == "Service"), "a Service in front of the API: {kinds:?}");
}

#[test]
fn a_wrong_flag_would_be_caught() {
    let result = std::panic::catch_unwind(|| {
        parses("bad", &["worker".to_owned(), "--metrics-port".to_owned(), "9090".to_owned()], &BTreeMap::new())
    });
    assert!(result.is_err(), "an unknown flag fails the check");
    let result = std::panic::catch_unwind(|| {
        let environment = BTreeMap::from([("KERF_NO_SUCH".to_owned(), "1".to_owned())]);
        parses("bad", &["serve".to_owned()], &environment)
    });
    assert!(result.is_err(), "an unknown variable fails the check");
}

/// A `major.minor[.patch]` version as three numbers (a missing patch is 0), for comparing.
fn version(text: &str) -> [u64; 3] {
    let mut numbers = [0; 3];
    for (number, part) in numbers.iter_mut().zip(text.split('.')) {
        *number = part.parse().unwrap_or_else(|e| panic!("version {text}: {e}"));
    }
    numbers
}

/// The highest `rust-version` among the packages the lock file resolves, with the package
/// declaring it, as `cargo metadata` reads them from the locked sources.
fn locked_minimum() -> ([u64; 3], String) {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let output = std::process::Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--locked"])
        .current_dir(&root)
        .output()
        .expect("cargo metadata runs");
    assert!(output.status.success(), "cargo metadata: {}", String::from_utf8_lossy(&output.stderr));
    let metadata: serde_json::Value = serde_json::from_slice(&output.stdout).expect("cargo metadata answers JSON");
    let members = metadata["workspace_members"].as_array().expect("workspace_members");
    metadata["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .filter(|package| !members.contains(&package["id"]))
        .filter_map(|package| {
            let needs = package["rust_version"].as_str()?;
            let (name, release) = (package["name"].as_str()?, package["version"].as_str()?);
            Some((version(needs), format!("{name} {release} needs {needs}")))
        })
        .max()
        .expect("some locked package declares a rust-version")
}

#[test]
fn the_declared_toolchain_is_the_one_the_lock_needs() {
    let manifest: toml::Table = toml::from_str(
        &std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../Cargo.toml"))
            .expect("the workspace manifest"),
    )
    .expect("Cargo.toml is TOML");
    let declared = manifest["workspace"]["package"]["rust-version"].as_str().expect("workspace rust-version");
    let (needed, by) = locked_minimum();
    assert!(version(declared) >= needed, "rust-version = {declared}, but {by}");
    let dockerfile = deploy("Dockerfile");
    let image = dockerfile
        .lines()
        .find_map(|line| line.strip_prefix("FROM rust:"))
        .expect("the build stage starts FROM rust:VERSION");
    let image_version = image.split(['-', ' ']).next().unwrap_or_default();
    assert_eq!(
        version(image_version),
        version(declared),
        "the Dockerfile builds with rust:{image_version}, the workspace declares rust-version = {declared}"
    );
}
