// Backward compositing: one workgroup per 8×8 tile, each invocation replaying one pixel in the
// forward front-to-back order over the faces whose coverage mask holds it, up to the entries the
// pixel consumed. With O the
// pixel's final output and P_n the accumulation up to and including face n,
//   dO/dα_n = q_n T_n − (O − P_n) / (1 − α_n),   dO/dq_n = α_n T_n,
// so no reverse traversal or division by T is needed. A face's gradient (w.r.t. its record's
// barycentric plane, window scale, 1/w, opacity, vertex colours and vertex part logits) is written
// per (face, tile) pair, at its emission index, into buffers cleared beforehand: straight from the
// one invocation whose pixel it covers when its mask has a single bit (most pairs: faces are a
// pixel or two), otherwise summed over the tile's pixels in workgroup memory first
// (compare-exchange on f32 bits: the browser has no float atomics).
//
// Pair gradient layout (PAIR_GRADS floats): 0–2 dL/da_i.x, 3–5 dL/da_i.y, 6–8 Σ dL/dλ_i,
// 9–11 dL/dk_i, 12–14 dL/d(1/w_i), 15 dL/dσ, 16–24 dL/dcolour_i (i major); part logits in their
// own buffer, 3·P floats per pair (vertex major).

// Bindings 0–4 (params, tile ranges, sorted faces, records, part logits) are in raster_tile.wgsl.
@group(0) @binding(5) var<storage, read> render: array<f32>;
@group(0) @binding(6) var<storage, read> grad_render: array<f32>;
@group(0) @binding(7) var<storage, read_write> pair_grads: array<f32>;
@group(0) @binding(8) var<storage, read_write> pair_logit_grads: array<f32>;

const INVOCATIONS: u32 = TILE * TILE;
var<workgroup> acc: array<atomic<u32>, BATCH * PAIR_GRADS>;
var<workgroup> acc_logits: array<atomic<u32>, BATCH * 3u * MAX_PARTS>;

fn add_acc(i: u32, v: f32) {
    if (v == 0.0) {
        return;
    }
    var old = atomicLoad(&acc[i]);
    loop {
        let r = atomicCompareExchangeWeak(&acc[i], old, bitcast<u32>(bitcast<f32>(old) + v));
        if (r.exchanged) {
            break;
        }
        old = r.old_value;
    }
}

fn add_acc_logit(i: u32, v: f32) {
    if (v == 0.0) {
        return;
    }
    var old = atomicLoad(&acc_logits[i]);
    loop {
        let r = atomicCompareExchangeWeak(&acc_logits[i], old, bitcast<u32>(bitcast<f32>(old) + v));
        if (r.exchanged) {
            break;
        }
        old = r.old_value;
    }
}

// One pixel's replay state: its final outputs O, their incoming gradients, and the running
// transmittance and accumulation P_n.
struct Pixel {
    p: vec2<f32>,
    out_rgb: vec3<f32>,
    out_depth: f32,
    out_alpha: f32,
    g_rgb: vec3<f32>,
    g_depth: f32,
    g_alpha: f32,
    out_logits: array<f32, MAX_PARTS>,
    g_logits: array<f32, MAX_PARTS>,
    pre_logits: array<f32, MAX_PARTS>,
    pre_rgb: vec3<f32>,
    pre_depth: f32,
    pre_alpha: f32,
    transmittance: f32,
    consumed: u32,
    done: bool,
}

// One face's gradient summed over an invocation's pixels (layout of PAIR_GRADS, logits aside).
struct FaceGrad {
    ax: vec3<f32>,
    ay: vec3<f32>,
    lambda: vec3<f32>,
    k: vec3<f32>,
    inv_w: vec3<f32>,
    sigma: f32,
    color0: vec3<f32>,
    color1: vec3<f32>,
    color2: vec3<f32>,
    hit: bool,
}

fn start_pixel(px: u32, py: u32) -> Pixel {
    var s = Pixel();
    s.p = vec2<f32>(f32(px) + 0.5, f32(py) + 0.5);
    s.transmittance = 1.0;
    s.done = px >= params.width || py >= params.height;
    if (s.done) {
        return s;
    }
    let parts = params.num_parts;
    let npix = params.width * params.height;
    let pix = py * params.width + px;
    s.out_rgb = vec3<f32>(render[pix], render[npix + pix], render[2u * npix + pix]);
    s.out_depth = render[3u * npix + pix];
    s.out_alpha = render[4u * npix + pix];
    s.g_rgb = vec3<f32>(grad_render[pix], grad_render[npix + pix], grad_render[2u * npix + pix]);
    s.g_depth = grad_render[3u * npix + pix];
    s.g_alpha = grad_render[4u * npix + pix];
    for (var k = 0u; k < parts; k++) {
        s.out_logits[k] = render[(5u + k) * npix + pix];
        s.g_logits[k] = grad_render[(5u + k) * npix + pix];
    }
    s.consumed = bitcast<u32>(render[(5u + parts) * npix + pix]);
    return s;
}

// Replays staged face `b` at pixel `s`, adding its gradient to `fg`.
// `direct`: write part-logit gradients straight to pair `slot` (emission index) instead of summing them.
fn backprop(s: ptr<function, Pixel>, fg: ptr<function, FaceGrad>, geom: FaceGeometry, b: u32, direct: bool, slot: u32) {
    let hit = evaluate_face(geom, (*s).p, params.gamma, params.alpha_min);
    if (hit.alpha <= 0.0) {
        return;
    }
    let hv = hit_vertices(batch_face[b]);
    let parts = params.num_parts;
    let mu = hit.mu;
    let t = (*s).transmittance;
    let w = hit.alpha * t;
    let one_minus = 1.0 - hit.alpha;
    let color = mu.x * hv.c0 + mu.y * hv.c1 + mu.z * hv.c2;
    (*s).pre_rgb += w * color;
    (*s).pre_depth += w * hit.z;
    (*s).pre_alpha += w;
    var g_a = dot((*s).g_rgb, color * t - ((*s).out_rgb - (*s).pre_rgb) / one_minus)
        + (*s).g_depth * (hit.z * t - ((*s).out_depth - (*s).pre_depth) / one_minus)
        + (*s).g_alpha * (t - ((*s).out_alpha - (*s).pre_alpha) / one_minus);
    // dL/dμ_i from colour and logits (depth goes through 1/Σρ below).
    let gc = (*s).g_rgb * w;
    var g_mu = vec3<f32>(dot(gc, hv.c0), dot(gc, hv.c1), dot(gc, hv.c2));
    let logit_base = b * 3u * parts;
    for (var k = 0u; k < parts; k++) {
        let sv = vertex_logits(hv.verts, k);
        let sk = dot(mu, sv);
        (*s).pre_logits[k] += w * sk;
        let gk = (*s).g_logits[k];
        g_a += gk * (sk * t - ((*s).out_logits[k] - (*s).pre_logits[k]) / one_minus);
        let gs = gk * w;
        g_mu += gs * sv;
        if (direct) {
            let base = slot * 3u * parts;
            pair_logit_grads[base + k] = mu.x * gs;
            pair_logit_grads[base + parts + k] = mu.y * gs;
            pair_logit_grads[base + 2u * parts + k] = mu.z * gs;
        } else {
            add_acc_logit(logit_base + k, mu.x * gs);
            add_acc_logit(logit_base + parts + k, mu.y * gs);
            add_acc_logit(logit_base + 2u * parts + k, mu.z * gs);
        }
    }
    // α = min(0.99, σ φ), φ = u^γ.
    let g_sp = select(g_a, 0.0, hit.clamped);
    let g_u = g_sp * geom.window.w * params.gamma * hit.phi / hit.u;
    let onehot = vec3<f32>(select(0.0, 1.0, hit.edge == 0u), select(0.0, 1.0, hit.edge == 1u), select(0.0, 1.0, hit.edge == 2u));
    var g_lambda = onehot * g_u * geom.window.xyz;
    // μ = ρ / Σρ, z = 1 / Σρ, ρ_i = λ_i / w_i.
    let g_rho = (g_mu - dot(g_mu, mu)) / hit.zsum - (*s).g_depth * w * hit.z * hit.z;
    g_lambda += g_rho * geom.inv_w.xyz;
    let d = (*s).p - vec2<f32>(geom.geom_x.w, geom.geom_y.w);
    (*fg).ax += g_lambda * d.x;
    (*fg).ay += g_lambda * d.y;
    (*fg).lambda += g_lambda;
    (*fg).k += onehot * g_u * hit.lambda;
    (*fg).inv_w += g_rho * hit.lambda;
    (*fg).sigma += g_sp * hit.phi;
    (*fg).color0 += mu.x * gc;
    (*fg).color1 += mu.y * gc;
    (*fg).color2 += mu.z * gc;
    (*fg).hit = true;
    (*s).transmittance *= one_minus;
}

fn flush(fg: FaceGrad, b: u32) {
    let base = b * PAIR_GRADS;
    for (var i = 0u; i < 3u; i++) {
        add_acc(base + i, fg.ax[i]);
        add_acc(base + 3u + i, fg.ay[i]);
        add_acc(base + 6u + i, fg.lambda[i]);
        add_acc(base + 9u + i, fg.k[i]);
        add_acc(base + 12u + i, fg.inv_w[i]);
        add_acc(base + 16u + i, fg.color0[i]);
        add_acc(base + 19u + i, fg.color1[i]);
        add_acc(base + 22u + i, fg.color2[i]);
    }
    add_acc(base + 15u, fg.sigma);
}

// Writes a single-pixel face's gradient (all but the part logits) to pair `slot` (emission index).
fn store_pair(fg: FaceGrad, slot: u32) {
    let base = slot * PAIR_GRADS;
    for (var i = 0u; i < 3u; i++) {
        pair_grads[base + i] = fg.ax[i];
        pair_grads[base + 3u + i] = fg.ay[i];
        pair_grads[base + 6u + i] = fg.lambda[i];
        pair_grads[base + 9u + i] = fg.k[i];
        pair_grads[base + 12u + i] = fg.inv_w[i];
        pair_grads[base + 16u + i] = fg.color0[i];
        pair_grads[base + 19u + i] = fg.color1[i];
        pair_grads[base + 22u + i] = fg.color2[i];
    }
    pair_grads[base + 15u] = fg.sigma;
}

// The staged faces whose mask has a single bit (bit b for batch slot b).
fn single_pixel_faces(count: u32) -> u32 {
    var word = 0u;
    for (var b = 0u; b < count; b++) {
        let m = batch_mask[b];
        word |= select(0u, 1u, countOneBits(m.x) + countOneBits(m.y) == 1u) << b;
    }
    return word;
}

@compute @workgroup_size(INVOCATIONS)
fn composite_backward(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let tile = workgroup_index(wg);
    if (tile >= params.tiles_x * params.tiles_y) {
        return;
    }
    let px = tile_pixel(tile, lid);
    var s = start_pixel(px.x, px.y);
    let r = tile_range(tile, lid);
    let logit_stride = 3u * params.num_parts;
    for (var start = r.x; start < r.y; start += BATCH) {
        stage_batch(start, r.y, lid, INVOCATIONS);
        workgroupBarrier();
        let count = min(BATCH, r.y - start);
        var word = covering_faces(lid, count);
        let single = single_pixel_faces(count);
        loop {
            if (word == 0u || s.done) {
                break;
            }
            let b = firstTrailingBit(word);
            word &= word - 1u;
            if (start + b - r.x >= s.consumed) {
                s.done = true;
                break;
            }
            var fg = FaceGrad();
            let direct = ((single >> b) & 1u) != 0u;
            backprop(&s, &fg, batch[b], b, direct, batch_pair[b]);
            if (fg.hit) {
                if (direct) {
                    store_pair(fg, batch_pair[b]);
                } else {
                    flush(fg, b);
                }
            }
        }
        workgroupBarrier();
        // Write this batch's sums of multi-pixel faces (and zero them for the next batch).
        for (var i = lid; i < count * PAIR_GRADS; i += INVOCATIONS) {
            let b = i / PAIR_GRADS;
            if (((single >> b) & 1u) == 0u) {
                let dst = batch_pair[b] * PAIR_GRADS + i % PAIR_GRADS;
                pair_grads[dst] = bitcast<f32>(atomicExchange(&acc[i], 0u));
            }
        }
        for (var i = lid; i < count * logit_stride; i += INVOCATIONS) {
            let b = i / logit_stride;
            if (((single >> b) & 1u) == 0u) {
                let dst = batch_pair[b] * logit_stride + i % logit_stride;
                pair_logit_grads[dst] = bitcast<f32>(atomicExchange(&acc_logits[i], 0u));
            }
        }
    }
}
