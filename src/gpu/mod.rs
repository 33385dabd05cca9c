//! The GPU backend (wgpu, Vulkan; WGSL kernels in `shaders/`).
//!
//! - [`context`]: adapter choice (`device gpu|auto`), limits for ≥ 10⁶ particles.
//! - [`shader`]: the program composed from `shaders/common/` and one
//!   evaluator file per interaction type, validated by naga.
//! - [`pack`]: the model flattened into the buffers the kernels read.
//! - [`backend`]: buffers, pipelines and the GPU-resident step loop.
//!
//! What runs where: each step — neighbour-list check and (when due) rebuild,
//! forces, overdamped integration — runs on the GPU without reading anything
//! back. The host reads positions back only when thermo, a dump or the end of
//! the run needs them; thermo quantities (energies, virial, pressure) are then
//! evaluated by the f64 CPU backend at the read-back positions.
//!
//! # Precision
//!
//! Forces are f32. Positions are double-single (an f32 value plus an f32
//! correction, relative to the box's lower corner, ≈ 48-bit mantissa), so
//! positions do not drift from the CPU trajectory through f32 rounding of the
//! positions themselves; separations are formed from the two parts (the high
//! parts cancel exactly for close particles). The remaining difference from
//! the CPU is the f32 force error (relative ≈ 1e-7 per evaluation), measured
//! in `tests/gpu.rs` and reported in the README.

pub mod backend;
pub mod context;
pub mod pack;
pub mod shader;

pub use backend::{GpuBackend, GpuHalt};
pub use context::{DevicePreference, GpuContext};
