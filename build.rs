//! Generates the C header `include/delta_collide.h` from `src/ffi/` with cbindgen.
//!
//! The header is always generated into `OUT_DIR`; it is copied to `include/` when it
//! differs, except when `CI` or `DELTA_COLLIDE_CHECK_HEADER` is set: then `include/` is left
//! alone and `tests/header.rs` fails if the committed header is stale.

use std::path::PathBuf;

fn main() {
    // cbindgen reads src/ffi/mod.rs and the modules it declares.
    println!("cargo:rerun-if-changed=src/ffi");
    println!("cargo:rerun-if-changed=cbindgen.toml");
    println!("cargo:rerun-if-env-changed=CI");
    println!("cargo:rerun-if-env-changed=DELTA_COLLIDE_CHECK_HEADER");
    let root =
        PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let config =
        cbindgen::Config::from_file(root.join("cbindgen.toml")).expect("cbindgen.toml is valid");
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/ffi/types.rs"))
        .with_src(root.join("src/ffi/mod.rs"))
        .generate()
        .expect("cbindgen can parse src/ffi");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
        .join("delta_collide.h");
    bindings.write_to_file(&out);
    let check_only = std::env::var_os("CI").is_some()
        || std::env::var_os("DELTA_COLLIDE_CHECK_HEADER").is_some();
    let committed = root.join("include/delta_collide.h");
    // cbindgen closes its C++ guards with `// comments`, which strict C89 rejects: use /* */.
    let fresh = std::fs::read_to_string(&out)
        .expect("header was just written")
        .replace("}  // extern \"C\"", "}  /* extern \"C\" */")
        .replace("#endif  // __cplusplus", "#endif  /* __cplusplus */")
        .replace("#endif // __cplusplus", "#endif /* __cplusplus */");
    std::fs::write(&out, &fresh).expect("can rewrite the header in OUT_DIR");
    if !check_only && std::fs::read_to_string(&committed).ok().as_deref() != Some(fresh.as_str()) {
        std::fs::create_dir_all(root.join("include")).expect("can create include/");
        std::fs::write(&committed, &fresh).expect("can write include/delta_collide.h");
    }
}
