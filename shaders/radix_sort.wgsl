// Stable least-significant-digit radix sort of (u32 key, u32 value) pairs, 8 bits per pass.
// Per pass: `count_digits` builds a per-block digit histogram laid out digit-major
// (hist[digit * num_blocks + block]), so its exclusive prefix sum (scan.wgsl) is directly each
// (digit, block)'s first output slot; `scatter` ranks each block's keys stably by digit in
// workgroup memory and writes them to those slots.

const ITEMS: u32 = 4u;               // keys per invocation
const BLOCK: u32 = WG_SIZE * ITEMS;  // keys per workgroup (1024: local ranks fit 16 bits)
const RADIX: u32 = 256u;             // digits per pass; equals WG_SIZE, one bin per invocation

struct SortParams {
    n: u32,           // number of keys
    num_blocks: u32,  // ceil(n / BLOCK)
    shift: u32,       // bit offset of this pass's digit
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: SortParams;
@group(0) @binding(1) var<storage, read> keys_in: array<u32>;
@group(0) @binding(2) var<storage, read> values_in: array<u32>;
@group(0) @binding(3) var<storage, read_write> keys_out: array<u32>;
@group(0) @binding(4) var<storage, read_write> values_out: array<u32>;
@group(0) @binding(5) var<storage, read_write> histogram: array<u32>;

var<workgroup> bins: array<atomic<u32>, RADIX>;
// (digit << 16) | local index, in the block's current order.
var<workgroup> ranked: array<u32, BLOCK>;
var<workgroup> digit_start: array<u32, RADIX>;

fn digit_of(key: u32) -> u32 {
    return (key >> params.shift) & (RADIX - 1u);
}

@compute @workgroup_size(WG_SIZE)
fn count_digits(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let block = linear_workgroup(wid, nwg);
    if (block >= params.num_blocks) {
        return;
    }
    atomicStore(&bins[lid], 0u);
    workgroupBarrier();
    for (var i = 0u; i < ITEMS; i++) {
        let idx = block * BLOCK + i * WG_SIZE + lid;
        if (idx < params.n) {
            atomicAdd(&bins[digit_of(keys_in[idx])], 1u);
        }
    }
    workgroupBarrier();
    histogram[lid * params.num_blocks + block] = atomicLoad(&bins[lid]);
}

@compute @workgroup_size(WG_SIZE)
fn scatter(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let block = linear_workgroup(wid, nwg);
    if (block >= params.num_blocks) {
        return;
    }
    // Padding past n gets the largest digit: being last in the block, a stable sort keeps it
    // behind every real key, so real ranks are unaffected; it is never written out.
    var item: array<u32, ITEMS>;
    for (var i = 0u; i < ITEMS; i++) {
        let local = lid * ITEMS + i;
        let idx = block * BLOCK + local;
        var digit = RADIX - 1u;
        if (idx < params.n) {
            digit = digit_of(keys_in[idx]);
        }
        item[i] = (digit << 16u) | local;
    }

    // Stable local sort by digit: one split per digit bit, zeros before ones, order kept.
    for (var bit = 16u; bit < 24u; bit++) {
        var zeros = 0u;
        for (var i = 0u; i < ITEMS; i++) {
            zeros += 1u - ((item[i] >> bit) & 1u);
        }
        let scanned = workgroup_exclusive_scan(lid, zeros);
        var next_zero = scanned.x;
        var next_one = scanned.y + lid * ITEMS - scanned.x;
        for (var i = 0u; i < ITEMS; i++) {
            if (((item[i] >> bit) & 1u) == 0u) {
                ranked[next_zero] = item[i];
                next_zero++;
            } else {
                ranked[next_one] = item[i];
                next_one++;
            }
        }
        workgroupBarrier();
        for (var i = 0u; i < ITEMS; i++) {
            item[i] = ranked[lid * ITEMS + i];
        }
        workgroupBarrier();
    }

    // First local position of each digit present in the block.
    for (var i = 0u; i < ITEMS; i++) {
        let pos = lid * ITEMS + i;
        let digit = item[i] >> 16u;
        if (pos == 0u || (ranked[pos - 1u] >> 16u) != digit) {
            digit_start[digit] = pos;
        }
    }
    workgroupBarrier();

    for (var i = 0u; i < ITEMS; i++) {
        let pos = lid * ITEMS + i;
        let digit = item[i] >> 16u;
        let idx = block * BLOCK + (item[i] & 0xffffu);
        if (idx < params.n) {
            let dst = histogram[digit * params.num_blocks + block] + pos - digit_start[digit];
            keys_out[dst] = keys_in[idx];
            values_out[dst] = values_in[idx];
        }
    }
}
