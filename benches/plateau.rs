//! Per-frame CPU cost of the plateau's sides on the largest shipped model (wingnut, 6090
//! triangles): face facing, silhouette edges, cones, tangents and Coons sheets, as a frame
//! whose caster or light moved rebuilds them.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Mat4, Vec3};
use softshadow::geometry::plateau::{Penumbra, PenumbraSize, PlateauLight, ReceiverPlane, plateau_sides};
use softshadow::geometry::silhouette::{Caster, EdgeSource, light_facing, penumbra_edges};
use softshadow::scene::Mesh;

fn plateau(c: &mut Criterion) {
    let wingnut = Mesh::load_obj(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/wingnut.obj")).unwrap();
    let model = Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0));
    let positions: Vec<Vec3> = wingnut.positions.iter().map(|p| model.transform_point3(*p)).collect();
    let caster = Caster { positions: &positions, triangles: &wingnut.triangles, adjacency: &wingnut.adjacency };
    let plane = ReceiverPlane::ground(0.0);
    let light = PlateauLight {
        position: Vec3::new(3.0, 9.0, 2.5),
        radius: 0.4,
        size: PenumbraSize::Physical { scale: 1.0 },
        penumbra: Penumbra::Centred,
        cone_segments: 32,
        wedges: true,
    };
    c.bench_function("plateau silhouettes, wingnut", |b| {
        b.iter(|| {
            let facing = light_facing(black_box(&caster), light.position);
            penumbra_edges(&caster, &facing, EdgeSource::Silhouettes)
        })
    });
    c.bench_function("plateau sides (silhouettes, cones, sheets), wingnut", |b| {
        b.iter(|| plateau_sides(&plane, &light, black_box(&caster), 1.0, EdgeSource::Silhouettes))
    });
}

criterion_group!(benches, plateau);
criterion_main!(benches);
