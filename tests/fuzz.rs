//! Fuzzing on stable Rust: proptest over arbitrary bytes and over mutations of the suite's
//! scene files and OBJ meshes. Whatever the input, loading gives a scene or an error that
//! names the file, never a panic or a hang; a scene that loads is one the checks accept.
//!
//! The suite runs 512 cases of each. For a long run (about an hour on one core):
//! `FUZZ_CASES=3000000 cargo test --test fuzz -- --test-threads=1`

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use softshadow::FrameSettings;
use softshadow::scene::{Mesh, Scene};

fn cases() -> u32 {
    std::env::var("FUZZ_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(512)
}

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The suite's scenes, with the paths they resolve meshes against.
fn seed_scenes() -> Vec<(PathBuf, String)> {
    let mut scenes: Vec<_> = std::fs::read_dir(repo("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect();
    scenes.sort();
    scenes
}

/// The small meshes (the large ones would make each case slow).
fn seed_meshes() -> Vec<String> {
    ["cube.obj", "cube_no_bottom.obj", "sphere.obj", "fish_low_resolution.obj"]
        .iter()
        .map(|m| std::fs::read_to_string(repo("models").join(m)).unwrap())
        .collect()
}

/// One edit of a text.
#[derive(Clone, Debug)]
enum Mutation {
    /// Removes `len` bytes at `at` (a fraction of the length).
    Delete { at: f64, len: usize },
    /// Copies the bytes at `from` to `to`.
    Duplicate { from: f64, to: f64, len: usize },
    /// Replaces the number nearest `at` with `with`.
    Number { at: f64, with: String },
    /// Inserts `text` at `at`.
    Insert { at: f64, text: String },
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|x| format!("{x:e}")),
        any::<i64>().prop_map(|i| i.to_string()),
        Just("nan".to_string()),
        Just("-inf".to_string()),
        Just("1e-45".to_string()),
        Just("0".to_string()),
        Just("-0.0".to_string()),
        Just("4294967296".to_string()),
        (0.0f64..1e10).prop_map(|x| x.to_string()),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let at = 0.0f64..1.0;
    prop_oneof![
        (at.clone(), 1usize..40).prop_map(|(at, len)| Mutation::Delete { at, len }),
        (at.clone(), at.clone(), 1usize..200).prop_map(|(from, to, len)| Mutation::Duplicate { from, to, len }),
        (at.clone(), number()).prop_map(|(at, with)| Mutation::Number { at, with }),
        (at, "[\\[\\]{}=,\"'#\\n a-z0-9.\\-]{1,12}").prop_map(|(at, text)| Mutation::Insert { at, text }),
    ]
}

/// The byte offset at fraction `f` of `text`, moved back to a character boundary.
fn offset(text: &str, f: f64) -> usize {
    let mut i = ((text.len() as f64) * f) as usize;
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i.min(text.len())
}

fn apply(text: &str, mutations: &[Mutation]) -> String {
    let mut s = text.to_string();
    for m in mutations {
        match m {
            Mutation::Delete { at, len } => {
                let a = offset(&s, *at);
                let b = offset(&s, ((a + len) as f64 / s.len().max(1) as f64).min(1.0));
                s.replace_range(a..b.max(a), "");
            }
            Mutation::Duplicate { from, to, len } => {
                let a = offset(&s, *from);
                let b = offset(&s, ((a + len) as f64 / s.len().max(1) as f64).min(1.0)).max(a);
                let piece = s[a..b].to_string();
                let t = offset(&s, *to);
                s.insert_str(t, &piece);
            }
            Mutation::Number { at, with } => {
                let a = offset(&s, *at);
                let start = s[a..].find(|c: char| c.is_ascii_digit()).map(|i| a + i);
                if let Some(start) = start {
                    let end = s[start..]
                        .find(|c: char| !(c.is_ascii_digit() || ".eE-+".contains(c)))
                        .map_or(s.len(), |i| start + i);
                    s.replace_range(start..end, with);
                }
            }
            Mutation::Insert { at, text } => {
                let a = offset(&s, *at);
                s.insert_str(a, text);
            }
        }
    }
    s
}

/// Loads `text` as if it were the file at `path`: a scene and its frame settings, or an error
/// naming the file. Both outcomes are fine; a panic fails the case.
fn load_scene(text: &str, path: &Path) {
    match Scene::from_toml(text, path).and_then(|s| FrameSettings::from_scene(&s).map(|f| (s, f))) {
        Ok((scene, settings)) => {
            scene.validate().expect("a loaded scene passes the checks a frame makes");
            assert!(settings.width > 0 && settings.height > 0);
        }
        Err(e) => {
            let message = e.to_string();
            assert!(message.starts_with(&path.display().to_string()), "the error does not name the file: {message}");
            assert!(message.len() < 4096, "a {} byte error", message.len());
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_are_a_scene_or_a_named_error(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        load_scene(&String::from_utf8_lossy(&bytes), &repo("scenes/fuzz.toml"));
    }

    #[test]
    fn mutated_scenes_are_a_scene_or_a_named_error(
        seed in any::<prop::sample::Index>(),
        mutations in proptest::collection::vec(mutation(), 1..6),
    ) {
        let seeds = seed_scenes();
        let (path, text) = &seeds[seed.index(seeds.len())];
        load_scene(&apply(text, &mutations), path);
    }

    #[test]
    fn mutated_meshes_are_a_mesh_or_a_named_error(
        seed in any::<prop::sample::Index>(),
        mutations in proptest::collection::vec(mutation(), 1..6),
    ) {
        let seeds = seed_meshes();
        let text = apply(&seeds[seed.index(seeds.len())], &mutations);
        let path = std::env::temp_dir().join(format!("softshadow-fuzz-{}-{:?}.obj", std::process::id(), std::thread::current().id()));
        std::fs::write(&path, &text).unwrap();
        match Mesh::load_obj(&path) {
            Ok(mesh) => {
                let (vertices, indices) = mesh.render_geometry();
                prop_assert!(vertices.iter().all(|v| v.position.iter().chain(&v.normal).all(|c| c.is_finite())));
                prop_assert!(indices.iter().all(|&i| (i as usize) < vertices.len()));
                prop_assert!(mesh.bounds.min.is_finite() && mesh.bounds.max.is_finite());
            }
            Err(e) => prop_assert!(e.to_string().contains(&path.display().to_string()), "{e}"),
        }
        std::fs::remove_file(&path).unwrap();
    }
}
