//! Graphics pipelines for dynamic rendering, each with one push-descriptor set: a pass pushes
//! its inputs when it records, so no descriptor pools or set lifetimes exist.

use ash::vk;

use super::Context;
use super::target::Target;
use crate::error::{Error, Result, VkContext};

/// What a binding of set 0 holds; bindings are numbered in the order given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    Uniform,
    Storage,
    /// A target read through the context's nearest clamp sampler.
    Sampled,
}

impl Binding {
    fn ty(self) -> vk::DescriptorType {
        match self {
            Binding::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
            Binding::Storage => vk::DescriptorType::STORAGE_BUFFER,
            Binding::Sampled => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    }
}

/// A pass input, in binding order.
#[derive(Clone, Copy)]
pub enum Descriptor<'a> {
    Buffer(vk::DescriptorBufferInfo),
    Image(&'a Target),
}

/// Vertex streams a pipeline reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexInput {
    /// Generated in the shader (full-screen triangle).
    None,
    /// Vertices of `stride` bytes; location i reads `attributes[i] = (offset, floats)`: 1 to 3
    /// floats at that byte offset.
    Interleaved { stride: u32, attributes: &'static [(u32, u32)] },
    /// Generated geometry: tightly packed floats, location i taking `floats[i]` of them.
    Floats(&'static [u32]),
}

impl VertexInput {
    /// The stride and the (byte offset, floats) of each location.
    fn layout(self) -> (u32, Vec<(u32, u32)>) {
        match self {
            VertexInput::None => (0, Vec::new()),
            VertexInput::Interleaved { stride, attributes } => (stride, attributes.to_vec()),
            VertexInput::Floats(floats) => {
                let offsets = floats.iter().scan(0, |offset, &n| {
                    let at = *offset;
                    *offset += 4 * n;
                    Some((at, n))
                });
                (4 * floats.iter().sum::<u32>(), offsets.collect())
            }
        }
    }
}

/// Depth test and write of a pipeline.
#[derive(Clone, Copy, Debug)]
pub struct DepthState {
    pub format: vk::Format,
    pub compare: vk::CompareOp,
}

/// How fragment outputs combine with what a color target holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Overwrite.
    None,
    /// dst + src: accumulation (Heckbert & Herf's accumulation buffer).
    Add,
    /// min(dst, src): the darkest value wins.
    Min,
}

/// A graphics pipeline's description.
pub struct PipelineDesc<'a> {
    pub name: &'static str,
    pub vertex: &'a [u32],
    pub fragment: &'a [u32],
    /// Bindings of set 0, with the stages that read them.
    pub bindings: &'a [(Binding, vk::ShaderStageFlags)],
    pub vertex_input: VertexInput,
    pub color_formats: &'a [vk::Format],
    pub depth: Option<DepthState>,
    /// Applied to every color target.
    pub blend: Blend,
    /// Fragment-shader specialization constants: `constant_id = i` takes `constants[i]`.
    pub constants: &'a [u32],
}

/// A full-screen pass: its fragment shader reads `bindings` and writes one color target.
pub struct Fullscreen<'a> {
    pub name: &'static str,
    pub fragment: &'a [u32],
    pub bindings: &'a [Binding],
    pub format: vk::Format,
    pub blend: Blend,
    pub constants: &'a [u32],
}

impl<'a> Fullscreen<'a> {
    /// Overwrites the target, no specialization.
    pub fn new(name: &'static str, fragment: &'a [u32], bindings: &'a [Binding], format: vk::Format) -> Self {
        Fullscreen { name, fragment, bindings, format, blend: Blend::None, constants: &[] }
    }

    pub fn blend(self, blend: Blend) -> Self {
        Fullscreen { blend, ..self }
    }

    /// Specialization constants, in `constant_id` order.
    pub fn constants(self, constants: &'a [u32]) -> Self {
        Fullscreen { constants, ..self }
    }
}

/// A pipeline, its layout and its push-descriptor set layout.
pub struct Pipeline {
    pub name: &'static str,
    pub(crate) pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    bindings: Vec<Binding>,
    bind_point: vk::PipelineBindPoint,
}

impl Pipeline {
    pub fn new(ctx: &Context, desc: &PipelineDesc<'_>) -> Result<Self> {
        let mut pipeline = Pipeline::with_set_layout(ctx, desc.name, desc.bindings, vk::PipelineBindPoint::GRAPHICS)?;
        // On failure, `destroy` releases what was made so far (null handles are ignored).
        if let Err(e) = pipeline.build(ctx, desc) {
            pipeline.destroy(ctx);
            return Err(e);
        }
        ctx.name(pipeline.pipeline, desc.name);
        Ok(pipeline)
    }

    /// A compute pipeline whose shader reads and writes `bindings`.
    pub fn compute(ctx: &Context, name: &'static str, shader: &[u32], bindings: &[Binding]) -> Result<Self> {
        let bindings: Vec<_> = bindings.iter().map(|b| (*b, vk::ShaderStageFlags::COMPUTE)).collect();
        let mut pipeline = Pipeline::with_set_layout(ctx, name, &bindings, vk::PipelineBindPoint::COMPUTE)?;
        let built = (|| {
            let set_layouts = [pipeline.set_layout];
            let layout_ci = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
            pipeline.layout =
                unsafe { ctx.device.create_pipeline_layout(&layout_ci, None) }.vk("vkCreatePipelineLayout")?;
            let module = shader_module(ctx, shader)?;
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(module)
                .name(c"main");
            let ci = vk::ComputePipelineCreateInfo::default().stage(stage).layout(pipeline.layout);
            let created = unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &[ci], None) };
            unsafe { ctx.device.destroy_shader_module(module, None) };
            pipeline.pipeline =
                created.map_err(|(_, result)| Error::Vulkan { call: "vkCreateComputePipelines", result })?[0];
            Ok(())
        })();
        if let Err(e) = built {
            pipeline.destroy(ctx);
            return Err(e);
        }
        ctx.name(pipeline.pipeline, name);
        Ok(pipeline)
    }

    /// The pipeline shell: its push-descriptor set layout, no layout or pipeline yet.
    fn with_set_layout(
        ctx: &Context,
        name: &'static str,
        bindings: &[(Binding, vk::ShaderStageFlags)],
        bind_point: vk::PipelineBindPoint,
    ) -> Result<Self> {
        let d = &ctx.device;
        let samplers = [ctx.nearest_sampler];
        let layout_bindings: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, (b, stages))| {
                let binding = vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(b.ty())
                    .descriptor_count(1)
                    .stage_flags(*stages);
                if *b == Binding::Sampled { binding.immutable_samplers(&samplers) } else { binding }
            })
            .collect();
        let set_ci = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
            .bindings(&layout_bindings);
        let set_layout = unsafe { d.create_descriptor_set_layout(&set_ci, None) }.vk("vkCreateDescriptorSetLayout")?;
        Ok(Pipeline {
            name,
            pipeline: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layout,
            bindings: bindings.iter().map(|(b, _)| *b).collect(),
            bind_point,
        })
    }

    /// A full-screen pass (`glsl/common/fullscreen.vert`) as `desc` describes it.
    pub fn fullscreen(ctx: &Context, desc: &Fullscreen<'_>) -> Result<Self> {
        let bindings: Vec<_> = desc.bindings.iter().map(|b| (*b, vk::ShaderStageFlags::FRAGMENT)).collect();
        Pipeline::new(
            ctx,
            &PipelineDesc {
                name: desc.name,
                vertex: super::shaders::COMMON_FULLSCREEN_VERT,
                fragment: desc.fragment,
                bindings: &bindings,
                vertex_input: VertexInput::None,
                color_formats: &[desc.format],
                depth: None,
                blend: desc.blend,
                constants: desc.constants,
            },
        )
    }

    fn build(&mut self, ctx: &Context, desc: &PipelineDesc<'_>) -> Result<()> {
        let d = &ctx.device;
        let set_layouts = [self.set_layout];
        let layout_ci = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        self.layout = unsafe { d.create_pipeline_layout(&layout_ci, None) }.vk("vkCreatePipelineLayout")?;

        let vert = shader_module(ctx, desc.vertex)?;
        let frag = match shader_module(ctx, desc.fragment) {
            Ok(f) => f,
            Err(e) => {
                unsafe { d.destroy_shader_module(vert, None) };
                return Err(e);
            }
        };
        let entries: Vec<_> = (0..desc.constants.len() as u32)
            .map(|i| vk::SpecializationMapEntry { constant_id: i, offset: 4 * i, size: 4 })
            .collect();
        let specialization =
            vk::SpecializationInfo::default().map_entries(&entries).data(bytemuck::cast_slice(desc.constants));
        let stages = [
            vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(vert).name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(frag)
                .name(c"main")
                .specialization_info(&specialization),
        ];
        let (stride, attributes) = desc.vertex_input.layout();
        let vb = [vk::VertexInputBindingDescription { binding: 0, stride, input_rate: vk::VertexInputRate::VERTEX }];
        let attrs: Vec<_> = attributes
            .iter()
            .enumerate()
            .map(|(location, &(offset, floats))| vk::VertexInputAttributeDescription {
                location: location as u32,
                binding: 0,
                format: [vk::Format::R32_SFLOAT, vk::Format::R32G32_SFLOAT, vk::Format::R32G32B32_SFLOAT]
                    [(floats as usize).clamp(1, 3) - 1],
                offset,
            })
            .collect();
        let vertex_input = if attrs.is_empty() {
            vk::PipelineVertexInputStateCreateInfo::default()
        } else {
            vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&vb)
                .vertex_attribute_descriptions(&attrs)
        };
        let assembly =
            vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        // Two-sided everywhere: plates and open meshes have no inside to cull.
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth.is_some())
            .depth_write_enable(desc.depth.is_some())
            .depth_compare_op(desc.depth.map_or(vk::CompareOp::ALWAYS, |d| d.compare));
        let op = match desc.blend {
            Blend::None | Blend::Add => vk::BlendOp::ADD,
            Blend::Min => vk::BlendOp::MIN,
        };
        let attachment = vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA)
            .blend_enable(desc.blend != Blend::None)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE)
            .color_blend_op(op)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(op);
        let blend = vec![attachment; desc.color_formats.len()];
        let blend_state = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
        let dynamic = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic_state = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth.map_or(vk::Format::UNDEFINED, |d| d.format));
        let ci = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend_state)
            .dynamic_state(&dynamic_state)
            .layout(self.layout)
            .push_next(&mut rendering);
        let created = unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[ci], None) };
        unsafe {
            d.destroy_shader_module(vert, None);
            d.destroy_shader_module(frag, None);
        }
        self.pipeline = created.map_err(|(_, result)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result })?[0];
        Ok(())
    }

    /// Binds the pipeline and pushes its inputs, which must match the bindings in order.
    pub fn bind(&self, ctx: &Context, cmd: vk::CommandBuffer, inputs: &[Descriptor<'_>]) {
        assert_eq!(inputs.len(), self.bindings.len(), "{}: wrong number of inputs", self.name);
        let buffers: Vec<[vk::DescriptorBufferInfo; 1]> = inputs
            .iter()
            .map(|i| match i {
                Descriptor::Buffer(b) => [*b],
                Descriptor::Image(_) => [vk::DescriptorBufferInfo::default()],
            })
            .collect();
        let images: Vec<[vk::DescriptorImageInfo; 1]> = inputs
            .iter()
            .map(|i| match i {
                Descriptor::Image(t) => [vk::DescriptorImageInfo {
                    sampler: vk::Sampler::null(),
                    image_view: t.view,
                    image_layout: t.last.layout,
                }],
                Descriptor::Buffer(_) => [vk::DescriptorImageInfo::default()],
            })
            .collect();
        let writes: Vec<_> = self
            .bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let w = vk::WriteDescriptorSet::default().dst_binding(i as u32).descriptor_type(b.ty());
                match inputs[i] {
                    Descriptor::Buffer(_) => w.buffer_info(&buffers[i]),
                    Descriptor::Image(_) => w.image_info(&images[i]),
                }
            })
            .collect();
        unsafe {
            ctx.device.cmd_bind_pipeline(cmd, self.bind_point, self.pipeline);
            ctx.push_descriptor.cmd_push_descriptor_set(cmd, self.bind_point, self.layout, 0, &writes);
        }
    }

    pub fn destroy(self, ctx: &Context) {
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

fn shader_module(ctx: &Context, words: &[u32]) -> Result<vk::ShaderModule> {
    let ci = vk::ShaderModuleCreateInfo::default().code(words);
    unsafe { ctx.device.create_shader_module(&ci, None) }.vk("vkCreateShaderModule")
}
