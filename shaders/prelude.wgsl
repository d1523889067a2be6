// Helpers shared by every kernel family; prepended to each .wgsl file by `KernelFamily`.

// Invocations per workgroup in every kernel: the browser's limit (lavapipe allows 1024).
const WG_SIZE: u32 = 256u;

// The workgroup's place in the dispatch. Only workgroup-uniform builtins belong here: the
// early returns built on it must keep the barriers that follow in uniform control flow.
struct Workgroup {
    @builtin(workgroup_id) id: vec3<u32>,
    @builtin(num_workgroups) count: vec3<u32>,
}

// Linear workgroup index of a dispatch tiled in 2-D (see `GpuContext::workgroup_grid`).
fn workgroup_index(wg: Workgroup) -> u32 {
    return wg.id.x + wg.id.y * wg.count.x;
}

var<workgroup> wg_scan: array<u32, WG_SIZE>;
// RAKE_LANES invocations each scan RAKE_LANES consecutive values (RAKE_LANES^2 = WG_SIZE).
const RAKE_LANES: u32 = 16u;
var<workgroup> wg_rake_offsets: array<u32, RAKE_LANES>;
var<workgroup> wg_scan_total: u32;

// Exclusive scan of one value per invocation across the workgroup. Returns (exclusive prefix,
// workgroup total). Call from uniform control flow only.
//
// Raking rather than Hillis–Steele: 4 barriers instead of 18. Barriers dominate on CPU
// implementations (lavapipe, SwiftShader run a workgroup as SIMD chunks and switch between
// them at every barrier), and the serial 16-element loops cost GPUs next to nothing.
fn workgroup_exclusive_scan(lid: u32, value: u32) -> vec2<u32> {
    wg_scan[lid] = value;
    workgroupBarrier();
    if (lid < RAKE_LANES) {
        var sum = 0u;
        for (var i = 0u; i < RAKE_LANES; i++) {
            let v = wg_scan[lid * RAKE_LANES + i];
            wg_scan[lid * RAKE_LANES + i] = sum;
            sum += v;
        }
        wg_rake_offsets[lid] = sum;
    }
    workgroupBarrier();
    if (lid == 0u) {
        var sum = 0u;
        for (var i = 0u; i < RAKE_LANES; i++) {
            let v = wg_rake_offsets[i];
            wg_rake_offsets[i] = sum;
            sum += v;
        }
        wg_scan_total = sum;
    }
    workgroupBarrier();
    let result = vec2<u32>(wg_scan[lid] + wg_rake_offsets[lid / RAKE_LANES], wg_scan_total);
    // The buffers are reused by the next call: nobody may overwrite them before all have read.
    workgroupBarrier();
    return result;
}
