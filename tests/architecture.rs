//! DESIGN.md §2: rooms whose doors open one way. Each room of `src/` may import only the rooms
//! below it; this test reads the sources and fails on a forbidden import (a `use
//! crate::technique` inside `scene/`), and on Vulkan types where no Vulkan may be.

use std::collections::BTreeMap;
use std::path::Path;

/// Each room and the rooms it may import besides [`BELOW_ALL`].
const ROOMS: &[(&str, &[&str])] = &[
    ("error", &[]),
    ("shader_constants", &[]),
    ("geometry", &[]),
    ("gpu", &[]),
    ("scene", &["geometry"]),
    ("frame", &["geometry", "gpu", "scene"]),
    ("technique", &["geometry", "gpu", "scene", "frame", "reference"]),
    ("reference", &["geometry", "scene", "frame"]),
    ("renderer", &["geometry", "gpu", "scene", "frame", "technique"]),
    ("measure", &["geometry", "gpu", "scene", "frame", "technique", "renderer", "reference"]),
    // The C ABI wraps the engine and its inputs; nothing imports it.
    ("ffi", &["geometry", "gpu", "scene", "frame", "technique", "renderer"]),
];

/// What every room may import: the crate's shared error type, and the constants it shares with
/// the shaders (plain numbers, importing nothing).
const BELOW_ALL: &[&str] = &["error", "shader_constants"];

/// The `unsafe` allowed above gpu: the embedder's promise about its raw handles, passed on by
/// `Engine::from_handles` to `Context::from_handles` and by `Engine::from_native` to
/// `Context::native` (which make the only Vulkan calls on them).
const UNSAFE_ALLOWED: &[(&str, &str)] = &[
    ("renderer/mod.rs", "pub unsafe fn from_handles(handles: EmbedderHandles)"),
    ("renderer/mod.rs", "Engine::on(unsafe { Context::from_handles(handles) }?)"),
    ("renderer/window.rs", "pub unsafe fn from_native("),
    ("renderer/window.rs", "Engine::on(unsafe { Context::native(options, window) }?)"),
];

/// The crate-level paths each file of `dir` imports, keyed by file.
fn imports(dir: &Path, out: &mut BTreeMap<String, Vec<(usize, String)>>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            imports(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            let found = text
                .lines()
                .enumerate()
                .flat_map(|(i, line)| {
                    line.match_indices("crate::").map(move |(at, _)| {
                        let room: String =
                            line[at + 7..].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                        (i + 1, room)
                    })
                })
                .collect();
            out.insert(path.display().to_string(), found);
        }
    }
}

/// The room a file of `src/` belongs to: its folder, or its name for a file at the top.
fn room_of(file: &str) -> String {
    let rel = file.split("src/").nth(1).unwrap();
    rel.split('/').next().unwrap().trim_end_matches(".rs").to_string()
}

#[test]
fn every_room_imports_only_rooms_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = BTreeMap::new();
    imports(&src, &mut files);
    let mut forbidden = Vec::new();
    for (file, found) in &files {
        let room = room_of(file);
        let Some((_, allowed)) = ROOMS.iter().find(|(r, _)| *r == room) else { continue };
        for (line, target) in found {
            if *target != room && !allowed.contains(&target.as_str()) && !BELOW_ALL.contains(&target.as_str()) {
                forbidden.push(format!("{file}:{line}: `{room}` imports `{target}`"));
            }
        }
    }
    assert!(forbidden.is_empty(), "imports against DESIGN.md §2:\n{}", forbidden.join("\n"));
}

#[test]
fn geometry_and_scene_know_no_vulkan() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    for room in ["geometry", "scene"] {
        let mut files = BTreeMap::new();
        imports(&src.join(room), &mut files);
        for file in files.keys() {
            let text = std::fs::read_to_string(file).unwrap();
            for (i, line) in text.lines().enumerate() {
                assert!(!line.contains("vk::") && !line.contains("ash::"), "{file}:{}: Vulkan in `{room}`", i + 1);
            }
        }
    }
}

/// Vulkan calls are the gpu room's: above it, techniques and the renderer go through its
/// helpers (passes, barriers, copies), so no `unsafe` appears there.
#[test]
fn only_gpu_calls_vulkan() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    for room in ["frame", "technique", "renderer", "measure", "reference", "scene", "geometry"] {
        let mut files = BTreeMap::new();
        imports(&src.join(room), &mut files);
        for file in files.keys() {
            let text = std::fs::read_to_string(file).unwrap();
            for (i, line) in text.lines().enumerate() {
                let allowed = UNSAFE_ALLOWED.iter().any(|(f, l)| file.ends_with(f) && line.contains(l));
                assert!(
                    (allowed || !line.contains("unsafe")) && !line.contains("ctx.device."),
                    "{file}:{}: Vulkan outside gpu",
                    i + 1
                );
            }
        }
    }
}

/// Only the frame submits work (DESIGN.md §3: an embedder's frame is the only one, and nothing
/// of the engine's waits on the queue behind it): every upload is recorded into a frame.
#[test]
fn only_frames_submit() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = BTreeMap::new();
    imports(&src, &mut files);
    let submitting: Vec<_> = files
        .keys()
        .filter(|f| std::fs::read_to_string(f).unwrap().contains("queue_submit"))
        .map(|f| f.trim_start_matches(src.to_str().unwrap()).to_string())
        .collect();
    assert_eq!(submitting, ["/gpu/frames.rs"], "files that submit to the queue");
}

/// The C ABI dereferences C pointers (its `unsafe`), but calls Vulkan only through the engine.
#[test]
fn the_c_abi_calls_no_vulkan_itself() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/ffi.rs");
    let text = std::fs::read_to_string(&file).unwrap();
    for (i, line) in text.lines().enumerate() {
        assert!(
            !line.contains("ctx.device.") && !line.contains(".cmd_"),
            "{}:{}: Vulkan in ffi",
            file.display(),
            i + 1
        );
    }
}

#[test]
fn the_unsafe_allowed_above_gpu_is_still_there() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    for (file, line) in UNSAFE_ALLOWED {
        let text = std::fs::read_to_string(src.join(file)).unwrap();
        assert!(text.contains(line), "src/{file} no longer has `{line}`: shrink UNSAFE_ALLOWED");
    }
}

/// The rule has teeth: the scanner sees an import that breaks it.
#[test]
fn the_scanner_finds_a_forbidden_import() {
    let dir = std::env::temp_dir().join(format!("softshadow-rooms-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("src/scene")).unwrap();
    std::fs::write(dir.join("src/scene/bad.rs"), "use crate::technique::knobs;\n").unwrap();
    let mut files = BTreeMap::new();
    imports(&dir.join("src"), &mut files);
    let (file, found) = files.iter().next().unwrap();
    assert_eq!(room_of(file), "scene");
    assert_eq!(found, &vec![(1, "technique".to_string())]);
    std::fs::remove_dir_all(dir).unwrap();
}
