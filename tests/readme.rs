//! The README quotes code that must stay true: its game loop is the example's, line for line.

use std::path::Path;

fn read(path: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

/// The first ```rust block after `heading`.
fn rust_block<'a>(readme: &'a str, heading: &str) -> &'a str {
    let section = &readme[readme.find(heading).unwrap_or_else(|| panic!("README has no {heading}"))..];
    let start = section.find("```rust\n").expect("a rust block") + "```rust\n".len();
    let len = section[start..].find("```\n").expect("the block's end");
    &section[start..start + len]
}

#[test]
fn the_readmes_game_loop_is_the_examples_loop_verbatim() {
    let readme = read("README.md");
    let quoted = rust_block(&readme, "## Game loop");
    // The example's loop sits in `main`, one level in.
    let indented: String =
        quoted.lines().map(|l| if l.is_empty() { "\n".to_string() } else { format!("    {l}\n") }).collect();
    let example = read("examples/game_loop.rs");
    assert!(quoted.lines().count() > 20, "the README quotes only {} lines", quoted.lines().count());
    assert!(example.contains(&indented), "README's game loop differs from examples/game_loop.rs:\n{quoted}");
}
