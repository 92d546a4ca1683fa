//! Where the tests find the external programs they check the service with. The build script
//! (`tests/build.rs`) includes this file too and sets the cfg flag `kerf_has_<name>` for each
//! [`EXTERNALS`] entry it finds, so a test that needs a missing one carries
//! `#[cfg_attr(not(kerf_has_<name>), ignore = "…")]` and cargo's summary counts it as ignored; the
//! tests look in the same places when they run it, so the two cannot disagree.
//!
//! Plain `std` only: the build script has no dependencies.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// A program (or set of programs) some tests need, and how to install it.
pub struct External {
    /// The cfg flag is `kerf_has_{name}`; `KERF_TEST_WITHOUT` takes this name.
    pub name: &'static str,
    /// What the tests need, for messages.
    pub what: &'static str,
    /// The commands that install it on Debian.
    pub install: &'static str,
    /// A Python module that `python3` on `PATH` must import (a PyPI tool of `tests/requirements.txt`
    /// used as a library), instead of a program of [`External::name`] on `PATH`.
    pub python_module: Option<&'static str>,
}

/// Every external program the tests use. A test's `ignore` reason is [`External::reason`]
/// written out (an attribute takes only a literal).
pub const EXTERNALS: &[External] = &[
    External { name: "rs274", what: "rs274", install: "apt-get install linuxcnc-uspace", python_module: None },
    External {
        name: "chromium",
        what: "chromium or its driver",
        install: "apt-get install chromium npm; npm ci --prefix tests/browser",
        python_module: None,
    },
    External {
        name: "gltf_validator",
        what: "node or the Khronos glTF validator",
        install: "apt-get install npm; npm ci --prefix tests/gltf",
        python_module: None,
    },
    External { name: "postgres", what: "PostgreSQL", install: "apt-get install postgresql", python_module: None },
    External { name: "openssl", what: "openssl", install: "apt-get install openssl", python_module: None },
    External { name: "python3", what: "python3", install: "apt-get install python3", python_module: None },
    External {
        name: "schemathesis",
        what: "schemathesis",
        install: "pip install -r tests/requirements.txt",
        python_module: None,
    },
    External {
        name: "openapi_python_client",
        what: "openapi-python-client",
        install: "pip install -r tests/requirements.txt",
        python_module: None,
    },
    External {
        name: "typescript_clients",
        what: "node or the TypeScript client generators",
        install: "apt-get install npm; npm ci --prefix clients/typescript",
        python_module: None,
    },
    External {
        name: "manifold3d",
        what: "manifold3d",
        install: "pip install -r tests/requirements.txt",
        python_module: Some("manifold3d"),
    },
    External {
        name: "nc_gcode_interpreter",
        what: "nc-gcode-interpreter",
        install: "pip install -r tests/requirements.txt",
        python_module: Some("nc_gcode_interpreter"),
    },
    External {
        name: "pygcode",
        what: "pygcode",
        install: "pip install -r tests/requirements.txt",
        python_module: Some("pygcode"),
    },
];

impl External {
    /// Why its tests are ignored without it: what is missing and how to install it.
    pub fn reason(&self) -> String {
        format!("{} not found: {}", self.what, self.install)
    }
}

/// The environment variables the lookups read: the build script probes again when one changes.
pub const ENVIRONMENT: [&str; 3] = ["PATH", "KERF_REQUIRE_EXTERNAL", "KERF_TEST_WITHOUT"];

/// Whether every external program is required (`KERF_REQUIRE_EXTERNAL=1`, set by `.ci/run`): the
/// build script then sets every flag, so a missing program fails its tests instead of leaving
/// them ignored.
pub fn required() -> bool {
    std::env::var("KERF_REQUIRE_EXTERNAL").is_ok_and(|v| v == "1")
}

/// Whether `name` is listed in `KERF_TEST_WITHOUT` (comma-separated [`External::name`]s): the
/// lookups then act as if it were not installed, to see what a machine without it reports.
fn withheld(name: &str) -> bool {
    std::env::var("KERF_TEST_WITHOUT").is_ok_and(|list| list.split(',').any(|item| item.trim() == name))
}

/// Records the paths a lookup depended on: the build script asks cargo to probe again when one
/// changes, so installing or removing a program flips its flag at the next build.
#[derive(Default)]
pub struct Watched(pub Vec<PathBuf>);

impl Watched {
    fn add(&mut self, path: PathBuf) {
        if !self.0.contains(&path) {
            self.0.push(path);
        }
    }
}

/// The folders of `PATH`.
fn path_folders() -> Vec<PathBuf> {
    std::env::var_os("PATH").map(|paths| std::env::split_paths(&paths).collect()).unwrap_or_default()
}

/// Watches the existing folders of `PATH` (not a relative one, which would make cargo scan the
/// package).
fn watch_path_folders(watched: &mut Watched) {
    path_folders().into_iter().filter(|dir| dir.is_absolute() && dir.is_dir()).for_each(|dir| watched.add(dir));
}

/// `program` in a folder of `PATH`. Watches the file found, else every existing folder of `PATH`
/// (installing a program there changes the folder).
fn on_path_watched(program: &str, watched: &mut Watched) -> Option<PathBuf> {
    let found = path_folders().into_iter().map(|dir| dir.join(program)).find(|path| path.is_file());
    match &found {
        Some(file) => watched.add(file.clone()),
        None => watch_path_folders(watched),
    }
    found
}

/// `program` on `PATH` (`rs274`, `node`, `chromium`, `schemathesis`), unless withheld by
/// `KERF_TEST_WITHOUT`.
pub fn on_path(program: &str) -> Option<PathBuf> {
    on_path_watched(program, &mut Watched::default()).filter(|_| !withheld(external_of(program)))
}

/// The [`External::name`] a program belongs to.
fn external_of(program: &str) -> &str {
    match program {
        "node" | "chromium" => "chromium",
        "initdb" | "pg_ctl" | "runuser" => "postgres",
        "openapi-python-client" => "openapi_python_client",
        other => other,
    }
}

/// The folder with the browser driver's `package.json` (`tests/browser`).
pub fn browser_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("browser")
}

/// Whether playwright-core is installed in `tests/browser/node_modules` (`npm ci --prefix
/// tests/browser`). Watches its `package.json`, else the folder `npm ci` fills.
fn browser_driver_watched(watched: &mut Watched) -> bool {
    let package = browser_folder().join("node_modules/playwright-core/package.json");
    let found = package.is_file();
    watched.add(if found { package } else { browser_folder() });
    found
}

/// Whether the browser driver (playwright-core) is installed (and not withheld).
pub fn browser_driver() -> bool {
    browser_driver_watched(&mut Watched::default()) && !withheld("chromium")
}

/// The folder with the glTF validator's `package.json` and its script (`tests/gltf`).
pub fn gltf_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("gltf")
}

/// The folder of the TypeScript clients' `package.json` (`clients/typescript`).
pub fn typescript_clients_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../clients/typescript")
}

/// The npm packages `clients/generate` and the TypeScript workflows run.
const TYPESCRIPT_CLIENT_PACKAGES: [&str; 5] =
    ["openapi-typescript", "openapi-fetch", "@hey-api/openapi-ts", "typescript", "tsx"];

/// Whether `npm ci --prefix clients/typescript` installed every package the TypeScript clients
/// need. Watches each `package.json` found, else the folder `npm ci` fills.
fn typescript_clients_watched(watched: &mut Watched) -> bool {
    let modules = typescript_clients_folder().join("node_modules");
    let mut found = true;
    for package in TYPESCRIPT_CLIENT_PACKAGES {
        let manifest = modules.join(package).join("package.json");
        if manifest.is_file() {
            watched.add(manifest);
        } else {
            found = false;
        }
    }
    if !found {
        watched.add(typescript_clients_folder());
    }
    found
}

/// Whether node and the TypeScript client generators are installed (and not withheld).
pub fn typescript_clients() -> bool {
    let mut watched = Watched::default();
    on_path_watched("node", &mut watched).is_some()
        && typescript_clients_watched(&mut watched)
        && !withheld("typescript_clients")
}

/// Whether this process runs as root (PostgreSQL then runs as the `postgres` user).
pub fn running_as_root() -> bool {
    std::fs::metadata("/proc/self").is_ok_and(|m| m.uid() == 0)
}

/// The uid and gid of the `postgres` system user, from `/etc/passwd`.
pub fn postgres_user() -> Option<(u32, u32)> {
    let passwd = std::fs::read_to_string("/etc/passwd").ok()?;
    let line = passwd.lines().find(|line| line.starts_with("postgres:"))?;
    let fields: Vec<&str> = line.split(':').collect();
    Some((fields.get(2)?.parse().ok()?, fields.get(3)?.parse().ok()?))
}

/// The folder with `initdb` and `pg_ctl`: on the PATH, else Debian's newest
/// `/usr/lib/postgresql/N/bin`.
fn postgres_bin_watched(watched: &mut Watched) -> Option<PathBuf> {
    let on_path = path_folders().into_iter().find(|dir| dir.join("initdb").is_file() && dir.join("pg_ctl").is_file());
    if let Some(dir) = on_path {
        watched.add(dir.join("initdb"));
        watched.add(dir.join("pg_ctl"));
        return Some(dir);
    }
    watch_path_folders(watched);
    let debian = Path::new("/usr/lib/postgresql");
    let mut versions: Vec<(u32, PathBuf)> = std::fs::read_dir(debian)
        .ok()?
        .filter_map(|entry| {
            let entry = entry.ok()?;
            let version = entry.file_name().to_str()?.parse().ok()?;
            let bin = entry.path().join("bin");
            (bin.join("initdb").is_file() && bin.join("pg_ctl").is_file()).then_some((version, bin))
        })
        .collect();
    versions.sort();
    let bin = versions.pop().map(|(_, bin)| bin);
    match &bin {
        Some(bin) => ["initdb", "pg_ctl"].into_iter().for_each(|program| watched.add(bin.join(program))),
        None if debian.is_dir() => watched.add(debian.to_path_buf()),
        None => {}
    }
    bin
}

/// [`postgres`], recording the paths it looked at.
fn postgres_watched(watched: &mut Watched) -> Result<(PathBuf, bool), &'static str> {
    let bin = postgres_bin_watched(watched).ok_or("PostgreSQL (initdb, pg_ctl) is not installed")?;
    let root = running_as_root();
    if root {
        watched.add(PathBuf::from("/etc/passwd"));
        postgres_user().ok_or("running as root and there is no postgres user to run PostgreSQL as")?;
        on_path_watched("runuser", watched).ok_or("running as root and runuser is missing")?;
    }
    Ok((bin, root))
}

/// PostgreSQL's programs as the tests run them: the folder with `initdb` and `pg_ctl`, and whether
/// they run as the `postgres` user through `runuser` (as root, which PostgreSQL refuses to run
/// as); or why they cannot run, also when withheld by `KERF_TEST_WITHOUT`.
pub fn postgres() -> Result<(PathBuf, bool), &'static str> {
    if withheld("postgres") {
        return Err("PostgreSQL is withheld by KERF_TEST_WITHOUT");
    }
    postgres_watched(&mut Watched::default())
}

/// Whether `external` is installed as its tests need it, and the paths that answer depends on.
pub fn probe(external: &External) -> (bool, Watched) {
    let mut watched = Watched::default();
    let found = match (external.name, external.python_module) {
        (_, Some(module)) => python_imports(module, &mut watched),
        ("chromium", None) => {
            // Evaluate every part so each one's paths are watched.
            let node = on_path_watched("node", &mut watched).is_some();
            let chromium = on_path_watched("chromium", &mut watched).is_some();
            node & chromium & browser_driver_watched(&mut watched)
        }
        ("gltf_validator", None) => {
            let node = on_path_watched("node", &mut watched).is_some();
            let package = gltf_folder().join("node_modules/gltf-validator/package.json");
            let found = package.is_file();
            watched.add(if found { package } else { gltf_folder() });
            node & found
        }
        ("postgres", None) => postgres_watched(&mut watched).is_ok(),
        ("openapi_python_client", None) => on_path_watched("openapi-python-client", &mut watched).is_some(),
        ("typescript_clients", None) => {
            let node = on_path_watched("node", &mut watched).is_some();
            node & typescript_clients_watched(&mut watched)
        }
        (program, None) => on_path_watched(program, &mut watched).is_some(),
    };
    (found && !withheld(external.name), watched)
}

/// Whether `python3` on `PATH` imports `module`. Watches the interpreter found (a venv's
/// `python3` is replaced when its packages are reinstalled), else the folders of `PATH`.
fn python_imports(module: &str, watched: &mut Watched) -> bool {
    let Some(python) = on_path_watched("python3", watched) else {
        return false;
    };
    if let Some(site) = python.parent().and_then(Path::parent) {
        watched.add(site.join("lib"));
    }
    std::process::Command::new(&python)
        .args(["-c", &format!("import {module}")])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|status| status.success())
}
