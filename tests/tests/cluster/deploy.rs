//! The deployment files in `deploy/` mirror the tested topology and say only what the binary
//! accepts: every command line in the Dockerfile, compose.yaml and kubernetes.yaml, with the
//! `KERF_*` variables set beside it turned into the flags they stand for, parses with the real
//! command-line parser (`Cli::try_parse_from`), and every `KERF_*` variable is one a flag reads.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::{CommandFactory, Parser};
use kerf_server::cli::{Cli, Command};
use yaml_rust2::{Yaml, YamlLoader};

fn deploy(name: &str) -> String {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
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
    for document in &documents {
        let kind = text(&document["kind"]);
        kinds.push(kind.clone());
        if kind != "Deployment" {
            continue;
        }
        let name = text(&document["metadata"]["name"]);
        for container in document["spec"]["template"]["spec"]["containers"].as_vec().expect("containers") {
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
            for probe in ["readinessProbe", "livenessProbe"] {
                let path = text(&container[probe]["httpGet"]["path"]);
                assert!(["/readyz", "/healthz"].contains(&path.as_str()), "{name}: {probe} on {path}");
            }
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
