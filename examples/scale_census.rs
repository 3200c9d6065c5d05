//! Where the plateau's and smoothie's time goes on a scene (issue 18, step 2): per caster, the
//! silhouette edges and vertices, the primitives of the cones, sheets and smoothies, and the
//! fragments they rasterise (the summed area of their triangles in texels of the plateau
//! texture or smoothie buffer: each texel a triangle covers is one fragment, overlaps
//! counted once per triangle), with the CPU milliseconds of one moving frame's geometry.
//!
//! `cargo run --release --example scale_census -- scenes/scale/koala.toml [texels]`

use std::time::Instant;

use glam::{Vec2, Vec3};
use softshadow::geometry::plateau::{
    self, PenumbraSize, PlateauGeometry, PlateauLight, ReceiverPlane, plateau_edges, plateau_sides,
};
use softshadow::geometry::silhouette::{Caster, EdgeSource, penumbra_edges};
use softshadow::geometry::smoothie::{self, ReceiverBound, SmoothieSize, SmoothieVertex, depth_range, smoothies};
use softshadow::geometry::{Aabb, fit_spot_frustum};
use softshadow::scene::Scene;
use softshadow::technique::shadow_mesh::texels_at_caster;

/// Summed triangle area of a triangle list of 2D points.
fn area(points: impl Iterator<Item = Vec2>) -> f64 {
    let p: Vec<Vec2> = points.collect();
    p.chunks_exact(3).map(|t| f64::from((t[1] - t[0]).perp_dot(t[2] - t[0]).abs()) * 0.5).sum()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: scale_census SCENE.toml [texels]")?;
    let texels: f64 = args.next().map_or(Ok(1024.0), |t| t.parse())?;
    let scene = Scene::load(&path)?;
    let ground = scene.ground.ok_or("the census needs a ground plane")?;
    let light = scene.light.position;
    let plane = ReceiverPlane::ground(ground.height);
    let plateau_light = PlateauLight {
        position: light,
        radius: scene.light.radius,
        size: PenumbraSize::Physical { scale: 1.0 },
        penumbra: plateau::Penumbra::Centred,
        wedges: true,
    };
    let h = ground.half_size;
    let receivers = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, z)| Vec3::new(x, ground.height, z));
    println!(
        "| caster | triangles | edges | boundary | silhouette edges | CPU ms: transform, facing+edges, plateau sides, smoothies | wedges | sheets | plateau fragments (1024²) | smoothie edge tris | corner tris | smoothie fragments (edges, corners, inner quads and wedges) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for o in scene.objects.iter().filter(|o| o.casts) {
        let mesh = &o.mesh;
        let model = o.transform.matrix();
        let started = Instant::now();
        let positions: Vec<Vec3> = mesh.positions.iter().map(|p| model.transform_point3(*p)).collect();
        let transform_ms = started.elapsed().as_secs_f64() * 1e3;
        let caster = Caster { positions: &positions, triangles: &mesh.triangles, adjacency: &mesh.adjacency };
        let source = if mesh.adjacency.is_closed() { EdgeSource::Silhouettes } else { EdgeSource::LightFacing };
        let object = Caster { positions: &mesh.positions, ..caster };
        let started = Instant::now();
        let facing = mesh.planes.light_facing(&model, light);
        let edges = plateau_edges(&object, &facing, source);
        let edges_ms = started.elapsed().as_secs_f64() * 1e3;
        let closed_edges = penumbra_edges(&caster, &facing, EdgeSource::Silhouettes);

        let started = Instant::now();
        let sides = plateau_sides(&plane, &plateau_light, &object, &model, &edges, source, 0.0);
        let sides_ms = started.elapsed().as_secs_f64() * 1e3;
        let (lo, hi) = sides.footprint.unwrap_or((Vec2::ZERO, Vec2::ONE));
        let plateau_texel = (texels * texels) / f64::from((hi - lo).x * (hi - lo).y).max(1e-12);
        // What the GPU draws: each wedge's three triangles, each sheet's hull.
        let drawn = |g: &PlateauGeometry| {
            let cones = area(g.cones.iter().flat_map(|w| w.outline())) * plateau_texel;
            (cones, area(g.sheets.iter().flat_map(|s| s.hull_points())) * plateau_texel)
        };
        let (cone_fragments, sheet_fragments) = drawn(&sides);

        if source != EdgeSource::Silhouettes {
            // What the open mesh would cost if only the edges bounding its lit part had sides.
            let started = Instant::now();
            let bounding_edges = plateau_edges(&object, &facing, EdgeSource::Silhouettes);
            let bounding =
                plateau_sides(&plane, &plateau_light, &object, &model, &bounding_edges, EdgeSource::Silhouettes, 0.0);
            let ms = started.elapsed().as_secs_f64() * 1e3;
            let (cones, sheets) = drawn(&bounding);
            println!(
                "{}: with only the edges bounding the lit part (silhouettes and lit boundary edges): {} wedges, {} sheets, {:.0} fragments, {ms:.2} CPU ms",
                o.name,
                bounding.cones.len(),
                bounding.sheets.len(),
                cones + sheets
            );
        }
        for texels in [1.0, 4.0] {
            let world = texels_at_caster(o, light, texels).ok_or("the light is inside the caster")?;
            let started = Instant::now();
            let simple = o.mesh.shadow_mesh(world / o.transform.scale.abs().max_element());
            println!(
                "{}: shadow mesh within {texels} texel(s): {} triangles, closed {}, simplified in {:.0} ms",
                o.name,
                simple.triangles.len(),
                simple.adjacency.is_closed(),
                started.elapsed().as_secs_f64() * 1e3
            );
        }
        let bounds = Aabb::from_points(positions.iter().copied());
        let frustum =
            fit_spot_frustum(light, scene.light.target, &[bounds], &receivers).frustum.ok_or("not in view")?;
        let behind = frustum.view.transform_point3(light).length();
        let size = SmoothieSize::Physical { light_radius: scene.light.radius, scale: 1.0, behind };
        let frustum =
            frustum.grown(size.largest_reach(frustum.near, frustum.window, ReceiverBound::up_to(frustum.far)));
        let [x0, y0, x1, y1] = frustum.window;
        // The buffer's grid, rasterized as llvmpipe does (8 subpixel bits).
        let grid = smoothie::CutGrid::new((x1 - x0).max(y1 - y0) / texels as f32, 8);
        let started = Instant::now();
        let (near, far) = depth_range(&frustum.view, &bounds);
        let penumbra = smoothie::Penumbra::Centred { near, far, grid };
        let g = smoothies(&frustum.view, &caster, &closed_edges, (size, ReceiverBound::up_to(frustum.far)), penumbra);
        let smoothie_ms = started.elapsed().as_secs_f64() * 1e3;
        let smoothie_texel = (texels * texels) / f64::from((x1 - x0) * (y1 - y0));
        let xy = |v: &SmoothieVertex| Vec2::new(v.x, v.y);
        let edge_fragments = area(g.edges.iter().map(xy)) * smoothie_texel;
        let corner_fragments = area(g.corners.iter().map(xy)) * smoothie_texel;
        let inner_fragments = area(g.inner.iter().map(xy)) * smoothie_texel;
        println!(
            "| {} | {} | {} | {} | {} ({} for the plateau) | {transform_ms:.2}, {edges_ms:.2}, {sides_ms:.2}, {smoothie_ms:.2} | {} | {} | cones {:.0} ({:.1}× the texture), sheets {:.0} | {} | {} | edges {:.0}, corners {:.0}, inner {:.0} ({:.1}× the buffer) |",
            o.name,
            mesh.triangles.len(),
            mesh.adjacency.edges.len(),
            mesh.adjacency.boundary,
            closed_edges.len(),
            edges.len(),
            sides.cones.len(),
            sides.sheets.len(),
            cone_fragments,
            cone_fragments / (texels * texels),
            sheet_fragments,
            g.edges.len() / 3,
            g.corners.len() / 3,
            edge_fragments,
            corner_fragments,
            inner_fragments,
            (edge_fragments + corner_fragments + inner_fragments) / (texels * texels),
        );
    }
    Ok(())
}
