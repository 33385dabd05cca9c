// GPU neighbour list: cell list by counting sort, then a per-particle Verlet
// list with skin, rebuilt only when some particle has moved more than skin/2.
//
// Each step runs `nb_displacement` and `nb_decide`; `nb_decide` writes the
// indirect dispatch sizes of the build kernels (zero workgroups when no build
// is due), so the decision never leaves the GPU. A build is:
//
//   nb_clear → nb_count (atomic counts per cell) → nb_scan_blocks →
//   nb_scan_totals → nb_scan_add (reduce-then-scan: no workgroup ever waits
//   on another, so it cannot deadlock) → nb_scatter → nb_sort (each cell's
//   members in ascending index, so the order is deterministic) → nb_build.
//
// `nb_build` writes at most `nlist_cap` neighbours per particle; a particle
// with more sets HALT_OVERFLOW and the largest count met, every later kernel
// of the call does nothing, and the host grows the list and resumes from the
// last completed step: neighbours are never dropped.

// cell_data sections: cell starts [0, cells], block sums [cells + 1, + blocks], members after.
fn off_block() -> u32 { return P.grid.w + 1u; }
fn off_members() -> u32 { return P.grid.w + 1u + P.scan_blocks; }

@group(1) @binding(0) var<storage, read_write> dispatch_args: array<u32>;

fn cell_coords(i: u32) -> vec3<u32> {
    let c = floor(relative_position(i) * P.cell_inv_width.xyz);
    let top = vec3<f32>(P.grid.xyz) - 1.0;
    return vec3<u32>(clamp(c, vec3<f32>(0.0), top));
}

fn cell_index(c: vec3<u32>) -> u32 {
    return (c.z * P.grid.y + c.y) * P.grid.x + c.x;
}

// Squared displacement since the last build, max-reduced through the bits
// of a non-negative f32 (monotone as u32).
@compute @workgroup_size(256)
fn nb_displacement(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    let dimg = vec3<f32>(image_of(i) - bitcast<vec3<i32>>(reference[2u * P.n + i].xyz));
    let then = Fixed3(bitcast<vec3<i32>>(reference[i].xyz), reference[P.n + i].xyz);
    let d = fixed_to_length(fixed_sub(fixed_of(i), then)) + dimg * P.box_len.xyz;
    let d2 = dot(d, d);
    if d2 > P.half_skin2 {
        atomicMax(&status[ST_MAX_DISP2], bitcast<u32>(d2));
    }
}

fn write_args(slot: u32, groups: u32, go: bool) {
    let gx = min(groups, P.groups_x);
    let gy = (groups + P.groups_x - 1u) / P.groups_x;
    dispatch_args[3u * slot] = select(0u, gx, go);
    dispatch_args[3u * slot + 1u] = select(0u, gy, go);
    dispatch_args[3u * slot + 2u] = select(0u, 1u, go);
}

// A list that overflowed when checked after the last `commit` (bind.wgsl)
// halts before any force reads it.
fn halt_if_list_overflowed() {
    if atomicLoad(&status[ST_LIST_AFTER_STEP]) == 0u && atomicLoad(&status[ST_OVERFLOW_NEED]) > P.nlist_cap {
        atomicOr(&status[ST_HALTED], HALT_OVERFLOW);
    }
}

// The start of a step whose list was checked after the last step's
// `commit` (with `bind` on the device; that check was this step's).
@compute @workgroup_size(1)
fn nb_list_ready() {
    halt_if_list_overflowed();
}

// Decides whether this step rebuilds; sizes the indirect dispatches. After
// `commit` (bind.wgsl) the check is the next step's: its number decides
// whether `every` is due.
@compute @workgroup_size(1)
fn nb_decide() {
    let next = select(0u, 1u, atomicLoad(&status[ST_LIST_AFTER_STEP]) != 0u);
    let step = atomicLoad(&status[ST_STEPS_DONE]) + P.step_lo + next; // the `every` test only needs the low word
    let moved = atomicLoad(&status[ST_MAX_DISP2]) != 0u;
    let due = (step % P.neighbor_every) == 0u && (moved || P.neighbor_check == 0u);
    let go = !halted() && (due || atomicLoad(&status[ST_FORCE_REBUILD]) != 0u);
    halt_if_list_overflowed();
    let particle_groups = (P.n + WORKGROUP - 1u) / WORKGROUP;
    let cell_groups = (P.grid.w + WORKGROUP - 1u) / WORKGROUP;
    write_args(0u, particle_groups, go);
    write_args(1u, cell_groups, go);
    write_args(2u, 1u, go);
    write_args(3u, (chunk.count + WORKGROUP - 1u) / WORKGROUP, go); // nb_build per chunk (chunk 0 is the largest)
    if go {
        atomicStore(&status[ST_MAX_DISP2], 0u);
        atomicStore(&status[ST_FORCE_REBUILD], 0u);
        atomicAdd(&status[ST_BUILDS], 1u);
    }
}

// Dispatched before and after the list check that follows `commit` (with
// `bind` on the device): toggles ST_LIST_AFTER_STEP.
@compute @workgroup_size(1)
fn nb_after_step() {
    atomicXor(&status[ST_LIST_AFTER_STEP], 1u);
}

@compute @workgroup_size(256)
fn nb_clear(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let c = linear_index(wg, local);
    if c < P.grid.w {
        atomicStore(&cell_count[c], 0u);
    }
}

@compute @workgroup_size(256)
fn nb_count(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i < P.n {
        atomicAdd(&cell_count[cell_index(cell_coords(i))], 1u);
    }
}

var<workgroup> scan_buffer: array<u32, 256>;

// Inclusive Hillis–Steele scan of scan_buffer within one workgroup.
fn workgroup_scan(local: u32) {
    for (var offset = 1u; offset < WORKGROUP; offset = offset * 2u) {
        workgroupBarrier();
        var add = 0u;
        if local >= offset {
            add = scan_buffer[local - offset];
        }
        workgroupBarrier();
        scan_buffer[local] = scan_buffer[local] + add;
    }
    workgroupBarrier();
}

// Pass 1: exclusive scan within each block of 256 cells; block totals aside.
@compute @workgroup_size(256)
fn nb_scan_blocks(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let block = wg.y * P.groups_x + wg.x;
    let c = block * WORKGROUP + local;
    var count = 0u;
    if c < P.grid.w {
        count = atomicLoad(&cell_count[c]);
    }
    scan_buffer[local] = count;
    workgroup_scan(local);
    if c < P.grid.w {
        cell_data[c] = scan_buffer[local] - count;
    }
    if local == WORKGROUP - 1u {
        cell_data[off_block() + block] = scan_buffer[local];
    }
}

// Pass 2: one workgroup scans the block totals, 256 at a time.
@compute @workgroup_size(256)
fn nb_scan_totals(@builtin(local_invocation_index) local: u32) {
    var carry = 0u;
    for (var base = 0u; base < P.scan_blocks; base = base + WORKGROUP) {
        let b = base + local;
        var total = 0u;
        if b < P.scan_blocks {
            total = cell_data[off_block() + b];
        }
        workgroupBarrier();
        scan_buffer[local] = total;
        workgroup_scan(local);
        if b < P.scan_blocks {
            cell_data[off_block() + b] = carry + scan_buffer[local] - total;
        }
        carry = carry + scan_buffer[WORKGROUP - 1u];
    }
    if local == 0u {
        cell_data[P.grid.w] = carry;
    }
}

// Pass 3: add each block's offset; reset the counts to serve as scatter cursors.
@compute @workgroup_size(256)
fn nb_scan_add(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let c = linear_index(wg, local);
    if c < P.grid.w {
        cell_data[c] = cell_data[c] + cell_data[off_block() + c / WORKGROUP];
        atomicStore(&cell_count[c], 0u);
    }
}

@compute @workgroup_size(256)
fn nb_scatter(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i < P.n {
        let c = cell_index(cell_coords(i));
        let slot = atomicAdd(&cell_count[c], 1u);
        cell_data[off_members() + cell_data[c] + slot] = i;
    }
}

// Insertion sort of each cell's members: the scatter order depends on
// thread timing, the sorted order does not.
@compute @workgroup_size(256)
fn nb_sort(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let c = linear_index(wg, local);
    if c >= P.grid.w {
        return;
    }
    let first = off_members() + cell_data[c];
    let end = off_members() + cell_data[c + 1u];
    for (var a = first + 1u; a < end; a++) {
        let v = cell_data[a];
        var b = a;
        while b > first && cell_data[b - 1u] > v {
            cell_data[b] = cell_data[b - 1u];
            b = b - 1u;
        }
        cell_data[b] = v;
    }
}

const NO_ENTRY: u32 = 0xffffffffu;

// Whether i and j are nodes of two different contact bodies.
fn contact_pair_kept(i: u32, j: u32) -> bool {
    if P.n_cfaces == 0u {
        return false;
    }
    let bi = topo[P.off_cbody + i];
    let bj = topo[P.off_cbody + j];
    return bi != NO_ENTRY && bj != NO_ENTRY && bi != bj;
}

fn is_excluded(i: u32, j: u32) -> bool {
    let first = topo[P.off_excl_offsets + i];
    let end = topo[P.off_excl_offsets + i + 1u];
    for (var k = first; k < end; k++) {
        if topo[P.off_excl + k] == j && exclusion_on(k) { // a broken kinetic bond excludes nothing
            return true;
        }
    }
    return false;
}

// The cells to visit along one axis: three around `c`, or all of them when
// the axis has fewer than three (so that no cell is visited twice).
fn stencil_start(c: u32, axis: u32) -> i32 {
    if P.grid[axis] < 3u {
        return 0;
    }
    return i32(c) - 1;
}

fn stencil_len(axis: u32) -> i32 {
    return i32(min(P.grid[axis], 3u));
}

// Wraps (periodic) or rejects (fixed, returns -1) a cell coordinate.
fn stencil_cell(v: i32, axis: u32) -> i32 {
    let g = i32(P.grid[axis]);
    if v >= 0 && v < g {
        return v;
    }
    if P.periodic[axis] == 1u {
        return (v + g) % g;
    }
    return -1;
}

// Appends to row `row` (holding `count` entries) the neighbours of i (in
// cell `ci`) within the list range that are (`cross`) or are not pairs of
// nodes of two contact bodies; returns the new count (entries beyond the
// capacity are counted, not written).
fn nb_gather(i: u32, ci: vec3<u32>, row: u32, count_in: u32, cross: bool) -> u32 {
    var count = count_in;
    for (var dz = 0; dz < stencil_len(2u); dz++) {
        let z = stencil_cell(stencil_start(ci.z, 2u) + dz, 2u);
        if z < 0 { continue; }
        for (var dy = 0; dy < stencil_len(1u); dy++) {
            let y = stencil_cell(stencil_start(ci.y, 1u) + dy, 1u);
            if y < 0 { continue; }
            for (var dx = 0; dx < stencil_len(0u); dx++) {
                let x = stencil_cell(stencil_start(ci.x, 0u) + dx, 0u);
                if x < 0 { continue; }
                let c = cell_index(vec3<u32>(u32(x), u32(y), u32(z)));
                let end = cell_data[c + 1u];
                for (var m = cell_data[c]; m < end; m++) {
                    let j = cell_data[off_members() + m];
                    if j == i || contact_pair_kept(i, j) != cross { continue; }
                    let d = separation(i, j);
                    if dot(d, d) < P.range2 {
                        // An excluded pair of different contact bodies stays, marked (src/gpu/contact.rs).
                        // With `bind` on the device (no pair terms there) bonded pairs stay:
                        // a bond that breaks may bind again within the step (bind.wgsl).
                        var entry = j;
                        if !bind_on() && is_excluded(i, j) {
                            entry = select(NO_ENTRY, j | CONTACT_ONLY, cross);
                        }
                        if entry != NO_ENTRY {
                            if count < P.nlist_cap {
                                nlist[row + 1u + count] = entry;
                            }
                            count++;
                        }
                    }
                }
            }
        }
    }
    return count;
}

// Each particle's row: with contact bodies, the nodes of other contact
// bodies first (the contact pass stops at the first entry that is not one,
// src/gpu/contact.rs), then the rest, each part in cell-stencil order.
@compute @workgroup_size(256)
fn nb_build(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = chunk_particle(wg, local);
    if !in_chunk(i) {
        return;
    }
    let ci = cell_coords(i);
    let row = nlist_row(i);
    var count = 0u;
    if P.n_cfaces > 0u {
        count = nb_gather(i, ci, row, count, true);
    }
    count = nb_gather(i, ci, row, count, false);
    nlist[row] = count;
    if count > P.nlist_cap {
        atomicMax(&status[ST_OVERFLOW_NEED], count);
        // After `commit` the step is finished first (its formation deferred, bind.wgsl).
        if atomicLoad(&status[ST_LIST_AFTER_STEP]) == 0u {
            atomicOr(&status[ST_HALTED], HALT_OVERFLOW);
        }
    }
    reference[i] = state[i];
    reference[P.n + i] = state[P.n + i];
    reference[2u * P.n + i] = state[2u * P.n + i];
}
