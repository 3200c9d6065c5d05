//! `shadow-volume`: exact hard shadows by stencil counting (z-pass and z-fail), against the
//! shadow map and the ray tracer, at the extremes the papers warn of, and soft by accumulation.

mod common;

use common::{engine, finish, render_with, scene, suite_scene, top_down};
use softshadow::Capture;

/// Pixels where `a` and `b` disagree on shadowed (V < ½) that are not within one pixel of a
/// shadow edge of `b`, as "x,y a/b".
fn off_edge_mismatches(a: &Capture, b: &Capture) -> Vec<String> {
    let dark = |c: &Capture, x: i64, y: i64| {
        let (x, y) = (x.clamp(0, c.width as i64 - 1) as u32, y.clamp(0, c.height as i64 - 1) as u32);
        c.visibility_at(x, y) < 0.5
    };
    let mut out = Vec::new();
    for y in 0..b.height as i64 {
        for x in 0..b.width as i64 {
            let here = dark(b, x, y);
            if dark(a, x, y) == here {
                continue;
            }
            let edge = (-1..=1).any(|dy| (-1..=1).any(|dx| dark(b, x + dx, y + dy) != here));
            if !edge {
                out.push(format!("{x},{y} {:.2}/{:.2}", a.visibility_at(x as u32, y as u32), b.visibility_at(x as u32, y as u32)));
            }
        }
    }
    out
}

fn assert_same_hard_shadow(a: &Capture, b: &Capture, what: &str) {
    let bad = off_edge_mismatches(a, b);
    assert!(bad.is_empty(), "{what}: {} px differ off the edges, first {:?}", bad.len(), &bad[..bad.len().min(6)]);
}

fn dark_pixels(c: &Capture) -> usize {
    c.visibility.iter().filter(|&&v| v < 32768).count()
}

#[test]
fn smoke() {
    let mut s = suite_scene("default");
    s.light.radius = 0.0;
    let mut e = engine();
    let map = render_with(&mut e, &s, "shadow-map", &[], 128);
    let ray = render_with(&mut e, &s, "raytrace", &[], 128);
    eprintln!("map vs ray {:?}", off_edge_mismatches(&map, &ray));
    for counting in ["1", "2"] {
        let v = render_with(&mut e, &s, "shadow-volume", &[("counting", counting)], 128);
        v.save_visibility(std::path::Path::new(&format!("/tmp/svt/default_{counting}.png"))).unwrap();
        map.save_visibility(std::path::Path::new("/tmp/svt/default_map.png")).unwrap();
        eprintln!("{counting} vs ray {:?}", off_edge_mismatches(&v, &ray));
        assert_same_hard_shadow(&v, &map, counting);
    }
    let _ = (scene, top_down, dark_pixels);
    finish(e);
}
