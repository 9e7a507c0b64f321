//! The committed C header is the one cbindgen generates from the current `src/ffi/`.
//!
//! `build.rs` refreshes `include/` during development; under `CI` it does not, so a stale
//! committed header fails here.

#[test]
fn committed_header_matches_a_fresh_generation() {
    let fresh = include_str!(concat!(env!("OUT_DIR"), "/delta_collide.h"));
    let committed =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/delta_collide.h"))
            .expect("include/delta_collide.h is committed");
    assert!(
        fresh == committed,
        "include/delta_collide.h is stale: run `cargo build` (outside CI) and commit include/"
    );
}

#[test]
fn header_is_ascii_with_c89_comments_and_a_do_not_edit_banner() {
    let h = include_str!(concat!(env!("OUT_DIR"), "/delta_collide.h"));
    assert!(h.is_ascii());
    assert!(!h.contains("//"), "strict C89 compilers reject // comments");
    assert!(h.contains("DO NOT EDIT"));
    for f in [
        "dc_init(",
        "dc_init_from_cell_file(",
        "dc_query(",
        "dc_destroy(",
        "dc_status_str(",
        "dc_version(",
    ] {
        assert!(h.contains(f), "{f} missing from the header");
    }
}
