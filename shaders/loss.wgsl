// Image loss of one rendered view against its target, forward and backward in one submission.
//
// Buffers are planar: map j of a multi-map buffer lives at [j * npix + pix], pix = y * width + x.
// Kernels, in dispatch order (one invocation per pixel each):
//   ssim_h      horizontal 11-tap Gaussian blur of x, y, x², y², xy per colour channel -> stats (15 maps)
//   ssim_v      vertical blur of stats, SSIM and its partials w.r.t. (μx, E[x²], E[xy]) -> dssim (9 maps)
//   ssim_back_h horizontal blur of dssim -> stats (first 9 maps; the blur is self-adjoint)
//   pixel       vertical blur of those, then every term's gradient for the pixel -> grad
//   finalize    one workgroup: sums the per-workgroup partial sums into the loss terms
// Sums go through per-workgroup partials (`sums`, SUMS_STRIDE floats per workgroup): the browser
// has no float atomics.

struct LossParams {
    width: u32,
    height: u32,
    npix: u32,
    num_parts: u32,
    target_offset: u32,  // first u32 of this view in `targets`
    num_groups: u32,     // workgroups of the per-pixel kernels
    depth_count: u32,    // pixels with valid target depth
    label_count: u32,    // pixels with a part label
    background: vec4<f32>,
    weights: vec4<f32>,  // l1, ssim, depth, part
    mask_weight: f32,
    inv_depth_count: f32,  // 1 / max(depth_count, 1)
    inv_label_count: f32,  // 1 / max(label_count, 1)
    _pad: f32,
    gauss: array<vec4<f32>, 3>,  // 11 normalised taps, centre at index 5
}

@group(0) @binding(0) var<uniform> params: LossParams;
@group(0) @binding(1) var<storage, read> render: array<f32>;
// Two words per pixel: RGBA8 (alpha = mask), then depth mm (low 16 bits) | label (high 16 bits).
@group(0) @binding(2) var<storage, read> targets: array<u32>;
@group(0) @binding(3) var<storage, read_write> grad: array<f32>;
@group(0) @binding(4) var<storage, read_write> stats: array<f32>;
@group(0) @binding(5) var<storage, read_write> dssim: array<f32>;
@group(0) @binding(6) var<storage, read_write> sums: array<f32>;
// total, l1, 1 - ssim, depth, part, mask, depth pixels, label pixels
@group(0) @binding(7) var<storage, read_write> terms: array<f32>;

const SSIM_C1: f32 = 0.0001;  // 0.01²
const SSIM_C2: f32 = 0.0009;  // 0.03²
const RADIUS: i32 = 5;
const SUMS_STRIDE: u32 = 8u;
// sums slots
const SUM_SSIM: u32 = 0u;
const SUM_L1: u32 = 1u;  // then depth, part, mask

fn tap(k: i32) -> f32 {
    let i = u32(k + RADIUS);
    return params.gauss[i / 4u][i % 4u];
}

struct Target {
    rgb: vec3<f32>,  // composited over the background
    mask: f32,
    depth: f32,      // metres, 0 = invalid
    label: u32,      // 0 = none, k + 1 = part k
}

fn load_target(pix: u32) -> Target {
    let base = params.target_offset + 2u * pix;
    let c = unpack4x8unorm(targets[base]);
    let w1 = targets[base + 1u];
    var t: Target;
    t.mask = c.w;
    t.rgb = c.xyz * c.w + params.background.xyz * (1.0 - c.w);
    t.depth = f32(w1 & 0xffffu) * 0.001;
    t.label = w1 >> 16u;
    return t;
}

fn render_rgb(pix: u32) -> vec3<f32> {
    let n = params.npix;
    return vec3<f32>(render[pix], render[n + pix], render[2u * n + pix]);
}

// Sign with sign(0) = 0: the subgradient the CPU reference uses too.
fn sgn(v: f32) -> f32 {
    return select(select(0.0, -1.0, v < 0.0), 1.0, v > 0.0);
}

var<workgroup> wg_sum: array<vec4<f32>, WG_SIZE>;
var<workgroup> wg_rake_sum: array<vec4<f32>, RAKE_LANES>;

// Sum of one vec4 per invocation over the workgroup (raking: two barriers). Uniform control flow only.
fn workgroup_sum(lid: u32, v: vec4<f32>) -> vec4<f32> {
    wg_sum[lid] = v;
    workgroupBarrier();
    if (lid < RAKE_LANES) {
        var s = vec4<f32>(0.0);
        for (var i = 0u; i < RAKE_LANES; i++) {
            s += wg_sum[lid * RAKE_LANES + i];
        }
        wg_rake_sum[lid] = s;
    }
    workgroupBarrier();
    var total = vec4<f32>(0.0);
    for (var i = 0u; i < RAKE_LANES; i++) {
        total += wg_rake_sum[i];
    }
    return total;
}

@compute @workgroup_size(WG_SIZE)
fn ssim_h(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let pix = workgroup_index(wg) * WG_SIZE + lid;
    if (pix >= params.npix) {
        return;
    }
    let n = params.npix;
    let px = i32(pix % params.width);
    let row = pix - u32(px);
    // Per channel: (μx, μy, E[x²], E[y²]) and E[xy].
    var acc = array<vec4<f32>, 3>();
    var acc_xy = vec3<f32>(0.0);
    for (var k = -RADIUS; k <= RADIUS; k++) {
        let x = px + k;
        if (x < 0 || x >= i32(params.width)) {
            continue;
        }
        let q = row + u32(x);
        let w = tap(k);
        let xs = render_rgb(q);
        let ys = load_target(q).rgb;
        for (var c = 0u; c < 3u; c++) {
            acc[c] += w * vec4<f32>(xs[c], ys[c], xs[c] * xs[c], ys[c] * ys[c]);
        }
        acc_xy += w * xs * ys;
    }
    for (var c = 0u; c < 3u; c++) {
        let base = c * 5u * n + pix;
        stats[base] = acc[c].x;
        stats[base + n] = acc[c].y;
        stats[base + 2u * n] = acc[c].z;
        stats[base + 3u * n] = acc[c].w;
        stats[base + 4u * n] = acc_xy[c];
    }
}

@compute @workgroup_size(WG_SIZE)
fn ssim_v(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let wg_index = workgroup_index(wg);
    if (wg_index >= params.num_groups) {
        return;
    }
    let pix = wg_index * WG_SIZE + lid;
    let n = params.npix;
    // Σ (1 - S) rather than Σ S: the sum stays small and 1 - mean S needs no cancelling
    // subtraction, which would cost the term its last digits (finite differences see them).
    var dssim_sum = 0.0;
    if (pix < n) {
        let py = i32(pix / params.width);
        let px = pix % params.width;
        for (var c = 0u; c < 3u; c++) {
            var m = vec4<f32>(0.0);  // μx, μy, E[x²], E[y²]
            var exy = 0.0;
            for (var k = -RADIUS; k <= RADIUS; k++) {
                let y = py + k;
                if (y < 0 || y >= i32(params.height)) {
                    continue;
                }
                let q = u32(y) * params.width + px;
                let w = tap(k);
                let base = c * 5u * n + q;
                m += w * vec4<f32>(stats[base], stats[base + n], stats[base + 2u * n], stats[base + 3u * n]);
                exy += w * stats[base + 4u * n];
            }
            let mx = m.x;
            let my = m.y;
            let a1 = 2.0 * mx * my + SSIM_C1;
            let a2 = 2.0 * (exy - mx * my) + SSIM_C2;
            let b1 = mx * mx + my * my + SSIM_C1;
            let b2 = (m.z - mx * mx) + (m.w - my * my) + SSIM_C2;
            let inv = 1.0 / (b1 * b2);
            let s = a1 * a2 * inv;
            dssim_sum += 1.0 - s;
            // S = a1 a2 / (b1 b2) as a function of (μx, E[x²], E[xy]) with the target's μy, E[y²] fixed:
            // a1' = 2μy, a2' = (-2μy, 0, 2), b1' = 2μx, b2' = (-2μx, 1, 0).
            let d_mu = (2.0 * my * (a2 - a1) - 2.0 * mx * s * (b2 - b1)) * inv;
            let d_xx = -s / b2;
            let d_xy = 2.0 * a1 * inv;
            let dst = c * 3u * n + pix;
            dssim[dst] = d_mu;
            dssim[dst + n] = d_xx;
            dssim[dst + 2u * n] = d_xy;
        }
    }
    let total = workgroup_sum(lid, vec4<f32>(dssim_sum, 0.0, 0.0, 0.0));
    if (lid == 0u) {
        sums[wg_index * SUMS_STRIDE + SUM_SSIM] = total.x;
    }
}

@compute @workgroup_size(WG_SIZE)
fn ssim_back_h(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let pix = workgroup_index(wg) * WG_SIZE + lid;
    if (pix >= params.npix) {
        return;
    }
    let n = params.npix;
    let px = i32(pix % params.width);
    let row = pix - u32(px);
    var acc = array<vec3<f32>, 3>();
    for (var k = -RADIUS; k <= RADIUS; k++) {
        let x = px + k;
        if (x < 0 || x >= i32(params.width)) {
            continue;
        }
        let q = row + u32(x);
        let w = tap(k);
        for (var c = 0u; c < 3u; c++) {
            let base = c * 3u * n + q;
            acc[c] += w * vec3<f32>(dssim[base], dssim[base + n], dssim[base + 2u * n]);
        }
    }
    for (var c = 0u; c < 3u; c++) {
        let base = c * 3u * n + pix;
        stats[base] = acc[c].x;
        stats[base + n] = acc[c].y;
        stats[base + 2u * n] = acc[c].z;
    }
}

@compute @workgroup_size(WG_SIZE)
fn pixel(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let wg_index = workgroup_index(wg);
    if (wg_index >= params.num_groups) {
        return;
    }
    let pix = wg_index * WG_SIZE + lid;
    let n = params.npix;
    // l1, depth, part, mask sums of this pixel
    var here = vec4<f32>(0.0);
    if (pix < n) {
        let py = i32(pix / params.width);
        let px = pix % params.width;
        var blurred = array<vec3<f32>, 3>();  // per channel: Σ g ∂S/∂μx, Σ g ∂S/∂E[x²], Σ g ∂S/∂E[xy]
        for (var k = -RADIUS; k <= RADIUS; k++) {
            let y = py + k;
            if (y < 0 || y >= i32(params.height)) {
                continue;
            }
            let q = u32(y) * params.width + px;
            let w = tap(k);
            for (var c = 0u; c < 3u; c++) {
                let base = c * 3u * n + q;
                blurred[c] += w * vec3<f32>(stats[base], stats[base + n], stats[base + 2u * n]);
            }
        }
        let t = load_target(pix);
        let xs = render_rgb(pix);
        let inv_colour = 1.0 / f32(3u * n);
        for (var c = 0u; c < 3u; c++) {
            let x = xs[c];
            let y = t.rgb[c];
            let diff = x - y;
            here.x += abs(diff);
            let b = blurred[c];
            let d_ssim = b.x + 2.0 * x * b.y + y * b.z;
            grad[c * n + pix] = (params.weights.x * sgn(diff) - params.weights.y * d_ssim) * inv_colour;
        }

        var g_depth = 0.0;
        if (t.depth > 0.0) {
            let diff = render[3u * n + pix] - t.depth;
            here.y = abs(diff);
            g_depth = params.weights.z * sgn(diff) * params.inv_depth_count;
        }
        grad[3u * n + pix] = g_depth;

        let mask_diff = render[4u * n + pix] - t.mask;
        here.w = abs(mask_diff);
        grad[4u * n + pix] = params.mask_weight * sgn(mask_diff) / f32(n);

        let logits = 5u * n + pix;
        let labelled = t.label > 0u && t.label <= params.num_parts;
        if (labelled) {
            // Stable log-sum-exp: shift by the largest logit.
            var top = render[logits];
            for (var j = 1u; j < params.num_parts; j++) {
                top = max(top, render[logits + j * n]);
            }
            var denom = 0.0;
            for (var j = 0u; j < params.num_parts; j++) {
                denom += exp(render[logits + j * n] - top);
            }
            let lse = top + log(denom);
            here.z = lse - render[logits + (t.label - 1u) * n];
            let scale = params.weights.w * params.inv_label_count;
            for (var j = 0u; j < params.num_parts; j++) {
                let p = exp(render[logits + j * n] - lse);
                grad[logits + j * n] = scale * (p - select(0.0, 1.0, j + 1u == t.label));
            }
        } else {
            for (var j = 0u; j < params.num_parts; j++) {
                grad[logits + j * n] = 0.0;
            }
        }
    }
    let total = workgroup_sum(lid, here);
    if (lid == 0u) {
        let base = wg_index * SUMS_STRIDE + SUM_L1;
        sums[base] = total.x;
        sums[base + 1u] = total.y;
        sums[base + 2u] = total.z;
        sums[base + 3u] = total.w;
    }
}

@compute @workgroup_size(WG_SIZE)
fn finalize(@builtin(local_invocation_index) lid: u32) {
    // (l1, depth, part, mask) and the Σ (1 - S) sum, strided over the workgroup partials.
    var acc = vec4<f32>(0.0);
    var acc_ssim = 0.0;
    for (var g = lid; g < params.num_groups; g += WG_SIZE) {
        let base = g * SUMS_STRIDE;
        acc += vec4<f32>(sums[base + SUM_L1], sums[base + SUM_L1 + 1u], sums[base + SUM_L1 + 2u], sums[base + SUM_L1 + 3u]);
        acc_ssim += sums[base + SUM_SSIM];
    }
    let a = workgroup_sum(lid, acc);
    let s = workgroup_sum(lid, vec4<f32>(acc_ssim, 0.0, 0.0, 0.0)).x;
    if (lid == 0u) {
        let inv_colour = 1.0 / f32(3u * params.npix);
        let l1 = a.x * inv_colour;
        let dssim_term = s * inv_colour;
        let depth = a.y * params.inv_depth_count;
        let part = a.z * params.inv_label_count;
        let mask = a.w / f32(params.npix);
        let w = params.weights;
        terms[0] = w.x * l1 + w.y * dssim_term + w.z * depth + w.w * part + params.mask_weight * mask;
        terms[1] = l1;
        terms[2] = dssim_term;
        terms[3] = depth;
        terms[4] = part;
        terms[5] = mask;
        terms[6] = f32(params.depth_count);
        terms[7] = f32(params.label_count);
    }
}
