//! Graphics and compute pipelines for dynamic rendering, each with one push-descriptor set: a
//! pass pushes its inputs when it records, so no descriptor pools or set lifetimes exist. The
//! set's layout and the specialization constants come from the shaders' SPIR-V
//! ([`reflect`](super::reflect)); what a call site binds is checked against it.

use ash::vk;

use super::Context;
use super::reflect::{Binding, DeclaredBinding, Reflection, reflect};
use super::shaders::{self, Shader};
use super::target::Target;
use crate::error::{Error, Result, VkContext};

/// A pass input, in binding order.
#[derive(Clone, Copy)]
pub enum Descriptor<'a> {
    Buffer(vk::DescriptorBufferInfo),
    Image(&'a Target),
    /// The target's texels as the format it was made to be reinterpreted as
    /// ([`TargetDesc::reinterpreted_as`](super::TargetDesc::reinterpreted_as)).
    Reinterpreted(&'a Target),
}

/// Vertex streams a pipeline reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexInput {
    /// Generated in the shader (full-screen triangle).
    None,
    /// Vertices of `stride` bytes; location i reads `attributes[i] = (offset, floats)`: 1 to 4
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

/// Depth test (and write) of a pipeline.
#[derive(Clone, Copy, Debug)]
pub struct DepthState {
    pub format: vk::Format,
    pub compare: vk::CompareOp,
    /// Off for passes that test against depth another pass wrote (shadow volumes).
    pub write: bool,
}

impl DepthState {
    /// Tests with `compare` and writes what passes.
    pub fn test_write(format: vk::Format, compare: vk::CompareOp) -> Self {
        DepthState { format, compare, write: true }
    }

    /// Tests with `compare`, leaves the depth as it is.
    pub fn test_only(format: vk::Format, compare: vk::CompareOp) -> Self {
        DepthState { format, compare, write: false }
    }
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
    /// max(dst, src).
    Max,
}

/// A graphics pipeline's description, declared with a named constructor and refined by
/// builder methods (kajiya's `ImageDesc`): full-screen-free defaults are no vertex input, no
/// color or depth target, two-sided, all channels written, no blending.
#[derive(Clone, Copy)]
pub struct PipelineDesc<'a> {
    pub name: &'static str,
    pub vertex: &'a Shader,
    pub fragment: &'a Shader,
    pub vertex_input: VertexInput,
    pub color_formats: &'a [vk::Format],
    pub depth: Option<DepthState>,
    /// Front and back stencil state (two-sided stencil); the depth format must have stencil.
    pub stencil: Option<(vk::StencilOpState, vk::StencilOpState)>,
    /// Two-sided by default: plates and open meshes have no inside to cull.
    pub cull: vk::CullModeFlags,
    pub color_write: vk::ColorComponentFlags,
    /// Depth clamped to the viewport's range instead of clipping at the near and far planes
    /// (shadow volumes reaching infinity).
    pub depth_clamp: bool,
    /// Applied to every color target.
    pub blend: Blend,
    /// Specialization constants by the name the shaders give them.
    pub constants: &'a [(&'static str, u32)],
}

impl<'a> PipelineDesc<'a> {
    pub fn new(name: &'static str, vertex: &'a Shader, fragment: &'a Shader) -> Self {
        PipelineDesc {
            name,
            vertex,
            fragment,
            vertex_input: VertexInput::None,
            color_formats: &[],
            depth: None,
            stencil: None,
            cull: vk::CullModeFlags::NONE,
            color_write: vk::ColorComponentFlags::RGBA,
            depth_clamp: false,
            blend: Blend::None,
            constants: &[],
        }
    }

    pub fn vertex_input(self, vertex_input: VertexInput) -> Self {
        PipelineDesc { vertex_input, ..self }
    }

    pub fn colors(self, color_formats: &'a [vk::Format]) -> Self {
        PipelineDesc { color_formats, ..self }
    }

    pub fn depth(self, depth: DepthState) -> Self {
        PipelineDesc { depth: Some(depth), ..self }
    }

    pub fn stencil(self, front: vk::StencilOpState, back: vk::StencilOpState) -> Self {
        PipelineDesc { stencil: Some((front, back)), ..self }
    }

    pub fn cull(self, cull: vk::CullModeFlags) -> Self {
        PipelineDesc { cull, ..self }
    }

    pub fn color_write(self, color_write: vk::ColorComponentFlags) -> Self {
        PipelineDesc { color_write, ..self }
    }

    pub fn blend(self, blend: Blend) -> Self {
        PipelineDesc { blend, ..self }
    }

    pub fn depth_clamp(self) -> Self {
        PipelineDesc { depth_clamp: true, ..self }
    }

    pub fn constants(self, constants: &'a [(&'static str, u32)]) -> Self {
        PipelineDesc { constants, ..self }
    }
}

/// A full-screen pass: its fragment shader reads its bindings and writes one color target.
pub struct Fullscreen<'a> {
    pub name: &'static str,
    pub fragment: &'a Shader,
    pub format: vk::Format,
    pub blend: Blend,
    pub constants: &'a [(&'static str, u32)],
}

impl<'a> Fullscreen<'a> {
    /// Overwrites the target, no specialization.
    pub fn new(name: &'static str, fragment: &'a Shader, format: vk::Format) -> Self {
        Fullscreen { name, fragment, format, blend: Blend::None, constants: &[] }
    }

    pub fn blend(self, blend: Blend) -> Self {
        Fullscreen { blend, ..self }
    }

    /// Specialization constants by name.
    pub fn constants(self, constants: &'a [(&'static str, u32)]) -> Self {
        Fullscreen { constants, ..self }
    }
}

/// A pipeline, its layout and its push-descriptor set layout.
pub struct Pipeline {
    pub name: &'static str,
    pub(crate) pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    /// Set 0 as the shaders declare it, by binding number; the shaders' paths, for messages.
    bindings: Vec<DeclaredBinding>,
    shaders: String,
    bind_point: vk::PipelineBindPoint,
}

/// One stage's shader, what it declares, and the stage flag.
struct Stage<'a> {
    shader: &'a Shader,
    reflection: Reflection,
    flag: vk::ShaderStageFlags,
}

impl<'a> Stage<'a> {
    fn new(shader: &'a Shader, flag: vk::ShaderStageFlags) -> Result<Self> {
        Ok(Stage { shader, reflection: reflect(shader.path, shader.words)?, flag })
    }
}

impl Pipeline {
    pub fn new(ctx: &Context, desc: &PipelineDesc<'_>) -> Result<Self> {
        let stages = [
            Stage::new(desc.vertex, vk::ShaderStageFlags::VERTEX)?,
            Stage::new(desc.fragment, vk::ShaderStageFlags::FRAGMENT)?,
        ];
        let mut pipeline = Pipeline::with_set_layout(ctx, desc.name, &stages, vk::PipelineBindPoint::GRAPHICS)?;
        // On failure, `destroy` releases what was made so far (null handles are ignored).
        if let Err(e) = pipeline.build(ctx, desc, &stages) {
            pipeline.destroy(ctx);
            return Err(e);
        }
        ctx.name(pipeline.pipeline, desc.name);
        Ok(pipeline)
    }

    /// A compute pipeline running `shader`, specialized by `constants`.
    pub fn compute(
        ctx: &Context,
        name: &'static str,
        shader: &Shader,
        constants: &[(&'static str, u32)],
    ) -> Result<Self> {
        let stages = [Stage::new(shader, vk::ShaderStageFlags::COMPUTE)?];
        let mut pipeline = Pipeline::with_set_layout(ctx, name, &stages, vk::PipelineBindPoint::COMPUTE)?;
        let built = (|| {
            let specializations = specializations(name, &stages, constants)?;
            let info = specialization_info(&specializations[0]);
            pipeline.layout = pipeline_layout(ctx, pipeline.set_layout)?;
            let module = shader_module(ctx, shader.words)?;
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(module)
                .name(c"main")
                .specialization_info(&info);
            let ci = vk::ComputePipelineCreateInfo::default().stage(stage).layout(pipeline.layout);
            let created =
                unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &[ci], ctx.host_allocator()) };
            unsafe { ctx.device.destroy_shader_module(module, ctx.host_allocator()) };
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

    /// The pipeline shell: its push-descriptor set layout, the union of what `stages` declare
    /// (a binding two stages declare must hold the same kind), no layout or pipeline yet.
    fn with_set_layout(
        ctx: &Context,
        name: &'static str,
        stages: &[Stage<'_>],
        bind_point: vk::PipelineBindPoint,
    ) -> Result<Self> {
        let shaders = stages.iter().map(|s| s.shader.path).collect::<Vec<_>>().join(" + ");
        let mut bindings: Vec<(DeclaredBinding, vk::ShaderStageFlags)> = Vec::new();
        for stage in stages {
            for b in &stage.reflection.bindings {
                match bindings.iter_mut().find(|(d, _)| d.binding == b.binding) {
                    Some((d, _)) if d.kind != b.kind => {
                        return Err(Error::Invalid(format!(
                            "pipeline `{name}` ({shaders}): binding {} is {:?} `{}` in one stage and {:?} `{}` in {}",
                            b.binding, d.kind, d.name, b.kind, b.name, stage.shader.path
                        )));
                    }
                    Some((_, flags)) => *flags |= stage.flag,
                    None => bindings.push((b.clone(), stage.flag)),
                }
            }
        }
        bindings.sort_by_key(|(b, _)| b.binding);
        let samplers = [ctx.nearest_sampler];
        let layout_bindings: Vec<_> = bindings
            .iter()
            .map(|(b, stages)| {
                let binding = vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(descriptor_type(b.kind))
                    .descriptor_count(1)
                    .stage_flags(*stages);
                if b.kind == Binding::Sampled { binding.immutable_samplers(&samplers) } else { binding }
            })
            .collect();
        let set_ci = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
            .bindings(&layout_bindings);
        let set_layout = unsafe { ctx.device.create_descriptor_set_layout(&set_ci, ctx.host_allocator()) }
            .vk("vkCreateDescriptorSetLayout")?;
        Ok(Pipeline {
            name,
            pipeline: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layout,
            bindings: bindings.into_iter().map(|(b, _)| b).collect(),
            shaders,
            bind_point,
        })
    }

    /// A full-screen pass (`glsl/common/fullscreen.vert`) as `desc` describes it.
    pub fn fullscreen(ctx: &Context, desc: &Fullscreen<'_>) -> Result<Self> {
        let formats = [desc.format];
        let pipeline = PipelineDesc::new(desc.name, &shaders::COMMON_FULLSCREEN_VERT, desc.fragment)
            .colors(&formats)
            .blend(desc.blend)
            .constants(desc.constants);
        Pipeline::new(ctx, &pipeline)
    }

    fn build(&mut self, ctx: &Context, desc: &PipelineDesc<'_>, stages: &[Stage<'_>; 2]) -> Result<()> {
        let d = &ctx.device;
        let specializations = specializations(desc.name, stages, desc.constants)?;
        let [vert_info, frag_info] = [0, 1].map(|i| specialization_info(&specializations[i]));
        let has_stencil = desc.depth.is_some_and(|s| format_has_stencil(s.format));
        if desc.stencil.is_some() && !has_stencil {
            return Err(Error::Invalid(format!(
                "pipeline `{}`: stencil state needs a depth-stencil format",
                desc.name
            )));
        }
        self.layout = pipeline_layout(ctx, self.set_layout)?;

        let vert = shader_module(ctx, desc.vertex.words)?;
        let frag = match shader_module(ctx, desc.fragment.words) {
            Ok(f) => f,
            Err(e) => {
                unsafe { d.destroy_shader_module(vert, ctx.host_allocator()) };
                return Err(e);
            }
        };
        let stage_infos = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vert)
                .name(c"main")
                .specialization_info(&vert_info),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(frag)
                .name(c"main")
                .specialization_info(&frag_info),
        ];
        let (stride, attributes) = desc.vertex_input.layout();
        let vb = [vk::VertexInputBindingDescription { binding: 0, stride, input_rate: vk::VertexInputRate::VERTEX }];
        let attrs: Vec<_> = attributes
            .iter()
            .enumerate()
            .map(|(location, &(offset, floats))| vk::VertexInputAttributeDescription {
                location: location as u32,
                binding: 0,
                format: [
                    vk::Format::R32_SFLOAT,
                    vk::Format::R32G32_SFLOAT,
                    vk::Format::R32G32B32_SFLOAT,
                    vk::Format::R32G32B32A32_SFLOAT,
                ][(floats as usize).clamp(1, 4) - 1],
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
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .depth_clamp_enable(desc.depth_clamp)
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(desc.cull)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let (front, back) = desc.stencil.unwrap_or_default();
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth.is_some())
            .depth_write_enable(desc.depth.is_some_and(|d| d.write))
            .depth_compare_op(desc.depth.map_or(vk::CompareOp::ALWAYS, |d| d.compare))
            .stencil_test_enable(desc.stencil.is_some())
            .front(front)
            .back(back);
        let op = match desc.blend {
            Blend::None | Blend::Add => vk::BlendOp::ADD,
            Blend::Min => vk::BlendOp::MIN,
            Blend::Max => vk::BlendOp::MAX,
        };
        let attachment = vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(desc.color_write)
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
            .depth_attachment_format(desc.depth.map_or(vk::Format::UNDEFINED, |d| d.format))
            .stencil_attachment_format(if has_stencil {
                desc.depth.map_or(vk::Format::UNDEFINED, |d| d.format)
            } else {
                vk::Format::UNDEFINED
            });
        let ci = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stage_infos)
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
        let created = unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[ci], ctx.host_allocator()) };
        unsafe {
            d.destroy_shader_module(vert, ctx.host_allocator());
            d.destroy_shader_module(frag, ctx.host_allocator());
        }
        self.pipeline = created.map_err(|(_, result)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result })?[0];
        Ok(())
    }

    /// Binds the pipeline and pushes `inputs`, one per binding the shaders declare, in binding
    /// order. A count or kind that disagrees with the shaders is an error naming the binding.
    pub fn bind(&self, ctx: &Context, cmd: vk::CommandBuffer, inputs: &[Descriptor<'_>]) -> Result<()> {
        let mismatch = |what: String| Error::Invalid(format!("pipeline `{}` ({}): {what}", self.name, self.shaders));
        if inputs.len() != self.bindings.len() {
            let declared: Vec<_> = self.bindings.iter().map(|b| format!("{} `{}`", b.binding, b.name)).collect();
            return Err(mismatch(format!(
                "{} inputs given, the shaders declare {} bindings ({})",
                inputs.len(),
                self.bindings.len(),
                declared.join(", ")
            )));
        }
        let mut buffers = Vec::with_capacity(inputs.len());
        let mut images = Vec::with_capacity(inputs.len());
        for (b, input) in self.bindings.iter().zip(inputs) {
            match (b.kind, input) {
                (Binding::Uniform | Binding::Storage, Descriptor::Buffer(info)) => buffers.push([*info]),
                (Binding::Sampled, &Descriptor::Image(t)) => images.push(sampled(t, t.view)),
                (Binding::Sampled, &Descriptor::Reinterpreted(t)) if let Some(view) = t.reinterpreted => {
                    images.push(sampled(t, view))
                }
                (Binding::Sampled, Descriptor::Reinterpreted(t)) => {
                    return Err(mismatch(format!(
                        "binding {} `{}` reads `{}` reinterpreted, which has no such view",
                        b.binding, b.name, t.desc.name
                    )));
                }
                (kind, _) => {
                    let given = if matches!(input, Descriptor::Buffer(_)) { "a buffer" } else { "an image" };
                    return Err(mismatch(format!("binding {} `{}` is {kind:?}, given {given}", b.binding, b.name)));
                }
            }
        }
        let (mut next_buffer, mut next_image) = (buffers.iter(), images.iter());
        let writes: Vec<_> = self
            .bindings
            .iter()
            .map(|b| {
                let w =
                    vk::WriteDescriptorSet::default().dst_binding(b.binding).descriptor_type(descriptor_type(b.kind));
                match b.kind {
                    Binding::Sampled => w.image_info(next_image.next().expect("one image per sampled binding")),
                    Binding::Uniform | Binding::Storage => {
                        w.buffer_info(next_buffer.next().expect("one buffer per buffer binding"))
                    }
                }
            })
            .collect();
        unsafe {
            ctx.device.cmd_bind_pipeline(cmd, self.bind_point, self.pipeline);
            // A pipeline whose shaders declare nothing has no set to push.
            if !writes.is_empty() {
                ctx.push_descriptor.cmd_push_descriptor_set(cmd, self.bind_point, self.layout, 0, &writes);
            }
        }
        Ok(())
    }

    pub fn destroy(self, ctx: &Context) {
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, ctx.host_allocator());
            ctx.device.destroy_pipeline_layout(self.layout, ctx.host_allocator());
            ctx.device.destroy_descriptor_set_layout(self.set_layout, ctx.host_allocator());
        }
    }
}

/// Pipelines of one pass specialized differently (a filter, a falloff curve), made on first
/// use and kept: switching a knob back and forth costs one compile each way, once.
pub struct Variants<K> {
    made: Vec<(K, Pipeline)>,
}

impl<K> Default for Variants<K> {
    fn default() -> Self {
        Variants { made: Vec::new() }
    }
}

impl<K: PartialEq> Variants<K> {
    /// The pipeline for `key`, made by `make` the first time.
    pub fn get(&mut self, key: K, make: impl FnOnce(&K) -> Result<Pipeline>) -> Result<&Pipeline> {
        let index = match self.made.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                let pipeline = make(&key)?;
                self.made.push((key, pipeline));
                self.made.len() - 1
            }
        };
        Ok(&self.made[index].1)
    }
}

impl<K> Variants<K> {
    pub fn destroy(self, ctx: &Context) {
        self.made.into_iter().for_each(|(_, p)| p.destroy(ctx));
    }
}

/// A sampled binding's view of `t` (the sampler is the layout's immutable one).
fn sampled(t: &Target, view: vk::ImageView) -> [vk::DescriptorImageInfo; 1] {
    [vk::DescriptorImageInfo { sampler: vk::Sampler::null(), image_view: view, image_layout: t.last.layout }]
}

fn descriptor_type(kind: Binding) -> vk::DescriptorType {
    match kind {
        Binding::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
        Binding::Storage => vk::DescriptorType::STORAGE_BUFFER,
        Binding::Sampled => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
    }
}

fn format_has_stencil(format: vk::Format) -> bool {
    matches!(format, vk::Format::D32_SFLOAT_S8_UINT | vk::Format::D24_UNORM_S8_UINT | vk::Format::D16_UNORM_S8_UINT)
}

/// One stage's specialization: map entries and the values they point into.
type Specialization = (Vec<vk::SpecializationMapEntry>, Vec<u32>);

fn specialization_info((entries, values): &Specialization) -> vk::SpecializationInfo<'_> {
    vk::SpecializationInfo::default().map_entries(entries).data(bytemuck::cast_slice(values))
}

/// Each stage's specialization by `constants`' names; a name no stage declares is an error
/// naming the pipeline and what the shaders do declare.
fn specializations(name: &str, stages: &[Stage<'_>], constants: &[(&'static str, u32)]) -> Result<Vec<Specialization>> {
    for (constant, _) in constants {
        if !stages.iter().any(|s| s.reflection.constants.iter().any(|c| c.name == *constant)) {
            let declared: Vec<_> =
                stages.iter().flat_map(|s| s.reflection.constants.iter().map(|c| c.name.as_str())).collect();
            let shaders: Vec<_> = stages.iter().map(|s| s.shader.path).collect();
            return Err(Error::Invalid(format!(
                "pipeline `{name}` ({}): no specialization constant `{constant}` (declared: {})",
                shaders.join(" + "),
                if declared.is_empty() { "none".to_string() } else { declared.join(", ") }
            )));
        }
    }
    Ok(stages
        .iter()
        .map(|stage| {
            stage
                .reflection
                .constants
                .iter()
                .filter_map(|c| constants.iter().find(|(n, _)| *n == c.name).map(|(_, v)| (c.id, *v)))
                .enumerate()
                .map(|(i, (id, v))| (vk::SpecializationMapEntry { constant_id: id, offset: 4 * i as u32, size: 4 }, v))
                .unzip()
        })
        .collect())
}

fn pipeline_layout(ctx: &Context, set_layout: vk::DescriptorSetLayout) -> Result<vk::PipelineLayout> {
    let set_layouts = [set_layout];
    let layout_ci = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
    unsafe { ctx.device.create_pipeline_layout(&layout_ci, ctx.host_allocator()) }.vk("vkCreatePipelineLayout")
}

fn shader_module(ctx: &Context, words: &[u32]) -> Result<vk::ShaderModule> {
    let ci = vk::ShaderModuleCreateInfo::default().code(words);
    unsafe { ctx.device.create_shader_module(&ci, ctx.host_allocator()) }.vk("vkCreateShaderModule")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::{ContextOptions, TargetDesc};

    /// The shaders, not the call site, declare the bindings and constants: a call that
    /// disagrees is an error naming the shader and the binding or constant.
    #[test]
    fn calls_that_disagree_with_the_shaders_are_named_errors() {
        let ctx = Context::headless(&ContextOptions { validation: true, device: None }).unwrap();
        let resolve = &shaders::SHADOW_MAP_RESOLVE_FRAG;
        let constants = [("FILTRE", 1)];
        let typo = Fullscreen::new("resolve", resolve, vk::Format::R16_UNORM).constants(&constants);
        let e = Pipeline::fullscreen(&ctx, &typo).err().expect("no such constant").to_string();
        assert!(e.contains("FILTRE") && e.contains("FILTER") && e.contains("shadow_map/resolve.frag"), "{e}");

        let pipeline = Pipeline::fullscreen(&ctx, &Fullscreen::new("resolve", resolve, vk::Format::R16_UNORM)).unwrap();
        let pool_ci = vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family);
        let pool = unsafe { ctx.device.create_command_pool(&pool_ci, ctx.host_allocator()) }.unwrap();
        let alloc = vk::CommandBufferAllocateInfo::default().command_pool(pool).command_buffer_count(1);
        let cmd = unsafe { ctx.device.allocate_command_buffers(&alloc) }.unwrap()[0];
        let buffer = Descriptor::Buffer(vk::DescriptorBufferInfo::default());
        let e = pipeline.bind(&ctx, cmd, &[buffer; 4]).unwrap_err().to_string();
        assert!(e.contains("4 inputs") && e.contains("5 bindings") && e.contains("shadow_map"), "{e}");
        let e = pipeline.bind(&ctx, cmd, &[buffer; 5]).unwrap_err().to_string();
        assert!(e.contains("binding 2 `camera_depth`") && e.contains("given a buffer"), "{e}");
        // A target read as another format must have been made with a view of it.
        let plain = Target::new(&ctx, TargetDesc::color("plain", vk::Format::R16G16_UNORM, 4, 4)).unwrap();
        let images = [Descriptor::Reinterpreted(&plain), Descriptor::Image(&plain), Descriptor::Image(&plain)];
        let e = pipeline.bind(&ctx, cmd, &[&[buffer; 2][..], &images].concat()).unwrap_err().to_string();
        assert!(e.contains("binding 2 `camera_depth`") && e.contains("`plain` reinterpreted"), "{e}");
        let packed = TargetDesc::color("packed", vk::Format::R16G16_UNORM, 4, 4).reinterpreted_as(vk::Format::R32_UINT);
        let packed = Target::new(&ctx, packed).unwrap();
        assert!(packed.reinterpreted.is_some());
        plain.destroy(&ctx);
        packed.destroy(&ctx);
        unsafe { ctx.device.destroy_command_pool(pool, ctx.host_allocator()) };
        pipeline.destroy(&ctx);
        let mut ctx = ctx;
        ctx.destroy();
        assert!(ctx.validation_errors().is_empty(), "{:?}", ctx.validation_errors());
    }
}
