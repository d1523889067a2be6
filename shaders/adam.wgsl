// Adam on flat f32 parameter groups, and the gather that remaps a group's moments when its
// elements are added, removed or reordered (densification and pruning).
//
// `adam_step` uses bindings 0-4; `remap_moments` uses 0 and 3-7 (the step's params/grads stay
// bound but unused). One layout serves both so a group needs no second kernel family.

struct AdamParams {
    n: u32,       // floats in the group (the new group for remap_moments)
    stride: u32,  // floats per element (remap_moments)
    _pad0: u32,
    _pad1: u32,
    lr: f32,
    beta1: f32,
    beta2: f32,
    eps: f32,
    bias1: f32,   // 1 - beta1^t
    bias2: f32,   // 1 - beta2^t
    _pad2: f32,
    _pad3: f32,
}

@group(0) @binding(0) var<uniform> params: AdamParams;
@group(0) @binding(1) var<storage, read_write> values: array<f32>;
@group(0) @binding(2) var<storage, read> grads: array<f32>;
@group(0) @binding(3) var<storage, read_write> m: array<f32>;
@group(0) @binding(4) var<storage, read_write> v: array<f32>;
// elem_map[new element] = old element, or NONE for a fresh element with zero moments.
@group(0) @binding(5) var<storage, read> elem_map: array<u32>;
@group(0) @binding(6) var<storage, read> old_m: array<f32>;
@group(0) @binding(7) var<storage, read> old_v: array<f32>;

const NONE: u32 = 0xffffffffu;

@compute @workgroup_size(WG_SIZE)
fn adam_step(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let i = workgroup_index(wg) * WG_SIZE + lid;
    if (i >= params.n) {
        return;
    }
    let g = grads[i];
    let m1 = params.beta1 * m[i] + (1.0 - params.beta1) * g;
    let v1 = params.beta2 * v[i] + (1.0 - params.beta2) * g * g;
    m[i] = m1;
    v[i] = v1;
    // torch.optim.Adam's form: bias-corrected moments, eps added to sqrt(v̂).
    values[i] -= params.lr * (m1 / params.bias1) / (sqrt(v1 / params.bias2) + params.eps);
}

@compute @workgroup_size(WG_SIZE)
fn remap_moments(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let i = workgroup_index(wg) * WG_SIZE + lid;
    if (i >= params.n) {
        return;
    }
    let src = elem_map[i / params.stride];
    if (src == NONE) {
        m[i] = 0.0;
        v[i] = 0.0;
    } else {
        let j = src * params.stride + i % params.stride;
        m[i] = old_m[j];
        v[i] = old_v[j];
    }
}
