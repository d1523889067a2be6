//! Ground-truth renderer against analytic references: box depth by ray casting, part ids of two boxes,
//! projection agreement with `Camera::project`, determinism, and the real Sektion cabinet at two states.

use std::path::Path;

use artmesh::data::{Camera, Intrinsics, PngPixels, encode_png, look_at, read_dir};
use artmesh::gpu::GpuContext;
use artmesh::object::{ArticulatedObject, Material, RenderMesh, box_mesh};
use artmesh::render::{GtRenderer, PartMesh, RenderedView, posed_part_meshes};
use glam::{Affine3A, DVec3, Vec2, Vec3};
use pollster::block_on;

const W: u32 = 64;
const H: u32 = 48;

fn context() -> GpuContext {
    block_on(GpuContext::new()).expect("a GPU adapter (lavapipe in CI)")
}

fn intrinsics() -> Intrinsics {
    // Non-square pixels and an off-centre principal point exercise the whole projection.
    Intrinsics {
        width: W,
        height: H,
        fx: 62.0,
        fy: 58.5,
        cx: 31.3,
        cy: 24.6,
    }
}

/// An axis-aligned box in world space.
#[derive(Clone, Copy)]
struct Aabb {
    centre: Vec3,
    size: Vec3,
    part: i16,
}

impl Aabb {
    fn mesh(&self) -> PartMesh {
        PartMesh {
            mesh: box_mesh(self.size, Material::default())
                .transformed(&Affine3A::from_translation(self.centre)),
            part: self.part,
        }
    }

    /// Entry parameter of the ray `o + t d` with the box grown by `grow` on every side (slab test, f64).
    fn hit(&self, o: DVec3, d: DVec3, grow: f64) -> Option<f64> {
        let half = self.size.as_dvec3() * 0.5 + DVec3::splat(grow);
        let lo = self.centre.as_dvec3() - half;
        let hi = self.centre.as_dvec3() + half;
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for a in 0..3 {
            let (a0, a1) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
            t0 = t0.max(a0.min(a1));
            t1 = t1.min(a0.max(a1));
        }
        (t0 <= t1 && t0 > 0.0).then_some(t0)
    }
}

/// Analytic reference for one pixel centre: the nearest box hit as (z-depth in metres, part), or `None`;
/// `ambiguous` when growing or shrinking the boxes by 0.2 mm changes which box (if any) is hit first, i.e.
/// the ray grazes an edge and the rasteriser's tie-breaking decides.
struct Reference {
    hit: Option<(f64, i16)>,
    ambiguous: bool,
}

fn reference(camera: &Camera, boxes: &[Aabb], x: u32, y: u32) -> Reference {
    let px = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
    // The ray through the pixel centre, scaled so that `t` is the z-depth.
    let o = camera.position().as_dvec3();
    let d = camera.unproject(px, 1.0).as_dvec3() - o;
    let nearest = |grow: f64| {
        boxes
            .iter()
            .filter_map(|b| b.hit(o, d, grow).map(|t| (t, b.part)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    let hit = nearest(0.0);
    let parts = [-2e-4, 2e-4].map(|g| nearest(g).map(|h| h.1));
    Reference {
        hit,
        ambiguous: parts[0] != parts[1] || parts[0] != hit.map(|h| h.1),
    }
}

/// Compares a render with the ray-cast reference: coverage and part ids on unambiguous pixels, depth on
/// pixels covered in both. Returns (max depth error in metres, covered pixel count, reference count).
fn check_against_reference(
    view: &RenderedView,
    camera: &Camera,
    boxes: &[Aabb],
) -> (f64, usize, usize) {
    let mut max_err = 0.0f64;
    let (mut covered, mut expected) = (0, 0);
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            let r = reference(camera, boxes, x, y);
            let alpha = view.rgba.pixels[i * 4 + 3];
            let part = view.parts.ids[i];
            covered += usize::from(alpha == 255);
            expected += usize::from(r.hit.is_some());
            assert!(alpha == 0 || alpha == 255, "alpha {alpha} at ({x}, {y})");
            assert_eq!(
                alpha == 255,
                part != -1,
                "mask and part map disagree at ({x}, {y})"
            );
            if !r.ambiguous {
                assert_eq!(part, r.hit.map_or(-1, |h| h.1), "part id at ({x}, {y})");
            }
            match (r.hit, part != -1) {
                (Some((z, _)), true) if !r.ambiguous => {
                    let got = view.depth_metres[i] as f64;
                    max_err = max_err.max((got - z).abs());
                    // Millimetres: rounded, so within half a millimetre plus the render error.
                    let mm = view.depth.millimetres[i] as f64;
                    assert!(
                        (mm - z * 1000.0).abs() <= 0.51,
                        "depth {mm} mm vs {z} m at ({x}, {y})"
                    );
                }
                (None, false) => {
                    assert_eq!(
                        view.depth.millimetres[i], 0,
                        "background depth at ({x}, {y})"
                    );
                    assert_eq!(view.depth_metres[i], 0.0);
                    assert_eq!(&view.rgba.pixels[i * 4..i * 4 + 4], &[0, 0, 0, 0]);
                }
                _ => {}
            }
        }
    }
    (max_err, covered, expected)
}

fn render(ctx: &GpuContext, meshes: &[PartMesh], camera: &Camera) -> RenderedView {
    let renderer = GtRenderer::new(ctx, W, H).unwrap();
    let view = block_on(renderer.render_view(ctx, meshes, camera)).unwrap();
    ctx.check().unwrap();
    view
}

#[test]
fn box_face_on_depth_is_exact() {
    let ctx = context();
    let b = Aabb {
        centre: Vec3::new(0.1, -0.05, 0.0),
        size: Vec3::new(0.4, 0.3, 0.2),
        part: 0,
    };
    // Straight down the −z axis at the +z face (z = 0.1): depth 1.9 m everywhere on it.
    let camera = Camera {
        camera_to_world: look_at(
            Vec3::new(0.1, -0.05, 2.0),
            Vec3::new(0.1, -0.05, 0.0),
            Vec3::Y,
        ),
        intrinsics: intrinsics(),
    };
    let view = render(&ctx, &[b.mesh()], &camera);
    let (err, covered, expected) = check_against_reference(&view, &camera, &[b]);
    eprintln!(
        "face-on: max depth error {:.4} mm, {covered} px covered, {expected} expected",
        err * 1e3
    );
    assert!(err < 0.5e-3, "max depth error {err} m");
    for (i, &mm) in view.depth.millimetres.iter().enumerate() {
        assert!(mm == 0 || mm == 1900, "pixel {i}: {mm} mm");
    }
    // Projected face area: 0.4 × 0.3 m at 1.9 m; edges may go either way by about a perimeter of pixels.
    let area = (0.4 * 62.0 / 1.9) * (0.3 * 58.5 / 1.9);
    assert!(
        (covered as f64 - area).abs() < 0.5 * (2.0 * (13.0 + 9.2)),
        "{covered} vs {area}"
    );
    assert!(
        (covered as i64 - expected as i64).abs() <= 4,
        "{covered} vs {expected}"
    );
}

#[test]
fn box_tilted_depth_matches_ray_plane_intersection() {
    let ctx = context();
    let b = Aabb {
        centre: Vec3::new(0.0, 0.0, 0.3),
        size: Vec3::new(0.5, 0.4, 0.6),
        part: 3,
    };
    let camera = Camera {
        camera_to_world: look_at(Vec3::new(1.3, -0.9, 1.4), b.centre, Vec3::Z),
        intrinsics: intrinsics(),
    };
    let view = render(&ctx, &[b.mesh()], &camera);
    let (err, covered, expected) = check_against_reference(&view, &camera, &[b]);
    eprintln!(
        "tilted: max depth error {:.4} mm, {covered} px covered, {expected} expected",
        err * 1e3
    );
    assert!(err < 0.5e-3, "max depth error {err} m");
    assert!(covered > 200);
    // Depth varies across the visible faces.
    let (lo, hi) = view.depth.range_mm().unwrap();
    assert!(hi - lo > 200, "{lo}..{hi}");
}

#[test]
fn part_ids_follow_geometry() {
    let ctx = context();
    let boxes = [
        Aabb {
            centre: Vec3::new(-0.3, 0.0, 0.0),
            size: Vec3::new(0.4, 0.4, 0.5),
            part: 0,
        },
        Aabb {
            centre: Vec3::new(0.25, 0.1, 0.05),
            size: Vec3::new(0.3, 0.5, 0.4),
            part: 1,
        },
    ];
    // Oblique, so one box partly hides the other and visibility matters.
    let camera = Camera {
        camera_to_world: look_at(Vec3::new(1.6, -1.2, 0.9), Vec3::ZERO, Vec3::Z),
        intrinsics: intrinsics(),
    };
    let meshes: Vec<PartMesh> = boxes.iter().map(Aabb::mesh).collect();
    let view = render(&ctx, &meshes, &camera);
    let (err, _, _) = check_against_reference(&view, &camera, &boxes);
    eprintln!("two boxes: max depth error {:.4} mm", err * 1e3);
    assert!(err < 0.5e-3);
    for id in [-1, 0, 1] {
        assert!(view.parts.ids.contains(&id), "part {id} missing");
    }
}

#[test]
fn rendering_is_deterministic() {
    let ctx = context();
    let meshes: Vec<PartMesh> = [(Vec3::ZERO, 0), (Vec3::new(0.2, 0.3, 0.1), 2)]
        .map(|(c, part)| PartMesh {
            mesh: box_mesh(Vec3::splat(0.3), Material::default())
                .transformed(&Affine3A::from_translation(c)),
            part,
        })
        .to_vec();
    let camera = Camera {
        camera_to_world: look_at(Vec3::new(0.9, -1.1, 0.7), Vec3::ZERO, Vec3::Z),
        intrinsics: intrinsics(),
    };
    let renderer = GtRenderer::new(&ctx, W, H).unwrap();
    let a = block_on(renderer.render_view(&ctx, &meshes, &camera)).unwrap();
    let b = block_on(renderer.render_view(&ctx, &meshes, &camera)).unwrap();
    let c = render(&ctx, &meshes, &camera);
    assert_eq!(a, b);
    assert_eq!(a.rgba.pixels, c.rgba.pixels);
    assert_eq!(a.depth, c.depth);
    assert_eq!(a.parts, c.parts);
    let bits = |v: &RenderedView| {
        v.depth_metres
            .iter()
            .map(|z| z.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&c));
}

#[test]
fn tiny_triangle_lands_where_camera_project_says() {
    let ctx = context();
    let camera = Camera {
        camera_to_world: look_at(
            Vec3::new(0.7, -1.5, 0.6),
            Vec3::new(0.05, 0.1, 0.0),
            Vec3::Z,
        ),
        intrinsics: intrinsics(),
    };
    let renderer = GtRenderer::new(&ctx, W, H).unwrap();
    for (k, target) in [
        (3.2, 4.4),
        (20.7, 13.3),
        (40.5, 30.5),
        (60.9, 44.1),
        (31.3, 24.6),
    ]
    .into_iter()
    .enumerate()
    {
        let target = Vec2::new(target.0, target.1);
        let depth = 1.2 + 0.3 * k as f32;
        let centroid = camera.unproject(target, depth);
        let (px, z) = camera.project(centroid).unwrap();
        assert!((px - target).length() < 1e-3 && (z - depth).abs() < 1e-4);
        // Corners 0.3 px around the target in the image plane: only the pixel containing it can be covered,
        // and its centre is covered only when the target lies within 0.15 px of it, so aim at the centre.
        let centre = target.floor() + Vec2::splat(0.5);
        let corners = [(0.0, -0.3), (0.26, 0.15), (-0.26, 0.15)]
            .map(|(dx, dy)| camera.unproject(centre + Vec2::new(dx, dy), depth));
        let mesh = RenderMesh {
            positions: corners.to_vec(),
            normals: vec![camera.forward() * -1.0; 3],
            uvs: None,
            colors: None,
            indices: vec![[0, 1, 2]],
            material: Material::default(),
        };
        let view =
            block_on(renderer.render_view(&ctx, &[PartMesh { mesh, part: 7 }], &camera)).unwrap();
        let covered: Vec<(u32, u32)> = (0..H)
            .flat_map(|y| (0..W).map(move |x| (x, y)))
            .filter(|&(x, y)| view.parts.ids[(y * W + x) as usize] == 7)
            .collect();
        let expected = (target.x.floor() as u32, target.y.floor() as u32);
        assert_eq!(covered, vec![expected], "target {target}");
        let i = (expected.1 * W + expected.0) as usize;
        assert!(
            (view.depth_metres[i] - depth).abs() < 2e-4,
            "{} vs {depth}",
            view.depth_metres[i]
        );
    }
}

#[test]
fn wrong_camera_size_is_an_error() {
    let ctx = context();
    let renderer = GtRenderer::new(&ctx, W, H).unwrap();
    let camera = Camera {
        camera_to_world: look_at(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Vec3::Y),
        intrinsics: Intrinsics::from_fov(32, 32, 1.0, None),
    };
    assert!(block_on(renderer.render_view(&ctx, &[], &camera)).is_err());
    assert!(GtRenderer::new(&ctx, 0, 8).is_err());
    let mut bad = box_mesh(Vec3::ONE, Material::default());
    bad.indices.push([0, 1, 1000]);
    let camera = Camera {
        camera_to_world: camera.camera_to_world,
        intrinsics: intrinsics(),
    };
    let meshes = [PartMesh { mesh: bad, part: 0 }];
    assert!(block_on(renderer.render_view(&ctx, &meshes, &camera)).is_err());
    // An empty scene renders background only.
    let empty = block_on(renderer.render_view(&ctx, &[], &camera)).unwrap();
    assert!(empty.parts.ids.iter().all(|&p| p == -1));
    assert!(empty.rgba.pixels.iter().all(|&b| b == 0));
}

#[test]
fn sektion_cabinet_renders_parts_at_two_states() {
    let files = read_dir(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/objects"
    )))
    .expect("../shared/objects is readable");
    let obj = ArticulatedObject::from_urdf("sektion/urdf/sektion_cabinet.urdf", &files).unwrap();
    let parts = obj.parts();
    let drawer = obj.joint_index("drawer_top_joint").unwrap();
    let drawer_part = parts
        .parts
        .iter()
        .position(|p| p.joint == Some(drawer))
        .unwrap();
    let closed = parts.configuration(&obj, &[]);
    let mut values = vec![0.0; parts.parts.len()];
    values[drawer_part] = 0.3;
    let open = parts.configuration(&obj, &values);

    // Frame the closed cabinet from its front (+x, where the drawers slide out), a little above and aside.
    let meshes = posed_part_meshes(&obj, &closed);
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in meshes.iter().flat_map(|m| m.mesh.positions.iter()) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5;
    let eye = centre + Vec3::new(1.0, 0.45, 0.5).normalize() * radius * 3.0;
    let camera = Camera {
        camera_to_world: look_at(eye, centre, Vec3::Z),
        intrinsics: Intrinsics::from_fov(W, H, 0.8, None),
    };

    let ctx = context();
    let renderer = GtRenderer::new(&ctx, W, H).unwrap();
    let a = block_on(renderer.render_view(&ctx, &meshes, &camera)).unwrap();
    let b = block_on(renderer.render_view(&ctx, &posed_part_meshes(&obj, &open), &camera)).unwrap();
    for view in [&a, &b] {
        let covered = view
            .rgba
            .pixels
            .chunks_exact(4)
            .filter(|p| p[3] == 255)
            .count();
        assert!(covered > 100, "{covered} covered pixels");
        let mut ids: Vec<i16> = view.parts.ids.iter().copied().filter(|&p| p >= 0).collect();
        ids.sort_unstable();
        ids.dedup();
        assert!(ids.len() >= 2, "part ids {ids:?}");
        // Depth sits within the framed bounding sphere, widened by the drawer's 0.3 m travel towards us.
        let (near, far) = view.depth.range_mm().unwrap();
        let d = (eye - centre).length() * 1000.0;
        let reach = (radius + 0.3) * 1000.0;
        assert!(
            near as f32 > d - reach && (far as f32) < d + reach,
            "depth {near}..{far} mm, centre at {d} mm, reach {reach} mm"
        );
    }
    let changed = a
        .parts
        .ids
        .iter()
        .zip(&b.parts.ids)
        .filter(|(x, y)| x != y)
        .count();
    assert!(
        changed > 10,
        "opening the drawer changed {changed} part-map pixels"
    );
    assert!(b.parts.ids.contains(&(drawer_part as i16)));

    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/artefacts"));
    std::fs::create_dir_all(dir).unwrap();
    let png = encode_png("render-sektion.png", W, H, PngPixels::Rgba8(&b.rgba.pixels)).unwrap();
    std::fs::write(dir.join("render-sektion.png"), png).unwrap();
}

#[test]
fn textures_are_sampled_with_gltf_orientation() {
    let ctx = context();
    // 8×8 texture in four 4×4 quadrants: red, green / blue, white (top row first); blocks, not single texels,
    // so bilinear filtering near a quadrant centre reads one colour. The +z face shows it upright from above.
    let quadrant = [
        [255, 0, 0, 255],
        [0, 255, 0, 255],
        [0, 0, 255, 255],
        [255; 4],
    ];
    let pixels = (0..8)
        .flat_map(|y| (0..8).map(move |x| quadrant[(y / 4) * 2 + x / 4]))
        .flatten()
        .collect();
    let texture = std::sync::Arc::new(artmesh::data::RgbaImage {
        width: 8,
        height: 8,
        pixels,
    });
    let material = Material {
        name: Some("checker".into()),
        base_color: [1.0; 4],
        texture: Some(texture),
    };
    let mesh = box_mesh(Vec3::new(0.6, 0.6, 0.1), material);
    let camera = Camera {
        camera_to_world: look_at(Vec3::new(0.0, 0.0, 1.5), Vec3::ZERO, Vec3::Y),
        intrinsics: intrinsics(),
    };
    let view = render(&ctx, &[PartMesh { mesh, part: 0 }], &camera);
    // Quadrant centres at (±0.15, ±0.15) on the top face (z = 0.05).
    let expect = [
        (Vec3::new(-0.15, 0.15, 0.05), [255, 0, 0]),
        (Vec3::new(0.15, 0.15, 0.05), [0, 255, 0]),
        (Vec3::new(-0.15, -0.15, 0.05), [0, 0, 255]),
        (Vec3::new(0.15, -0.15, 0.05), [255, 255, 255]),
    ];
    for (p, rgb) in expect {
        let (px, _) = camera.project(p).unwrap();
        let i = ((px.y as u32) * W + px.x as u32) as usize;
        let got = &view.rgba.pixels[i * 4..i * 4 + 4];
        for c in 0..3 {
            assert!(
                (got[c] as i32 - rgb[c]).abs() < 8,
                "at {p}: got {got:?}, expected about {rgb:?}"
            );
        }
        assert_eq!(got[3], 255);
    }
}

#[test]
fn ground_slab_reaching_behind_the_camera_is_not_clipped() {
    let ctx = context();
    // A 100 m ground slab whose vertices lie far ahead of and behind the camera: the near plane must follow
    // the visible geometry, not the nearest vertex in front (about 45 m away here).
    let slab = Aabb {
        centre: Vec3::new(0.0, 0.0, -0.05),
        size: Vec3::new(100.0, 100.0, 0.1),
        part: 0,
    };
    let camera = Camera {
        camera_to_world: look_at(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 4.0, 0.0), Vec3::Z),
        intrinsics: intrinsics(),
    };
    let view = render(&ctx, &[slab.mesh()], &camera);
    let (err, covered, expected) = check_against_reference(&view, &camera, &[slab]);
    eprintln!(
        "ground slab: max depth error {:.4} mm, {covered} of {expected} px",
        err * 1e3
    );
    assert!(err < 0.5e-3, "max depth error {err} m");
    // The bottom row sees the ground about 1.3 m away.
    let bottom = ((H - 1) * W + W / 2) as usize;
    assert!(view.depth.millimetres[bottom] > 0 && view.depth.millimetres[bottom] < 2000);
}

#[test]
fn depth_beyond_the_u16_range_is_clamped() {
    let ctx = context();
    let far_box = Aabb {
        centre: Vec3::new(0.0, 0.0, -75.0),
        size: Vec3::new(12.0, 12.0, 10.0),
        part: 0,
    };
    let camera = Camera {
        camera_to_world: look_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y),
        intrinsics: intrinsics(),
    };
    let view = render(&ctx, &[far_box.mesh()], &camera);
    let centre = ((H / 2) * W + W / 2) as usize;
    assert!(
        (view.depth_metres[centre] - 70.0).abs() < 1e-3,
        "{}",
        view.depth_metres[centre]
    );
    assert_eq!(view.depth.millimetres[centre], u16::MAX);
}
