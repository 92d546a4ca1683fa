//! Lists every file of `web/` for `src/web.rs` to embed, so a new page file is served without a
//! hand-kept list.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn files(folder: &Path, found: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(folder)
        .unwrap_or_else(|error| panic!("reading {}: {error}", folder.display()))
        .map(|entry| entry.expect("a directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            files(&path, found);
        } else {
            found.push(path);
        }
    }
}

fn media_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).unwrap_or_default() {
        "html" => "text/html; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "json" => "application/json",
        "svg" => "image/svg+xml",
        "png" => "image/png",
        _ => "text/plain; charset=utf-8",
    }
}

fn main() {
    let web = Path::new(&std::env::var("CARGO_MANIFEST_DIR").expect("manifest dir")).join("../web");
    let web = web.canonicalize().expect("the web folder");
    println!("cargo:rerun-if-changed={}", web.display());
    let mut found = Vec::new();
    files(&web, &mut found);
    let mut list = String::from("&[\n");
    for path in &found {
        let relative = path.strip_prefix(&web).expect("under web/").to_string_lossy().replace('\\', "/");
        let served = if relative == "index.html" { "/".to_owned() } else { format!("/{relative}") };
        writeln!(
            list,
            "    Asset {{ path: {served:?}, media_type: {:?}, body: include_bytes!({:?}) }},",
            media_type(path),
            path.display().to_string()
        )
        .expect("writing to a string");
    }
    list.push(']');
    let out = Path::new(&std::env::var("OUT_DIR").expect("OUT_DIR")).join("web_assets.rs");
    std::fs::write(out, list).expect("writing the asset list");
}
