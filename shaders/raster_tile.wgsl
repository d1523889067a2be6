// Shared by the two per-tile compositing kernels (raster_composite.wgsl, raster_backward.wgsl):
// their common bindings, the batch of faces staged in workgroup memory with their coverage masks,
// and the tile → pixel map. One invocation per pixel: a pixel walks only the staged faces whose
// mask covers it (`covering_faces`), so the work per tile is the number of pixel–face hits, not
// faces × 64.
// Prepended after raster_common.wgsl.

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> tile_ranges: array<u32>;
@group(0) @binding(2) var<storage, read> sorted_info: array<vec4<u32>>;  // face, mask (2 words), emission index
@group(0) @binding(3) var<storage, read> records: array<FaceRecord>;
@group(0) @binding(4) var<storage, read> part_logits: array<f32>;   // [vertex][part]

const BATCH: u32 = 32u;
var<workgroup> batch: array<FaceGeometry, BATCH>;
var<workgroup> batch_face: array<u32, BATCH>;
var<workgroup> batch_mask: array<vec2<u32>, BATCH>;
var<workgroup> batch_pair: array<u32, BATCH>;  // emission index, where the pair's gradient goes
var<workgroup> range: vec2<u32>;

// The tile's [start, end) in the sorted list, uniform across the workgroup.
fn tile_range(tile: u32, lid: u32) -> vec2<u32> {
    if (lid == 0u) {
        range = vec2<u32>(tile_ranges[2u * tile], tile_ranges[2u * tile + 1u]);
    }
    return workgroupUniformLoad(&range);
}

// The pixel invocation `lid` shades in `tile` (its bit in the coverage masks is `lid`).
fn tile_pixel(tile: u32, lid: u32) -> vec2<u32> {
    return vec2<u32>(
        (tile % params.tiles_x) * TILE + lid % TILE,
        (tile / params.tiles_x) * TILE + lid / TILE,
    );
}

// The staged faces (bit b for batch slot b) whose mask covers pixel bit `lid`.
fn covering_faces(lid: u32, count: u32) -> u32 {
    let high = lid >= 32u;
    let shift = lid & 31u;
    var word = 0u;
    for (var b = 0u; b < count; b++) {
        let m = batch_mask[b];
        word |= ((select(m.x, m.y, high) >> shift) & 1u) << b;
    }
    return word;
}

// Stages sorted entries start .. min(start + BATCH, end); a barrier must follow.
fn stage_batch(start: u32, end: u32, lid: u32, invocations: u32) {
    for (var i = lid; i < BATCH && start + i < end; i += invocations) {
        let info = sorted_info[start + i];
        batch_face[i] = info.x;
        batch_mask[i] = info.yz;
        batch_pair[i] = info.w;
        batch[i] = face_geometry(records[info.x]);
    }
}

// What a hit needs beyond the staged geometry, read field by field: a whole-record load is 36
// per-lane gathers on CPU drivers.
struct HitVertices {
    c0: vec3<f32>,
    c1: vec3<f32>,
    c2: vec3<f32>,
    verts: vec3<u32>,
}

fn hit_vertices(f: u32) -> HitVertices {
    return HitVertices(records[f].color0.xyz, records[f].color1.xyz, records[f].color2.xyz, records[f].verts.xyz);
}

// Part logit k of the three vertices.
fn vertex_logits(v: vec3<u32>, k: u32) -> vec3<f32> {
    let parts = params.num_parts;
    return vec3<f32>(part_logits[v.x * parts + k], part_logits[v.y * parts + k], part_logits[v.z * parts + k]);
}
