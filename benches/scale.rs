//! Cost at scale (issue 18) on koala.obj (99 994 triangles, 149 991 edges): silhouette
//! extraction in edges per second (one core), from the face planes built with the mesh as the
//! plateau and smoothie do, and the CPU geometry of a frame whose caster moved, for the plateau
//! (face planes, silhouettes and partial silhouettes, cones and sheets as one primitive each)
//! and the smoothie (face planes, silhouettes and partial silhouettes, smoothie edges and
//! corners), from the full mesh and from the one-texel shadow mesh both cast from by default.
//! Goal: at most 2 ms a moving frame.

use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Mat4, Vec3};
use softshadow::geometry::plateau::{self, PenumbraSize, PlateauLight, ReceiverPlane, caster_sides};
use softshadow::geometry::silhouette::{Caster, EdgeSource, partial_silhouettes, penumbra_edges};
use softshadow::geometry::smoothie::{self, ReceiverBound, SmoothieSize, depth_range, partial_smoothies, smoothies};
use softshadow::geometry::{Aabb, fit_spot_frustum};
use softshadow::scene::{Mesh, Object, Transform};
use softshadow::technique::shadow_mesh::texels_at_caster;

fn scale(c: &mut Criterion) {
    let koala = Mesh::load_obj(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/koala.obj")).unwrap();
    // As scenes/scale/koala.toml places it: standing, 1.4 m tall, over the ground.
    let mut o = Object::new("koala", Arc::new(koala));
    o.transform = Transform {
        position: Vec3::new(0.0, 0.7, 0.0),
        rotation_deg: Vec3::new(-90.0, 0.0, 0.0),
        scale: Vec3::splat(0.15),
    };
    let model = o.transform.matrix();
    let light = Vec3::new(2.0, 7.0, 1.5);
    let koala = &o.mesh;
    let positions: Vec<Vec3> = koala.positions.iter().map(|p| model.transform_point3(*p)).collect();
    let caster = Caster { positions: &positions, triangles: &koala.triangles, adjacency: &koala.adjacency };

    let mut group = c.benchmark_group("koala (99 994 triangles)");
    group.throughput(Throughput::Elements(koala.adjacency.edges.len() as u64));
    let object = Caster { positions: &koala.positions, ..caster };
    group.bench_function("silhouette extraction (edges/s)", |b| {
        b.iter(|| {
            penumbra_edges(&object, &koala.planes.light_facing(black_box(&model), light), EdgeSource::Silhouettes)
        })
    });
    group.throughput(Throughput::Elements(1));
    let plane = ReceiverPlane::ground(0.0);
    // The defaults: centred penumbrae of the physical size.
    let plateau_light = PlateauLight {
        position: light,
        radius: 0.3,
        size: PenumbraSize::Physical { scale: 1.0 },
        penumbra: plateau::Penumbra::Centred,
        wedges: true,
    };
    let bounds = Aabb::from_points(positions.iter().copied());
    let ground = [(-6.0, -6.0), (6.0, -6.0), (6.0, 6.0), (-6.0, 6.0)].map(|(x, z)| Vec3::new(x, 0.0, z));
    let frustum = fit_spot_frustum(light, None, &[bounds], &ground).frustum.expect("the koala is in view");
    let size =
        (SmoothieSize::Physical { light_radius: 0.3, scale: 1.0, behind: 0.0 }, ReceiverBound::up_to(frustum.far));
    // The full mesh, and the one-texel shadow mesh both techniques cast from by default (built
    // once, when the caster first casts, and cached).
    let world = texels_at_caster(&o, light, 1.0).expect("the light is outside the koala");
    let shadow = koala.shadow_mesh(world / 0.15);
    for (name, mesh) in [("", koala), (", 1-texel shadow mesh", &shadow)] {
        let object = Caster { positions: &mesh.positions, triangles: &mesh.triangles, adjacency: &mesh.adjacency };
        let mut step = 0.0f32;
        // The grid of a 1024² buffer, rasterized as llvmpipe does (8 subpixel bits).
        let [x0, y0, x1, y1] = frustum.window;
        let grid = smoothie::CutGrid::new((x1 - x0).max(y1 - y0) / 1024.0, 8);
        // As the technique does: facing from the face planes, only the edges' vertices transformed.
        group.bench_function(format!("plateau CPU geometry, moving frame{name}"), |b| {
            b.iter(|| {
                step = (step + 1e-3) % 0.05; // moving, but staying where it was placed
                let model = Mat4::from_translation(Vec3::X * step) * model;
                caster_sides(&plane, &plateau_light, (&object, &mesh.planes), &model, EdgeSource::Silhouettes, 0.0)
            })
        });
        // As the technique does: silhouettes from the face planes, smoothies through view · model.
        group.bench_function(format!("smoothie CPU geometry, moving frame{name}"), |b| {
            b.iter(|| {
                step = (step + 1e-3) % 0.05; // moving, but staying where it was placed
                let model = Mat4::from_translation(Vec3::X * step) * model;
                let facing = mesh.planes.light_facing(&model, light);
                let edges = penumbra_edges(&object, &facing, EdgeSource::Silhouettes);
                let partial = partial_silhouettes(&object, &mesh.planes, &facing, &model, light, 0.3);
                let view = frustum.view * model;
                let (near, far) = depth_range(&view, &mesh.bounds);
                let penumbra = smoothie::Penumbra::Centred { near, far, grid };
                let mut geometry = smoothies(&view, &object, &edges, size, penumbra);
                geometry.extend(&partial_smoothies(&view, &object, &partial, size, penumbra));
                geometry
            })
        });
    }
    group.finish();
}

criterion_group!(benches, scale);
criterion_main!(benches);
