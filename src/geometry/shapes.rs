//! Procedural closed shapes centred on the origin, counter-clockwise seen from outside: welded
//! positions and triangles, the raw material of the scene's primitive meshes and of tests.

use std::f32::consts::TAU;

use glam::Vec3;

/// Positions and counter-clockwise triangles into them.
pub type Shape = (Vec<Vec3>, Vec<[u32; 3]>);

/// Segments around a sphere or cylinder: 15° steps, smooth under the 40° crease rule.
const SEGMENTS: u32 = 24;
const SPHERE_RINGS: u32 = 16;

/// A box of `size`; a zero `size.y` makes a plate: two back-to-back quads sharing their rim, a
/// closed surface of zero thickness (each rim edge has its two faces).
pub fn cuboid(size: Vec3) -> Shape {
    let h = size * 0.5;
    if size.y == 0.0 {
        let p = vec![
            Vec3::new(-h.x, 0.0, -h.z),
            Vec3::new(h.x, 0.0, -h.z),
            Vec3::new(h.x, 0.0, h.z),
            Vec3::new(-h.x, 0.0, h.z),
        ];
        // Top faces +Y; the bottom uses the other diagonal so no edge joins four faces.
        let tris = vec![[0, 2, 1], [0, 3, 2], [0, 1, 3], [1, 2, 3]];
        return (p, tris);
    }
    let p: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    // Each face as a quad listed counter-clockwise from outside.
    let quads = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
    let tris = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    (p, tris)
}

/// A UV sphere with welded poles.
pub fn sphere(radius: f32) -> Shape {
    let mut p = vec![Vec3::new(0.0, radius, 0.0)];
    for ring in 1..SPHERE_RINGS {
        let theta = std::f32::consts::PI * ring as f32 / SPHERE_RINGS as f32;
        for s in 0..SEGMENTS {
            let phi = TAU * s as f32 / SEGMENTS as f32;
            p.push(radius * Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    p.push(Vec3::new(0.0, -radius, 0.0));
    let south = p.len() as u32 - 1;
    let at = |ring: u32, s: u32| 1 + (ring - 1) * SEGMENTS + s % SEGMENTS;
    let mut tris = Vec::new();
    for s in 0..SEGMENTS {
        tris.push([0, at(1, s), at(1, s + 1)]);
        tris.push([south, at(SPHERE_RINGS - 1, s + 1), at(SPHERE_RINGS - 1, s)]);
        for ring in 1..SPHERE_RINGS - 1 {
            let (a, b, c, d) = (at(ring, s), at(ring + 1, s), at(ring + 1, s + 1), at(ring, s + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    (p, tris)
}

/// A capped cylinder along Y, centred on the origin.
pub fn cylinder(radius: f32, height: f32) -> Shape {
    let h = height * 0.5;
    let mut p = vec![Vec3::new(0.0, h, 0.0), Vec3::new(0.0, -h, 0.0)];
    for s in 0..SEGMENTS {
        let phi = TAU * s as f32 / SEGMENTS as f32;
        let (x, z) = (radius * phi.cos(), -radius * phi.sin());
        p.push(Vec3::new(x, h, z));
        p.push(Vec3::new(x, -h, z));
    }
    let top = |s: u32| 2 + 2 * (s % SEGMENTS);
    let bottom = |s: u32| 3 + 2 * (s % SEGMENTS);
    let mut tris = Vec::new();
    for s in 0..SEGMENTS {
        tris.push([0, top(s), top(s + 1)]);
        tris.push([1, bottom(s + 1), bottom(s)]);
        tris.push([top(s), bottom(s), bottom(s + 1)]);
        tris.push([top(s), bottom(s + 1), top(s + 1)]);
    }
    (p, tris)
}

/// A (2, 3) torus knot (a trefoil) tube of about `triangles` triangles, fitting in the unit
/// sphere: one closed genus-1 surface whose triangle count is a free parameter, for measuring
/// cost against mesh size. Rings along the knot outnumber the segments around the tube 8:1 so
/// the quads stay near square.
pub fn torus_knot(triangles: u32) -> Shape {
    const TUBE: f32 = 0.4;
    const EXTENT: f32 = 3.0 + TUBE; // the centre line's largest radius plus the tube's
    let around = ((triangles as f32 / 16.0).sqrt().round() as u32).max(3);
    let along = (triangles / (2 * around)).max(3);
    let centre = |t: f32| {
        let r = 2.0 + (3.0 * t).cos();
        Vec3::new(r * (2.0 * t).cos(), (3.0 * t).sin(), r * (2.0 * t).sin())
    };
    let mut p = Vec::with_capacity((along * around) as usize);
    for i in 0..along {
        let t = TAU * i as f32 / along as f32;
        // Frenet frame from central differences: the trefoil's curvature never vanishes.
        let h = 1e-3;
        let (before, at, after) = (centre(t - h), centre(t), centre(t + h));
        let tangent = (after - before).normalize();
        let normal = (after - 2.0 * at + before).reject_from(tangent).normalize();
        let binormal = tangent.cross(normal);
        for j in 0..around {
            let phi = TAU * j as f32 / around as f32;
            p.push((at + TUBE * (phi.cos() * normal + phi.sin() * binormal)) / EXTENT);
        }
    }
    let at = |i: u32, j: u32| (i % along) * around + j % around;
    let mut tris = Vec::with_capacity(2 * (along * around) as usize);
    for i in 0..along {
        for j in 0..around {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            tris.push([a, c, b]);
            tris.push([a, d, c]);
        }
    }
    (p, tris)
}
