//! The module layout docs/architecture.md promises, checked on the sources: inside each crate the
//! top-level modules depend on each other without a circle, and the job layer never reaches into
//! the HTTP layer. A `crate::name` path anywhere in a module's files (outside its `#[cfg(test)]`
//! part) counts as a dependency on `name`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Where one module names another: the file and line, for the failure message.
type Uses = BTreeMap<String, BTreeMap<String, String>>;

/// The top-level modules of the crate whose sources are in `src` and, for each, the other
/// top-level modules its files name, with the first place each is named.
fn dependencies(src: &Path) -> Uses {
    let mut files = Vec::new();
    collect_rust_files(src, &mut files);
    let top_of = |file: &Path| -> Option<String> {
        let first = file.strip_prefix(src).ok()?.components().next()?.as_os_str().to_str()?.to_owned();
        let name = first.strip_suffix(".rs").unwrap_or(&first).to_owned();
        (name != "lib" && name != "main").then_some(name)
    };
    let modules: BTreeSet<String> = files.iter().filter_map(|file| top_of(file)).collect();
    let mut uses: Uses = modules.iter().map(|module| (module.clone(), BTreeMap::new())).collect();
    for file in &files {
        let Some(from) = top_of(file) else { continue };
        let text = std::fs::read_to_string(file).unwrap_or_else(|error| panic!("{}: {error}", file.display()));
        // Unit tests may reach anywhere; the layout is about the code that ships.
        let shipped = text.split("#[cfg(test)]").next().unwrap_or_default();
        for (line_number, line) in shipped.lines().enumerate() {
            for to in named_modules(line) {
                if to != from && modules.contains(&to) {
                    let place = format!("{}:{}", file.strip_prefix(src).unwrap_or(file).display(), line_number + 1);
                    uses.get_mut(&from).map(|named| named.entry(to).or_insert(place));
                }
            }
        }
    }
    uses
}

/// The module names a line reaches through `crate::`: `crate::a::b` names `a`, and a group
/// `use crate::{a, b::c}` names `a` and `b` (a group spread over several lines is read by its
/// first line only, which is how rustfmt starts it; the later lines are caught by their own
/// `crate::` or by the module's other uses).
fn named_modules(line: &str) -> Vec<String> {
    let mut names = Vec::new();
    for (index, _) in line.match_indices("crate::") {
        if index > 0 && line[..index].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &line[index + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut item_start = true;
            for (position, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item_start = true,
                    _ if item_start && (c.is_alphanumeric() || c == '_') => {
                        let name: String =
                            group[position..].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                        names.push(name);
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                names.push(name);
            }
        }
    }
    names
}

fn collect_rust_files(folder: &Path, files: &mut Vec<PathBuf>) {
    let entries = std::fs::read_dir(folder).unwrap_or_else(|error| panic!("{}: {error}", folder.display()));
    for entry in entries {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            collect_rust_files(&path, files);
        } else if path.extension().is_some_and(|extension| extension == "rs") {
            files.push(path);
        }
    }
    files.sort();
}

/// Every circle of `uses` (Tarjan's strongly connected components of more than one module),
/// each with the places that close it.
fn circles(uses: &Uses) -> Vec<String> {
    struct Walk<'a> {
        uses: &'a Uses,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        found: Vec<Vec<&'a str>>,
    }
    impl<'a> Walk<'a> {
        fn visit(&mut self, module: &'a str) {
            let next = self.index.len();
            self.index.insert(module, next);
            self.low.insert(module, next);
            self.stack.push(module);
            for to in self.uses[module].keys() {
                if !self.index.contains_key(to.as_str()) {
                    self.visit(to);
                    let low = self.low[module].min(self.low[to.as_str()]);
                    self.low.insert(module, low);
                } else if self.stack.contains(&to.as_str()) {
                    let low = self.low[module].min(self.index[to.as_str()]);
                    self.low.insert(module, low);
                }
            }
            if self.low[module] == self.index[module] {
                let at = self.stack.iter().position(|m| *m == module).expect("on the stack");
                let component = self.stack.split_off(at);
                if component.len() > 1 {
                    self.found.push(component);
                }
            }
        }
    }
    let mut walk = Walk { uses, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), found: Vec::new() };
    for module in uses.keys() {
        if !walk.index.contains_key(module.as_str()) {
            walk.visit(module);
        }
    }
    walk.found
        .iter()
        .map(|component| {
            let edges: Vec<String> = component
                .iter()
                .flat_map(|from| {
                    uses[*from]
                        .iter()
                        .filter(|(to, _)| component.contains(&to.as_str()))
                        .map(move |(to, place)| format!("  {from} → {to} ({place})"))
                })
                .collect();
            format!("{{{}}}:\n{}", component.join(", "), edges.join("\n"))
        })
        .collect()
}

fn crate_src(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(name).join("src")
}

#[test]
fn the_solver_has_no_import_circle() {
    let found = circles(&dependencies(&crate_src("solver")));
    assert!(found.is_empty(), "import circles in solver/src:\n{}", found.join("\n"));
}

#[test]
fn the_server_has_no_import_circle() {
    let found = circles(&dependencies(&crate_src("server")));
    assert!(found.is_empty(), "import circles in server/src:\n{}", found.join("\n"));
}

#[test]
fn the_job_layer_never_imports_the_http_layer() {
    let uses = dependencies(&crate_src("server"));
    assert!(!uses["jobs"].contains_key("http"), "server/src/jobs imports crate::http at {}", uses["jobs"]["http"]);
}

#[test]
fn a_circle_is_found_and_named() {
    // The check itself: a made-up crate with a → b → c → a and d → a.
    let edge = |to: &str| (to.to_owned(), format!("{to}.rs:1"));
    let uses: Uses = [
        ("a".to_owned(), BTreeMap::from([edge("b")])),
        ("b".to_owned(), BTreeMap::from([edge("c")])),
        ("c".to_owned(), BTreeMap::from([edge("a")])),
        ("d".to_owned(), BTreeMap::from([edge("a")])),
    ]
    .into();
    let found = circles(&uses);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].starts_with('{') && found[0].contains("c → a (a.rs:1)") && !found[0].contains('d'),
        "{}",
        found[0]
    );
    assert_eq!(named_modules("use crate::{db::Db, error::{AppError, Problem}, store};"), ["db", "error", "store"]);
    assert_eq!(named_modules("let x = kerf_crate::a; crate::machine::rule::f(crate::tool::Tool)"), ["machine", "tool"]);
}
