//! Debian 12's `libshaderc.so.1` references glslang and SPIRV-Tools symbols without naming the
//! libraries that define them (they ship only as static archives in `glslang-dev` and
//! `spirv-tools`), and its shared build crashes when given them. So shaderc is linked statically
//! (`prefer-static-linking`, with `SHADERC_NO_PKG_CONFIG` in `.cargo/config.toml`) and this crate
//! adds the glslang and SPIRV-Tools archives it needs, from the same Debian build. Nothing is
//! built from source. The list comes from the system's pkg-config files.
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = Command::new("pkg-config").args(["--libs", "--static", "glslang", "SPIRV-Tools"]).output();
    let libs = match out {
        Ok(out) if out.status.success() => String::from_utf8_lossy(&out.stdout).into_owned(),
        _ => panic!(
            "pkg-config could not find glslang and SPIRV-Tools: install the system shader \
             compiler with `apt-get install libshaderc-dev glslang-dev spirv-tools pkg-config`"
        ),
    };
    // pkg-config drops the default library directory; rustc needs it to find the archives.
    if let Ok(dir) = Command::new("pkg-config").args(["--variable=libdir", "glslang"]).output() {
        println!("cargo:rustc-link-search=native={}", String::from_utf8_lossy(&dir.stdout).trim());
    }
    // glslang.pc omits libSPIRV.a, which holds GlslangToSpv.
    for flag in ["-lSPIRV"].into_iter().chain(libs.split_whitespace()) {
        if let Some(dir) = flag.strip_prefix("-L") {
            println!("cargo:rustc-link-search=native={dir}");
        } else if let Some(lib) = flag.strip_prefix("-l") {
            // -bundle: hand the archives to the final link instead of copying them into the rlib.
            let kind = if lib == "pthread" { "dylib" } else { "static:-bundle" };
            println!("cargo:rustc-link-lib={kind}={lib}");
        }
    }
    println!("cargo:rustc-link-lib=dylib=stdc++");
}
