//! CPU ground truth (DESIGN.md §2): a ray tracer over the very triangles the GPU draws, for the
//! very camera rays the rasterizer samples. It finds each pixel's visible surface itself and
//! estimates V there, so it is an independent check of the GPU `reference`.
//!
//! - [`TraceScene::visibility`]: V exactly as defined, by stratified shadow rays uniform in the
//!   solid angle of the light sphere.
//! - [`TraceScene::parker`]: Parker, Shirley & Smits' single-sample soft shadows.

mod parker;

use glam::{Vec2, Vec3};
use parry3d::query::{Ray, RayCast};
use parry3d::shape::{CompositeShapeRef, TriMesh};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::frame::Surfaces;
use crate::geometry::{CameraProjection, point_like};
use crate::scene::{Ground, Light, Scene};

/// A visibility image and the surfaces it was estimated at.
#[derive(Clone, Debug)]
pub struct TracedImage {
    /// V in [0, 1], row-major, row 0 at the top.
    pub visibility: Vec<f32>,
    pub surfaces: Surfaces,
}

/// World-space triangles of one scene, with acceleration structures.
pub struct TraceScene {
    /// Every object: what camera rays hit, besides the ground.
    everything: Option<TriMesh>,
    /// Object index of each triangle of `everything`.
    object_of: Vec<u32>,
    /// The ground as the exact plane it is (object index `receives.len() - 1`): two triangles
    /// a million times wider than the casters would place every hit on them metres off.
    ground: Option<Ground>,
    receives: Vec<bool>,
    /// The casters' triangles: what shadow rays test.
    casters: Option<TriMesh>,
    /// Object index of each caster triangle.
    caster_object_of: Vec<u32>,
    /// Casters that are exact spheres (centre, radius), by object index.
    spheres: Vec<Option<(Vec3, f32)>>,
    /// Which objects cast, by object index.
    casts: Vec<bool>,
}

/// Offset of a shadow ray's origin off its surface, relative to the coordinates that place the
/// hit (f32 resolves 1.2e-7 of them): local, so a wide ground or far objects do not lift it.
const LIFT: f32 = 1e-5;

struct Triangles {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    object_of: Vec<u32>,
}

impl Triangles {
    fn new() -> Self {
        Triangles { positions: Vec::new(), indices: Vec::new(), object_of: Vec::new() }
    }

    fn push(&mut self, object: u32, positions: impl IntoIterator<Item = Vec3>, triangles: &[[u32; 3]]) {
        let base = self.positions.len() as u32;
        self.positions.extend(positions);
        self.indices.extend(triangles.iter().map(|t| t.map(|i| base + i)));
        self.object_of.extend(std::iter::repeat_n(object, triangles.len()));
    }

    fn mesh(self, what: &str) -> Result<Option<(TriMesh, Vec<u32>)>> {
        if self.indices.is_empty() {
            return Ok(None);
        }
        let mesh = TriMesh::new(self.positions, self.indices)
            .map_err(|e| Error::Invalid(format!("ray tracer: cannot build the {what} mesh: {e:?}")))?;
        Ok(Some((mesh, self.object_of)))
    }
}

impl TraceScene {
    pub fn new(scene: &Scene) -> Result<Self> {
        let (mut all, mut casters) = (Triangles::new(), Triangles::new());
        let mut receives = Vec::new();
        let mut spheres = Vec::new();
        let mut casts = Vec::new();
        for (i, o) in scene.objects.iter().enumerate() {
            let model = o.transform.matrix();
            let world: Vec<Vec3> = o.mesh.positions.iter().map(|p| model.transform_point3(*p)).collect();
            all.push(i as u32, world.iter().copied(), &o.mesh.triangles);
            if o.casts {
                casters.push(i as u32, world, &o.mesh.triangles);
            }
            receives.push(o.receives);
            casts.push(o.casts);
            spheres.push(o.sphere().filter(|_| o.casts));
        }
        if scene.ground.is_some() {
            receives.push(true);
            casts.push(false);
        }
        let (everything, object_of) = all.mesh("scene")?.unzip();
        if everything.is_none() && scene.ground.is_none() {
            return Err(Error::Invalid("ray tracer: the scene has nothing to trace".into()));
        }
        let (casters, caster_object_of) = casters.mesh("caster")?.unzip();
        Ok(TraceScene {
            everything,
            object_of: object_of.unwrap_or_default(),
            ground: scene.ground,
            receives,
            casters,
            caster_object_of: caster_object_of.unwrap_or_default(),
            spheres,
            casts,
        })
    }

    /// The surface each camera pixel sees (the ray through its centre) and `shade` evaluated
    /// there, in parallel over rows. `shade` gets the point lifted off the surface towards the
    /// camera, the [`Surface`] and the pixel's index. `progress` is told of every finished row.
    pub fn render(
        &self,
        camera: &CameraProjection,
        width: u32,
        height: u32,
        shade: impl Fn(Surface, usize) -> f32 + Sync,
        progress: &(dyn Fn() + Sync),
    ) -> TracedImage {
        let n = width as usize * height as usize;
        let mut visibility = vec![1.0; n];
        let mut depth = vec![f32::INFINITY; n];
        let mut normal = vec![Vec3::ZERO; n];
        let mut receives = vec![false; n];
        let mut cast = vec![false; n];
        let row = width as usize;
        visibility
            .par_chunks_mut(row)
            .zip(depth.par_chunks_mut(row))
            .zip(normal.par_chunks_mut(row))
            .zip(receives.par_chunks_mut(row))
            .zip(cast.par_chunks_mut(row))
            .enumerate()
            .for_each(|(y, ((((v_row, d_row), n_row), r_row), c_row))| {
                for x in 0..width as usize {
                    let index = y * width as usize + x;
                    let uv = Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
                    let (origin, dir) = camera.ray(uv);
                    let Some(hit) = self.camera_hit(origin, dir) else { continue };
                    let p = origin + dir * hit.t;
                    d_row[x] = (p - camera.position).dot(camera.forward);
                    let facing = if hit.facet.dot(dir) > 0.0 { -hit.facet } else { hit.facet };
                    n_row[x] = facing;
                    if !self.receives[hit.object] {
                        continue;
                    }
                    r_row[x] = true;
                    let caster = self.casts[hit.object];
                    c_row[x] = caster;
                    let lift = LIFT * (p.abs().max_element() + hit.t + hit.extent).max(f32::MIN_POSITIVE);
                    let surface = Surface { point: p + facing * lift, solid_side: caster.then_some(facing) };
                    v_row[x] = shade(surface, index);
                }
                progress();
            });
        TracedImage { visibility, surfaces: Surfaces { depth, normal, receives, casts: cast } }
    }

    /// The nearest surface along the camera ray from `origin` along unit `dir`.
    fn camera_hit(&self, origin: Vec3, dir: Vec3) -> Option<Hit> {
        let ray = Ray::new(origin, dir);
        let object = self.everything.as_ref().and_then(|m| {
            let (tri, t) = CompositeShapeRef(m).cast_local_ray(&ray, f32::MAX, false)?;
            let triangle = m.triangle(tri);
            let extent = (triangle.b - triangle.a).abs().max((triangle.c - triangle.a).abs()).max_element();
            let facet = triangle.normal().unwrap_or(-dir);
            Some(Hit { t, facet, object: self.object_of[tri as usize] as usize, extent })
        });
        let ground = self.ground.and_then(|g| {
            let t = (g.height - origin.y) / dir.y;
            let p = origin + dir * t;
            let inside = t > 0.0 && p.x.abs() <= g.half_size && p.z.abs() <= g.half_size;
            inside.then(|| Hit { t, facet: Vec3::Y, object: self.receives.len() - 1, extent: 0.0 })
        });
        match (object, ground) {
            (Some(o), Some(g)) => Some(if g.t < o.t { g } else { o }),
            (o, g) => o.or(g),
        }
    }

    /// Whether a caster crosses the segment from `origin` along unit `dir` for `length`.
    fn blocked(&self, origin: Vec3, dir: Vec3, length: f32) -> bool {
        self.casters.as_ref().is_some_and(|c| c.intersects_local_ray(&Ray::new(origin, dir), length))
    }

    /// Whether a shadow ray from `s` along unit `dir` is blocked within `length`: by the
    /// caster the surface belongs to when `dir` leaves on its solid side (exactly, with no
    /// dependence on the lift off the surface), else by any caster on the way.
    fn shadow_ray_blocked(&self, s: Surface, dir: Vec3, length: f32) -> bool {
        s.solid_side.is_some_and(|n| n.dot(dir) <= 0.0) || self.blocked(s.point, dir, length)
    }

    /// V at `s`: the unblocked fraction of the light sphere's solid angle, from `samples`
    /// directions uniform in that solid angle (a cone: cos θ uniform in [cos θ_max, 1]),
    /// stratified in cos θ and spread in azimuth by the golden angle, with a per-`seed` jitter.
    pub fn visibility(&self, s: Surface, light: &Light, samples: usize, seed: u64) -> f32 {
        let p = s.point;
        let to_center = light.position - p;
        let d = to_center.length();
        if point_like(light.position, light.radius) {
            return if self.shadow_ray_blocked(s, to_center / d, d) { 0.0 } else { 1.0 };
        }
        if d <= light.radius {
            return 1.0; // inside the light: nothing can block all of it
        }
        let axis = to_center / d;
        let (u, v) = axis.any_orthonormal_pair();
        // 1 − cos θ_max from sin θ_max = r / d, without the cancellation of 1 − cos: exact for
        // lights a million times smaller than their distance and for those nearly as large.
        let (r, d64) = (light.radius as f64, d as f64);
        let sin2 = (r / d64).powi(2);
        let one_minus_cos_max = (sin2 / (1.0 + (1.0 - sin2).sqrt())) as f32;
        // Distance from p to the sphere's near side along `dir` (for the ray length): the near
        // root of t² − 2bt + (d − r)(d + r) = 0, as (d² − r²) / (b + √(b² − d² + r²)).
        let c2 = ((d64 - r) * (d64 + r)) as f32;
        let mut rng = Rng::new(seed);
        let phi0 = rng.next() * std::f32::consts::TAU;
        let golden_angle = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
        let lit = (0..samples)
            .filter(|&i| {
                let one_minus_cos = one_minus_cos_max * (i as f32 + rng.next()) / samples as f32;
                let cos = 1.0 - one_minus_cos;
                let sin = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
                let phi = phi0 + golden_angle * i as f32;
                let dir = cos * axis + sin * (phi.cos() * u + phi.sin() * v);
                let b = dir.dot(to_center);
                let to_light = c2 / (b + (b * b - c2).max(0.0).sqrt());
                !self.shadow_ray_blocked(s, dir, to_light)
            })
            .count();
        lit as f32 / samples as f32
    }
}

/// A camera ray's hit: distance, facet normal, object index, and the size of what was hit
/// (a triangle's coordinates, which limit how exactly its hit is placed).
struct Hit {
    t: f32,
    facet: Vec3,
    object: usize,
    extent: f32,
}

/// A point where V is estimated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// On the surface, lifted a hair off it towards the viewer.
    pub point: Vec3,
    /// For a caster's own surface, its facet normal on the viewer's side: light from behind
    /// the facet's plane is blocked by the caster itself. `None` for surfaces that cast nothing.
    pub solid_side: Option<Vec3>,
}

impl Surface {
    /// A point in free space, or on a surface that casts no shadow (the ground).
    pub fn free(point: Vec3) -> Self {
        Surface { point, solid_side: None }
    }
}

/// SplitMix64: a small, seedable generator (the tracer must give the same image every run).
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03)
    }

    /// Uniform in [0, 1).
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
}
