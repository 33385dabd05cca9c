//! Choosing the adapter and opening the device.
//!
//! `device gpu` takes whatever Vulkan adapter exists, Mesa's software
//! rasteriser (llvmpipe/lavapipe) included; `device auto` takes a hardware
//! adapter when there is one and otherwise leaves the run on the CPU backend.
//! The device is opened with the adapter's own limits (not WebGPU's
//! defaults), so that buffers for ≥ 10⁶ particles and all twelve storage
//! bindings fit.

pub use super::prelude::context::WORKGROUP;

/// The deck's `device` setting.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DevicePreference {
    /// The f64 CPU backend.
    #[default]
    Cpu,
    /// The GPU backend on any adapter (software drivers included).
    Gpu,
    /// The GPU backend on a hardware adapter, otherwise the CPU backend.
    Auto,
}

impl DevicePreference {
    pub fn from_keyword(word: &str) -> Option<Self> {
        match word {
            "cpu" => Some(Self::Cpu),
            "gpu" => Some(Self::Gpu),
            "auto" => Some(Self::Auto),
            _ => None,
        }
    }
}

/// Storage buffers bound by the kernels at once (see shaders/common/layout.wgsl).
pub const STORAGE_BINDINGS: u32 = 13;

/// An open device and its queue (cheap to clone: handles are shared).
#[derive(Clone)]
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
}

impl GpuContext {
    /// Opens a Vulkan adapter; with `hardware_only`, software adapters are refused.
    pub fn open(hardware_only: bool) -> Result<Self, String> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
        let is_hardware =
            |a: &wgpu::Adapter| matches!(a.get_info().device_type, wgpu::DeviceType::DiscreteGpu | wgpu::DeviceType::IntegratedGpu);
        let found: Vec<String> = adapters.iter().map(|a| format!("{} ({:?})", a.get_info().name, a.get_info().device_type)).collect();
        let adapter =
            adapters.iter().find(|a| is_hardware(a)).or_else(|| if hardware_only { None } else { adapters.first() }).ok_or_else(|| {
                if found.is_empty() {
                    "no Vulkan adapter found: install a GPU driver, or Mesa's software driver (Debian package \
                     `mesa-vulkan-drivers`), or use `device cpu`"
                        .to_string()
                } else {
                    format!("no hardware Vulkan adapter among: {}", found.join(", "))
                }
            })?;
        let info = adapter.get_info();
        let available = adapter.limits();
        if available.max_storage_buffers_per_shader_stage < STORAGE_BINDINGS {
            return Err(format!(
                "adapter {} allows {} storage buffers per shader stage; cellmd's kernels need {STORAGE_BINDINGS}",
                info.name, available.max_storage_buffers_per_shader_stage
            ));
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("cellmd"),
            required_features: wgpu::Features::empty(),
            required_limits: available.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| format!("opening {}: {e}", info.name))?;
        Ok(Self { device, queue, info, limits: available })
    }

    /// "NAME (TYPE, driver DRIVER)" for the start-of-run message.
    pub fn describe(&self) -> String {
        format!("{} ({:?}, {} {})", self.info.name, self.info.device_type, self.info.driver, self.info.driver_info)
    }

    /// Whether the adapter is a hardware GPU (not a software rasteriser).
    pub fn is_hardware(&self) -> bool {
        matches!(self.info.device_type, wgpu::DeviceType::DiscreteGpu | wgpu::DeviceType::IntegratedGpu)
    }
}

/// A compute-stage storage buffer entry of a bind group layout.
pub(super) fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
