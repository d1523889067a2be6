// Rigid part motions on the GPU: move a state's vertices by their part's affine map (the
// articulated mesh the pixel-wise motion consistency renders), and reduce the rasterizer's
// vertex-position gradients to per-part first moments Σ g and Σ g xᵀ (what the motion
// parameters need; the rest of the chain rule runs on the CPU in f64).
//
// No float atomics: each workgroup writes its own partial sums, the CPU adds the few partials.

struct MotionParams {
    num_vertices: u32,
    num_parts: u32,
    _pad0: u32,
    _pad1: u32,
}

// x̂ = A x + b for the vertices of one part; A's columns in c0..c2, b in b (w unused).
struct PartAffine {
    c0: vec4<f32>,
    c1: vec4<f32>,
    c2: vec4<f32>,
    b: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: MotionParams;
@group(0) @binding(1) var<storage, read> motions: array<PartAffine>;
@group(0) @binding(2) var<storage, read> rest_positions: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> vertex_parts: array<u32>;
@group(0) @binding(4) var<storage, read_write> positions: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> grad_positions: array<vec4<f32>>;
// [workgroup][part][12]: Σ g (3) then Σ g xᵀ column-major (9).
@group(0) @binding(6) var<storage, read_write> partials: array<f32>;

// Vertices one workgroup of the reduction covers.
const REDUCE_ITEMS: u32 = 16u;
const MOMENTS: u32 = 12u;

@compute @workgroup_size(WG_SIZE)
fn apply_motion(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let i = workgroup_index(wg) * WG_SIZE + lid;
    if (i >= params.num_vertices) {
        return;
    }
    let m = motions[min(vertex_parts[i], params.num_parts - 1u)];
    let x = rest_positions[i].xyz;
    let a = mat3x3<f32>(m.c0.xyz, m.c1.xyz, m.c2.xyz);
    positions[i] = vec4<f32>(a * x + m.b.xyz, 0.0);
}

var<workgroup> wg_moments: array<f32, 3072>; // MOMENTS × WG_SIZE

@compute @workgroup_size(WG_SIZE)
fn reduce_motion_gradients(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let group = workgroup_index(wg);
    let first = group * WG_SIZE * REDUCE_ITEMS;
    for (var k = 0u; k < params.num_parts; k++) {
        var s: array<f32, 12>;
        for (var j = 0u; j < MOMENTS; j++) {
            s[j] = 0.0;
        }
        for (var item = 0u; item < REDUCE_ITEMS; item++) {
            let i = first + item * WG_SIZE + lid;
            if (i < params.num_vertices && vertex_parts[i] == k) {
                let g = grad_positions[i].xyz;
                let x = rest_positions[i].xyz;
                s[0] += g.x;
                s[1] += g.y;
                s[2] += g.z;
                for (var c = 0u; c < 3u; c++) {
                    s[3u + 3u * c] += g.x * x[c];
                    s[4u + 3u * c] += g.y * x[c];
                    s[5u + 3u * c] += g.z * x[c];
                }
            }
        }
        for (var j = 0u; j < MOMENTS; j++) {
            wg_moments[j * WG_SIZE + lid] = s[j];
        }
        workgroupBarrier();
        for (var stride = WG_SIZE / 2u; stride > 0u; stride /= 2u) {
            if (lid < stride) {
                for (var j = 0u; j < MOMENTS; j++) {
                    wg_moments[j * WG_SIZE + lid] += wg_moments[j * WG_SIZE + lid + stride];
                }
            }
            workgroupBarrier();
        }
        if (lid < MOMENTS) {
            partials[(group * params.num_parts + k) * MOMENTS + lid] = wg_moments[lid * WG_SIZE];
        }
        // The next part reuses wg_moments: everyone must have read before it is overwritten.
        workgroupBarrier();
    }
}
