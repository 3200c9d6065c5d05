//! The C ABI from C: the checked-in header is what cbindgen makes of src/ffi.rs today, the C
//! game loop compiles against it and the shared library and puts the shadow where physics says,
//! and the bad-calls program gets an error code and a message for each bad call (under
//! valgrind, when installed, with definitely lost blocks of our code failing the test).

mod common;

use std::path::Path;
use std::process::Command;

use common::c::{compile, passes, root};

fn generated_header() -> String {
    let config = cbindgen::Config::from_file(root().join("cbindgen.toml")).unwrap();
    // Only the ABI's file: the rest of the crate's public items are not C's business.
    let mut out = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(root().join("src/ffi.rs"))
        .generate()
        .expect("cbindgen reads src/ffi.rs")
        .write(&mut out);
    String::from_utf8(out).unwrap()
}

/// A fresh generation equals include/softshadow.h; `SOFTSHADOW_BLESS=1` rewrites it instead.
#[test]
fn the_checked_in_header_is_generated_from_the_code() {
    let fresh = generated_header();
    let path = root().join("include/softshadow.h");
    if std::env::var("SOFTSHADOW_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, &fresh).unwrap();
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == fresh,
        "include/softshadow.h differs from cbindgen's output for src/ffi.rs: \
         regenerate it with `SOFTSHADOW_BLESS=1 cargo test --test c_abi`"
    );
    for rust_only in ["Vec<", "Option<", "&mut", "Box<", "Result<"] {
        assert!(!fresh.contains(rust_only), "a Rust type in the header: {rust_only}");
    }
}

/// The box's shadow in the `visibility.pgm` a C program wrote to `dir`, seen orthographically
/// from above, 3 m each way (world x = (column + ½) / w · 6 − 3, z likewise): dark at x = 0.25,
/// where the box's top edge falls, lit in the open and on the box's top. Returns the image's size.
fn assert_box_shadow(dir: &Path) -> (usize, usize) {
    let (w, h, v) = read_pgm(&dir.join("visibility.pgm"));
    let at = |x: f32, z: f32| {
        let (c, r) = (((x + 3.0) / 6.0 * w as f32) as usize, ((z + 3.0) / 6.0 * h as f32) as usize);
        v[r * w + c] as f32 / 65535.0
    };
    assert!(at(0.25, 0.0) < 0.05, "V {} in the umbra", at(0.25, 0.0));
    assert!(at(-2.0, 0.0) > 0.95 && at(2.5, 1.5) > 0.95, "V {} and {} in the open", at(-2.0, 0.0), at(2.5, 1.5));
    assert!(at(1.0, 0.0) > 0.95, "V {} on the box's top", at(1.0, 0.0));
    (w, h)
}

/// Reads a 16-bit binary PGM.
fn read_pgm(path: &Path) -> (usize, usize, Vec<u16>) {
    let bytes = std::fs::read(path).unwrap();
    let header: Vec<&[u8]> = bytes.splitn(5, |b| b.is_ascii_whitespace()).collect();
    assert_eq!(header[0], b"P5");
    let parse = |b: &[u8]| std::str::from_utf8(b).unwrap().parse::<usize>().unwrap();
    let (w, h, max) = (parse(header[1]), parse(header[2]), parse(header[3]));
    assert_eq!(max, 65535);
    let samples = header[4].chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect::<Vec<_>>();
    assert_eq!(samples.len(), w * h);
    (w, h, samples)
}

/// 200 frames from C moving the box to x = 1, shadow-map then PCSS: in the last frame the light
/// at (4, 8, 0) casts the box's far top edge (x = 0.5, y = 1) onto the ground at x = 0, so the
/// ground between x = 0 and the box's side at x = 0.5 is in the umbra, the ground far from the
/// box is lit and so is the box's top; every pass took time.
#[test]
fn the_c_game_loop_runs_and_shadows_where_physics_says() {
    let exe = compile("game_loop", &[]);
    let dir = std::env::temp_dir().join(format!("softshadow-game-loop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let output = Command::new(&exe).arg(&dir).current_dir(root()).output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "game_loop failed");
    assert!(stdout.contains("technique shadow-map") && stdout.contains("technique pcss"), "{stdout}");
    let last = passes(&stdout, "frame 199 pass ");
    let names: Vec<_> = last.iter().map(|(n, _)| *n).collect();
    assert_eq!(names, ["prepass", "shadow_map", "resolve", "composite"], "{stdout}");
    assert!(last.iter().all(|(_, ms)| *ms > 0.0), "{last:?}");

    let (w, h) = assert_box_shadow(&dir);
    assert!(std::fs::metadata(dir.join("color.ppm")).unwrap().len() > (w * h * 3) as u64);
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_file(&exe).unwrap();
}

/// A C renderer's frames (its own instance and device under validation and synchronization
/// validation, its own depth: the ground seen straight down, the box's top over it), recorded by
/// `softshadow_record` into its command buffers and submitted by it. With the light at (4, 8, 0),
/// the box's top edge at x = 0.5 falls on the ground at x = 0: V there is dark, the open ground
/// and the box's top are lit, every pass took time (the import first), the layer reported no
/// error, and the embedder's host allocator served the engine and got every block back.
#[test]
fn a_c_renderer_records_the_shadow_into_its_own_command_buffers() {
    let exe = compile("embedder", &["-lvulkan"]);
    let dir = std::env::temp_dir().join(format!("softshadow-embedder-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let output = Command::new(&exe).arg(&dir).current_dir(root()).output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "embedder failed");
    assert!(stdout.contains("; 0 validation errors"), "{stdout}");
    let host = stdout.lines().find_map(|l| l.strip_prefix("host blocks through the callbacks: ")).expect("host blocks");
    let made: usize = host.split(' ').next().unwrap().parse().unwrap();
    assert!(made > 0 && host.ends_with(" 0 alive after the engine"), "the embedder's host allocator: {host}");
    let passes = passes(&stdout, "pass ");
    let names: Vec<_> = passes.iter().map(|(n, _)| *n).collect();
    assert_eq!(names, ["import", "shadow_map", "resolve"], "{stdout}");
    assert!(passes.iter().all(|(_, ms)| *ms > 0.0), "{passes:?}");
    assert_box_shadow(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_file(&exe).unwrap();
}

/// The bad-calls program: every bad call gets its status and a message. Under valgrind (when
/// installed), a definitely lost block fails the run unless it was allocated inside the Vulkan
/// loader or driver, which leak at exit by design (tests/valgrind.supp); our own leaks, in
/// libsoftshadow.so or the C program, are not suppressed.
#[test]
fn every_bad_c_call_gets_an_error_code_and_a_message() {
    let exe = compile("bad_calls", &[]);
    let valgrind = Command::new("valgrind").arg("--version").output().is_ok_and(|o| o.status.success());
    let mut command = if valgrind {
        let mut c = Command::new("valgrind");
        // Debug info of libraries unloaded at exit stays, so their leaks match the suppressions.
        c.args([
            "--leak-check=full",
            "--errors-for-leak-kinds=definite",
            "--show-leak-kinds=definite",
            "--keep-debuginfo=yes",
        ])
        .arg(format!("--suppressions={}", root().join("tests/valgrind.supp").display()))
        .args(["--error-exitcode=99", "--quiet"])
        .arg(&exe);
        c
    } else {
        Command::new(&exe)
    };
    let output = command.current_dir(root()).output().unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    eprintln!("{stdout}{stderr}");
    assert!(output.status.success(), "bad_calls exited with {:?} (99: valgrind found errors or leaks)", output.status);
    assert!(stdout.contains("0 call(s) misbehaved"), "{stdout}");
    assert!(stdout.lines().filter(|l| l.starts_with("ok ")).count() >= 40, "{stdout}");
    std::fs::remove_file(&exe).unwrap();
}
