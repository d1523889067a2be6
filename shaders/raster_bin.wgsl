// Tile binning. `emit_pairs` (one invocation per face) writes a (tile, depth) sort key for every
// tile where the face's coverage mask is not empty, at the face's scanned offset, with the face
// and its mask; after the radix sort, `tile_ranges` (one invocation per sorted pair) records each
// tile's [start, end) in the sorted list and the face, mask and emission index of every sorted
// slot (the backward pass writes each pair's gradient at its emission index, so a face's pairs
// are contiguous and are gathered without atomics).

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> records: array<FaceRecord>;
@group(0) @binding(2) var<storage, read> offsets: array<u32>;        // exclusive scan of tile counts
@group(0) @binding(3) var<storage, read_write> keys: array<u32>;     // the sorter's keys
@group(0) @binding(4) var<storage, read_write> values: array<u32>;   // the sorter's values: emission index
@group(0) @binding(5) var<storage, read_write> pair_info: array<vec4<u32>>;   // emission index -> face, mask (2 words), 0
@group(0) @binding(6) var<storage, read_write> sorted_info: array<vec4<u32>>; // sorted slot -> face, mask, emission index
@group(0) @binding(7) var<storage, read_write> tile_ranges: array<u32>; // 2 per tile: start, end

fn depth_key(depth: f32) -> u32 {
    let mask = (1u << params.depth_bits) - 1u;
    let t = clamp((log(max(depth, 1e-30)) - LOG_DEPTH_MIN) / (LOG_DEPTH_MAX - LOG_DEPTH_MIN), 0.0, 1.0);
    return min(u32(t * f32(mask)), mask);
}

@compute @workgroup_size(WG_SIZE)
fn emit_pairs(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let f = workgroup_index(wg) * WG_SIZE + lid;
    if (f >= params.num_faces) {
        return;
    }
    let rec = records[f];
    let box = rec.pixels;
    if (box.x > box.z) {
        return;
    }
    let lo = box.xy;
    let hi = box.zw;
    let exact = exact_masks(lo, hi);
    let g = face_geometry(rec);
    let depth = depth_key(rec.inv_w.w);
    let t0 = lo / TILE;
    let t1 = hi / TILE;
    var e = offsets[f];
    let end = offsets[f + 1u];
    var tile = 0u;
    for (var ty = t0.y; ty <= t1.y; ty++) {
        for (var tx = t0.x; tx <= t1.x; tx++) {
            let m = tile_mask(g, vec2<u32>(tx, ty), lo, hi, exact, params.gamma, params.alpha_min);
            tile = ty * params.tiles_x + tx;
            // Never more than `project_faces` counted, whatever the compiler made of the test.
            if ((m.x | m.y) != 0u && e < end) {
                keys[e] = (tile << params.depth_bits) | depth;
                values[e] = e;
                pair_info[e] = vec4<u32>(f, m, 0u);
                e++;
            }
        }
    }
    // Fewer found than counted (same caveat): fill with empty masks, which composite nothing.
    for (; e < end; e++) {
        keys[e] = (tile << params.depth_bits) | depth;
        values[e] = e;
        pair_info[e] = vec4<u32>(f, 0u, 0u, 0u);
    }
}

fn tile_of(j: u32) -> u32 {
    return keys[j] >> params.depth_bits;
}

@compute @workgroup_size(WG_SIZE)
fn find_tile_ranges(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let j = workgroup_index(wg) * WG_SIZE + lid;
    let n = params.num_pairs;
    if (j >= n) {
        return;
    }
    let e = values[j];
    sorted_info[j] = vec4<u32>(pair_info[e].xyz, e);
    let tile = tile_of(j);
    if (j == 0u || tile_of(j - 1u) != tile) {
        tile_ranges[2u * tile] = j;
    }
    if (j + 1u == n || tile_of(j + 1u) != tile) {
        tile_ranges[2u * tile + 1u] = j + 1u;
    }
}
