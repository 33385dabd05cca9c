//! Where the GPU neighbour list lives: one row of 1 + capacity words per
//! particle (its neighbour count, then the neighbour indices), in one buffer
//! bound a chunk of particles at a time.
//!
//! Adapters cap a single storage binding (llvmpipe: 128 MiB) well below
//! their largest buffer, and a list for 10⁶ particles with ~100 neighbours
//! each needs 400 MB. So the rows of particles `[first, first + count)` of a
//! chunk are bound through a dynamic offset, and the two kernels that touch
//! the list (`nb_build`, `forces`) are dispatched once per chunk, with a
//! second dynamic offset selecting the chunk's `Chunk { first, count }`
//! uniform. Particle i's row starts at word i·(1 + capacity) of the buffer,
//! (i − first)·(1 + capacity) of its chunk's binding. When the whole list
//! fits one binding there is one chunk of all particles; otherwise each
//! chunk holds a multiple of 64 particles, so that every offset is a multiple
//! of 256 bytes (the largest offset alignment wgpu allows an adapter to ask).

use super::context::GpuContext;

/// Bytes between consecutive `Chunk` uniforms (wgpu's largest uniform
/// offset alignment).
const CHUNK_UNIFORM_STRIDE: u64 = 256;
/// Particles per chunk are a multiple of this, so that chunk offsets are
/// multiples of 256 bytes.
const CHUNK_GRANULE: u64 = 64;

/// The neighbour list's buffers and their chunking.
pub struct NeighbourStorage {
    /// Neighbours per particle the rows hold.
    pub capacity: u32,
    /// Particles per chunk (the last chunk may hold fewer).
    pub per_chunk: u32,
    /// Chunks covering all particles.
    pub chunks: u32,
    /// The rows, `chunks × per_chunk` of them.
    pub list: wgpu::Buffer,
    /// One `Chunk { first, count, 0, 0 }` per chunk, 256 bytes apart.
    pub chunk_info: wgpu::Buffer,
}

impl NeighbourStorage {
    /// Rows of `capacity` neighbours for `n` particles, chunked so that no
    /// binding exceeds `binding_limit` bytes; an error when even 64 rows
    /// exceed it or the whole list exceeds the adapter's largest buffer.
    pub fn new(ctx: &GpuContext, n: u32, capacity: u32, binding_limit: u64) -> Result<Self, String> {
        let row = row_bytes(capacity);
        let total = n.max(1) as u64 * row;
        let per_chunk = if total <= binding_limit { n.max(1) as u64 } else { (binding_limit / row) / CHUNK_GRANULE * CHUNK_GRANULE };
        let mib = |bytes: u64| bytes as f64 / 1_048_576.0;
        if per_chunk == 0 {
            return Err(format!(
                "the neighbour list needs {} B per particle ({capacity} neighbours for some particle), and {CHUNK_GRANULE} particles' \
                 rows exceed the largest storage binding {} allows ({:.0} MiB); reduce the cutoff or the neighbour skin, or use `device cpu`",
                row,
                ctx.info.name,
                mib(binding_limit)
            ));
        }
        let chunks = (n.max(1) as u64).div_ceil(per_chunk);
        let list_bytes = chunks * per_chunk * row;
        // Dynamic offsets are u32: chunks beyond 4 GiB cannot be addressed.
        let largest = ctx.limits.max_buffer_size.min(1 << 32);
        if list_bytes > largest {
            return Err(format!(
                "the neighbour list needs {:.0} MiB ({capacity} neighbours for some particle), more than the largest buffer {} allows \
                 ({:.0} MiB); reduce the particle count, the cutoff or the neighbour skin, or use `device cpu`",
                mib(list_bytes),
                ctx.info.name,
                mib(largest)
            ));
        }
        let mut info = vec![0u32; (chunks * CHUNK_UNIFORM_STRIDE / 4) as usize];
        for c in 0..chunks {
            let first = c * per_chunk;
            let slot = (c * CHUNK_UNIFORM_STRIDE / 4) as usize;
            info[slot] = first as u32;
            info[slot + 1] = per_chunk.min((n as u64).saturating_sub(first)) as u32;
        }
        let list = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("nlist"),
            size: list_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let chunk_info = wgpu::util::DeviceExt::create_buffer_init(
            &ctx.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("nlist chunks"),
                contents: bytemuck::cast_slice(&info),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        Ok(Self { capacity, per_chunk: per_chunk as u32, chunks: chunks as u32, list, chunk_info })
    }

    /// Bytes of one chunk's rows (the size of the list binding).
    pub fn binding_bytes(&self) -> u64 {
        self.per_chunk as u64 * row_bytes(self.capacity)
    }

    /// The dynamic offsets selecting chunk `c`, in binding order: the rows
    /// (binding 8), then the `Chunk` uniform (binding 11).
    pub fn offsets(&self, c: u32) -> [u32; 2] {
        [(c as u64 * self.binding_bytes()) as u32, (c as u64 * CHUNK_UNIFORM_STRIDE) as u32]
    }

    /// The bind-group entries of the rows and the `Chunk` uniform.
    pub fn entries(&self) -> [wgpu::BindGroupEntry<'_>; 2] {
        let bind = |binding, buffer, size| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer, offset: 0, size: std::num::NonZeroU64::new(size) }),
        };
        [bind(8, &self.list, self.binding_bytes()), bind(11, &self.chunk_info, 16)]
    }
}

fn row_bytes(capacity: u32) -> u64 {
    4 * (1 + capacity as u64)
}
