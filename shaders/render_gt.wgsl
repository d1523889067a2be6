// Ground-truth renderer (src/render): a plain rasterisation pass writing colour (alpha = coverage),
// camera z-depth in metres and the part id of the nearest surface.
//
// Projection: pinhole intrinsics mapped to clip space so that a camera-space point lands exactly where
// `Camera::project` puts it (pixel centres at +0.5). Depth buffer: reversed z (near → 1, far → 0,
// compare `greater`), used only for visibility; the reported depth is the interpolated camera-space z.

struct Frame {
    // World → camera (OpenGL axes: the camera looks down −z).
    world_to_camera: mat4x4<f32>,
    // (2 fx / W, 2 cx / W − 1, 2 fy / H, 1 − 2 cy / H): clip x = p.x·a + z·b, clip y = p.y·c + z·d.
    proj: vec4<f32>,
    // (A, B, near, far) of reversed z: clip z = A·z + B with z the positive view depth.
    depth: vec4<f32>,
}

struct MeshParams {
    // Part id written to the part target.
    part: i32,
    // 1 when the texture holds the material's base-colour texture, 0 for the 1×1 white stand-in.
    textured: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> mesh: MeshParams;
@group(1) @binding(1) var base_texture: texture_2d<f32>;
@group(1) @binding(2) var base_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // Linear base colour (vertex colour, or the material's on every vertex).
    @location(3) color: vec3<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    // Camera-space position and normal; z-depth is −camera.z (perspective-correct interpolation keeps it
    // exact on planar triangles).
    @location(0) camera: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) color: vec3<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    let p = frame.world_to_camera * vec4<f32>(v.position, 1.0);
    let z = -p.z;
    var out: VertexOut;
    out.clip = vec4<f32>(
        p.x * frame.proj.x + z * frame.proj.y,
        p.y * frame.proj.z + z * frame.proj.w,
        frame.depth.x * z + frame.depth.y,
        z,
    );
    out.camera = p.xyz;
    out.normal = (frame.world_to_camera * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    out.color = v.color;
    return out;
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) depth: f32,
    @location(2) part: i32,
}

// Linear → sRGB transfer, so the 8-bit colour target holds display values like the input photos.
fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = x * 12.92;
    let high = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, x <= vec3<f32>(0.0031308));
}

@fragment
fn fs_main(f: VertexOut) -> FragmentOut {
    var albedo = f.color;
    // Sampled unconditionally (uniform control flow); the stand-in texture is white.
    let texel = textureSample(base_texture, base_sampler, f.uv);
    if mesh.textured != 0u {
        albedo = albedo * texel.rgb;
    }
    // Headlight at the camera centre; two-sided because imported meshes do not always wind consistently.
    let n = normalize(f.normal);
    let to_eye = normalize(-f.camera);
    var lambert = abs(dot(n, to_eye));
    if !(lambert >= 0.0) {
        lambert = 1.0; // degenerate normal (NaN): treat as facing the camera
    }
    let shade = 0.3 + 0.7 * lambert;
    var out: FragmentOut;
    out.color = vec4<f32>(srgb_encode(albedo * shade), 1.0);
    out.depth = -f.camera.z;
    out.part = mesh.part;
    return out;
}
