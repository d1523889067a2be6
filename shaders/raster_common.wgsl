// Structs and helpers shared by the rasterizer's kernel families (prepended after prelude.wgsl by
// `raster::Rasterizer`). Layouts mirror `RasterParams` and `FaceRecord` in src/raster/kernels.rs.
//
// Conventions: pixel coordinates have their origin at the top-left image corner, pixel centres at
// +0.5; the camera looks down −z (OpenGL); w = −z_camera is the view depth (metres).
//
// Every function-scope `var` has an explicit initializer (`T()`): in Chromium 156 (SwiftShader) a
// `var x: T;` declared inside a loop kept the previous iteration's value instead of being zeroed,
// which corrupted the backward pass there while lavapipe was right.

const TILE: u32 = 8u;                  // tile side in pixels; one workgroup per tile
const MAX_PARTS: u32 = 16u;            // part logits per vertex (K + 1), at most
const PAIR_GRADS: u32 = 25u;           // per-(face, tile) gradient floats, without part logits
const CORNER_GRADS: u32 = 8u;          // per-corner gradient floats before the part logits
const LOG_DEPTH_MIN: f32 = -6.907755;  // ln(1e-3 m): sort keys quantise ln(depth) over [1 mm, 1 km]
const LOG_DEPTH_MAX: f32 = 6.907755;   // ln(1e3 m)

struct RasterParams {
    world_to_camera: mat4x4<f32>,
    camera_position: vec4<f32>,   // xyz: camera centre in world coordinates
    focal: vec4<f32>,             // fx, fy, cx, cy in pixels
    background: vec4<f32>,        // rgb composited behind the mesh
    width: u32,
    height: u32,
    tiles_x: u32,
    tiles_y: u32,
    num_faces: u32,
    num_vertices: u32,
    num_parts: u32,
    sh_degree: u32,               // active SH degree 0..3
    gamma: f32,                   // window sharpness exponent
    opacity_floor: f32,           // face opacity = floor + (1 − floor) · mean vertex opacity
    alpha_min: f32,               // contributions below this alpha are skipped (1/255; 0 while checking gradients)
    transmittance_min: f32,       // compositing stops below this transmittance (1e-4; 0 while checking)
    near: f32,                    // faces with a vertex closer than this are culled
    depth_bits: u32,              // low bits of a sort key holding the quantised depth
    num_pairs: u32,               // (face, tile) pairs emitted this view
    _pad: u32,
}

// One projected face: everything a pixel needs to evaluate it, in pixel units.
// Barycentrics are affine in the pixel: λ_i(p) = a_i · (p − s0) + [i == 0]. The first four
// vectors are what the per-pixel loops stage in workgroup memory (`FaceGeometry`); colours and
// vertex indices are read from the record only where a face actually covers the pixel.
struct FaceRecord {
    geom_x: vec4<f32>,  // a_i.x (i = 0..2), w: s0.x (projected vertex 0)
    geom_y: vec4<f32>,  // a_i.y, w: s0.y
    window: vec4<f32>,  // k_i = perimeter / l_i (l_i: length of the edge opposite vertex i), w: face opacity σ
    inv_w: vec4<f32>,   // 1 / w_i of the three vertices (perspective-correct weights), w: sort depth
    color0: vec4<f32>,  // view-dependent vertex colours (rgb)
    color1: vec4<f32>,
    color2: vec4<f32>,
    verts: vec4<u32>,   // vertex indices
    pixels: vec4<u32>,  // inclusive box of the pixel centres it may cover, x0, y0, x1, y1; x0 > x1 when culled
}

// The part of a record the coverage test needs.
struct FaceGeometry {
    geom_x: vec4<f32>,
    geom_y: vec4<f32>,
    window: vec4<f32>,
    inv_w: vec4<f32>,
}

fn face_geometry(rec: FaceRecord) -> FaceGeometry {
    return FaceGeometry(rec.geom_x, rec.geom_y, rec.window, rec.inv_w);
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// What a face contributes at a pixel; `alpha` is 0 when it contributes nothing.
struct Hit {
    alpha: f32,
    clamped: bool,      // alpha hit the 0.99 ceiling (no gradient through σφ)
    lambda: vec3<f32>,  // screen-space barycentrics
    u: f32,             // min_i λ_i k_i: 1 at the incenter, 0 on the edges
    edge: u32,          // arg-min of λ_i k_i
    phi: f32,           // window ReLU(u)^γ
    mu: vec3<f32>,      // perspective-correct barycentrics
    z: f32,             // perspective-correct view depth
    zsum: f32,          // Σ λ_i / w_i (= 1 / z)
}

// The triangle window of MeshSplatting: φ = ReLU(L(p) / L(s))^γ with L the max of the edge
// functions and s the incenter, written as (min_i distance to edge i / inradius)^γ
// = (min_i λ_i · perimeter / l_i)^γ.
fn evaluate_face(g: FaceGeometry, p: vec2<f32>, gamma: f32, alpha_min: f32) -> Hit {
    var hit = Hit();
    hit.alpha = 0.0;
    let d = p - vec2<f32>(g.geom_x.w, g.geom_y.w);
    let lambda = vec3<f32>(
        g.geom_x.x * d.x + g.geom_y.x * d.y + 1.0,
        g.geom_x.y * d.x + g.geom_y.y * d.y,
        g.geom_x.z * d.x + g.geom_y.z * d.y,
    );
    let scaled = lambda * g.window.xyz;
    var edge = 0u;
    var u = scaled.x;
    if (scaled.y < u) { u = scaled.y; edge = 1u; }
    if (scaled.z < u) { u = scaled.z; edge = 2u; }
    if (u <= 0.0) {
        return hit;
    }
    let phi = pow(u, gamma);
    let raw = g.window.w * phi;
    let alpha = min(raw, 0.99);
    if (alpha < alpha_min || alpha <= 0.0) {
        return hit;
    }
    let rho = lambda * g.inv_w.xyz;
    let zsum = rho.x + rho.y + rho.z;
    hit.alpha = alpha;
    hit.clamped = raw > 0.99;
    hit.lambda = lambda;
    hit.u = u;
    hit.edge = edge;
    hit.phi = phi;
    hit.mu = rho / zsum;
    hit.z = 1.0 / zsum;
    hit.zsum = zsum;
    return hit;
}

fn hit_color(rec: FaceRecord, mu: vec3<f32>) -> vec3<f32> {
    return mu.x * rec.color0.xyz + mu.y * rec.color1.xyz + mu.z * rec.color2.xyz;
}

// Pixel boxes larger than this get conservative coverage masks (every pixel of the box): the
// exact test costs one face evaluation per pixel of the box, in one invocation.
const EXACT_MASK_PIXELS: u32 = 1024u;

// Which pixels of `tile` a face reaches: bit (y · TILE + x) of the tile's 64 (x, y local; bits
// 32.. in the second word) is set where `evaluate_face` gives α > 0, inside the pixel box
// [lo, hi]; with `exact` false, every pixel of the box. Emission drops pairs whose mask is empty
// and the compositing kernels evaluate a face only where its bit is set, so this is the test
// that decides which pixel–face evaluations happen at all.
fn tile_mask(g: FaceGeometry, tile: vec2<u32>, lo: vec2<u32>, hi: vec2<u32>, exact: bool, gamma: f32, alpha_min: f32) -> vec2<u32> {
    let t0 = tile * TILE;
    let a = max(lo, t0);
    let b = min(hi, t0 + vec2<u32>(TILE - 1u));
    var m = vec2<u32>(0u, 0u);
    for (var y = a.y; y <= b.y; y++) {
        for (var x = a.x; x <= b.x; x++) {
            let p = vec2<f32>(f32(x) + 0.5, f32(y) + 0.5);
            if (!exact || evaluate_face(g, p, gamma, alpha_min).alpha > 0.0) {
                let bit = (y - t0.y) * TILE + (x - t0.x);
                if (bit < 32u) {
                    m.x |= 1u << bit;
                } else {
                    m.y |= 1u << (bit - 32u);
                }
            }
        }
    }
    return m;
}

// Whether a face's pixel box is small enough for exact masks.
fn exact_masks(lo: vec2<u32>, hi: vec2<u32>) -> bool {
    let size = hi - lo + vec2<u32>(1u);
    return size.x * size.y <= EXACT_MASK_PIXELS;
}
