//! Per-frame CPU cost of the shadow volumes' CPU path on the largest shipped model (wingnut,
//! 6090 triangles), as a frame whose caster or light moved rebuilds them: face facing, the
//! sides of every edge by its multiplicity, light and dark caps. The GPU path does the same in
//! its `silhouettes` compute pass (`softshadow render --set gpu_silhouettes=1 --timings`).

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Mat4, Vec3};
use softshadow::geometry::shadow_volume::{is_open, shadow_volume};
use softshadow::geometry::silhouette::{Caster, light_facing};
use softshadow::scene::Mesh;

fn volumes(c: &mut Criterion) {
    let wingnut = Mesh::load_obj(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/wingnut.obj")).unwrap();
    let model = Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0));
    let positions: Vec<Vec3> = wingnut.positions.iter().map(|p| model.transform_point3(*p)).collect();
    let caster = Caster { positions: &positions, triangles: &wingnut.triangles, adjacency: &wingnut.adjacency };
    let light = Vec3::new(3.0, 9.0, 2.5);
    c.bench_function("shadow volume (facing, sides, caps), wingnut", |b| {
        b.iter(|| {
            let facing = light_facing(black_box(&caster), light);
            shadow_volume(&caster, &facing, is_open(&caster))
        })
    });
}

criterion_group!(benches, volumes);
criterion_main!(benches);
