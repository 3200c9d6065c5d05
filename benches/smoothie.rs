//! Per-frame CPU cost of the smoothie's geometry on the largest shipped model (wingnut, 6090
//! triangles, 9135 edges): silhouette extraction (face facing once per face, then every edge)
//! and the smoothie edges and corners of one light view, of every edge and of the chains merged
//! within one smoothie-buffer texel (`geometry::chains`).

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Mat4, Vec3};
use softshadow::geometry::fit_spot_frustum;
use softshadow::geometry::silhouette::Caster;
use softshadow::geometry::smoothie::{
    Penumbra, ReceiverBound, SmoothieSize, merged_silhouette, merged_smoothies, silhouette, smoothies,
};
use softshadow::scene::Mesh;

fn smoothie(c: &mut Criterion) {
    let wingnut = Mesh::load_obj(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/wingnut.obj")).unwrap();
    // As the technique does: object-space positions and face planes, placed by the model.
    let model = Mat4::from_translation(Vec3::Y);
    let caster = Caster { positions: &wingnut.positions, triangles: &wingnut.triangles, adjacency: &wingnut.adjacency };
    let light = Vec3::new(3.0, 9.0, 2.5);
    let mut group = c.benchmark_group("smoothie, wingnut");
    group.throughput(Throughput::Elements(wingnut.adjacency.edges.len() as u64));
    group.bench_function("silhouette edges", |b| {
        b.iter(|| silhouette(black_box(&caster), &wingnut.planes, black_box(&model), light))
    });
    let edges = silhouette(&caster, &wingnut.planes, &model, light);
    // The light view a frame would fit: around the model, cut to a ground square under it.
    let bounds = wingnut.bounds.transformed(&model);
    let ground = [(-3.0, -3.0), (3.0, -3.0), (3.0, 3.0), (-3.0, 3.0)].map(|(x, z)| Vec3::new(x, 0.0, z));
    let frustum = fit_spot_frustum(light, None, &[bounds], &ground).frustum.expect("the model is in view");
    let view = frustum.view * model;
    let size =
        (SmoothieSize::Physical { light_radius: 0.4, scale: 1.0, behind: 0.0 }, ReceiverBound::up_to(frustum.far));
    group.bench_function("smoothie geometry", |b| {
        b.iter(|| smoothies(&view, black_box(&caster), &edges, size, Penumbra::Outer))
    });
    // One texel of the default 1024² smoothie buffer over the light view's window.
    let [x0, y0, x1, y1] = frustum.window;
    let texel = (x1 - x0).max(y1 - y0) / 1024.0;
    group.bench_function("smoothie geometry, chains merged within a texel", |b| {
        b.iter(|| {
            let merged = merged_silhouette(&view, black_box(&caster), &edges, size, texel);
            merged_smoothies(&view, &caster, &merged, size, Penumbra::Outer)
        })
    });
    group.finish();
}

criterion_group!(benches, smoothie);
criterion_main!(benches);
