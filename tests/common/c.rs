//! Compiling and running the C programs of examples/c against the header and the shared library.

use std::path::{Path, PathBuf};
use std::process::Command;

pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The folder cargo put `libsoftshadow.so` in: `cargo test` leaves it in `deps/`, beside the
/// test binary; `cargo build` also copies it to the folder above.
pub fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let found = [deps, deps.parent().unwrap()].into_iter().find(|d| d.join("libsoftshadow.so").exists());
    found.unwrap_or_else(|| panic!("no libsoftshadow.so in {} or its parent", deps.display())).to_path_buf()
}

/// The `NAME MS` pairs a C program printed on lines starting with `prefix`.
pub fn passes<'a>(stdout: &'a str, prefix: &str) -> Vec<(&'a str, f64)> {
    stdout
        .lines()
        .filter_map(|l| l.strip_prefix(prefix))
        .map(|l| {
            let mut parts = l.split(' ');
            (parts.next().unwrap(), parts.next().unwrap().parse().unwrap())
        })
        .collect()
}

/// Compiles `examples/c/NAME.c` with the system `cc` against the header and the shared library,
/// and `libs` besides.
pub fn compile(name: &str, libs: &[&str]) -> PathBuf {
    let lib = library_dir();
    let out = std::env::temp_dir().join(format!("softshadow-{name}-{}", std::process::id()));
    let status = Command::new("cc")
        .arg(root().join(format!("examples/c/{name}.c")))
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-O1"])
        .arg(format!("-I{}", root().join("include").display()))
        .arg(format!("-L{}", lib.display()))
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        // DT_RPATH, not RUNPATH: searched before LD_LIBRARY_PATH, where cargo puts target/debug
        // and with it any older libsoftshadow.so a `cargo build` left there.
        .arg("-Wl,--disable-new-dtags")
        .args(["-lsoftshadow", "-lm"])
        .args(libs)
        .arg("-o")
        .arg(&out)
        .status()
        .expect("the system C compiler `cc`");
    assert!(status.success(), "cc failed on examples/c/{name}.c");
    out
}
