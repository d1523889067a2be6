// Per-vertex gather of corner gradients through the vertex → corner CSR (one invocation per
// vertex; deterministic, no atomics): shared vertices sum the gradients of every face they belong
// to. Overwrites the position, colour, opacity and part-logit gradients of this view.

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> csr_offsets: array<u32>;   // num_vertices + 1
@group(0) @binding(2) var<storage, read> csr_corners: array<u32>;   // corner = 3 · face + i
@group(0) @binding(3) var<storage, read> corner_grads: array<f32>;
@group(0) @binding(4) var<storage, read_write> grad_positions: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> grad_colors: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> grad_opacity: array<f32>;
@group(0) @binding(7) var<storage, read_write> grad_part_logits: array<f32>;

@compute @workgroup_size(WG_SIZE)
fn vertex_gradients(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let v = workgroup_index(wg) * WG_SIZE + lid;
    if (v >= params.num_vertices) {
        return;
    }
    let parts = params.num_parts;
    let stride = CORNER_GRADS + parts;
    var pos = vec3<f32>(0.0);
    var col = vec3<f32>(0.0);
    var opa = 0.0;
    let first = csr_offsets[v];
    let last = csr_offsets[v + 1u];
    for (var c = first; c < last; c++) {
        let base = csr_corners[c] * stride;
        pos += vec3<f32>(corner_grads[base], corner_grads[base + 1u], corner_grads[base + 2u]);
        opa += corner_grads[base + 3u];
        col += vec3<f32>(corner_grads[base + 4u], corner_grads[base + 5u], corner_grads[base + 6u]);
    }
    for (var k = 0u; k < parts; k++) {
        var sum = 0.0;
        for (var c = first; c < last; c++) {
            sum += corner_grads[csr_corners[c] * stride + CORNER_GRADS + k];
        }
        grad_part_logits[v * parts + k] = sum;
    }
    grad_positions[v] = vec4<f32>(pos, 0.0);
    grad_colors[v] = vec4<f32>(col, 0.0);
    grad_opacity[v] = opa;
}
