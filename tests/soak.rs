//! A short soak through the game-loop API: 2 000 frames of a moving caster, every real-time
//! technique in turn (twice), a loop that never takes its timings. Nothing may grow: GPU
//! allocations return to the same count at the same point of each round, the timing records
//! stay within their history, and the validation layer reports no object left alive.
//! The long soak (100 000 frames, resident memory sampled) is `cargo run --release --example soak`.
//! A loop that streams meshes (a game loading level after level) lets each one go once it is
//! no longer drawn, in every technique's caches as in the renderer's.

mod common;

use common::{engine, finish, realtime_runs, suite_scene};
use std::sync::Arc;

use softshadow::renderer::DEFAULT_TIMING_HISTORY;
use softshadow::scene::Mesh;
use softshadow::technique::{Kind, Params, TECHNIQUES};
use softshadow::{Engine, FrameSettings};

const FRAMES_PER_TECHNIQUE: usize = 200;

/// One round: each real-time technique for its frames; the live allocations after each.
fn round(e: &mut Engine, scene: &mut softshadow::scene::Scene, frame: &mut usize) -> Vec<usize> {
    let mut live = Vec::new();
    for info in TECHNIQUES.iter().filter(|t| t.kind == Kind::Realtime) {
        let settings = FrameSettings { width: 32, height: 32, params: Params::defaults(info) };
        for _ in 0..FRAMES_PER_TECHNIQUE {
            scene.objects[0].transform.position.x = (*frame as f32 * 0.01).sin();
            e.render(scene, &settings).unwrap();
            *frame += 1;
        }
        e.flush().unwrap();
        live.push(e.context().live_allocations());
    }
    live
}

#[test]
fn two_thousand_frames_grow_nothing() {
    let mut e = engine();
    let mut scene = suite_scene("plate");
    let mut frame = 0;
    let first = round(&mut e, &mut scene, &mut frame);
    let second = round(&mut e, &mut scene, &mut frame);
    assert!(frame >= 2000, "{frame} frames");
    assert_eq!(first, second, "GPU allocations after each technique, round 1 vs round 2");
    let kept = e.take_timings();
    assert_eq!(kept.len(), DEFAULT_TIMING_HISTORY, "timing records of a loop that never took them");
    assert!(e.take_timings().is_empty());
    finish(e);
}

/// Every real-time technique, and both compute paths, drawing a caster whose mesh is replaced
/// by a new one (a fresh mesh id, as a streamed level's) every few frames: once the old
/// meshes are out of flight, the live GPU allocations are what they were after the first.
#[test]
fn streamed_meshes_are_let_go() {
    let mut e = engine();
    let mut scene = suite_scene("sphere");
    for (name, params) in realtime_runs() {
        let settings = FrameSettings { width: 32, height: 32, params };
        let mut live = Vec::new();
        for _ in 0..4 {
            let m = &scene.objects[0].mesh;
            let fresh = Mesh::new(m.name.clone(), m.positions.clone(), m.triangles.clone()).unwrap();
            scene.objects[0].mesh = Arc::new(fresh);
            for _ in 0..3 {
                e.render(&scene, &settings).unwrap();
            }
            e.flush().unwrap();
            live.push(e.context().live_allocations());
        }
        assert!(
            live.windows(2).skip(1).all(|w| w[0] == w[1]),
            "{name}: live allocations after each new mesh: {live:?}"
        );
    }
    finish(e);
}
