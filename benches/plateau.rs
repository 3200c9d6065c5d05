//! Per-frame CPU cost of the plateau's sides on the largest shipped model (wingnut, 6090
//! triangles): face facing from the face planes and silhouette edges, then cones, tangents and
//! sheets, as a frame whose caster or light moved rebuilds them, and the whole frame with the
//! partial silhouettes.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Mat4, Vec3};
use softshadow::geometry::plateau::{
    Penumbra, PenumbraSize, PlateauLight, ReceiverPlane, caster_sides, plateau_edges, plateau_sides,
};
use softshadow::geometry::silhouette::{Caster, EdgeSource};
use softshadow::scene::Mesh;

fn plateau(c: &mut Criterion) {
    let wingnut = Mesh::load_obj(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/wingnut.obj")).unwrap();
    let model = Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0));
    let caster = Caster { positions: &wingnut.positions, triangles: &wingnut.triangles, adjacency: &wingnut.adjacency };
    let plane = ReceiverPlane::ground(0.0);
    let light = PlateauLight {
        position: Vec3::new(3.0, 9.0, 2.5),
        radius: 0.4,
        size: PenumbraSize::Physical { scale: 1.0 },
        penumbra: Penumbra::Centred,
        wedges: true,
    };
    let source = EdgeSource::Silhouettes;
    c.bench_function("plateau silhouettes, wingnut", |b| {
        b.iter(|| plateau_edges(black_box(&caster), &wingnut.planes.light_facing(&model, light.position), source))
    });
    let edges = plateau_edges(&caster, &wingnut.planes.light_facing(&model, light.position), source);
    c.bench_function("plateau sides (cones, sheets), wingnut", |b| {
        b.iter(|| plateau_sides(&plane, &light, black_box(&caster), &model, &edges, source, 1.0))
    });
    c.bench_function("plateau frame (facing, edges, sides, partial silhouettes), wingnut", |b| {
        b.iter(|| caster_sides(&plane, &light, (black_box(&caster), &wingnut.planes), &model, source, 1.0))
    });
}

criterion_group!(benches, plateau);
criterion_main!(benches);
