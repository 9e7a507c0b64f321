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
