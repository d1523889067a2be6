// Forward compositing: one workgroup per 8×8 tile. Faces of the tile arrive depth-sorted
// (front to back) and are staged in workgroup memory in batches; each pixel composites
// α_n = min(0.99, σ_n φ_n(p)) with colour, depth and part logits interpolated by
// perspective-correct barycentrics, skipping α < alpha_min and stopping once T < transmittance_min.
//
// Each invocation shades PIXELS = 8 pixels, a whole column of the tile: a staged face is read from
// workgroup memory once for eight pixels. CPU drivers (lavapipe, SwiftShader) turn every
// workgroup-memory read into a per-lane gather, which made that read the dominant cost. Tiles are
// 8×8 rather than 3DGS's 16×16 because our faces are small: with faces of a pixel or two, a
// 16×16 tile lists ~4× more faces than cover any one of its pixels (measured: 3.7× fewer
// evaluations and 1.7–2.9× faster iterations on lavapipe at 8×8).
//
// Output planes (planar f32, plane c at c · width · height): 0–2 RGB over the background,
// 3 expected depth Σ w z, 4 accumulated alpha Σ w, 5.. part logits Σ w s, and after the P logit
// planes the number of list entries each pixel consumed (u32 bits), which the backward pass replays.
// Per face it records the largest blending weight w = α T (as f32 bits: atomicMax on u32 orders
// non-negative floats correctly) and how many pixels it reached.

// Bindings 0–4 (params, tile ranges, sorted faces, records, part logits) are in raster_tile.wgsl.
@group(0) @binding(5) var<storage, read_write> render: array<f32>;
@group(0) @binding(6) var<storage, read_write> face_stats: array<atomic<u32>>;  // [face]: max weight bits, pixel count

const PIXELS: u32 = 8u;                  // pixels per invocation, rows of one column
const INVOCATIONS: u32 = TILE * TILE / PIXELS;
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
    if ((*s).done) {
        return;
    }
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
    let column = column_pixel(tile, lid, PIXELS);
    let px = column.x;
    let py = column.y;
    var s0 = start_pixel(px, py + 0u);
    var s1 = start_pixel(px, py + 1u);
    var s2 = start_pixel(px, py + 2u);
    var s3 = start_pixel(px, py + 3u);
    var s4 = start_pixel(px, py + 4u);
    var s5 = start_pixel(px, py + 5u);
    var s6 = start_pixel(px, py + 6u);
    var s7 = start_pixel(px, py + 7u);
    let r = tile_range(tile, lid);
    for (var start = r.x; start < r.y; start += BATCH) {
        stage_batch(start, r.y, lid, INVOCATIONS);
        workgroupBarrier();
        // A uniform loop (no break on `done`): a divergent counter would make `batch[b]` a gather.
        let count = min(BATCH, r.y - start);
        for (var b = 0u; b < count; b++) {
            let g = batch[b];
            let entry = start + b - r.x;
            shade(&s0, g, b, entry);
            shade(&s1, g, b, entry);
            shade(&s2, g, b, entry);
            shade(&s3, g, b, entry);
            shade(&s4, g, b, entry);
            shade(&s5, g, b, entry);
            shade(&s6, g, b, entry);
            shade(&s7, g, b, entry);
        }
        // Stop the whole tile once every pixel is saturated.
        if (workgroupUniformLoad(&finished) == TILE * TILE) {
            break;
        }
    }
    write_pixel(s0, px, py + 0u);
    write_pixel(s1, px, py + 1u);
    write_pixel(s2, px, py + 2u);
    write_pixel(s3, px, py + 3u);
    write_pixel(s4, px, py + 4u);
    write_pixel(s5, px, py + 5u);
    write_pixel(s6, px, py + 6u);
    write_pixel(s7, px, py + 7u);
}
