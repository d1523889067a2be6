// Forward compositing: one workgroup per 16×16 tile, one invocation per pixel. Faces of the tile
// arrive depth-sorted (front to back) and are staged in workgroup memory in batches; each pixel
// composites α_n = min(0.99, σ_n φ_n(p)) with colour, depth and part logits interpolated by
// perspective-correct barycentrics, skipping α < alpha_min and stopping once T < transmittance_min.
//
// Output planes (planar f32, plane c at c · width · height): 0–2 RGB over the background,
// 3 expected depth Σ w z, 4 accumulated alpha Σ w, 5.. part logits Σ w s, and after the P logit
// planes the number of list entries each pixel consumed (u32 bits), which the backward pass replays.
// Per face it records the largest blending weight w = α T (as f32 bits: atomicMax on u32 orders
// non-negative floats correctly) and how many pixels it reached.

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> tile_ranges: array<u32>;
@group(0) @binding(2) var<storage, read> sorted_face: array<u32>;
@group(0) @binding(3) var<storage, read> records: array<FaceRecord>;
@group(0) @binding(4) var<storage, read> part_logits: array<f32>;   // [vertex][part]
@group(0) @binding(5) var<storage, read_write> render: array<f32>;
@group(0) @binding(6) var<storage, read_write> face_stats: array<atomic<u32>>;  // [face]: max weight bits, pixel count

const BATCH: u32 = 64u;
var<workgroup> batch: array<FaceGeometry, BATCH>;
var<workgroup> batch_face: array<u32, BATCH>;
var<workgroup> range: vec2<u32>;
var<workgroup> finished: atomic<u32>;

@compute @workgroup_size(WG_SIZE)
fn composite_forward(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let tile = workgroup_index(wg);
    if (tile >= params.tiles_x * params.tiles_y) {
        return;
    }
    let px = (tile % params.tiles_x) * TILE + lid % TILE;
    let py = (tile / params.tiles_x) * TILE + lid / TILE;
    let inside = px < params.width && py < params.height;
    let p = vec2<f32>(f32(px) + 0.5, f32(py) + 0.5);
    if (lid == 0u) {
        range = vec2<u32>(tile_ranges[2u * tile], tile_ranges[2u * tile + 1u]);
    }
    let r = workgroupUniformLoad(&range);
    let parts = params.num_parts;

    var transmittance = 1.0;
    var rgb = vec3<f32>(0.0);
    var depth = 0.0;
    var alpha_sum = 0.0;
    var logits: array<f32, MAX_PARTS>;
    var consumed = 0u;
    var done = !inside;
    if (done) {
        atomicAdd(&finished, 1u);
    }
    for (var start = r.x; start < r.y; start += BATCH) {
        let j = start + lid;
        if (lid < BATCH && j < r.y) {
            let f = sorted_face[j];
            batch_face[lid] = f;
            batch[lid] = face_geometry(records[f]);
        }
        workgroupBarrier();
        let count = min(BATCH, r.y - start);
        // The loop stays uniform (no break on `done`): a divergent loop counter would turn the
        // workgroup-memory reads of `batch[b]` into per-lane gathers on CPU implementations.
        for (var b = 0u; b < count; b++) {
            if (!done) {
                let hit = evaluate_face(batch[b], p, params);
                if (hit.alpha > 0.0) {
                    let f = batch_face[b];
                    let rec = records[f];
                    let w = hit.alpha * transmittance;
                    rgb += w * hit_color(rec, hit.mu);
                    depth += w * hit.z;
                    alpha_sum += w;
                    let v = rec.verts;
                    for (var k = 0u; k < parts; k++) {
                        logits[k] += w * (hit.mu.x * part_logits[v.x * parts + k]
                            + hit.mu.y * part_logits[v.y * parts + k]
                            + hit.mu.z * part_logits[v.z * parts + k]);
                    }
                    atomicMax(&face_stats[2u * f], bitcast<u32>(w));
                    atomicAdd(&face_stats[2u * f + 1u], 1u);
                    transmittance *= 1.0 - hit.alpha;
                    consumed = start + b + 1u - r.x;
                    if (transmittance < params.transmittance_min) {
                        done = true;
                        atomicAdd(&finished, 1u);
                    }
                }
            }
        }
        // Stop the whole tile once every pixel is saturated.
        if (workgroupUniformLoad(&finished) == WG_SIZE) {
            break;
        }
    }
    if (!inside) {
        return;
    }
    let npix = params.width * params.height;
    let pix = py * params.width + px;
    let color = rgb + transmittance * params.background.xyz;
    render[pix] = color.x;
    render[npix + pix] = color.y;
    render[2u * npix + pix] = color.z;
    render[3u * npix + pix] = depth;
    render[4u * npix + pix] = alpha_sum;
    for (var k = 0u; k < parts; k++) {
        render[(5u + k) * npix + pix] = logits[k];
    }
    render[(5u + parts) * npix + pix] = bitcast<f32>(consumed);
}
