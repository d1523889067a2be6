// Stable least-significant-digit radix sort of (u32 key, u32 value) pairs, 8 bits per pass.
// Per pass: `count_digits` builds a per-block digit histogram laid out digit-major
// (hist[digit * num_blocks + block]), so its exclusive prefix sum (scan.wgsl) is directly each
// (digit, block)'s first output slot; `scatter` ranks each block's keys stably by digit in
// workgroup memory and writes them to those slots.
//
// Local ranking is two stable 16-way multi-splits (low nibble of the digit, then high nibble):
// each invocation counts its keys per nibble value, one raking scan of those 16 counters
// (packed two per u32) places every key. On lavapipe this is 1.4x faster than eight one-bit
// splits (the cost is per round). Workgroup arrays are kept flat: an array of arrays indexed
// per invocation gave wrong results on SwiftShader (Chromium 156) while lavapipe was right.

// 16 keys per invocation: on lavapipe the cost is per workgroup round (barriers), so 4096-key
// blocks sort 3.4x faster than 1024-key ones (1M keys, 32 bits: 1183 -> 349 ms). Workgroup memory
// is 27 KB (`ranked` 16 KB): within the 32 KB that lavapipe and SwiftShader offer.
const ITEMS: u32 = 16u;              // keys per invocation
const BLOCK: u32 = WG_SIZE * ITEMS;  // keys per workgroup (4096: local ranks fit 16 bits)
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

// Multi-split state: 16 counters per invocation, two 16-bit counters per word (counts <= BLOCK).
const BUCKETS: u32 = 16u;
const PACKED: u32 = 8u;
const RAKE: u32 = 16u;  // RAKE * RAKE = WG_SIZE
var<workgroup> bucket_counts: array<u32, WG_SIZE * PACKED>;  // [invocation * PACKED + word]
var<workgroup> rake_sums: array<u32, RAKE * PACKED>;          // [lane * PACKED + word]
var<workgroup> bucket_base: array<u32, BUCKETS>;

fn digit_of(key: u32) -> u32 {
    return (key >> params.shift) & (RADIX - 1u);
}

@compute @workgroup_size(WG_SIZE)
fn count_digits(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let block = workgroup_index(wg);
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
fn scatter(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let block = workgroup_index(wg);
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

    // Stable local sort by digit: low nibble first, then high nibble (LSD within the block).
    for (var nibble_shift = 16u; nibble_shift < 24u; nibble_shift += 4u) {
        // Each key's rank among this invocation's keys of equal nibble, and the invocation's
        // 16 counters, from register comparisons (no index that depends on the data).
        var nibble = array<u32, ITEMS>();
        for (var i = 0u; i < ITEMS; i++) {
            nibble[i] = (item[i] >> nibble_shift) & (BUCKETS - 1u);
        }
        var rank_in_thread = array<u32, ITEMS>();
        for (var i = 0u; i < ITEMS; i++) {
            var rank = 0u;
            for (var j = 0u; j < i; j++) {
                rank += u32(nibble[j] == nibble[i]);
            }
            rank_in_thread[i] = rank;
        }
        for (var w = 0u; w < PACKED; w++) {
            var packed = 0u;
            for (var i = 0u; i < ITEMS; i++) {
                packed += u32(nibble[i] == 2u * w) + (u32(nibble[i] == 2u * w + 1u) << 16u);
            }
            bucket_counts[lid * PACKED + w] = packed;
        }
        workgroupBarrier();
        // Raking exclusive scan over invocations, all 16 counters at once.
        if (lid < RAKE) {
            for (var w = 0u; w < PACKED; w++) {
                var sum = 0u;
                for (var r = 0u; r < RAKE; r++) {
                    let at = (lid * RAKE + r) * PACKED + w;
                    let v = bucket_counts[at];
                    bucket_counts[at] = sum;
                    sum += v;
                }
                rake_sums[lid * PACKED + w] = sum;
            }
        }
        workgroupBarrier();
        if (lid == 0u) {
            var base = 0u;
            for (var w = 0u; w < PACKED; w++) {
                var sum = 0u;
                for (var r = 0u; r < RAKE; r++) {
                    let v = rake_sums[r * PACKED + w];
                    rake_sums[r * PACKED + w] = sum;
                    sum += v;
                }
                bucket_base[2u * w] = sum & 0xffffu;
                bucket_base[2u * w + 1u] = sum >> 16u;
            }
            // Totals per bucket -> first position of each bucket in the block.
            for (var b = 0u; b < BUCKETS; b++) {
                let total = bucket_base[b];
                bucket_base[b] = base;
                base += total;
            }
        }
        workgroupBarrier();
        for (var i = 0u; i < ITEMS; i++) {
            let b = nibble[i];
            let w = b >> 1u;
            let packed = bucket_counts[lid * PACKED + w] + rake_sums[(lid / RAKE) * PACKED + w];
            let before = (packed >> ((b & 1u) * 16u)) & 0xffffu;
            ranked[bucket_base[b] + before + rank_in_thread[i]] = item[i];
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
