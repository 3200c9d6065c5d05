//! The gpu layer as an embedder or a windowed front end uses it: a device filter, a context on
//! the embedder's handles, wrapped images, depth-stencil targets and semaphore submissions. Every
//! test runs with validation on and fails on any validation error, leaks included.

mod common;

use ash::vk;
use common::embedder::Embedder;
use common::{context, finish_context as finish};
use gpu_allocator::MemoryLocation;
use softshadow::Error;
use softshadow::gpu::{
    Access, Attachment, Buffer, Context, ContextOptions, DeviceFilter, FrameRing, Ownership, RenderPass, Semaphores,
    Target, TargetDesc, copy_to_buffer, copy_to_host, required_device_extensions, required_vulkan13_features,
    transition,
};

const SIDE: u32 = 4;
const TEXELS: usize = (SIDE * SIDE) as usize;
const RGBA8: vk::Format = vk::Format::R8G8B8A8_UNORM;

fn readback(ctx: &Context, bytes: u64) -> Buffer {
    Buffer::new(ctx, "readback", bytes, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu).unwrap()
}

/// Records one frame with `record` and submits it with `semaphores`.
fn submit(ctx: &Context, ring: &mut FrameRing, semaphores: &Semaphores, record: impl FnOnce(vk::CommandBuffer)) {
    let (frame, _) = ring.begin(ctx).unwrap();
    let (slot, cmd) = (frame.slot, frame.cmd);
    record(cmd);
    ring.submit(ctx, slot, semaphores).unwrap();
}

/// Clears `target` (a color target) to `rgba`, discarding what it held.
fn clear(ctx: &Context, cmd: vk::CommandBuffer, target: &mut Target, rgba: [f32; 4]) {
    transition(ctx, cmd, &mut [(target, Access::COLOR_WRITE, true)]);
    RenderPass::begin(ctx, cmd, &[Attachment::clear_color(target, rgba)], None).end(ctx, cmd);
}

/// Copies all of `target` (a color target) to the start of `dst` for the host.
fn read_out(ctx: &Context, cmd: vk::CommandBuffer, target: &mut Target, dst: &Buffer) {
    transition(ctx, cmd, &mut [(target, Access::COPY_READ, false)]);
    copy_to_buffer(ctx, cmd, target, dst, &[target.whole_copy(0)]);
    copy_to_host(ctx, cmd);
}

fn assert_texels(buffer: &Buffer, rgba: [u8; 4]) {
    let texels = &buffer.read()[..TEXELS * 4];
    assert!(texels.chunks(4).all(|t| t == rgba), "expected {rgba:?} everywhere, read {texels:?}");
}

/// An image in memory of its own, made with raw Vulkan as an embedder would.
fn raw_image(ctx: &Context, desc: &TargetDesc) -> (vk::Image, vk::DeviceMemory) {
    let d = ctx.device();
    let ci = vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(desc.format)
        .extent(vk::Extent3D { width: desc.extent.width, height: desc.extent.height, depth: 1 })
        .mip_levels(1)
        .array_layers(1)
        .samples(vk::SampleCountFlags::TYPE_1)
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(desc.usage);
    let image = unsafe { d.create_image(&ci, None) }.unwrap();
    let requirements = unsafe { d.get_image_memory_requirements(image) };
    let memory_props = unsafe { ctx.instance().get_physical_device_memory_properties(ctx.physical_device()) };
    let memory_type = (0..memory_props.memory_type_count)
        .find(|&i| {
            requirements.memory_type_bits & (1 << i) != 0
                && memory_props.memory_types[i as usize].property_flags.contains(vk::MemoryPropertyFlags::DEVICE_LOCAL)
        })
        .expect("a device-local memory type");
    let alloc = vk::MemoryAllocateInfo::default().allocation_size(requirements.size).memory_type_index(memory_type);
    let memory = unsafe { d.allocate_memory(&alloc, None) }.unwrap();
    unsafe { d.bind_image_memory(image, memory, 0) }.unwrap();
    (image, memory)
}

#[test]
fn a_filter_that_rejects_every_queue_family_names_its_requirement() {
    let options = ContextOptions { validation: true, device: None };
    let filter =
        DeviceFilter { supports: &|_, _, _| false, requirement: "passes the test's filter", ..DeviceFilter::HEADLESS };
    match Context::new(&options, &filter) {
        Err(Error::NoDevice(why)) => assert!(why.contains("queue family that passes the test's filter"), "{why}"),
        Err(e) => panic!("expected NoDevice, got {e}"),
        Ok(_) => panic!("a filter rejecting every family must not give a context"),
    }
    let missing = [c"VK_KHR_no_such_extension"];
    let filter = DeviceFilter { instance_extensions: &missing, ..DeviceFilter::HEADLESS };
    let why = Context::new(&options, &filter).err().expect("a missing instance extension").to_string();
    assert!(why.contains("VK_KHR_no_such_extension"), "{why}");
}

#[test]
fn a_headless_context_owns_its_device_and_a_depth_stencil_format() {
    let ctx = context();
    assert_eq!(ctx.ownership(), Ownership::Owned);
    assert!(
        [vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D24_UNORM_S8_UINT].contains(&ctx.depth_stencil_format()),
        "{:?}",
        ctx.depth_stencil_format()
    );
    finish(ctx);
}

/// The wrapped image is cleared through a view the target makes, then read back through a view
/// of the test's, in the state the clear left it; neither target destroys the image.
#[test]
fn a_wrapped_image_is_drawn_and_read_but_not_destroyed() {
    let ctx = context();
    let desc = TargetDesc::color("wrapped", RGBA8, SIDE, SIDE).usage(vk::ImageUsageFlags::TRANSFER_SRC);
    let (image, memory) = raw_image(&ctx, &desc);
    let mut ring = FrameRing::new(&ctx).unwrap();
    let buffer = readback(&ctx, TEXELS as u64 * 4);

    let mut target = Target::wrap(&ctx, desc, image, None, Access::NONE).unwrap();
    submit(&ctx, &mut ring, &Semaphores::NONE, |cmd| clear(&ctx, cmd, &mut target, [0.0, 1.0, 0.0, 1.0]));
    ring.drain(&ctx).unwrap();
    target.destroy(&ctx);

    let view_ci = vk::ImageViewCreateInfo::default()
        .image(image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(RGBA8)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        });
    let view = unsafe { ctx.device().create_image_view(&view_ci, None) }.unwrap();
    let mut target = Target::wrap(&ctx, desc, image, Some(view), Access::COLOR_WRITE).unwrap();
    submit(&ctx, &mut ring, &Semaphores::NONE, |cmd| read_out(&ctx, cmd, &mut target, &buffer));
    ring.drain(&ctx).unwrap();
    target.destroy(&ctx);
    assert_texels(&buffer, [0, 255, 0, 255]);

    // Destroying what the targets did not make must be valid: they left it alive.
    unsafe {
        ctx.device().destroy_image_view(view, None);
        ctx.device().destroy_image(image, None);
        ctx.device().free_memory(memory, None);
    }
    ring.destroy(&ctx);
    buffer.destroy(&ctx);
    finish(ctx);
}

#[test]
fn a_depth_stencil_target_clears_both_aspects() {
    let ctx = context();
    let format = ctx.depth_stencil_format();
    let desc = TargetDesc::depth_stencil("depth-stencil", format, SIDE, SIDE).usage(vk::ImageUsageFlags::TRANSFER_SRC);
    assert_eq!(desc.aspect(), vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL);
    let mut target = Target::new(&ctx, desc).unwrap();
    let mut ring = FrameRing::new(&ctx).unwrap();
    // Depth copies out as 4 bytes a texel in both formats, stencil as 1.
    let buffer = readback(&ctx, TEXELS as u64 * 5);
    let stencil_offset = TEXELS as u64 * 4;
    submit(&ctx, &mut ring, &Semaphores::NONE, |cmd| {
        transition(&ctx, cmd, &mut [(&mut target, Access::DEPTH_STENCIL_WRITE, true)]);
        RenderPass::begin(&ctx, cmd, &[], Some(Attachment::clear_depth_stencil(&target, 0.25, 7))).end(&ctx, cmd);
        // Through the layout a stencil-tested pass reads the count in, contents kept.
        transition(&ctx, cmd, &mut [(&mut target, Access::DEPTH_STENCIL_READ, false)]);
        transition(&ctx, cmd, &mut [(&mut target, Access::COPY_READ, false)]);
        let regions = [
            target.aspect_copy(vk::ImageAspectFlags::DEPTH, 0),
            target.aspect_copy(vk::ImageAspectFlags::STENCIL, stencil_offset),
        ];
        copy_to_buffer(&ctx, cmd, &target, &buffer, &regions);
        copy_to_host(&ctx, cmd);
    });
    ring.drain(&ctx).unwrap();
    let bytes = buffer.read();
    for texel in bytes[..stencil_offset as usize].chunks(4) {
        let raw = u32::from_le_bytes(texel.try_into().unwrap());
        let depth = match format {
            vk::Format::D32_SFLOAT_S8_UINT => f32::from_bits(raw),
            _ => (raw & 0xFF_FFFF) as f32 / 0xFF_FFFF as f32,
        };
        assert!((depth - 0.25).abs() < 1e-6, "depth {depth}");
    }
    let stencil = &bytes[stencil_offset as usize..][..TEXELS];
    assert!(stencil.iter().all(|&s| s == 7), "stencil {stencil:?}");
    target.destroy(&ctx);
    ring.destroy(&ctx);
    buffer.destroy(&ctx);
    finish(ctx);
}

/// Frame A signals a semaphore that frame B waits on, twice: a binary semaphore may be signalled
/// again only once a wait has consumed it, so a missing wait or signal is a validation error.
#[test]
fn a_frame_waits_on_the_semaphore_another_signals() {
    let ctx = context();
    let semaphore = unsafe { ctx.device().create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }.unwrap();
    let desc = TargetDesc::color("signalled", RGBA8, SIDE, SIDE).usage(vk::ImageUsageFlags::TRANSFER_SRC);
    let mut target = Target::new(&ctx, desc).unwrap();
    let mut ring = FrameRing::new(&ctx).unwrap();
    let buffer = readback(&ctx, TEXELS as u64 * 4);
    for (rgba, expected) in [([1.0, 0.0, 0.0, 1.0], [255, 0, 0, 255]), ([0.0, 0.0, 1.0, 1.0], [0, 0, 255, 255])] {
        let signal = [(semaphore, vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)];
        submit(&ctx, &mut ring, &Semaphores { signal: &signal, ..Semaphores::NONE }, |cmd| {
            clear(&ctx, cmd, &mut target, rgba)
        });
        let wait = [(semaphore, vk::PipelineStageFlags2::COPY)];
        submit(&ctx, &mut ring, &Semaphores { wait: &wait, ..Semaphores::NONE }, |cmd| {
            read_out(&ctx, cmd, &mut target, &buffer)
        });
        ring.drain(&ctx).unwrap();
        assert_texels(&buffer, expected);
    }
    unsafe { ctx.device().destroy_semaphore(semaphore, None) };
    target.destroy(&ctx);
    ring.destroy(&ctx);
    buffer.destroy(&ctx);
    finish(ctx);
}

/// The context renders on the embedder's device and leaves it, and the instance, alive: the
/// embedder destroys them afterwards without a double destroy or a leak report.
#[test]
fn a_context_on_the_embedders_device_renders_and_destroys_only_its_own() {
    let embedder = Embedder::new(required_device_extensions(), required_vulkan13_features());
    let mut ctx = unsafe { Context::from_handles(embedder.handles(required_vulkan13_features())) }.unwrap();
    assert_eq!(ctx.ownership(), Ownership::Borrowed);
    let desc = TargetDesc::color("embedded", RGBA8, SIDE, SIDE).usage(vk::ImageUsageFlags::TRANSFER_SRC);
    let mut target = Target::new(&ctx, desc).unwrap();
    let mut ring = FrameRing::new(&ctx).unwrap();
    let buffer = readback(&ctx, TEXELS as u64 * 4);
    submit(&ctx, &mut ring, &Semaphores::NONE, |cmd| {
        clear(&ctx, cmd, &mut target, [1.0, 1.0, 0.0, 1.0]);
        read_out(&ctx, cmd, &mut target, &buffer);
    });
    ring.drain(&ctx).unwrap();
    assert_texels(&buffer, [255, 255, 0, 255]);
    target.destroy(&ctx);
    ring.destroy(&ctx);
    buffer.destroy(&ctx);
    ctx.destroy();
    assert!(ctx.validation_errors().is_empty());
    drop(ctx);
    embedder.finish();
}

#[test]
fn an_embedders_device_without_what_we_need_is_refused_by_name() {
    let embedder = Embedder::new(&[], required_vulkan13_features());
    let why = unsafe { Context::from_handles(embedder.handles(required_vulkan13_features())) }
        .err()
        .expect("no push descriptors")
        .to_string();
    assert!(why.contains("VK_KHR_push_descriptor"), "{why}");
    let handles = embedder.handles(required_vulkan13_features().synchronization2(false));
    let why = unsafe { Context::from_handles(handles) }.err().expect("no synchronization2").to_string();
    assert!(why.contains("synchronization2"), "{why}");
    embedder.finish();
}

/// The pipeline state the shadow volumes need, on a depth-stencil target: full-screen triangles
/// scissored to nested squares, with the stencil incremented where each lands, the depth tested
/// but not written and the colour masked off. Texel (x, y) is covered by square k when both
/// coordinates are at least k, so its count is min(x, y) + 1.
#[test]
fn a_stencil_pipeline_counts_overlapping_quads() {
    use softshadow::gpu::{DepthState, Pipeline, PipelineDesc, shaders};
    let ctx = context();
    let format = ctx.depth_stencil_format();
    let usage = vk::ImageUsageFlags::TRANSFER_SRC;
    let mut depth = Target::new(&ctx, TargetDesc::depth_stencil("counts", format, SIDE, SIDE).usage(usage)).unwrap();
    let mut color =
        Target::new(&ctx, TargetDesc::color("masked", vk::Format::R16_UNORM, SIDE, SIDE).usage(usage)).unwrap();
    let count = vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: vk::StencilOp::INCREMENT_AND_CLAMP,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: vk::CompareOp::ALWAYS,
        compare_mask: 0xFF,
        write_mask: 0xFF,
        reference: 0,
    };
    let formats = [vk::Format::R16_UNORM];
    // Any fragment shader with no inputs: the shadow volumes' stencil-only one.
    let desc = PipelineDesc::new("count", &shaders::COMMON_FULLSCREEN_VERT, &shaders::SHADOW_VOLUME_STENCIL_FRAG)
        .colors(&formats)
        .color_write(vk::ColorComponentFlags::empty())
        .depth(DepthState::test_only(format, vk::CompareOp::ALWAYS))
        .stencil(count, count);
    let pipeline = Pipeline::new(&ctx, &desc).unwrap();
    let mut ring = FrameRing::new(&ctx).unwrap();
    let buffer = readback(&ctx, TEXELS as u64 * (4 + 1 + 2));
    let (stencil_at, color_at) = (TEXELS as u64 * 4, TEXELS as u64 * 5);
    submit(&ctx, &mut ring, &Semaphores::NONE, |cmd| {
        transition(
            &ctx,
            cmd,
            &mut [(&mut depth, Access::DEPTH_STENCIL_WRITE, true), (&mut color, Access::COLOR_WRITE, true)],
        );
        let pass = RenderPass::begin(
            &ctx,
            cmd,
            &[Attachment::clear_color(&color, [0.5; 4])],
            Some(Attachment::clear_depth_stencil(&depth, 0.25, 0)),
        );
        pipeline.bind(&ctx, cmd, &[]).unwrap();
        for k in 0..SIDE {
            let offset = vk::Offset2D { x: k as i32, y: k as i32 };
            let extent = vk::Extent2D { width: SIDE - k, height: SIDE - k };
            pass.set_area(&ctx, cmd, vk::Rect2D { offset, extent });
            unsafe { ctx.device().cmd_draw(cmd, 3, 1, 0, 0) };
        }
        pass.end(&ctx, cmd);
        transition(&ctx, cmd, &mut [(&mut depth, Access::COPY_READ, false), (&mut color, Access::COPY_READ, false)]);
        let regions = [
            depth.aspect_copy(vk::ImageAspectFlags::DEPTH, 0),
            depth.aspect_copy(vk::ImageAspectFlags::STENCIL, stencil_at),
        ];
        copy_to_buffer(&ctx, cmd, &depth, &buffer, &regions);
        copy_to_buffer(&ctx, cmd, &color, &buffer, &[color.whole_copy(color_at)]);
        copy_to_host(&ctx, cmd);
    });
    ring.drain(&ctx).unwrap();
    let bytes = buffer.read();
    let stencil = &bytes[stencil_at as usize..][..TEXELS];
    let expected: Vec<u8> = (0..TEXELS as u32).map(|i| ((i % SIDE).min(i / SIDE) + 1) as u8).collect();
    assert_eq!(stencil, &expected[..], "stencil counts");
    for texel in bytes[..stencil_at as usize].chunks(4) {
        let raw = u32::from_le_bytes(texel.try_into().unwrap());
        let d = if format == vk::Format::D32_SFLOAT_S8_UINT {
            f32::from_bits(raw)
        } else {
            (raw & 0xFF_FFFF) as f32 / 0xFF_FFFF as f32
        };
        assert!((d - 0.25).abs() < 1e-6, "depth written: {d}");
    }
    let colors = &bytes[color_at as usize..][..TEXELS * 2];
    assert!(colors.chunks(2).all(|c| u16::from_le_bytes([c[0], c[1]]) == 32768), "colour written: {colors:?}");
    pipeline.destroy(&ctx);
    depth.destroy(&ctx);
    color.destroy(&ctx);
    ring.destroy(&ctx);
    buffer.destroy(&ctx);
    finish(ctx);
}
