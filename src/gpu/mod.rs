//! The GPU backend (wgpu, Vulkan; WGSL kernels in `shaders/`).
//!
//! - [`context`]: adapter choice (`device gpu|auto`), limits for ≥ 10⁶ particles.
//! - [`shader`]: the program composed from `shaders/common/`, one
//!   evaluator file per interaction type and per kinetic rule with a device
//!   form (`src/kinetics/NAME.wgsl`), validated by naga.
//! - `prelude`: the constants the host and the kernels share (buffer layouts,
//!   halt bits, record sizes, physics constants), written once
//!   in Rust and generated into the program.
//! - [`custom`]: evaluators generated from a model's `custom` expressions.
//! - [`pack`]: the model flattened into the buffers the kernels read.
//! - [`backend`]: the GPU-resident step loop composing the features below,
//!   the buffers they share, the build, the read-backs and the profile.
//! - `step`: the phases of a device step, the dispatcher and the
//!   `StepFeature` trait through which each feature encodes its kernels of
//!   each phase (the neighbour list, the force passes, contact, protocols
//!   and device kinetics so far).
//! - `neighbours`: the neighbour list's check and rebuild as a feature;
//!   `nlist`: its buffer, bound in chunks of particles where it exceeds the
//!   adapter's largest storage binding.
//! - `forces`: the force passes (surface, volume, pair, bonded, external).
//! - [`surface`]: surface (body) terms: face, body, edge and node passes,
//!   deterministic (no float atomics).
//! - [`contact`]: node–face contact between bodies (`Law::Contact`) and
//!   the explicit step clamp as a device reduction.
//! - [`adhesion`]: area-weighted contact between bodies
//!   (`Law::ContactArea`: adhesion), in passes around the contact pass.
//! - [`kinetics`]: bond breaking and rebinding decided on the device, events
//!   compacted in bond order and drained by the host at synchronisations.
//! - [`bind`]: `bind` formation on the device: candidates from the GPU
//!   neighbour list, accepted in the CPU's order into a preallocated pool.
//! - `special`: pairs of bonded neighbours with a fractional
//!   `special_bonds` weight, each particle's own list.
//! - [`tetra`]: volume elements (`[ tetrahedra ]`): one pass per element
//!   into corner slots, gathered per particle.
//! - [`protocol`]: `freeze`, `move` and `ramp` on the device: held
//!   coordinates and moving groups in the integrator, ramped parameters
//!   written per step from a table.
//! - [`implicit`]: `integrator implicit`: per-term stiffness blocks and
//!   Jacobi-preconditioned conjugate gradients in one workgroup, matrix-free;
//!   `implicit_split`: the same CG split over every workgroup (one dispatch
//!   per phase, an iteration budget per step) for large systems.
//! - [`shake`]: `constrain`: overdamped SHAKE after the explicit step, the
//!   constraints coloured so that a colour's corrections run in parallel,
//!   swept in one workgroup until converged.
//! - [`fire`]: `minimize`: FIRE iterations as device steps, the power and
//!   norms summed by fixed trees, stopping at convergence.
//! - `side_group`: the bind group 1 and pipelines of the kernels with
//!   buffers of their own (the implicit step, the projection, FIRE).
//!
//! File-level circles, on purpose: `pack.rs` ↔ `surface.rs`, `tetra.rs`
//! and `special.rs`. `pack.rs` lays out the whole topology, their sections
//! included, and they build those sections' CSR lists with pack's
//! `push_csr`, the one CSR builder of the GPU buffers. And `backend/` ↔
//! `kinetics.rs`: the backend owns the device kinetics' buffer and
//! composes its step feature, and `kinetics.rs` lays that buffer
//! out and adds to `GpuBackend` the methods that read its events and bond
//! state back, so the buffer's layout has one home. And `shader.rs` ↔
//! `implicit.rs` (and through `side_group.rs`): the composer appends the
//! implicit step's stiffness dispatch, `implicit.rs` reads the evaluator
//! files to tell which laws have a device stiffness block, and
//! `side_group.rs`, which compiles the composed program for the implicit
//! step's kernels, is one of `implicit.rs`'s imports, and one of
//! `implicit_split.rs`'s, which takes the split solve's kernels from it.
//!
//! What runs where: each step — neighbour-list check and (when due) rebuild,
//! forces, overdamped integration — runs on the GPU without reading anything
//! back. The host reads positions back only when thermo, a dump or the end of
//! the run needs them; thermo quantities (energies, virial, pressure) are then
//! evaluated by the f64 CPU backend at the read-back positions.
//!
//! Not on the GPU (refused by [`GpuBackend::new`], and by `device gpu`
//! before a run; `device auto` falls back to the CPU): custom surface terms
//! of bodies, which have no kernel yet; pairs through several periodic
//! images (a periodic edge shorter than 2·(pair cutoff + skin), walked by
//! the CPU's list, `neighbor::ImageShifts`); the implicit
//! step of the models [`implicit::refusal`] names; constraints where
//! [`shake::refusal`] names why. Bond kinetics
//! are decided on the device for the rules [`kinetics`] ports, else on the
//! host after every step (see [`backend`]).
//!
//! # Precision
//!
//! Forces are f32. Positions are 64-bit fixed point relative to the box's
//! lower corner (an i32 and a u32 word per axis, unit q·2⁻³² with q a power
//! of two ≈ box/2²⁰, so ≈ 2⁻⁵² of the box: f64-like), updated with exact
//! integer adds; periodic wrapping subtracts the box length in fixed point.
//! A first version used double-single floats (f32 value + f32 correction);
//! it drifted by 3.7e-3 over 10⁴ steps on llvmpipe, because WGSL lets the
//! compiler rewrite float expressions as real arithmetic, which cancels the
//! error terms of two-sum; integers cannot be rewritten that way.
//! Separations are exact integer differences rounded once to f32. The
//! remaining difference from the CPU is the f32 force and displacement
//! rounding (relative ≈ 1e-7 per step), measured in `tests/suite/gpu.rs`.

pub mod adhesion;
pub mod backend;
pub mod bind;
pub mod contact;
pub mod context;
pub mod custom;
pub mod fire;
mod forces;
pub mod implicit;
mod implicit_split;
pub mod kinetics;
mod neighbours;
mod nlist;
pub mod pack;
mod prelude;
pub mod protocol;
pub mod shader;
pub mod shake;
mod side_group;
mod special;
mod step;
pub mod surface;
pub mod tetra;

pub use backend::{GpuBackend, GpuHalt};
pub use context::{DevicePreference, GpuContext};
