// Backward compositing: one workgroup per tile, one invocation per pixel, replaying the forward
// front-to-back order up to the entries the pixel consumed. With O the pixel's final output and
// P_n the accumulation up to and including face n,
//   dO/dα_n = q_n T_n − (O − P_n) / (1 − α_n),   dO/dq_n = α_n T_n,
// so no reverse traversal or division by T is needed. Each pixel's per-face gradient (w.r.t. the
// face record's barycentric plane, window scale, 1/w, opacity, vertex colours and vertex part
// logits) is summed over the tile's pixels in workgroup memory (compare-exchange on f32 bits:
// the browser has no float atomics) and written once per (face, tile) pair, at its sorted slot.
//
// Pair gradient layout (PAIR_GRADS floats): 0–2 dL/da_i.x, 3–5 dL/da_i.y, 6–8 Σ dL/dλ_i,
// 9–11 dL/dk_i, 12–14 dL/d(1/w_i), 15 dL/dσ, 16–24 dL/dcolour_i (i major); part logits in their
// own buffer, 3·P floats per pair (vertex major).

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> tile_ranges: array<u32>;
@group(0) @binding(2) var<storage, read> sorted_face: array<u32>;
@group(0) @binding(3) var<storage, read> records: array<FaceRecord>;
@group(0) @binding(4) var<storage, read> part_logits: array<f32>;
@group(0) @binding(5) var<storage, read> render: array<f32>;
@group(0) @binding(6) var<storage, read> grad_render: array<f32>;
@group(0) @binding(7) var<storage, read_write> pair_grads: array<f32>;
@group(0) @binding(8) var<storage, read_write> pair_logit_grads: array<f32>;

const BATCH: u32 = 32u;
var<workgroup> batch: array<FaceGeometry, BATCH>;
var<workgroup> batch_face: array<u32, BATCH>;
var<workgroup> acc: array<atomic<u32>, BATCH * PAIR_GRADS>;
var<workgroup> acc_logits: array<atomic<u32>, BATCH * 3u * MAX_PARTS>;
var<workgroup> range: vec2<u32>;

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

@compute @workgroup_size(WG_SIZE)
fn composite_backward(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
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
    let npix = params.width * params.height;
    let pix = min(py * params.width + px, npix - 1u);

    // Final outputs and their incoming gradients.
    let out_rgb = vec3<f32>(render[pix], render[npix + pix], render[2u * npix + pix]);
    let out_depth = render[3u * npix + pix];
    let out_alpha = render[4u * npix + pix];
    let g_rgb = vec3<f32>(grad_render[pix], grad_render[npix + pix], grad_render[2u * npix + pix]);
    let g_depth = grad_render[3u * npix + pix];
    let g_alpha_out = grad_render[4u * npix + pix];
    var out_logits: array<f32, MAX_PARTS>;
    var g_logits: array<f32, MAX_PARTS>;
    for (var k = 0u; k < parts; k++) {
        out_logits[k] = render[(5u + k) * npix + pix];
        g_logits[k] = grad_render[(5u + k) * npix + pix];
    }
    let consumed = bitcast<u32>(render[(5u + parts) * npix + pix]);

    var transmittance = 1.0;
    var pre_rgb = vec3<f32>(0.0);
    var pre_depth = 0.0;
    var pre_alpha = 0.0;
    var pre_logits: array<f32, MAX_PARTS>;
    var done = !inside;
    let logit_stride = 3u * parts;
    for (var start = r.x; start < r.y; start += BATCH) {
        let j = start + lid;
        if (lid < BATCH && j < r.y) {
            let f = sorted_face[j];
            batch_face[lid] = f;
            batch[lid] = face_geometry(records[f]);
        }
        workgroupBarrier();
        let count = min(BATCH, r.y - start);
        for (var b = 0u; b < count; b++) {
            // Uniform loop (see raster_composite.wgsl): `done` guards the body instead of breaking.
            if (start + b - r.x >= consumed) {
                done = true;
            }
            if (done) {
                continue;
            }
            let geom = batch[b];
            let hit = evaluate_face(geom, p, params);
            if (hit.alpha <= 0.0) {
                continue;
            }
            let rec = records[batch_face[b]];
            let mu = hit.mu;
            let w = hit.alpha * transmittance;
            let one_minus = 1.0 - hit.alpha;
            let color = hit_color(rec, mu);
            pre_rgb += w * color;
            pre_depth += w * hit.z;
            pre_alpha += w;
            var g_a = dot(g_rgb, color * transmittance - (out_rgb - pre_rgb) / one_minus)
                + g_depth * (hit.z * transmittance - (out_depth - pre_depth) / one_minus)
                + g_alpha_out * (transmittance - (out_alpha - pre_alpha) / one_minus);
            // dL/dμ_i from colour and logits (depth goes through 1/Σρ below).
            let gc = g_rgb * w;
            var g_mu = vec3<f32>(dot(gc, rec.color0.xyz), dot(gc, rec.color1.xyz), dot(gc, rec.color2.xyz));
            let v = rec.verts;
            for (var k = 0u; k < parts; k++) {
                let s = vec3<f32>(part_logits[v.x * parts + k], part_logits[v.y * parts + k], part_logits[v.z * parts + k]);
                let sk = dot(mu, s);
                pre_logits[k] += w * sk;
                g_a += g_logits[k] * (sk * transmittance - (out_logits[k] - pre_logits[k]) / one_minus);
                let gs = g_logits[k] * w;
                g_mu += gs * s;
                add_acc_logit(b * logit_stride + k, mu.x * gs);
                add_acc_logit(b * logit_stride + parts + k, mu.y * gs);
                add_acc_logit(b * logit_stride + 2u * parts + k, mu.z * gs);
            }
            // α = min(0.99, σ φ), φ = u^γ.
            let g_sp = select(g_a, 0.0, hit.clamped);
            let sigma = geom.window.w;
            let g_sigma = g_sp * hit.phi;
            let g_u = g_sp * sigma * params.gamma * hit.phi / hit.u;
            let onehot = vec3<f32>(select(0.0, 1.0, hit.edge == 0u), select(0.0, 1.0, hit.edge == 1u), select(0.0, 1.0, hit.edge == 2u));
            var g_lambda = onehot * g_u * geom.window.xyz;
            let g_k = onehot * g_u * hit.lambda;
            // μ = ρ / Σρ, z = 1 / Σρ, ρ_i = λ_i / w_i.
            let g_rho = (g_mu - dot(g_mu, mu)) / hit.zsum - g_depth * w * hit.z * hit.z;
            g_lambda += g_rho * geom.inv_w.xyz;
            let g_inv_w = g_rho * hit.lambda;
            let d = p - vec2<f32>(geom.geom_x.w, geom.geom_y.w);
            let base = b * PAIR_GRADS;
            add_acc(base + 0u, g_lambda.x * d.x);
            add_acc(base + 1u, g_lambda.y * d.x);
            add_acc(base + 2u, g_lambda.z * d.x);
            add_acc(base + 3u, g_lambda.x * d.y);
            add_acc(base + 4u, g_lambda.y * d.y);
            add_acc(base + 5u, g_lambda.z * d.y);
            add_acc(base + 6u, g_lambda.x);
            add_acc(base + 7u, g_lambda.y);
            add_acc(base + 8u, g_lambda.z);
            add_acc(base + 9u, g_k.x);
            add_acc(base + 10u, g_k.y);
            add_acc(base + 11u, g_k.z);
            add_acc(base + 12u, g_inv_w.x);
            add_acc(base + 13u, g_inv_w.y);
            add_acc(base + 14u, g_inv_w.z);
            add_acc(base + 15u, g_sigma);
            for (var c = 0u; c < 3u; c++) {
                add_acc(base + 16u + c, mu.x * gc[c]);
                add_acc(base + 19u + c, mu.y * gc[c]);
                add_acc(base + 22u + c, mu.z * gc[c]);
            }
            transmittance *= one_minus;
        }
        workgroupBarrier();
        // Flush this batch's sums (and zero them for the next batch).
        for (var i = lid; i < count * PAIR_GRADS; i += WG_SIZE) {
            pair_grads[start * PAIR_GRADS + i] = bitcast<f32>(atomicExchange(&acc[i], 0u));
        }
        for (var i = lid; i < count * logit_stride; i += WG_SIZE) {
            pair_logit_grads[start * logit_stride + i] = bitcast<f32>(atomicExchange(&acc_logits[i], 0u));
        }
    }
}
