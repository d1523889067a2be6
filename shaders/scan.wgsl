// Exclusive prefix sum of u32, in place, reduce-then-scan over blocks of 1024 elements.
// `scan_blocks` scans each block and records its total; the totals are scanned recursively
// (the same kernel one level up), then `add_block_offsets` adds each block's offset back.

const ITEMS: u32 = 4u;               // elements per invocation
const BLOCK: u32 = WG_SIZE * ITEMS;  // elements per workgroup

struct ScanParams {
    n: u32,           // elements at this level
    num_blocks: u32,  // ceil(n / BLOCK)
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: ScanParams;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> block_sums: array<u32>;

@compute @workgroup_size(WG_SIZE)
fn scan_blocks(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let block = workgroup_index(wg);
    if (block >= params.num_blocks) {
        return;
    }
    // Each invocation owns ITEMS consecutive elements so the block keeps its order.
    let base = block * BLOCK + lid * ITEMS;
    var local: array<u32, ITEMS>;
    var sum = 0u;
    for (var i = 0u; i < ITEMS; i++) {
        local[i] = sum;
        if (base + i < params.n) {
            sum += data[base + i];
        }
    }
    let scanned = workgroup_exclusive_scan(lid, sum);
    for (var i = 0u; i < ITEMS; i++) {
        if (base + i < params.n) {
            data[base + i] = scanned.x + local[i];
        }
    }
    if (lid == 0u) {
        block_sums[block] = scanned.y;
    }
}

@compute @workgroup_size(WG_SIZE)
fn add_block_offsets(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let block = workgroup_index(wg);
    if (block >= params.num_blocks) {
        return;
    }
    let offset = block_sums[block];
    for (var i = 0u; i < ITEMS; i++) {
        // Strided so neighbouring invocations touch neighbouring words.
        let idx = block * BLOCK + i * WG_SIZE + lid;
        if (idx < params.n) {
            data[idx] += offset;
        }
    }
}
