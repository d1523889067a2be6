// Image loss of one rendered view against its target, forward and backward in one submission.
//
// Buffers are planar: map j of a multi-map buffer lives at [j * npix + pix], pix = y * width + x.
// Kernels, in dispatch order (one invocation per SEGMENT pixels of a row or column, see below):
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
    num_groups: u32,     // workgroups of the vertical (column) kernels, which write partial sums
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

// The SSIM blurs run as sliding windows: one invocation walks SEGMENT consecutive outputs of one
// line (a row for the horizontal passes, a column for the vertical ones), holding the last 11
// inputs in registers (r0..r10, shifted by one per step), so each input is loaded once per
// segment instead of once per tap (11×). Consecutive invocations take consecutive lines: the
// vertical passes' loads are coalesced on a GPU; on CPU drivers every load is a per-lane gather,
// which is what this saves. Taps outside the image count as zero (the CPU reference's padding).
const SEGMENT: u32 = 32u;

// One invocation's run: its line, the first output position on it and how many it owns.
struct Run {
    line: u32,
    first: u32,
    count: u32,
    valid: bool,
}

// `lines` lines of length `len`, SEGMENT outputs per invocation; invocation `id`.
fn run_of(id: u32, lines: u32, len: u32) -> Run {
    var r = Run();
    r.line = id % lines;
    r.first = (id / lines) * SEGMENT;
    r.valid = r.first < len;
    r.count = select(0u, min(SEGMENT, len - r.first), r.valid);
    return r;
}

// Pixel index of position `i` on row line / column line.
fn row_pixel(line: u32, i: u32) -> u32 {
    return line * params.width + i;
}

fn column_pixel(line: u32, i: u32) -> u32 {
    return i * params.width + line;
}

// Per channel (x, y, x², y²) and the three xy products: what SSIM blurs (15 values).
struct Moments {
    r: vec4<f32>,
    g: vec4<f32>,
    b: vec4<f32>,
    xy: vec3<f32>,
}

fn mad_moments(acc: Moments, w: f32, v: Moments) -> Moments {
    return Moments(acc.r + w * v.r, acc.g + w * v.g, acc.b + w * v.b, acc.xy + w * v.xy);
}

// Per channel (∂S/∂μx, ∂S/∂E[x²], ∂S/∂E[xy]) (9 values).
struct Partials {
    r: vec3<f32>,
    g: vec3<f32>,
    b: vec3<f32>,
}

fn mad_partials(acc: Partials, w: f32, v: Partials) -> Partials {
    return Partials(acc.r + w * v.r, acc.g + w * v.g, acc.b + w * v.b);
}

fn pixel_moments(q: u32) -> Moments {
    let x = render_rgb(q);
    let y = load_target(q).rgb;
    return Moments(
        vec4<f32>(x.x, y.x, x.x * x.x, y.x * y.x),
        vec4<f32>(x.y, y.y, x.y * x.y, y.y * y.y),
        vec4<f32>(x.z, y.z, x.z * x.z, y.z * y.z),
        x * y,
    );
}

// stats: channel c's (μx, μy, E[x²], E[y²], E[xy]) at maps 5c .. 5c + 4.
fn store_moments(q: u32, m: Moments) {
    let n = params.npix;
    let c = array<vec4<f32>, 3>(m.r, m.g, m.b);
    for (var k = 0u; k < 3u; k++) {
        let base = k * 5u * n + q;
        stats[base] = c[k].x;
        stats[base + n] = c[k].y;
        stats[base + 2u * n] = c[k].z;
        stats[base + 3u * n] = c[k].w;
        stats[base + 4u * n] = m.xy[k];
    }
}

fn load_moments(q: u32) -> Moments {
    let n = params.npix;
    var c = array<vec4<f32>, 3>();
    var xy = vec3<f32>();
    for (var k = 0u; k < 3u; k++) {
        let base = k * 5u * n + q;
        c[k] = vec4<f32>(stats[base], stats[base + n], stats[base + 2u * n], stats[base + 3u * n]);
        xy[k] = stats[base + 4u * n];
    }
    return Moments(c[0], c[1], c[2], xy);
}

// Partials live at maps 3c .. 3c + 2 of `dssim` (per pixel) and of `stats` (blurred along rows).
fn load_dssim(q: u32) -> Partials {
    let n = params.npix;
    return Partials(
        vec3<f32>(dssim[q], dssim[q + n], dssim[q + 2u * n]),
        vec3<f32>(dssim[3u * n + q], dssim[4u * n + q], dssim[5u * n + q]),
        vec3<f32>(dssim[6u * n + q], dssim[7u * n + q], dssim[8u * n + q]),
    );
}

fn load_blurred_partials(q: u32) -> Partials {
    let n = params.npix;
    return Partials(
        vec3<f32>(stats[q], stats[q + n], stats[q + 2u * n]),
        vec3<f32>(stats[3u * n + q], stats[4u * n + q], stats[5u * n + q]),
        vec3<f32>(stats[6u * n + q], stats[7u * n + q], stats[8u * n + q]),
    );
}

// The 11 taps, read once per invocation.
struct Taps {
    t0: f32, t1: f32, t2: f32, t3: f32, t4: f32, t5: f32, t6: f32, t7: f32, t8: f32, t9: f32, t10: f32,
}

fn taps() -> Taps {
    return Taps(tap(-5), tap(-4), tap(-3), tap(-2), tap(-1), tap(0), tap(1), tap(2), tap(3), tap(4), tap(5));
}

// Horizontal blur of the moments: stats.
@compute @workgroup_size(WG_SIZE)
fn ssim_h(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let run = run_of(workgroup_index(wg) * WG_SIZE + lid, params.height, params.width);
    if (!run.valid || run.line >= params.height) {
        return;
    }
    let t = taps();
    var r0 = Moments(); var r1 = Moments(); var r2 = Moments(); var r3 = Moments();
    var r4 = Moments(); var r5 = Moments(); var r6 = Moments(); var r7 = Moments();
    var r8 = Moments(); var r9 = Moments(); var r10 = Moments();
    let len = i32(params.width);
    let first = i32(run.first);
    for (var i = first - RADIUS; i < first + i32(run.count) + RADIUS; i++) {
        r0 = r1; r1 = r2; r2 = r3; r3 = r4; r4 = r5; r5 = r6; r6 = r7; r7 = r8; r8 = r9; r9 = r10;
        r10 = Moments();
        if (i >= 0 && i < len) {
            r10 = pixel_moments(row_pixel(run.line, u32(i)));
        }
        if (i >= first + RADIUS) {
            var m = Moments();
            m = mad_moments(m, t.t0, r0); m = mad_moments(m, t.t1, r1); m = mad_moments(m, t.t2, r2);
            m = mad_moments(m, t.t3, r3); m = mad_moments(m, t.t4, r4); m = mad_moments(m, t.t5, r5);
            m = mad_moments(m, t.t6, r6); m = mad_moments(m, t.t7, r7); m = mad_moments(m, t.t8, r8);
            m = mad_moments(m, t.t9, r9); m = mad_moments(m, t.t10, r10);
            store_moments(row_pixel(run.line, u32(i - RADIUS)), m);
        }
    }
}

// SSIM of one channel from its blurred moments: Σ(1 − S) term and the partials of S w.r.t.
// (μx, E[x²], E[xy]) with the target's μy, E[y²] fixed.
fn ssim_partials(m: vec4<f32>, exy: f32, one_minus: ptr<function, f32>) -> vec3<f32> {
    let mx = m.x;
    let my = m.y;
    let a1 = 2.0 * mx * my + SSIM_C1;
    let a2 = 2.0 * (exy - mx * my) + SSIM_C2;
    let b1 = mx * mx + my * my + SSIM_C1;
    let b2 = (m.z - mx * mx) + (m.w - my * my) + SSIM_C2;
    let inv = 1.0 / (b1 * b2);
    let s = a1 * a2 * inv;
    *one_minus += 1.0 - s;
    // a1' = 2μy, a2' = (-2μy, 0, 2), b1' = 2μx, b2' = (-2μx, 1, 0).
    let d_mu = (2.0 * my * (a2 - a1) - 2.0 * mx * s * (b2 - b1)) * inv;
    let d_xx = -s / b2;
    let d_xy = 2.0 * a1 * inv;
    return vec3<f32>(d_mu, d_xx, d_xy);
}

// Vertical blur of stats, SSIM and its partials: dssim, and Σ(1 − S) per workgroup.
@compute @workgroup_size(WG_SIZE)
fn ssim_v(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let wg_index = workgroup_index(wg);
    if (wg_index >= params.num_groups) {
        return;
    }
    let run = run_of(wg_index * WG_SIZE + lid, params.width, params.height);
    // Σ (1 - S) rather than Σ S: the sum stays small and 1 - mean S needs no cancelling
    // subtraction, which would cost the term its last digits (finite differences see them).
    var dssim_sum = 0.0;
    if (run.valid && run.line < params.width) {
        let t = taps();
        var r0 = Moments(); var r1 = Moments(); var r2 = Moments(); var r3 = Moments();
        var r4 = Moments(); var r5 = Moments(); var r6 = Moments(); var r7 = Moments();
        var r8 = Moments(); var r9 = Moments(); var r10 = Moments();
        let len = i32(params.height);
        let first = i32(run.first);
        let n = params.npix;
        for (var i = first - RADIUS; i < first + i32(run.count) + RADIUS; i++) {
            r0 = r1; r1 = r2; r2 = r3; r3 = r4; r4 = r5; r5 = r6; r6 = r7; r7 = r8; r8 = r9; r9 = r10;
            r10 = Moments();
            if (i >= 0 && i < len) {
                r10 = load_moments(column_pixel(run.line, u32(i)));
            }
            if (i >= first + RADIUS) {
                var m = Moments();
                m = mad_moments(m, t.t0, r0); m = mad_moments(m, t.t1, r1); m = mad_moments(m, t.t2, r2);
                m = mad_moments(m, t.t3, r3); m = mad_moments(m, t.t4, r4); m = mad_moments(m, t.t5, r5);
                m = mad_moments(m, t.t6, r6); m = mad_moments(m, t.t7, r7); m = mad_moments(m, t.t8, r8);
                m = mad_moments(m, t.t9, r9); m = mad_moments(m, t.t10, r10);
                let q = column_pixel(run.line, u32(i - RADIUS));
                let dr = ssim_partials(m.r, m.xy.x, &dssim_sum);
                let dg = ssim_partials(m.g, m.xy.y, &dssim_sum);
                let db = ssim_partials(m.b, m.xy.z, &dssim_sum);
                dssim[q] = dr.x; dssim[q + n] = dr.y; dssim[q + 2u * n] = dr.z;
                dssim[3u * n + q] = dg.x; dssim[4u * n + q] = dg.y; dssim[5u * n + q] = dg.z;
                dssim[6u * n + q] = db.x; dssim[7u * n + q] = db.y; dssim[8u * n + q] = db.z;
            }
        }
    }
    let total = workgroup_sum(lid, vec4<f32>(dssim_sum, 0.0, 0.0, 0.0));
    if (lid == 0u) {
        sums[wg_index * SUMS_STRIDE + SUM_SSIM] = total.x;
    }
}

// Horizontal blur of dssim into the first 9 maps of stats (the blur is self-adjoint).
@compute @workgroup_size(WG_SIZE)
fn ssim_back_h(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let run = run_of(workgroup_index(wg) * WG_SIZE + lid, params.height, params.width);
    if (!run.valid || run.line >= params.height) {
        return;
    }
    let t = taps();
    var r0 = Partials(); var r1 = Partials(); var r2 = Partials(); var r3 = Partials();
    var r4 = Partials(); var r5 = Partials(); var r6 = Partials(); var r7 = Partials();
    var r8 = Partials(); var r9 = Partials(); var r10 = Partials();
    let len = i32(params.width);
    let first = i32(run.first);
    let n = params.npix;
    for (var i = first - RADIUS; i < first + i32(run.count) + RADIUS; i++) {
        r0 = r1; r1 = r2; r2 = r3; r3 = r4; r4 = r5; r5 = r6; r6 = r7; r7 = r8; r8 = r9; r9 = r10;
        r10 = Partials();
        if (i >= 0 && i < len) {
            r10 = load_dssim(row_pixel(run.line, u32(i)));
        }
        if (i >= first + RADIUS) {
            var m = Partials();
            m = mad_partials(m, t.t0, r0); m = mad_partials(m, t.t1, r1); m = mad_partials(m, t.t2, r2);
            m = mad_partials(m, t.t3, r3); m = mad_partials(m, t.t4, r4); m = mad_partials(m, t.t5, r5);
            m = mad_partials(m, t.t6, r6); m = mad_partials(m, t.t7, r7); m = mad_partials(m, t.t8, r8);
            m = mad_partials(m, t.t9, r9); m = mad_partials(m, t.t10, r10);
            let q = row_pixel(run.line, u32(i - RADIUS));
            stats[q] = m.r.x; stats[q + n] = m.r.y; stats[q + 2u * n] = m.r.z;
            stats[3u * n + q] = m.g.x; stats[4u * n + q] = m.g.y; stats[5u * n + q] = m.g.z;
            stats[6u * n + q] = m.b.x; stats[7u * n + q] = m.b.y; stats[8u * n + q] = m.b.z;
        }
    }
}

// Every term's gradient at one pixel given its vertically blurred SSIM partials (per channel
// Σ g ∂S/∂μx, Σ g ∂S/∂E[x²], Σ g ∂S/∂E[xy]); returns its (l1, depth, part, mask) sums.
fn pixel_terms(pix: u32, blurred: array<vec3<f32>, 3>) -> vec4<f32> {
    let n = params.npix;
    var here = vec4<f32>(0.0);
    {
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
    return here;
}

// Vertical blur of the row-blurred partials, then every term's gradient: grad, and the
// (l1, depth, part, mask) sums per workgroup.
@compute @workgroup_size(WG_SIZE)
fn pixel(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let wg_index = workgroup_index(wg);
    if (wg_index >= params.num_groups) {
        return;
    }
    let run = run_of(wg_index * WG_SIZE + lid, params.width, params.height);
    var here = vec4<f32>(0.0);
    if (run.valid && run.line < params.width) {
        let t = taps();
        var r0 = Partials(); var r1 = Partials(); var r2 = Partials(); var r3 = Partials();
        var r4 = Partials(); var r5 = Partials(); var r6 = Partials(); var r7 = Partials();
        var r8 = Partials(); var r9 = Partials(); var r10 = Partials();
        let len = i32(params.height);
        let first = i32(run.first);
        for (var i = first - RADIUS; i < first + i32(run.count) + RADIUS; i++) {
            r0 = r1; r1 = r2; r2 = r3; r3 = r4; r4 = r5; r5 = r6; r6 = r7; r7 = r8; r8 = r9; r9 = r10;
            r10 = Partials();
            if (i >= 0 && i < len) {
                r10 = load_blurred_partials(column_pixel(run.line, u32(i)));
            }
            if (i >= first + RADIUS) {
                var m = Partials();
                m = mad_partials(m, t.t0, r0); m = mad_partials(m, t.t1, r1); m = mad_partials(m, t.t2, r2);
                m = mad_partials(m, t.t3, r3); m = mad_partials(m, t.t4, r4); m = mad_partials(m, t.t5, r5);
                m = mad_partials(m, t.t6, r6); m = mad_partials(m, t.t7, r7); m = mad_partials(m, t.t8, r8);
                m = mad_partials(m, t.t9, r9); m = mad_partials(m, t.t10, r10);
                here += pixel_terms(column_pixel(run.line, u32(i - RADIUS)), array<vec3<f32>, 3>(m.r, m.g, m.b));
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
