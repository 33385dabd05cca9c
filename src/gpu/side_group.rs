//! Kernels with buffers of their own in bind group 1, beside the backend's
//! main group 0: the implicit step (src/gpu/implicit.rs), the constraints'
//! projection (src/gpu/shake.rs) and FIRE (src/gpu/fire.rs). One home for the check that
//! the adapter can bind them, their bind group, and their pipelines compiled
//! from the composed program (with the model's custom evaluators).

use super::context::{storage_entry, GpuContext};
use super::shader;
use crate::system::Model;

/// A bind group 1 of storage buffers and the module its kernels come from.
pub(super) struct SideGroup {
    pub(super) group: wgpu::BindGroup,
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
}

impl SideGroup {
    /// Binds `buffers` (binding, read-only, buffer) in group 1 for `what`
    /// (named in the refusal when the adapter allows too few storage buffers).
    pub(super) fn new(
        ctx: &GpuContext,
        main_layout: &wgpu::BindGroupLayout,
        model: &Model,
        what: &str,
        buffers: &[(u32, bool, &wgpu::Buffer)],
    ) -> Result<Self, String> {
        let needed = super::context::STORAGE_BINDINGS + buffers.len() as u32;
        if ctx.limits.max_storage_buffers_per_shader_stage < needed {
            return Err(format!(
                "{what} needs {needed} storage buffers per shader stage; {} allows {}",
                ctx.info.name, ctx.limits.max_storage_buffers_per_shader_stage
            ));
        }
        let device = &ctx.device;
        let label = Some(what);
        let entries: Vec<_> = buffers.iter().map(|&(binding, read_only, _)| storage_entry(binding, read_only)).collect();
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label, entries: &entries });
        let entries: Vec<_> =
            buffers.iter().map(|&(binding, _, buffer)| wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }).collect();
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor { label, layout: &group_layout, entries: &entries });
        let program = shader::compose_with(&super::custom::source(model)?);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label, source: wgpu::ShaderSource::Wgsl(program.into()) });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label,
            bind_group_layouts: &[Some(main_layout), Some(&group_layout)],
            immediate_size: 0,
        });
        Ok(Self { group, module, layout })
    }

    /// The kernel `entry` of the program, with both groups.
    pub(super) fn pipeline(&self, ctx: &GpuContext, entry: &str) -> wgpu::ComputePipeline {
        ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&self.layout),
            module: &self.module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    }
}
