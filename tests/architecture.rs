//! The map of the code tells the truth about every file: each source file of `src/` is named
//! in `docs/ARCHITECTURE.md`'s file map, the map names no file that is gone, and the crate map
//! of `src/lib.rs` names every top-level module.

use std::path::{Path, PathBuf};

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_file_map_names_every_source_file_and_no_other() {
    let doc = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let map = doc.split("## File map").nth(1).expect("a `## File map` section");
    let map = map.split("\n## ").next().unwrap();
    let src = root().join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let named: Vec<String> = map
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .map(str::to_string)
        .collect();
    let mut missing = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
        if !named.contains(&rel) {
            missing.push(rel);
        }
    }
    assert!(missing.is_empty(), "files missing from docs/ARCHITECTURE.md's file map: {missing:?}");
    let gone: Vec<&String> = named.iter().filter(|n| !src.join(n).is_file()).collect();
    assert!(gone.is_empty(), "the file map names files that do not exist: {gone:?}");
}

#[test]
fn the_crate_map_names_every_top_level_module() {
    let lib = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
    let modules: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';'))
        .collect();
    assert!(modules.len() >= 7, "{modules:?}");
    for m in modules {
        assert!(
            lib.contains(&format!("| [`{m}`] |")),
            "src/lib.rs's crate map has no row for `{m}`"
        );
    }
}

/// The layers, lowest first: a module may import its own layer and those below, never one
/// above (`docs/ARCHITECTURE.md`, "Modules").
const LAYERS: [&str; 9] =
    ["math", "geometry", "robot", "cell", "cspace", "table", "coord", "ffi", "sim"];

/// A file's text without its unit tests (which may reach up to build their cases).
fn without_tests(text: &str) -> &str {
    text.split("#[cfg(test)]\nmod tests").next().unwrap()
}

/// The `crate::` paths a file imports with `use` (outside its tests), and the modules it names.
fn imports(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in without_tests(text).lines() {
        let line = line.trim_start();
        let Some(rest) =
            line.strip_prefix("use crate::").or_else(|| line.strip_prefix("pub use crate::"))
        else {
            continue;
        };
        out.push(rest.split([';', '{', ' ']).next().unwrap().trim_end_matches("::").to_string());
    }
    out
}

#[test]
fn no_import_runs_up_the_layers_and_the_cli_uses_no_ffi() {
    let src = root().join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut wrong = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
        let text = std::fs::read_to_string(f).unwrap();
        if rel.starts_with("bin/") {
            if without_tests(&text).contains("delta_collide::ffi") {
                wrong.push(format!("{rel} uses delta_collide::ffi"));
            }
            continue;
        }
        let Some(own) = LAYERS.iter().position(|l| rel.starts_with(&format!("{l}/"))) else {
            continue;
        };
        for path in imports(&text) {
            let top = path.split("::").next().unwrap();
            if LAYERS.iter().position(|l| *l == top).is_some_and(|layer| layer > own) {
                wrong.push(format!("{rel} imports crate::{path}"));
            }
        }
    }
    assert!(wrong.is_empty(), "imports against the layers: {wrong:#?}");
}

#[test]
fn no_two_files_import_each_other() {
    let src = root().join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    // Each file's module path (`cell::protective::kept`, a `mod.rs` its folder's).
    let module = |f: &PathBuf| {
        let rel = f.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
        rel.trim_end_matches(".rs").trim_end_matches("/mod").replace('/', "::")
    };
    let modules: Vec<String> = files.iter().map(module).collect();
    let deps: Vec<Vec<String>> = files
        .iter()
        .map(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            let mut found: Vec<String> = imports(&text)
                .into_iter()
                .filter_map(|p| {
                    let parts: Vec<&str> = p.split("::").collect();
                    (1..=parts.len())
                        .rev()
                        .map(|k| parts[..k].join("::"))
                        .find(|m| modules.contains(m))
                })
                .collect();
            found.dedup();
            found
        })
        .collect();
    let mut mutual = Vec::new();
    for (i, a) in modules.iter().enumerate() {
        for b in &deps[i] {
            let j = modules.iter().position(|m| m == b).unwrap();
            if i < j && deps[j].contains(a) {
                mutual.push(format!("{a} <-> {b}"));
            }
        }
    }
    assert!(mutual.is_empty(), "files that import each other: {mutual:?}");
}
