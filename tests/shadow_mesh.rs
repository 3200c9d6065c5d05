//! The simplified shadow mesh (issue 18) keeps the shadow within its stated error: seen from
//! the light, its outline strays from the full mesh's by no more than the bound in texels of
//! the light's view ([`LIGHT_VIEW_TEXELS`]² fitted to the caster), with fewer triangles; and
//! every path that casts from it does (the shadow volumes': tests/shadow_volume.rs).

mod common;

use std::sync::Arc;

use glam::{Vec2, Vec3};
use softshadow::scene::{Mesh, Object, primitives};
use softshadow::technique::shadow_mesh::{LIGHT_VIEW_TEXELS, texels_at_caster};

const LIGHT: Vec3 = Vec3::new(2.0, 7.0, 1.5);

/// Which cells of an N × N grid over the caster's tangent-plane bounds from the light its
/// triangles cover (cell centres), N chosen so a cell is one texel of the light's view.
fn silhouette_mask(o: &Object, mesh: &Mesh) -> (Vec<bool>, usize) {
    let b = o.bounds();
    let (centre, radius) = ((b.min + b.max) * 0.5, (b.max - b.min).length() * 0.5);
    let axis = (centre - LIGHT).normalize();
    let u = axis.cross(Vec3::Y).normalize();
    let v = u.cross(axis);
    let half = (radius / (centre - LIGHT).length()).asin().tan();
    let n = LIGHT_VIEW_TEXELS as usize;
    let model = o.transform.matrix();
    let cell = |p: Vec3| {
        let d = model.transform_point3(p) - LIGHT;
        (Vec2::new(d.dot(u), d.dot(v)) / d.dot(axis) + half) / (2.0 * half) * n as f32
    };
    let mut mask = vec![false; n * n];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| cell(mesh.positions[i as usize]));
        let (lo, hi) = (a.min(b).min(c).max(Vec2::ZERO), a.max(b).max(c).min(Vec2::splat(n as f32 - 1.0)));
        let area = (b - a).perp_dot(c - a);
        for y in lo.y.floor() as usize..=hi.y.ceil() as usize {
            for x in lo.x.floor() as usize..=hi.x.ceil() as usize {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w = [(c - b).perp_dot(p - b), (a - c).perp_dot(p - c), (b - a).perp_dot(p - a)];
                if w.iter().all(|w| w * area >= 0.0) {
                    mask[y * n + x] = true;
                }
            }
        }
    }
    (mask, n)
}

/// Cells where the masks differ that lie farther than `reach` cells from the full outline.
fn strays(full: &[bool], simple: &[bool], n: usize, reach: usize) -> Vec<(usize, usize)> {
    let near_outline = |x: usize, y: usize| {
        let inside = full[y * n + x];
        let ys = y.saturating_sub(reach)..=(y + reach).min(n - 1);
        ys.flat_map(|yy| (x.saturating_sub(reach)..=(x + reach).min(n - 1)).map(move |xx| (xx, yy)))
            .any(|(xx, yy)| full[yy * n + xx] != inside)
    };
    (0..n * n).filter(|&i| full[i] != simple[i]).map(|i| (i % n, i / n)).filter(|&(x, y)| !near_outline(x, y)).collect()
}

#[test]
fn the_simplified_shadow_mesh_stays_within_its_stated_error() {
    let mut o = Object::new("knot", Arc::new(primitives::knot(20_000).unwrap()));
    o.transform.position = Vec3::new(0.0, 1.0, 0.0);
    o.transform.scale = Vec3::splat(0.8);
    let (full, n) = silhouette_mask(&o, &o.mesh);
    for texels in [1.0, 4.0] {
        let world = texels_at_caster(&o, LIGHT, texels).expect("the light is outside the caster");
        let simple = o.mesh.shadow_mesh(world / 0.8);
        assert!(simple.triangles.len() < o.mesh.triangles.len(), "{texels} texels: {}", simple.triangles.len());
        assert!(simple.adjacency.is_closed(), "a closed mesh stays closed: its silhouettes stay closed loops");
        let (mask, _) = silhouette_mask(&o, &simple);
        // One more cell for where a cell centre falls on either side of an outline.
        let out = strays(&full, &mask, n, texels as usize + 1);
        assert!(out.is_empty(), "{texels} texels: {} cells stray, e.g. {:?}", out.len(), &out[..out.len().min(5)]);
    }
    // An error so large that the simplifier would open the knot: the full mesh casts.
    let huge = o.mesh.shadow_mesh(0.5);
    assert!(huge.adjacency.is_closed());
    // No error allowed: the full mesh itself.
    assert!(Arc::ptr_eq(&o.mesh.shadow_mesh(0.0), &o.mesh));
}

/// Where the simplifier folds a fin into a closed mesh (the 100k-triangle knot at 2⁻⁹: two
/// triangles back to back, their edges shared by four faces), the copy drops it and stays closed
/// with far fewer triangles, instead of the full mesh casting.
#[test]
fn a_simplification_that_folds_fins_still_gives_a_closed_copy() {
    let knot = Arc::new(primitives::knot(100_000).unwrap());
    let simple = knot.shadow_mesh(2f32.powi(-9));
    assert!(simple.adjacency.is_closed());
    assert!(
        simple.triangles.len() * 2 < knot.triangles.len(),
        "{} of {} triangles",
        simple.triangles.len(),
        knot.triangles.len()
    );
}

/// The smoothie's compute path (`gpu_silhouettes = 1`) casts from the simplified mesh as its CPU
/// path does: the same smoothies from it, and not the full mesh's. On one grid: the two paths
/// estimate the narrowest smoothie differently, and may size it apart.
#[test]
fn the_smoothies_compute_path_casts_from_the_shadow_mesh_too() {
    use common::{engine, finish, render_with, top_down};
    use softshadow::measure::Metrics;
    let knot = "[[object]]\nshape = \"knot\"\ntriangles = 20000\nposition = [0.0, 1.0, 0.0]\nscale = 0.8\n";
    let s = top_down(0.0, 2.0, LIGHT.to_array(), 0.3, knot);
    let mut e = engine();
    let grid = ("penumbra_texels", "0");
    let simple = [("shadow_mesh_error", "4"), grid];
    let gpu = [simple[0], grid, ("gpu_silhouettes", "1")];
    let cpu = render_with(&mut e, &s, "smoothie", &simple, 128);
    let on_gpu = render_with(&mut e, &s, "smoothie", &gpu, 128);
    let full = render_with(&mut e, &s, "smoothie", &[("gpu_silhouettes", "1"), ("shadow_mesh_error", "0"), grid], 128);
    let same = Metrics::between(&on_gpu, &cpu).unwrap().max_abs;
    let apart = Metrics::between(&full, &cpu).unwrap().max_abs;
    assert!(same < 0.01 && apart > 10.0 * same.max(1e-3), "GPU vs CPU {same}, full vs simplified {apart}");
    finish(e);
}

/// `technique` casts its whole shadow from the shadow mesh its silhouettes come from: on the
/// ground, its shadow is the one the simplified caster itself casts, not a mix of the two meshes.
fn casts_wholly_from_the_shadow_mesh(technique: &str) {
    use common::{engine, finish, render_with, top_down};
    use softshadow::measure::Metrics;
    // Receiving nothing itself: only the ground's V, where the shadow falls, is compared.
    let knot =
        "[[object]]\nshape = \"knot\"\ntriangles = 20000\nposition = [0.0, 1.0, 0.0]\nscale = 0.8\nreceives = false\n";
    let s = top_down(0.0, 2.0, LIGHT.to_array(), 0.3, knot);
    let world = texels_at_caster(&s.objects[0], LIGHT, 4.0).expect("the light is outside the caster");
    let mut simplified = s.clone();
    simplified.objects[0].mesh = s.objects[0].mesh.shadow_mesh(world / 0.8);
    let mut e = engine();
    let cast = render_with(&mut e, &s, technique, &[("shadow_mesh_error", "4")], 128);
    let by_itself = render_with(&mut e, &simplified, technique, &[("shadow_mesh_error", "0")], 128);
    let full = render_with(&mut e, &s, technique, &[("shadow_mesh_error", "0")], 128);
    let same = Metrics::between(&cast, &by_itself).unwrap();
    let apart = Metrics::between(&full, &cast).unwrap();
    assert!(
        same.max_abs < 0.01 && apart.max_abs > 10.0 * same.max_abs.max(1e-3),
        "shadow mesh vs itself {same:?}, full vs simplified {apart:?}"
    );
    finish(e);
}

/// The plateau draws its umbra from the shadow mesh its sides come from.
#[test]
fn the_plateaus_umbra_is_cast_from_the_shadow_mesh_too() {
    casts_wholly_from_the_shadow_mesh("plateau");
}

/// The smoothie's shadow map is drawn from the shadow mesh its smoothies come from, so the hard
/// edge the penumbra straddles is the silhouettes' own.
#[test]
fn the_smoothies_shadow_map_is_cast_from_the_shadow_mesh_too() {
    casts_wholly_from_the_shadow_mesh("smoothie");
}

/// A caster that receives shadows and casts from its simplified copy does not shadow its own
/// lit side: the copy strays from the surface by up to its bound, in front of it as well as
/// behind, and the map's biases (texels at the receiver, more where the surface turns from the
/// light) hold that much at the default bound and at four times it.
#[test]
fn a_simplified_shadow_map_does_not_shadow_its_casters_lit_side() {
    use common::{engine, finish, render_with, top_down};
    let knot = "[[object]]\nshape = \"knot\"\ntriangles = 20000\nposition = [0.0, 1.0, 0.0]\nscale = 0.8\n";
    let s = top_down(0.0, 2.0, LIGHT.to_array(), 0.3, knot);
    let mut e = engine();
    let full = render_with(&mut e, &s, "smoothie", &[("shadow_mesh_error", "0")], 128);
    for texels in ["1", "4"] {
        let cast = render_with(&mut e, &s, "smoothie", &[("shadow_mesh_error", texels)], 128);
        let v = |c: &softshadow::Capture, i: usize| f64::from(c.visibility[i]) / 65535.0;
        let lit: Vec<usize> =
            (0..full.visibility.len()).filter(|&i| full.surfaces.casts[i] && v(&full, i) == 1.0).collect();
        let darkened = lit.iter().filter(|&&i| v(&cast, i) < 0.9).count();
        assert!(lit.len() > 1000 && darkened * 200 <= lit.len(), "{texels} texels: {darkened} of {}", lit.len());
    }
    finish(e);
}
