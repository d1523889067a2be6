// View-dependent vertex colour from real spherical harmonics (degree 0..3, 16 coefficients per
// colour channel), forward and backward. One invocation per vertex.
//
// colour = max(Σ_l Y_l(d) c_l + 0.5, 0) with d the unit direction from the camera centre to the
// vertex (the 3DGS convention). The backward pass writes dL/dc and adds the gradient through d to
// the position gradient that the vertex gather already wrote.

const SH_COEFFS: u32 = 16u;

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> sh: array<f32>;             // [vertex][coeff][rgb]
@group(0) @binding(3) var<storage, read_write> colors: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> grad_colors: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> grad_sh: array<f32>;
@group(0) @binding(6) var<storage, read_write> grad_positions: array<vec4<f32>>;

const C0: f32 = 0.28209479177387814;
const C1: f32 = 0.4886025119029199;
const C2_0: f32 = 1.0925484305920792;
const C2_1: f32 = -1.0925484305920792;
const C2_2: f32 = 0.31539156525252005;
const C2_3: f32 = -1.0925484305920792;
const C2_4: f32 = 0.5462742152960396;
const C3_0: f32 = -0.5900435899266435;
const C3_1: f32 = 2.890611442640554;
const C3_2: f32 = -0.4570457994644658;
const C3_3: f32 = 0.3731763325901154;
const C3_4: f32 = -0.4570457994644658;
const C3_5: f32 = 1.445305721320277;
const C3_6: f32 = -0.5900435899266435;

fn coeff_count(degree: u32) -> u32 {
    return (degree + 1u) * (degree + 1u);
}

// Y_l(d) for l < 16 (unused entries are zero beyond the active degree).
fn sh_basis(d: vec3<f32>, degree: u32) -> array<f32, 16> {
    var y = array<f32, 16>();
    let x = d.x;
    let yy = d.y;
    let z = d.z;
    y[0] = C0;
    if (degree >= 1u) {
        y[1] = -C1 * yy;
        y[2] = C1 * z;
        y[3] = -C1 * x;
    }
    if (degree >= 2u) {
        y[4] = C2_0 * x * yy;
        y[5] = C2_1 * yy * z;
        y[6] = C2_2 * (2.0 * z * z - x * x - yy * yy);
        y[7] = C2_3 * x * z;
        y[8] = C2_4 * (x * x - yy * yy);
    }
    if (degree >= 3u) {
        y[9] = C3_0 * yy * (3.0 * x * x - yy * yy);
        y[10] = C3_1 * x * yy * z;
        y[11] = C3_2 * yy * (4.0 * z * z - x * x - yy * yy);
        y[12] = C3_3 * z * (2.0 * z * z - 3.0 * x * x - 3.0 * yy * yy);
        y[13] = C3_4 * x * (4.0 * z * z - x * x - yy * yy);
        y[14] = C3_5 * z * (x * x - yy * yy);
        y[15] = C3_6 * x * (x * x - 3.0 * yy * yy);
    }
    return y;
}

// Σ_l (dY_l/dd) w_l for per-coefficient weights w_l (w_l = g · c_l).
fn sh_basis_grad(d: vec3<f32>, degree: u32, w: array<f32, 16>) -> vec3<f32> {
    let x = d.x;
    let y = d.y;
    let z = d.z;
    var g = vec3<f32>(0.0);
    if (degree >= 1u) {
        g += vec3<f32>(0.0, -C1, 0.0) * w[1] + vec3<f32>(0.0, 0.0, C1) * w[2] + vec3<f32>(-C1, 0.0, 0.0) * w[3];
    }
    if (degree >= 2u) {
        g += vec3<f32>(C2_0 * y, C2_0 * x, 0.0) * w[4];
        g += vec3<f32>(0.0, C2_1 * z, C2_1 * y) * w[5];
        g += vec3<f32>(-2.0 * C2_2 * x, -2.0 * C2_2 * y, 4.0 * C2_2 * z) * w[6];
        g += vec3<f32>(C2_3 * z, 0.0, C2_3 * x) * w[7];
        g += vec3<f32>(2.0 * C2_4 * x, -2.0 * C2_4 * y, 0.0) * w[8];
    }
    if (degree >= 3u) {
        g += vec3<f32>(6.0 * C3_0 * x * y, C3_0 * (3.0 * x * x - 3.0 * y * y), 0.0) * w[9];
        g += vec3<f32>(C3_1 * y * z, C3_1 * x * z, C3_1 * x * y) * w[10];
        g += vec3<f32>(-2.0 * C3_2 * x * y, C3_2 * (4.0 * z * z - x * x - 3.0 * y * y), 8.0 * C3_2 * y * z) * w[11];
        g += vec3<f32>(-6.0 * C3_3 * x * z, -6.0 * C3_3 * y * z, C3_3 * (6.0 * z * z - 3.0 * x * x - 3.0 * y * y)) * w[12];
        g += vec3<f32>(C3_4 * (4.0 * z * z - 3.0 * x * x - y * y), -2.0 * C3_4 * x * y, 8.0 * C3_4 * x * z) * w[13];
        g += vec3<f32>(2.0 * C3_5 * x * z, -2.0 * C3_5 * y * z, C3_5 * (x * x - y * y)) * w[14];
        g += vec3<f32>(C3_6 * (3.0 * x * x - 3.0 * y * y), -6.0 * C3_6 * x * y, 0.0) * w[15];
    }
    return g;
}

fn vertex_index(wg: Workgroup, lid: u32) -> u32 {
    return workgroup_index(wg) * WG_SIZE + lid;
}

// Unit direction from the camera centre to vertex v (xyz) and the distance (w).
fn view_ray(v: u32) -> vec4<f32> {
    let offset = positions[v].xyz - params.camera_position.xyz;
    let dist = max(length(offset), 1e-12);
    return vec4<f32>(offset / dist, dist);
}

fn raw_color(v: u32, basis: array<f32, 16>, n: u32) -> vec3<f32> {
    var c = vec3<f32>(0.5);
    for (var l = 0u; l < n; l++) {
        let base = (v * SH_COEFFS + l) * 3u;
        c += basis[l] * vec3<f32>(sh[base], sh[base + 1u], sh[base + 2u]);
    }
    return c;
}

@compute @workgroup_size(WG_SIZE)
fn vertex_colors(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let v = vertex_index(wg, lid);
    if (v >= params.num_vertices) {
        return;
    }
    let basis = sh_basis(view_ray(v).xyz, params.sh_degree);
    let c = raw_color(v, basis, coeff_count(params.sh_degree));
    colors[v] = vec4<f32>(max(c, vec3<f32>(0.0)), 0.0);
}

@compute @workgroup_size(WG_SIZE)
fn sh_backward(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let v = vertex_index(wg, lid);
    if (v >= params.num_vertices) {
        return;
    }
    let ray = view_ray(v);
    let d = ray.xyz;
    let dist = ray.w;
    let basis = sh_basis(d, params.sh_degree);
    let n = coeff_count(params.sh_degree);
    let c = raw_color(v, basis, n);
    // The clamp at 0 passes no gradient.
    let g = select(vec3<f32>(0.0), grad_colors[v].xyz, c > vec3<f32>(0.0));
    var w = array<f32, 16>();
    for (var l = 0u; l < SH_COEFFS; l++) {
        let base = (v * SH_COEFFS + l) * 3u;
        let gl = g * basis[l];
        grad_sh[base] = gl.x;
        grad_sh[base + 1u] = gl.y;
        grad_sh[base + 2u] = gl.z;
        if (l < n) {
            w[l] = dot(g, vec3<f32>(sh[base], sh[base + 1u], sh[base + 2u]));
        }
    }
    let g_dir = sh_basis_grad(d, params.sh_degree, w);
    // d = offset / |offset|: the Jacobian projects out the radial component.
    let g_pos = (g_dir - d * dot(d, g_dir)) / dist;
    grad_positions[v] = grad_positions[v] + vec4<f32>(g_pos, 0.0);
}
