// FMA throughput probe: every invocation runs CHAINS independent dependent-FMA chains (vec4 each,
// so 4 · CHAINS scalar chains) for `iterations` rounds of UNROLL steps. Independent chains hide the
// FMA latency (ILP); few enough registers that CPU drivers (lavapipe runs invocations as SIMD lanes)
// do not spill. The multiplier and addend come from the uniform and the result is stored, so the
// compiler can neither fold nor drop the loop. Chains converge to add / (1 - mul): no inf, no denormals.

struct FmaParams {
    iterations: u32,
    _pad: u32,
    mul: f32,
    add: f32,
}

@group(0) @binding(0) var<uniform> params: FmaParams;
@group(0) @binding(1) var<storage, read_write> sink: array<f32>;

@compute @workgroup_size(WG_SIZE)
fn fma_chains(@builtin(local_invocation_index) lid: u32, wg: Workgroup) {
    let i = workgroup_index(wg) * WG_SIZE + lid;
    let b = vec4<f32>(params.mul);
    let c = vec4<f32>(params.add);
    let s = f32(i & 1023u) * 1e-4;
    var a0 = vec4<f32>(s, s + 0.1, s + 0.2, s + 0.3);
    var a1 = vec4<f32>(s + 0.4, s + 0.5, s + 0.6, s + 0.7);
    for (var k = 0u; k < params.iterations; k++) {
        // UNROLL = 4 steps of both chains: 32 scalar FMAs per iteration.
        a0 = fma(a0, b, c);
        a1 = fma(a1, b, c);
        a0 = fma(a0, b, c);
        a1 = fma(a1, b, c);
        a0 = fma(a0, b, c);
        a1 = fma(a1, b, c);
        a0 = fma(a0, b, c);
        a1 = fma(a1, b, c);
    }
    sink[i] = dot(a0 + a1, vec4<f32>(1.0));
}
