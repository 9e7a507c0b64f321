//! The CLI's pictures as a user makes them: `render`, `quilt` and `eval --plot` each write a
//! PNG that decodes, has the requested size and shows what it should (the colours of a
//! collision, of free space, of unreachable cells), and bad requests fail with a message.
//!
//! Tables are built once, at k = 16, by the CLI itself.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn cli(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_delta-collide"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn temp_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("dc-pictures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    })
}

fn path(name: &str) -> String {
    temp_dir().join(name).to_str().unwrap().to_string()
}

/// A T1 table at k = 16 (6D unless `variant` says otherwise), built once per variant.
fn t1_table(variant: &'static str) -> String {
    static TABLES: OnceLock<std::sync::Mutex<Vec<&'static str>>> = OnceLock::new();
    let built = TABLES.get_or_init(Default::default);
    let mut built = built.lock().unwrap();
    let file = path(&format!("t1-k16-{variant}.dct"));
    if !built.contains(&variant) {
        ok(&cli(&["build", "--cell", "T1", "--k", "16", "--variant", variant, "--output", &file]));
        built.push(variant);
    }
    file
}

/// A decoded 8-bit RGB picture.
struct Picture {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
}

impl Picture {
    fn read(file: &str) -> Picture {
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(file).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut rgb = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut rgb).unwrap();
        assert_eq!(
            (info.color_type, info.bit_depth),
            (png::ColorType::Rgb, png::BitDepth::Eight),
            "{file}"
        );
        rgb.truncate(info.buffer_size());
        Picture { width: info.width, height: info.height, rgb }
    }

    fn pixels(&self) -> impl Iterator<Item = [u8; 3]> + '_ {
        self.rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]])
    }

    /// How many pixels satisfy `pred`.
    fn count(&self, pred: impl Fn([u8; 3]) -> bool) -> usize {
        self.pixels().filter(|&p| pred(p)).count()
    }

    fn distinct_colours(&self) -> usize {
        let mut seen: Vec<[u8; 3]> = self.pixels().collect();
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    }
}

/// The collision red of boxes and ticks (drawn translucent or solid: red clearly dominant).
fn reddish(p: [u8; 3]) -> bool {
    p[0] >= 180 && p[1] <= 150 && p[2] <= 150 && p[0] as i32 - p[1] as i32 >= 80
}

fn exactly(c: [u8; 3]) -> impl Fn([u8; 3]) -> bool {
    move |p| p == c
}

const BLACK: [u8; 3] = [0, 0, 0];
const ORANGE: [u8; 3] = [240, 170, 60];
const GREY: [u8; 3] = [200, 200, 200];
const FREE_TICK: [u8; 3] = [120, 200, 120];

fn assert_picture(file: &str, width: u32, height: u32) -> Picture {
    let meta = std::fs::metadata(file).unwrap_or_else(|e| panic!("{file}: {e}"));
    assert!(meta.len() > 1000, "{file}: only {} bytes", meta.len());
    let pic = Picture::read(file);
    assert_eq!((pic.width, pic.height), (width, height), "{file}: requested size");
    assert!(
        pic.distinct_colours() > 10,
        "{file}: {} colours, a blank picture",
        pic.distinct_colours()
    );
    pic
}

#[test]
fn render_marks_colliding_boxes_red_and_a_free_configuration_has_none() {
    let hit = path("render-collision.png");
    let text = ok(&cli(&[
        "render",
        "--cell",
        "T1",
        "--tcp",
        "180,30,-460",
        "--tcp",
        "-170,-20,-440",
        "--output",
        &hit,
        "--width",
        "900",
        "--height",
        "480",
    ]));
    assert!(text.contains("COLLISION: A lower link 0 × B lower link 1"), "{text}");
    let collision = assert_picture(&hit, 900, 480);
    let free = path("render-free.png");
    let text = ok(&cli(&[
        "render",
        "--cell",
        "cells/t1.toml",
        "--tcp",
        "-120,0,-450",
        "--tcp",
        "120,0,-450",
        "--output",
        &free,
    ]));
    assert!(text.contains("free, closest boxes"), "{text}");
    let free = assert_picture(&free, 1400, 700);
    // The legend's swatch is red in both; only the colliding boxes add thousands of red pixels.
    let (red_hit, red_free) = (collision.count(reddish), free.count(reddish));
    assert!(
        red_hit > 5_000 && red_free < 1_000,
        "red pixels: collision {red_hit}, free {red_free}"
    );
    // Both robots' colours are drawn (blue A, green B).
    assert!(
        free.count(|p| p[2] > 150 && p[0] < 120) > 1_000
            && free.count(|p| p[1] > 120 && p[0] < 100) > 1_000
    );
}

#[test]
fn render_of_an_unreachable_tcp_and_bad_arguments() {
    let file = path("render-unreachable.png");
    let text = ok(&cli(&[
        "render", "--cell", "T2", "--tcp", "0,0,-900", "--tcp", "0,0,-450", "--output", &file,
    ]));
    assert!(text.contains("unreachable: robot A"), "{text}");
    assert_picture(&file, 1400, 700);
    let out = cli(&["render", "--cell", "T1", "--tcp", "0,0,-450", "--output", &file]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("one --tcp x,y,z per robot"));
    let out =
        cli(&["render", "--cell", "T1", "--tcp", "0,0", "--tcp", "0,0,-450", "--output", &file]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("three numbers"));
    let out = cli(&[
        "render", "--cell", "T1", "--tcp", "0,0,-450", "--tcp", "0,0,-450", "--width", "10",
        "--output", &file,
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("at least"));
}

#[test]
fn quilt_of_a_6d_table_shows_collision_free_and_unreachable_cells() {
    let table = t1_table("6d");
    for (axes, slices) in [
        ("yy", "25 slices of 14 x 14"),
        ("zz", "196 slices of 5 x 5"),
        ("xx", "25 slices of 14 x 14"),
    ] {
        let file = path(&format!("quilt-{axes}.png"));
        let text = ok(&cli(&[
            "quilt", "--cell", "T1", "--table", &table, "--axes", axes, "--output", &file,
            "--width", "640", "--height", "700",
        ]));
        assert!(text.contains(slices), "{axes}: {text}");
        let pic = assert_picture(&file, 640, 700);
        // Legend swatches are 14 x 12 pixels: far more than that means cells of that colour.
        assert!(pic.count(exactly(BLACK)) > 2_000, "{axes}: collision cells");
        assert!(pic.count(exactly(ORANGE)) > 2_000, "{axes}: unreachable cells");
    }
    // The xx'-slices of T1 hold both labels: free cells counted by the CLI, drawn white.
    let text = ok(&cli(&[
        "quilt",
        "--cell",
        "T1",
        "--table",
        &table,
        "--axes",
        "xx",
        "--fix",
        "8,8",
        "--output",
        &path("q.png"),
    ]));
    let free: usize =
        text.split(" collision, ").nth(1).unwrap().split(" free").next().unwrap().parse().unwrap();
    assert!(free > 1_000, "{text}");
}

#[test]
fn quilt_with_a_fixed_cell_of_a_shows_b_slices_per_depth_and_works_on_a_4d_table() {
    let table = t1_table("4d-yy");
    let file = path("quilt-a.png");
    let text = ok(&cli(&[
        "quilt", "--cell", "T1", "--table", &table, "--a", "12,8,3", "--output", &file, "--width",
        "500", "--height", "520",
    ]));
    assert!(text.contains("5 slices of 14 x 14"), "{text}");
    let pic = assert_picture(&file, 500, 520);
    for (name, c) in [("collision", BLACK), ("unreachable", ORANGE), ("outside the grid", GREY)] {
        assert!(pic.count(exactly(c)) > 500, "{name}");
    }
    let out = cli(&["quilt", "--cell", "T1", "--table", &table, "--a", "12,8", "--output", &file]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("expected 3 grid indices"));
    let out = cli(&[
        "quilt", "--cell", "T1", "--table", &table, "--axes", "zz", "--width", "200", "--height",
        "200", "--output", &file,
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("too small"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = cli(&["quilt", "--cell", "T1", "--table", &table, "--axes", "xy", "--output", &file]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("use yy"));
    let out = cli(&["quilt", "--cell", "T3", "--table", &table, "--output", &file]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("rebuild"),
        "a T1 table is refused for T3"
    );
}

#[test]
fn eval_plots_distance_and_labels_along_both_scenarios() {
    let table = t1_table("6d");
    let file = path("eval.png");
    let text = ok(&cli(&[
        "eval", "--cell", "T1", "--table", &table, "--random", "200", "--plot", &file, "--width",
        "1000", "--height", "640",
    ]));
    assert!(text.contains("1000 x 640 pixels, 2 scenarios"), "{text}");
    let pic = assert_picture(&file, 1000, 640);
    // Free ticks in green strips, the collision run's last part in red, the distance in blue.
    assert!(pic.count(exactly(FREE_TICK)) > 10_000);
    assert!(pic.count(reddish) > 1_000);
    assert!(pic.count(|p| p[2] > 150 && p[0] < 100 && p[1] < 140) > 1_000);
    let out = cli(&[
        "eval", "--cell", "T1", "--table", &table, "--random", "10", "--plot", &file, "--height",
        "100",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn simulate_plots_the_coordination_diagram_with_its_obstacles_and_the_run() {
    let file = path("diagram.png");
    let text = ok(&cli(&[
        "simulate",
        "--cell",
        "T1",
        "--runs",
        "1",
        "--ticks",
        "1200",
        "--mode",
        "coordinate",
        "--paths",
        "--plot",
        &file,
    ]));
    assert!(text.contains("coordinate"), "{text}");
    let pic = assert_picture(&file, 900, 940);
    // Obstacles in grey (the place points are shared every cycle), the programmed timing in
    // green, the run in blue.
    assert!(pic.count(exactly([150, 150, 150])) > 5_000);
    assert!(pic.count(exactly(FREE_TICK)) > 500);
    assert!(pic.count(exactly([40, 90, 200])) > 500);
}
