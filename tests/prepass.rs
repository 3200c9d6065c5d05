//! The camera prepass draws the meshes and the ground with pipelines of their own (the meshes'
//! depth tested before their shader, the ground's exact depth written by its own), and what a
//! pixel sees is what it saw with one pipeline for both: the nearer of the meshes' surface and
//! the ground's, each as drawn alone. (The camera's near and far planes are fitted to the scene,
//! so the scenes drawn apart are rasterised at depths of their own precision: compared to 1e-5
//! of the distance, facet normals to 1e-4, roles exactly. The bit-identity of the G-buffer with
//! the one-pipeline prepass was checked once, across builds: see the commit.)

mod common;

use common::{engine, finish, render_with, suite_scene};
use softshadow::Capture;

/// Whether pixel `i` shows the same surface in `a` and `b`.
fn same_surface(a: &Capture, b: &Capture, i: usize) -> bool {
    let (a, b) = (&a.surfaces, &b.surfaces);
    let (da, db) = (a.depth[i], b.depth[i]);
    (da == db || (da - db).abs() <= 1e-5 * db)
        && (a.normal[i] - b.normal[i]).abs().max_element() <= 1e-4
        && (a.receives[i], a.casts[i]) == (b.receives[i], b.casts[i])
}

#[test]
fn meshes_and_ground_are_drawn_as_each_alone_the_nearer_kept() {
    let mut e = engine();
    for name in ["default", "contact", "wingnut", "open_mesh", "overlap"] {
        let both = suite_scene(name);
        let mut meshes = both.clone();
        meshes.ground = None;
        let mut ground = both.clone();
        ground.objects.clear();
        let [all, m, g] = [&both, &meshes, &ground].map(|s| render_with(&mut e, s, "shadow-map", &[], 96));
        let (mut from_meshes, mut from_ground) = (0, 0);
        for i in 0..all.surfaces.depth.len() {
            let (dm, dg) = (m.surfaces.depth[i], g.surfaces.depth[i]);
            if dm.is_finite() && (dm - dg).abs() <= 1e-5 * dm {
                continue; // too close to order at these precisions: either surface
            }
            let expected = if dm < dg { &m } else { &g };
            let (a, want) = (&all.surfaces, &expected.surfaces);
            assert!(
                same_surface(&all, expected, i),
                "{name}: pixel {i}: {} {} {}, alone {} {} {}",
                a.depth[i],
                a.normal[i],
                a.receives[i],
                want.depth[i],
                want.normal[i],
                want.receives[i]
            );
            if dm.is_finite() && dm < dg {
                from_meshes += 1;
            } else if dg.is_finite() {
                from_ground += 1;
            }
        }
        assert!(from_meshes > 100 && from_ground > 100, "{name}: {from_meshes} mesh, {from_ground} ground pixels");
    }
    finish(e);
}
