// Forward compositing: one workgroup per 8×8 tile, one invocation per pixel. Faces of the tile
// arrive depth-sorted (front to back) with their coverage masks and are staged in workgroup memory
// in batches; each pixel composites, in list order, only the staged faces whose mask covers it:
// α_n = min(0.99, σ_n φ_n(p)) with colour, depth and part logits interpolated by
// perspective-correct barycentrics, skipping α < alpha_min and stopping once T < transmittance_min.
//
// Faces are mostly a pixel or two, so a face covers few of a tile's 64 pixels: walking the mask
// bits instead of testing every face at every pixel cut the evaluations ~60-fold at 128² (most
// of the old ones were misses). Tiles are 8×8 rather than 3DGS's 16×16 for the same reason: a
// 16×16 tile lists ~4× more faces, and building each pixel's word costs one step per listed face.
//
// Output planes (planar f32, plane c at c · width · height): 0–2 RGB over the background,
// 3 expected depth Σ w z, 4 accumulated alpha Σ w, 5.. part logits Σ w s, and after the P logit
// planes the number of list entries each pixel consumed (u32 bits), which the backward pass replays.
// Per face it records the largest blending weight w = α T (as f32 bits: atomicMax on u32 orders
// non-negative floats correctly) and how many pixels it reached.

// Bindings 0–4 (params, tile ranges, sorted faces, records, part logits) are in raster_tile.wgsl.
@group(0) @binding(5) var<storage, read_write> render: array<f32>;
@group(0) @binding(6) var<storage, read_write> face_stats: array<atomic<u32>>;  // [face]: max weight bits, pixel count

const INVOCATIONS: u32 = TILE * TILE;
var<workgroup> finished: atomic<u32>;

struct Pixel {
    p: vec2<f32>,
    transmittance: f32,
    rgb: vec3<f32>,
    depth: f32,
    alpha: f32,
    consumed: u32,
    done: bool,
    logits: array<f32, MAX_PARTS>,
}

fn start_pixel(px: u32, py: u32) -> Pixel {
    var s = Pixel();
    s.p = vec2<f32>(f32(px) + 0.5, f32(py) + 0.5);
    s.transmittance = 1.0;
    s.done = px >= params.width || py >= params.height;
    if (s.done) {
        atomicAdd(&finished, 1u);
    }
    return s;
}

// Composites staged face `b` (list entry `entry`) over pixel `s`.
fn shade(s: ptr<function, Pixel>, g: FaceGeometry, b: u32, entry: u32) {
    let hit = evaluate_face(g, (*s).p, params.gamma, params.alpha_min);
    if (hit.alpha <= 0.0) {
        return;
    }
    let f = batch_face[b];
    let hv = hit_vertices(f);
    let w = hit.alpha * (*s).transmittance;
    (*s).rgb += w * (hit.mu.x * hv.c0 + hit.mu.y * hv.c1 + hit.mu.z * hv.c2);
    (*s).depth += w * hit.z;
    (*s).alpha += w;
    for (var k = 0u; k < params.num_parts; k++) {
        (*s).logits[k] += w * dot(hit.mu, vertex_logits(hv.verts, k));
    }
    atomicMax(&face_stats[2u * f], bitcast<u32>(w));
    atomicAdd(&face_stats[2u * f + 1u], 1u);
    (*s).transmittance *= 1.0 - hit.alpha;
    (*s).consumed = entry + 1u;
    if ((*s).transmittance < params.transmittance_min) {
        (*s).done = true;
        atomicAdd(&finished, 1u);
    }
}

fn write_pixel(s: Pixel, px: u32, py: u32) {
    if (px >= params.width || py >= params.height) {
        return;
    }
    let npix = params.width * params.height;
    let pix = py * params.width + px;
    let color = s.rgb + s.transmittance * params.background.xyz;
    render[pix] = color.x;
    render[npix + pix] = color.y;
    render[2u * npix + pix] = color.z;
    render[3u * npix + pix] = s.depth;
    render[4u * npix + pix] = s.alpha;
    for (var k = 0u; k < params.num_parts; k++) {
        render[(5u + k) * npix + pix] = s.logits[k];
    }
    render[(5u + params.num_parts) * npix + pix] = bitcast<f32>(s.consumed);
}

@compute @workgroup_size(INVOCATIONS)
fn composite_forward(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let tile = workgroup_index(wg);
    if (tile >= params.tiles_x * params.tiles_y) {
        return;
    }
    let px = tile_pixel(tile, lid);
    var s = start_pixel(px.x, px.y);
    let r = tile_range(tile, lid);
    for (var start = r.x; start < r.y; start += BATCH) {
        stage_batch(start, r.y, lid, INVOCATIONS);
        workgroupBarrier();
        var word = covering_faces(lid, min(BATCH, r.y - start));
        while (word != 0u && !s.done) {
            let b = firstTrailingBit(word);
            word &= word - 1u;
            shade(&s, batch[b], b, start + b - r.x);
        }
        // Stop the whole tile once every pixel is saturated.
        if (workgroupUniformLoad(&finished) == TILE * TILE) {
            break;
        }
    }
    write_pixel(s, px.x, px.y);
}
