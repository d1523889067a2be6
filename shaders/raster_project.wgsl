// Projection and culling: one invocation per face builds its `FaceRecord` (barycentric plane,
// window scale, perspective weights, opacity, colours, pixel box) and counts the tiles whose
// coverage mask (`tile_mask`) is not empty. Culled faces (behind the near plane, degenerate,
// reaching no pixel centre with α ≥ alpha_min, face opacity < 0.01) touch no tile. The counts
// are then scanned into emission offsets.

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> faces: array<u32>;          // 3 per face
@group(0) @binding(3) var<storage, read> opacity: array<f32>;        // logit per vertex
@group(0) @binding(4) var<storage, read> colors: array<vec4<f32>>;   // this view's vertex colours
@group(0) @binding(5) var<storage, read_write> records: array<FaceRecord>;
@group(0) @binding(6) var<storage, read_write> tile_counts: array<u32>;

fn sigmoid(x: f32) -> f32 {
    return 1.0 / (1.0 + exp(-x));
}

fn culled(f: u32) {
    var rec = FaceRecord();
    rec.pixels = vec4<u32>(1u, 0u, 0u, 0u);
    records[f] = rec;
    tile_counts[f] = 0u;
}

@compute @workgroup_size(WG_SIZE)
fn project_faces(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let f = workgroup_index(wg) * WG_SIZE + lid;
    if (f >= params.num_faces) {
        return;
    }
    var idx = vec3<u32>(faces[3u * f], faces[3u * f + 1u], faces[3u * f + 2u]);
    var s = array<vec2<f32>, 3>();
    var w = vec3<f32>();
    var o = 0.0;
    for (var i = 0u; i < 3u; i++) {
        let x = positions[idx[i]];
        let c = params.world_to_camera * vec4<f32>(x.xyz, 1.0);
        w[i] = -c.z;
        s[i] = vec2<f32>(params.focal.z + params.focal.x * c.x / w[i], params.focal.w - params.focal.y * c.y / w[i]);
        o += sigmoid(opacity[idx[i]]);
    }
    let sigma = params.opacity_floor + (1.0 - params.opacity_floor) * o / 3.0;
    if (min(w.x, min(w.y, w.z)) < params.near || sigma < 0.01) {
        culled(f);
        return;
    }
    let e1 = s[1] - s[0];
    let e2 = s[2] - s[0];
    let area2 = cross2(e1, e2);
    let l = vec3<f32>(length(s[1] - s[2]), length(s[2] - s[0]), length(s[0] - s[1]));
    let perimeter = l.x + l.y + l.z;
    // Degenerate or edge-on: the barycentric plane would blow up.
    if (abs(area2) < 1e-6 || min(l.x, min(l.y, l.z)) < 1e-6) {
        culled(f);
        return;
    }
    // Pixel centres inside the bounding box (centre of pixel i at i + 0.5).
    let s_lo = min(s[0], min(s[1], s[2]));
    let s_hi = max(s[0], max(s[1], s[2]));
    let px0 = max(ceil(s_lo - 0.5), vec2<f32>(0.0));
    let px1 = min(floor(s_hi - 0.5), vec2<f32>(f32(params.width) - 1.0, f32(params.height) - 1.0));
    if (px0.x > px1.x || px0.y > px1.y) {
        culled(f);
        return;
    }
    let lo = vec2<u32>(px0);
    let hi = vec2<u32>(px1);

    var rec = FaceRecord();
    let inv = 1.0 / area2;
    let a0 = vec2<f32>(s[1].y - s[2].y, s[2].x - s[1].x) * inv;
    let a1 = vec2<f32>(s[2].y - s[0].y, s[0].x - s[2].x) * inv;
    let a2 = vec2<f32>(s[0].y - s[1].y, s[1].x - s[0].x) * inv;
    rec.geom_x = vec4<f32>(a0.x, a1.x, a2.x, s[0].x);
    rec.geom_y = vec4<f32>(a0.y, a1.y, a2.y, s[0].y);
    rec.window = vec4<f32>(perimeter / l, sigma);
    rec.inv_w = vec4<f32>(1.0 / w, (w.x + w.y + w.z) / 3.0);
    rec.color0 = colors[idx.x];
    rec.color1 = colors[idx.y];
    rec.color2 = colors[idx.z];
    rec.verts = vec4<u32>(idx, 0u);
    rec.pixels = vec4<u32>(lo, hi);
    // Count the tiles with a non-empty mask, as `emit_pairs` will find them.
    let t0 = lo / TILE;
    let t1 = hi / TILE;
    let exact = exact_masks(lo, hi);
    let g = face_geometry(rec);
    var count = 0u;
    for (var ty = t0.y; ty <= t1.y; ty++) {
        for (var tx = t0.x; tx <= t1.x; tx++) {
            let m = tile_mask(g, vec2<u32>(tx, ty), lo, hi, exact, params.gamma, params.alpha_min);
            count += select(0u, 1u, (m.x | m.y) != 0u);
        }
    }
    if (count == 0u) {
        culled(f);
        return;
    }
    records[f] = rec;
    tile_counts[f] = count;
}
