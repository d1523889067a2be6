// Helpers shared by every kernel family; prepended to each .wgsl file by `KernelFamily`.

// Invocations per workgroup in every kernel: the browser's limit (lavapipe allows 1024).
const WG_SIZE: u32 = 256u;

// Linear workgroup index of a dispatch tiled in 2-D (see `GpuContext::workgroup_grid`).
fn linear_workgroup(id: vec3<u32>, count: vec3<u32>) -> u32 {
    return id.x + id.y * count.x;
}

var<workgroup> wg_scan: array<u32, WG_SIZE>;

// Exclusive scan of one value per invocation across the workgroup (Hillis–Steele).
// Returns (exclusive prefix, workgroup total). Call from uniform control flow only.
fn workgroup_exclusive_scan(lid: u32, value: u32) -> vec2<u32> {
    wg_scan[lid] = value;
    workgroupBarrier();
    for (var offset = 1u; offset < WG_SIZE; offset = offset << 1u) {
        var left = 0u;
        if (lid >= offset) {
            left = wg_scan[lid - offset];
        }
        workgroupBarrier();
        wg_scan[lid] += left;
        workgroupBarrier();
    }
    let inclusive = wg_scan[lid];
    let total = wg_scan[WG_SIZE - 1u];
    // The buffer is reused by the next call: nobody may overwrite it before all have read.
    workgroupBarrier();
    return vec2<u32>(inclusive - value, total);
}
