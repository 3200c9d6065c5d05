//! `shadow-volume`: stencil shadow volumes (Crow 1977; DDJ 2005 "shadow volumes"; Komura
//! "shadow volume"): exact hard shadows from a point, soft by accumulating N of them.
//!
//! Per light point, in the papers' order: `silhouettes` (on the CPU, the shared silhouette
//! code, cached while nothing moves, a CPU span of the timings; or with `gpu_silhouettes` a
//! compute pass, [`GpuVolumes`], a GPU one, not recorded while nothing moves under one light
//! point), `volumes` (the silhouette edges extruded to infinity,
//! w = 0, counted by two-sided stencil in one pass), `caps` (z-fail only: the light caps, the
//! caster's light-facing triangles, and the dark caps at infinity), then the stencil resolved
//! into V: 0 is lit, anything else shadowed ([`Accumulation`]), and `resolve`.
//!
//! Reach. Perspective views extrude to infinity (w = 0); orthographic ones, where points at
//! infinity along the view axis collapse into one and the dark caps would vanish, extrude far
//! past every receiver instead ([`FINITE_REACH`]).
//!
//! Depth. The volumes test against the camera prepass's depth, copied bit for bit into a
//! depth-stencil target of our own (`glsl/shadow_volume/depth.frag`): one full-screen pass,
//! cheaper than drawing the scene again, and exactly the surfaces V is reported at. Depth
//! clamping (the device's `depthClamp`) keeps volumes whole past the far plane and in front of
//! the near one, so no volume is ever too short or too long, with the camera's own fitted
//! projection, perspective or orthographic (an infinite far plane would serve only the first).
//!
//! Counting. z-pass (front faces in front of the surface add, back faces subtract) is wrong
//! where a view ray starts inside a volume; z-fail (Carmack's reverse: count what lies behind,
//! with both caps) is not. With depth clamping the near plane cuts nothing, so what remains is
//! the view rays' start, the eye: the engine picks z-fail exactly when the eye can lie in a
//! caster's shadow (orthographic rays start infinitely far behind, outside every volume),
//! `counting` forces either. Deviation from the papers' "near plane" test: with the near plane
//! unclipped it is the eye, not the near plane, that matters. No depth
//! bias anywhere: self-shadowing comes from the counts alone (light caps have the surface's
//! depth to the bit, `glsl/shadow_volume/volume.vert`).
//!
//! Shadow mesh (issue 18, `shadow_mesh_error`; the DDJ's "separate shadowing and drawing
//! models"): a caster that receives no shadow casts its volumes from the simplified mesh
//! (`Mesh::shadow_mesh`, within the knob's texels of the light's view), sides, caps, nesting
//! bound and two-sided choice all from that one mesh, so every volume stays closed and the
//! counts whole, z-fail included (the simplifier keeps a closed mesh closed, or the full mesh
//! casts). A caster that receives keeps its own mesh: the counts start at its drawn surface
//! with no bias, and a simplified light cap standing over that surface would put the caster's
//! own lit side inside its volume, shadowing it in patches.
//!
//! Counts beyond the stencil's bits: volumes are counted modulo 128 in the low 7 bits, casters
//! taken in groups whose nesting bounds (`nesting_bound`) sum to at most 127, and each group's
//! non-zero pixels marked in the top bit before the next group counts. One caster alone that
//! could nest more than 127 times in itself is the one case left to the modulo.

use std::sync::Arc;
use std::time::Instant;

use ash::vk;
use bytemuck::cast_slice;
use glam::{Mat4, Vec3, Vec4};

use super::accumulation::{Accumulation, SAMPLES, StencilRule, end_span, span, stencil};
use super::knobs::{Knob, Params};
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, SweepKnobs, TechniqueInfo};
use super::shadow_mesh::{SHADOW_MESH_ERROR, shadow_mesh};
use super::shadow_volume_gpu::{GpuVolumes, PARTS};
use super::{Technique, clear_visibility};
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::frame::interface::SampleView;
use crate::geometry::shadow_volume::{ShadowVolume, eye_may_be_in_shadow, is_open, nesting_bound, shadow_volume};
use crate::geometry::silhouette::Caster;
use crate::geometry::{Aabb, Projection};
use crate::gpu::{
    Access, Attachment, Context, DepthState, Descriptor, FRAMES_IN_FLIGHT, Guard, PerFrame, Pipeline, PipelineDesc,
    RenderPass, Target, TargetDesc, VertexInput, draw_fullscreen, draw_vertices, ensure, shaders, transition,
};
use crate::scene::{Mesh, MeshId, Object};
use crate::shader_constants::VOLUME_VERTEX_FLOATS;

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "shadow-volume",
    summary: "stencil shadow volumes: silhouettes extruded to infinity, z-pass or z-fail; N accumulated for soft",
    kind: Kind::Realtime,
    knobs: &[SAMPLES, COUNTING, GPU_SILHOUETTES, SHADOW_MESH_ERROR],
    create: |ctx, _, visibility| Ok(Box::new(ShadowVolumes::new(ctx, visibility)?)),
    bench: &[
        &[],
        &[("counting", "z-fail")],
        &[("gpu_silhouettes", "on")],
        &[("samples", "16")],
        &[("shadow_mesh_error", "1")],
    ],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

const COUNTING: Knob = Knob::choice(
    "counting",
    0.0,
    &["auto", "z-pass|zpass", "z-fail|zfail"],
    "auto: z-fail where a view ray can start in shadow, else z-pass; or always z-pass, or z-fail",
);

const GPU_SILHOUETTES: Knob = Knob::switch(
    "gpu_silhouettes",
    "on: silhouettes, volumes and caps built by a compute pass, drawn indirectly; off: on the CPU",
);

/// The stencil bits that count; the top one marks the pixels an earlier group shadowed.
const COUNT_MASK: u32 = 0x7F;
const SHADOWED_BY_A_GROUP: u32 = 0x80;
/// Orthographic views: how far volumes reach, in multiples of the farthest scene point's
/// distance from the light (a dark cap's chord stays beyond the scene up to 170° of caster).
const FINITE_REACH: f32 = 1e3;

/// What a caster's volumes were built from: rebuilt only when any of it changes.
#[derive(Clone, Debug, PartialEq)]
struct VolumeKey {
    mesh: MeshId,
    model: Mat4,
    points: Vec<Vec3>,
}

/// What a frame slot's volume vertices were written from: every object's volumes, the groups,
/// the objects' indices, the buffer's size (a grown buffer holds nothing yet).
#[derive(Clone, Debug, PartialEq)]
struct Written {
    volumes: Vec<Option<VolumeKey>>,
    groups: Vec<Vec<usize>>,
    instances: Vec<u32>,
    capacity: u64,
}

/// What a mesh's volumes need, found once: whether it takes the two-sided construction, and
/// its nesting bound.
#[derive(Clone, Copy, Debug)]
struct MeshFacts {
    two_sided: bool,
    bound: u32,
}

/// One group's vertex ranges in this frame's volume buffer: first, then sides, caps, turned.
type GroupRange = (u32, [u32; PARTS]);

pub struct ShadowVolumes {
    depth_copy: Pipeline,
    /// Counting pipelines: z-pass, z-fail, z-fail for the turned light caps.
    zpass: Pipeline,
    zfail: Pipeline,
    zfail_turned: Pipeline,
    mark: Pipeline,
    accumulation: Accumulation,
    format: vk::Format,
    vertices: Option<PerFrame>,
    /// Per frame slot: what its copy of `vertices` holds, and its ranges.
    written: [Option<(Written, Vec<GroupRange>)>; FRAMES_IN_FLIGHT],
    depth_stencil: Option<Target>,
    /// Per scene object: its volumes, one per light point, and what they were built from.
    volumes: Vec<Option<(VolumeKey, Vec<ShadowVolume>)>>,
    facts: Vec<(MeshId, MeshFacts)>,
    /// Built on first use of `gpu_silhouettes`.
    gpu: Option<GpuVolumes>,
}

impl ShadowVolumes {
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let format = ctx.depth_stencil_format();
        let vert = &shaders::SHADOW_VOLUME_VOLUME_VERT;
        let frag = &shaders::SHADOW_VOLUME_STENCIL_FRAG;
        let fullscreen = &shaders::COMMON_FULLSCREEN_VERT;
        let masks = (0xFF, COUNT_MASK);
        let (keep, up, down) =
            (vk::StencilOp::KEEP, vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP);
        let always = vk::CompareOp::ALWAYS;
        let counting = |name, front: vk::StencilOpState, back: vk::StencilOpState| {
            let desc = PipelineDesc::new(name, vert, frag)
                .vertex_input(VertexInput::Floats(&[3, 1, 1]))
                // Reverse Z: in front of the surface is greater.
                .depth(DepthState::test_only(format, vk::CompareOp::GREATER))
                .depth_clamp()
                .stencil(front, back);
            Pipeline::new(ctx, &desc)
        };
        // z-pass: what passes the depth test counts; z-fail: what fails it, with signs swapped.
        let zpass = Guard::new(
            ctx,
            counting("volumes", stencil(always, 0, masks, up, keep), stencil(always, 0, masks, down, keep))?,
        );
        let zfail_front = stencil(always, 0, masks, keep, down);
        let zfail_back = stencil(always, 0, masks, keep, up);
        let zfail = Guard::new(ctx, counting("volumes", zfail_front, zfail_back)?);
        let zfail_turned = Guard::new(ctx, counting("caps", zfail_back, zfail_front)?);
        let marked = stencil(vk::CompareOp::NOT_EQUAL, 0, (COUNT_MASK, 0xFF), vk::StencilOp::REPLACE, keep);
        let marked = vk::StencilOpState { reference: SHADOWED_BY_A_GROUP, ..marked };
        let mark = PipelineDesc::new("mark", fullscreen, frag)
            .depth(DepthState::test_only(format, always))
            .stencil(marked, marked);
        let mark = Guard::new(ctx, Pipeline::new(ctx, &mark)?);
        let copy = PipelineDesc::new("depth", fullscreen, &shaders::SHADOW_VOLUME_DEPTH_FRAG)
            .depth(DepthState::test_write(format, always));
        let depth_copy = Guard::new(ctx, Pipeline::new(ctx, &copy)?);
        let rule = StencilRule {
            lit: (vk::CompareOp::EQUAL, 0),
            shadowed: (vk::CompareOp::NOT_EQUAL, 0, vk::StencilOp::ZERO),
        };
        let accumulation = Accumulation::new(ctx, format, visibility, rule)?;
        Ok(ShadowVolumes {
            depth_copy: depth_copy.keep(),
            zpass: zpass.keep(),
            zfail: zfail.keep(),
            zfail_turned: zfail_turned.keep(),
            mark: mark.keep(),
            accumulation,
            format,
            vertices: None,
            written: Default::default(),
            depth_stencil: None,
            volumes: Vec::new(),
            facts: Vec::new(),
            gpu: None,
        })
    }

    /// The mesh `o` casts its volumes from: the simplified shadow mesh where
    /// `shadow_mesh_error` asks for it and `o` receives no shadow, else its own. A receiving
    /// caster keeps its own: the volume's light caps must lie on the drawn surface (the counts
    /// start there, no bias), and a simplified cap standing over the surface would put the
    /// caster's own lit side inside its volume.
    fn volume_mesh(o: &Object, light: Vec3, params: &Params) -> Arc<Mesh> {
        if o.receives { o.mesh.clone() } else { shadow_mesh(o, light, params) }
    }

    /// What every caster's mesh needs, found the first time it is seen; forgotten once no
    /// caster casts from it.
    fn learn_meshes(&mut self, meshes: &[Option<Arc<Mesh>>]) {
        self.facts.retain(|(id, _)| meshes.iter().flatten().any(|m| m.id() == *id));
        for m in meshes.iter().flatten() {
            if self.facts.iter().any(|(id, _)| *id == m.id()) {
                continue;
            }
            let caster = Caster { positions: &m.positions, triangles: &m.triangles, adjacency: &m.adjacency };
            let two_sided = is_open(&caster);
            self.facts.push((m.id(), MeshFacts { two_sided, bound: nesting_bound(&caster, two_sided) }));
        }
    }

    fn facts_of(&self, mesh: MeshId) -> MeshFacts {
        self.facts.iter().find(|(id, _)| *id == mesh).expect("learnt every caster's mesh").1
    }

    /// Every caster's volumes from every point, rebuilt only for casters or lights that moved.
    fn build(&mut self, frame: &FrameInputs<'_>, meshes: &[Option<Arc<Mesh>>], points: &[Vec3]) {
        let objects = &frame.scene.objects;
        self.volumes.resize_with(objects.len(), || None);
        let facts = &self.facts;
        for ((o, m), cached) in objects.iter().zip(meshes).zip(&mut self.volumes) {
            let Some(m) = m else {
                *cached = None;
                continue;
            };
            let model = o.transform.matrix();
            let key = VolumeKey { mesh: m.id(), model, points: points.to_vec() };
            if cached.as_ref().is_some_and(|(k, _)| *k == key) {
                continue;
            }
            // Facing from the face planes built with the mesh against each point taken into
            // object space: the volumes are vertex numbers, drawn from the object-space
            // positions, so a moved caster transforms no vertex here.
            let caster = Caster { positions: &m.positions, triangles: &m.triangles, adjacency: &m.adjacency };
            let two_sided = facts.iter().any(|(id, f)| *id == m.id() && f.two_sided);
            let volumes =
                points.iter().map(|q| shadow_volume(&caster, &m.planes.light_facing(&model, *q), two_sided)).collect();
            *cached = Some((key, volumes));
        }
    }

    /// Casters in groups whose nesting bounds sum to at most [`COUNT_MASK`].
    fn groups(&self, meshes: &[Option<Arc<Mesh>>]) -> Vec<Vec<usize>> {
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut room = 0;
        for (i, m) in meshes.iter().enumerate().filter_map(|(i, m)| Some((i, m.as_ref()?))) {
            let bound = self.facts_of(m.id()).bound.min(COUNT_MASK);
            if groups.is_empty() || bound > room {
                groups.push(Vec::new());
                room = COUNT_MASK;
            }
            groups.last_mut().expect("pushed").push(i);
            room -= bound;
        }
        groups
    }

    /// The volume vertices of every point and group, and each one's ranges.
    fn vertices(
        &self,
        frame: &FrameInputs<'_>,
        meshes: &[Option<Arc<Mesh>>],
        points: usize,
        groups: &[Vec<usize>],
    ) -> (Vec<f32>, Vec<GroupRange>) {
        let triangles: usize = (self.volumes.iter().flatten())
            .flat_map(|(_, v)| v)
            .map(|v| v.sides.len() + v.far_caps.len() + v.near_caps.len() + v.turned_caps.len())
            .sum();
        let mut out = Vec::with_capacity(3 * VOLUME_VERTEX_FLOATS * triangles);
        let mut ranges = Vec::with_capacity(points * groups.len());
        for p in 0..points {
            for group in groups {
                let first = (out.len() / VOLUME_VERTEX_FLOATS) as u32;
                let mut counts = [0u32; 3];
                for (part, count) in counts.iter_mut().enumerate() {
                    let start = out.len();
                    for &i in group {
                        let mesh = meshes[i].as_ref().expect("a caster");
                        let object = frame.draws[i].instance as f32;
                        let volume = &self.volumes[i].as_ref().expect("built for every caster").1[p];
                        let mut put = |vertex: u32, far: bool| {
                            let q = mesh.positions[vertex as usize];
                            out.extend_from_slice(&[q.x, q.y, q.z, far as u32 as f32, object]);
                        };
                        match part {
                            0 => volume.sides.iter().flatten().for_each(|c| put(c.vertex, c.at_infinity)),
                            1 => {
                                volume.far_caps.iter().flatten().for_each(|c| put(c.vertex, c.at_infinity));
                                volume.near_caps.iter().flatten().for_each(|&v| put(v, false));
                            }
                            _ => volume.turned_caps.iter().flatten().for_each(|&v| put(v, false)),
                        }
                    }
                    *count = ((out.len() - start) / VOLUME_VERTEX_FLOATS) as u32;
                }
                ranges.push((first, counts));
            }
        }
        (out, ranges)
    }

    /// How far volumes reach past their caster: `None`, to infinity (w = 0), for a perspective
    /// camera. An orthographic one sees points at infinity along its axis as one point, so its
    /// dark caps would vanish; there the volumes end [`FINITE_REACH`] scene sizes out, far
    /// beyond every receiver, and, depth clamping keeping what lies behind the camera, every
    /// view ray starts outside them: z-pass is exact.
    fn extrusion(frame: &FrameInputs<'_>, points: &[Vec3]) -> Option<f32> {
        let Projection::Orthographic { .. } = frame.scene.camera.projection else { return None };
        let scene = frame.draws.iter().fold(Aabb::EMPTY, |b, d| b.union(&d.bounds));
        let far = points.iter().flat_map(|q| scene.corners().map(|c| (c - *q).length())).fold(0.0, f32::max);
        Some(FINITE_REACH * far)
    }

    /// Whether this frame counts by z-fail.
    fn z_fail(frame: &FrameInputs<'_>, params: &Params, points: &[Vec3]) -> bool {
        match params.get(&COUNTING) as u32 {
            1 => false,
            2 => true,
            _ if Self::extrusion(frame, points).is_some() => false,
            _ => {
                let casters: Vec<_> = frame.draws.iter().filter(|d| d.casts).map(|d| d.bounds).collect();
                points.iter().any(|q| eye_may_be_in_shadow(*q, frame.camera.position, &casters))
            }
        }
    }
}

impl Technique for ShadowVolumes {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        if !frame.draws.iter().any(|d| d.casts) || frame.receivers_in_view.is_empty() {
            return clear_visibility(frame, visibility);
        }
        let ctx = frame.ctx;
        let samples = Accumulation::points(frame, params.get(&SAMPLES) as usize);
        let points: Vec<Vec3> = samples.iter().map(|s| s.position).collect();
        let z_fail = Self::z_fail(frame, params, &points);
        let reach = Self::extrusion(frame, &points).unwrap_or(0.0);
        // One shadow mesh per caster for every point: the one for the light's centre, which the
        // error's texels are stated from.
        let light = frame.scene.light.position;
        let meshes: Vec<Option<Arc<Mesh>>> =
            frame.scene.objects.iter().map(|o| o.casts.then(|| Self::volume_mesh(o, light, params))).collect();
        self.learn_meshes(&meshes);
        let groups = self.groups(&meshes);
        let on_gpu = params.is_on(&GPU_SILHOUETTES);
        // The CPU path's ranges; the GPU path's are its draw commands.
        let ranges = if on_gpu {
            let sided: Vec<Vec<(usize, &Mesh, bool)>> = groups
                .iter()
                .map(|g| {
                    g.iter()
                        .map(|&i| {
                            let m = meshes[i].as_deref().expect("a caster");
                            (i, m, self.facts_of(m.id()).two_sided)
                        })
                        .collect()
                })
                .collect();
            let gpu = match &mut self.gpu {
                Some(gpu) => gpu,
                None => self.gpu.insert(GpuVolumes::new(ctx)?),
            };
            gpu.prepare(frame, &points, &sided)?;
            Vec::new()
        } else {
            let start = Instant::now();
            self.build(frame, &meshes, &points);
            // The slot's vertices are written again only when what they hold changed.
            let mut written = Written {
                volumes: self.volumes.iter().map(|v| v.as_ref().map(|(k, _)| k.clone())).collect(),
                groups: groups.clone(),
                instances: frame.draws.iter().map(|d| d.instance).collect(),
                capacity: self.vertices.as_ref().map_or(0, PerFrame::capacity),
            };
            let ranges = match &self.written[frame.slot] {
                Some((w, ranges)) if *w == written => ranges.clone(),
                _ => {
                    let (vertices, ranges) = self.vertices(frame, &meshes, points.len(), &groups);
                    if !vertices.is_empty() {
                        let usage = vk::BufferUsageFlags::VERTEX_BUFFER;
                        let bytes: &[u8] = cast_slice(&vertices);
                        PerFrame::ensure(ctx, &mut self.vertices, "shadow volumes", bytes.len() as u64, usage)?
                            .write(frame.slot, bytes);
                    }
                    written.capacity = self.vertices.as_ref().map_or(0, PerFrame::capacity);
                    self.written[frame.slot] = Some((written, ranges.clone()));
                    ranges
                }
            };
            frame.cpu_spans.push(("silhouettes", start.elapsed().as_secs_f64() * 1e3));
            ranges
        };
        let views: Vec<SampleView> = samples
            .iter()
            .map(|s| (s.position, s.normal.extend(s.weight)))
            .map(|(q, normal)| SampleView {
                transform: frame.camera.view_proj,
                light: q.extend(reach),
                plane: Vec4::ZERO,
                normal,
                pad: [Vec4::ZERO; 9],
            })
            .collect();
        let extent = visibility.extent();
        self.accumulation.prepare(frame, &views, extent)?;
        let desc = TargetDesc::depth_stencil("shadow volume stencil", self.format, extent.width, extent.height);
        ensure(ctx, &mut self.depth_stencil, desc)?;
        let ds = self.depth_stencil.as_mut().expect("ensured");
        let cmd = frame.cmd;
        let timed = points.len() == 1;
        let several = groups.len() > 1;
        // z-pass needs no caps, but for finite volumes (orthographic views) rays from behind
        // the camera cross the dark caps; light caps in front of a surface would hide it, so
        // drawing them as well changes nothing.
        let caps = z_fail || reach > 0.0;
        span(frame, !timed, "accumulate");
        for p in 0..points.len() {
            if let Some(gpu) = self.gpu.as_ref().filter(|g| on_gpu && g.building()) {
                span(frame, timed, "silhouettes");
                gpu.record(frame, p)?;
                end_span(frame, timed);
            }
            let view = Descriptor::Buffer(self.accumulation.view(frame.slot, p));
            let inputs = [Descriptor::Buffer(frame.globals), view, Descriptor::Buffer(frame.objects)];
            let (cpu_vertices, gpu) = (&self.vertices, &self.gpu);
            let draw = |frame: &FrameInputs<'_>, g: usize, part: usize| match ranges.get(p * groups.len() + g) {
                Some(&(first, counts)) => {
                    if let Some(vb) = cpu_vertices {
                        let before: u32 = counts[..part].iter().sum();
                        draw_vertices(ctx, cmd, vb.range(frame.slot), first + before, counts[part]);
                    }
                }
                None => gpu.as_ref().expect("the GPU path").draw(frame, p, g, part),
            };
            for g in 0..groups.len() {
                let first = p == 0 && g == 0;
                span(frame, timed, "volumes");
                transition(ctx, cmd, &mut [(ds, Access::DEPTH_STENCIL_WRITE, first)]);
                let attachment = if first {
                    Attachment::clear_depth_stencil(ds, 0.0, 0)
                } else {
                    Attachment { target: ds, clear: None }
                };
                let pass = RenderPass::begin(ctx, cmd, &[], Some(attachment));
                if first {
                    self.depth_copy.bind(ctx, cmd, &[Descriptor::Image(frame.depth)])?;
                    draw_fullscreen(ctx, cmd);
                }
                let counting = if z_fail { &self.zfail } else { &self.zpass };
                counting.bind(ctx, cmd, &inputs)?;
                draw(frame, g, 0);
                if several && !caps {
                    self.mark.bind(ctx, cmd, &[])?;
                    draw_fullscreen(ctx, cmd);
                }
                pass.end(ctx, cmd);
                end_span(frame, timed);
                if caps {
                    span(frame, timed, "caps");
                    transition(ctx, cmd, &mut [(ds, Access::DEPTH_STENCIL_WRITE, false)]);
                    let pass = RenderPass::begin(ctx, cmd, &[], Some(Attachment { target: ds, clear: None }));
                    counting.bind(ctx, cmd, &inputs)?;
                    draw(frame, g, 1);
                    if z_fail {
                        self.zfail_turned.bind(ctx, cmd, &inputs)?;
                        draw(frame, g, 2);
                    }
                    if several {
                        self.mark.bind(ctx, cmd, &[])?;
                        draw_fullscreen(ctx, cmd);
                    }
                    pass.end(ctx, cmd);
                    end_span(frame, timed);
                }
            }
            span(frame, timed, "accumulate");
            self.accumulation.add(frame, ds, p)?;
            end_span(frame, timed);
        }
        end_span(frame, !timed);
        self.accumulation.resolve(frame, visibility)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        for p in [this.depth_copy, this.zpass, this.zfail, this.zfail_turned, this.mark] {
            p.destroy(ctx);
        }
        this.accumulation.destroy(ctx);
        this.vertices.into_iter().for_each(|b| b.destroy(ctx));
        this.gpu.into_iter().for_each(|g| g.destroy(ctx));
        this.depth_stencil.into_iter().for_each(|t| t.destroy(ctx));
    }
}
