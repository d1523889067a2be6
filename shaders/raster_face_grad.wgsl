// Per-face gradient gather and chain rule, one invocation per face: sums the face's (face, tile)
// pair gradients (contiguous at the face's scanned emission offsets: deterministic, no atomics), then differentiates the face record's construction back to the
// three vertices: barycentric plane and window scale → projected vertices → camera space
// → world positions; 1/w → view depth; σ → opacity logits. Writes one corner record per face
// corner: [dL/dx (3), dL/d opacity logit, dL/dcolour (3), 0, dL/d part logits (P)].

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> faces: array<u32>;
@group(0) @binding(3) var<storage, read> opacity: array<f32>;
@group(0) @binding(4) var<storage, read> offsets: array<u32>;
@group(0) @binding(5) var<storage, read> pair_grads: array<f32>;        // per emitted pair
@group(0) @binding(6) var<storage, read> pair_logit_grads: array<f32>;
@group(0) @binding(7) var<storage, read_write> corner_grads: array<f32>;

fn sigmoid(x: f32) -> f32 {
    return 1.0 / (1.0 + exp(-x));
}

@compute @workgroup_size(WG_SIZE)
fn face_gradients(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let f = workgroup_index(wg) * WG_SIZE + lid;
    if (f >= params.num_faces) {
        return;
    }
    let parts = params.num_parts;
    let stride = CORNER_GRADS + parts;
    let first = offsets[f];
    let last = offsets[f + 1u];

    var g = array<f32, PAIR_GRADS>();
    for (var e = first; e < last; e++) {
        for (var c = 0u; c < PAIR_GRADS; c++) {
            g[c] += pair_grads[e * PAIR_GRADS + c];
        }
    }
    for (var i = 0u; i < 3u; i++) {
        let corner = (3u * f + i) * stride;
        for (var k = 0u; k < parts; k++) {
            var sum = 0.0;
            for (var e = first; e < last; e++) {
                sum += pair_logit_grads[e * 3u * parts + i * parts + k];
            }
            corner_grads[corner + CORNER_GRADS + k] = sum;
        }
        corner_grads[corner + 4u] = g[16u + 3u * i];
        corner_grads[corner + 5u] = g[17u + 3u * i];
        corner_grads[corner + 6u] = g[18u + 3u * i];
        corner_grads[corner + 7u] = 0.0;
    }
    if (first == last) {
        for (var i = 0u; i < 3u; i++) {
            let corner = (3u * f + i) * stride;
            for (var c = 0u; c < 4u; c++) {
                corner_grads[corner + c] = 0.0;
            }
        }
        return;
    }

    // Recompute the projection (as in raster_project.wgsl).
    var idx = vec3<u32>(faces[3u * f], faces[3u * f + 1u], faces[3u * f + 2u]);
    var s = array<vec2<f32>, 3>();
    var cam = array<vec3<f32>, 3>();
    var w = vec3<f32>();
    for (var i = 0u; i < 3u; i++) {
        let c = params.world_to_camera * vec4<f32>(positions[idx[i]].xyz, 1.0);
        cam[i] = c.xyz;
        w[i] = -c.z;
        s[i] = vec2<f32>(params.focal.z + params.focal.x * c.x / w[i], params.focal.w - params.focal.y * c.y / w[i]);
    }
    let area2 = cross2(s[1] - s[0], s[2] - s[0]);
    var a = array<vec2<f32>, 3>();
    a[0] = vec2<f32>(s[1].y - s[2].y, s[2].x - s[1].x) / area2;
    a[1] = vec2<f32>(s[2].y - s[0].y, s[0].x - s[2].x) / area2;
    a[2] = vec2<f32>(s[0].y - s[1].y, s[1].x - s[0].x) / area2;
    let l = vec3<f32>(length(s[1] - s[2]), length(s[2] - s[0]), length(s[0] - s[1]));
    let perimeter = l.x + l.y + l.z;

    var gs = array<vec2<f32>, 3>();
    // λ_i(p) = a_i · (p − s0) + [i == 0]: the origin s0 gets −Σ_i a_i Σ_p dL/dλ_i.
    var g_area = 0.0;
    for (var i = 0u; i < 3u; i++) {
        let ga = vec2<f32>(g[i], g[3u + i]);
        gs[0] -= a[i] * g[6u + i];
        // a_i = N_i / area2.
        g_area -= dot(ga, a[i]) / area2;
        a[i] = ga / area2;  // now dL/dN_i
    }
    // N_0 = (s1.y − s2.y, s2.x − s1.x), N_1 = (s2.y − s0.y, s0.x − s2.x), N_2 = (s0.y − s1.y, s1.x − s0.x).
    gs[1] += vec2<f32>(-a[0].y, a[0].x);
    gs[2] += vec2<f32>(a[0].y, -a[0].x);
    gs[2] += vec2<f32>(-a[1].y, a[1].x);
    gs[0] += vec2<f32>(a[1].y, -a[1].x);
    gs[0] += vec2<f32>(-a[2].y, a[2].x);
    gs[1] += vec2<f32>(a[2].y, -a[2].x);
    // area2 = cross(e1, e2), e1 = s1 − s0, e2 = s2 − s0.
    let e1 = s[1] - s[0];
    let e2 = s[2] - s[0];
    let g_e1 = g_area * vec2<f32>(e2.y, -e2.x);
    let g_e2 = g_area * vec2<f32>(-e1.y, e1.x);
    gs[1] += g_e1;
    gs[2] += g_e2;
    gs[0] -= g_e1 + g_e2;
    // k_i = perimeter / l_i.
    let g_k = vec3<f32>(g[9], g[10], g[11]);
    let g_l = vec3<f32>(dot(g_k, 1.0 / l)) - g_k * perimeter / (l * l);
    let d0 = (s[1] - s[2]) / l.x;
    let d1 = (s[2] - s[0]) / l.y;
    let d2 = (s[0] - s[1]) / l.z;
    gs[1] += g_l.x * d0;
    gs[2] -= g_l.x * d0;
    gs[2] += g_l.y * d1;
    gs[0] -= g_l.y * d1;
    gs[0] += g_l.z * d2;
    gs[1] -= g_l.z * d2;

    // Screen → camera: s = (cx + fx x / w, cy − fy y / w), w = −z.
    let rot = mat3x3<f32>(params.world_to_camera[0].xyz, params.world_to_camera[1].xyz, params.world_to_camera[2].xyz);
    let sigma_scale = (1.0 - params.opacity_floor) / 3.0 * g[15];
    for (var i = 0u; i < 3u; i++) {
        let fx = params.focal.x;
        let fy = params.focal.y;
        let inv = 1.0 / w[i];
        // 1/w_i from the perspective weights.
        var g_w = -g[12u + i] * inv * inv;
        g_w += -gs[i].x * fx * cam[i].x * inv * inv + gs[i].y * fy * cam[i].y * inv * inv;
        let g_cam = vec3<f32>(gs[i].x * fx * inv, -gs[i].y * fy * inv, -g_w);
        let g_x = transpose(rot) * g_cam;
        let o = sigmoid(opacity[idx[i]]);
        let corner = (3u * f + i) * stride;
        corner_grads[corner] = g_x.x;
        corner_grads[corner + 1u] = g_x.y;
        corner_grads[corner + 2u] = g_x.z;
        corner_grads[corner + 3u] = sigma_scale * o * (1.0 - o);
    }
}
