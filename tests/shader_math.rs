//! The corners' arithmetic as the shaders compute it (`glsl/common/corners.glsl`, run by
//! `glsl/checks/corners.comp`), against the same quantities computed here in f64: the inverse of
//! the disk-edge curve, which both centred techniques write near corners, and the part of the
//! light's disk two edges' lines leave, which their corners are. With validation on.

mod common;

use ash::vk;
use common::{context, finish_context};
use gpu_allocator::MemoryLocation;
use softshadow::gpu::{
    Buffer, BufferAccess, Descriptor, FrameRing, Pipeline, Semaphores, buffer_barrier, dispatch, shaders,
};
use std::f64::consts::PI;

/// One input of corners.comp: v for disk_below_inverse; d1, d2 and delta for disk_in_both.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Input {
    v: f32,
    d1: f32,
    d2: f32,
    delta: f32,
}

/// Runs corners.comp over `inputs` and returns (disk_below_inverse(v), disk_in_both) for each.
fn on_the_gpu(inputs: &[Input]) -> Vec<[f32; 2]> {
    let ctx = context();
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let bytes: &[u8] = bytemuck::cast_slice(inputs);
    let mut input = Buffer::new(&ctx, "inputs", bytes.len() as u64, usage, MemoryLocation::CpuToGpu).unwrap();
    input.write(0, bytes);
    let output = Buffer::new(&ctx, "outputs", 8 * inputs.len() as u64, usage, MemoryLocation::GpuToCpu).unwrap();
    let pipeline = Pipeline::compute(&ctx, "corners", &shaders::CHECKS_CORNERS_COMP, &[]).unwrap();
    let mut ring = FrameRing::new(&ctx).unwrap();
    let (frame, _) = ring.begin(&ctx).unwrap();
    let (slot, cmd) = (frame.slot, frame.cmd);
    pipeline.bind(&ctx, cmd, &[Descriptor::Buffer(input.range()), Descriptor::Buffer(output.range())]).unwrap();
    dispatch(&ctx, cmd, inputs.len() as u32);
    buffer_barrier(&ctx, cmd, BufferAccess::COMPUTE_WRITE, BufferAccess::HOST_READ);
    ring.submit(&ctx, slot, &Semaphores::NONE).unwrap();
    ring.drain(&ctx).unwrap();
    let results = bytemuck::cast_slice::<u8, [f32; 2]>(&output.read()[..8 * inputs.len()]).to_vec();
    ring.destroy(&ctx);
    pipeline.destroy(&ctx);
    input.destroy(&ctx);
    output.destroy(&ctx);
    finish_context(ctx);
    results
}

/// The fraction of the unit disk below the chord at h from its centre (disk.glsl).
fn disk_below(h: f64) -> f64 {
    let h = h.clamp(-1.0, 1.0);
    1.0 - (h.acos() - h * (1.0 - h * h).sqrt()) / PI
}

/// The fraction of the unit disk in u·x ≥ d for both lines, u1 = (1, 0) and u2 at `delta`,
/// integrated across u1: at x = cos θ the disk's chord is |y| ≤ sin θ, which the second line
/// cuts to an interval, and the area is that length over dx = sin θ dθ, θ from 0 to acos d1
/// (the midpoint rule in 100 000 steps: within 1e-7 of the disk, the length's kinks included).
fn disk_in_both(d1: f64, d2: f64, delta: f64) -> f64 {
    const STEPS: usize = 100_000;
    let (cos, sin) = (delta.cos(), delta.sin());
    let end = d1.clamp(-1.0, 1.0).acos();
    let step = end / STEPS as f64;
    let length = |theta: f64| {
        let (x, half) = (theta.cos(), theta.sin());
        // Where on the chord cos·x + sin·y = d2.
        let at = (d2 - cos * x) / sin;
        let (lo, hi) = if sin > 0.0 {
            (at.max(-half), half)
        } else if sin < 0.0 {
            (-half, at.min(half))
        } else if cos * x >= d2 {
            (-half, half)
        } else {
            (0.0, 0.0)
        };
        (hi - lo).max(0.0)
    };
    let area: f64 = (0..STEPS).map(|k| (k as f64 + 0.5) * step).map(|t| length(t) * t.sin() * step).sum();
    area / PI
}

/// Inputs spread over the functions' ranges: v across [0, 1] and toward both ends, where the
/// inverse's slope is unbounded; lines from missing the disk to halving it, at every angle.
fn inputs() -> Vec<Input> {
    let mut seed = 0x2545_f491_u32;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    };
    let ends = (1..=12).flat_map(|k| {
        let e = 10f32.powi(-k);
        [e, 1.0 - e]
    });
    let v = (0..=2048).map(|k| k as f32 / 2048.0).chain(ends);
    v.map(|v| Input {
        v,
        d1: 2.4 * next() - 1.2,
        d2: 2.4 * next() - 1.2,
        delta: (2.0 * next() - 1.0) * std::f32::consts::PI,
    })
    .collect()
}

/// The inverse is the curve's to within 5e-6, a third of the 16-bit step the smoothie buffer
/// and the plateau texture store it in, with its ends exact (an alpha of ±1 is lit or umbra,
/// which the smoothie pass and the resolve test for) and never decreasing.
#[test]
fn the_disk_edge_curve_s_inverse_is_its_inverse() {
    let inputs = inputs();
    let results = on_the_gpu(&inputs);
    let mut pairs: Vec<(f32, f32)> = inputs.iter().zip(&results).map(|(i, &[u, _])| (i.v, u)).collect();
    for &(v, u) in &pairs {
        assert!((-1.0..=1.0).contains(&u), "disk_below_inverse({v}) = {u}, outside [-1, 1]");
        let back = disk_below(f64::from(u));
        assert!((back - f64::from(v)).abs() <= 5e-6, "disk_below(disk_below_inverse({v}) = {u}) = {back}");
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in pairs.windows(2) {
        assert!(w[1].1 >= w[0].1, "decreasing: {} at v = {}, {} at v = {}", w[0].1, w[0].0, w[1].1, w[1].0);
    }
    for (v, exact) in [(0.0, -1.0), (0.5, 0.0), (1.0, 1.0)] {
        let &(_, u) = pairs.iter().find(|p| p.0 == v).expect("v among the inputs");
        assert_eq!(u, exact, "disk_below_inverse({v})");
    }
}

/// The corner's visibility, Green's theorem over the region's arcs and chords, is the area the
/// integral across the disk gives, to 1e-3 of the light (a quarter of an 8-bit step).
#[test]
fn two_lines_leave_the_part_of_the_disk_the_integral_does() {
    let inputs = inputs();
    let results = on_the_gpu(&inputs);
    let worst = inputs
        .iter()
        .zip(&results)
        .map(|(i, &[_, area])| {
            let truth = disk_in_both(f64::from(i.d1), f64::from(i.d2), f64::from(i.delta));
            ((f64::from(area) - truth).abs(), i.d1, i.d2, i.delta, area, truth)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap();
    assert!(
        worst.0 <= 1e-3,
        "disk_in_both(d1 {}, d2 {}, delta {}) = {}, the integral's {}",
        worst.1,
        worst.2,
        worst.3,
        worst.4,
        worst.5
    );
}
