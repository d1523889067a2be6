//! The viewer scene's unit tests: sliders, states and play phase, colours and legend, the true
//! parts' ghost, the camera.

use super::*;
use crate::data::{GtJoint, GtMeshes, JointKind as GtKind, TriMesh};
use crate::export::Twin;

fn cube(at: Vec3) -> TriMesh {
    let m = box_mesh(Vec3::splat(0.2), Material::default());
    TriMesh {
        positions: m.positions.iter().map(|p| *p + at).collect(),
        triangles: m.indices,
    }
}

fn scene() -> TwinScene {
    let start = GtMeshes {
        static_part: cube(Vec3::ZERO),
        movable: vec![
            cube(Vec3::new(0.3, 0.0, 0.0)),
            cube(Vec3::new(0.0, 0.3, 0.0)),
        ],
    };
    let joints = [
        GtJoint {
            kind: GtKind::Revolute,
            origin: Vec3::new(0.2, 0.0, 0.0),
            direction: Vec3::Z,
            start: 0.0,
            end: 60.0,
        },
        GtJoint {
            kind: GtKind::Prismatic,
            origin: Vec3::new(0.0, 0.3, 0.0),
            direction: Vec3::Y,
            start: 0.0,
            end: 0.1,
        },
    ];
    let twin = Twin::from_truth("two", &start, &joints);
    TwinScene::new(twin.visual_object(), twin.end_configuration())
}

#[test]
fn sliders_are_in_degrees_and_metres_and_clamp() {
    let mut s = scene();
    let j = s.joints().to_vec();
    assert_eq!(j.len(), 2);
    assert_eq!((j[0].kind, j[0].unit), ("revolute", "°"));
    assert!(
        (j[0].upper - 60.0).abs() < 1e-3 && j[0].lower == 0.0,
        "{j:?}"
    );
    assert!((j[1].end - 0.1).abs() < 1e-6 && j[1].unit == "m");
    assert_eq!(s.slider_values(), vec![0.0, 0.0]);
    assert!(s.set_joint(0, 200.0) && s.set_joint(1, 0.05));
    let v = s.slider_values();
    assert!(
        (v[0] - 60.0).abs() < 1e-3 && (v[1] - 0.05).abs() < 1e-6,
        "{v:?}"
    );
    assert!(!s.set_joint(2, 1.0) && !s.set_joint(0, f32::NAN));
    s.set_state(true);
    let v = s.slider_values();
    assert!(
        (v[0] - 60.0).abs() < 1e-3 && (v[1] - 0.1).abs() < 1e-6,
        "{v:?}"
    );
    s.set_state(false);
    assert_eq!(s.slider_values(), vec![0.0, 0.0]);
}

#[test]
fn moving_a_slider_moves_only_its_part_and_axes_are_drawn() {
    let mut s = scene();
    let before = s.meshes();
    assert_eq!(before.len(), 3 + 2, "three parts and two axis rods");
    s.set_joint(1, 0.1);
    let after = s.meshes();
    for (a, b) in before.iter().zip(&after) {
        let moved = a.mesh.positions != b.mesh.positions;
        assert_eq!(moved, a.part == 2, "part {} moved: {moved}", a.part);
    }
    let shifted = after[2].mesh.positions[0] - before[2].mesh.positions[0];
    assert!(
        (shifted - Vec3::new(0.0, 0.1, 0.0)).length() < 1e-5,
        "{shifted}"
    );
    s.show_axes = false;
    s.colour_by_part = true;
    let plain = s.meshes();
    assert_eq!(plain.len(), 3);
    assert_eq!(plain[1].mesh.colors.as_ref().unwrap()[0], part_colour(1));
    // The true axes are drawn, in their own colour, while asked for.
    s.truth_axes = vec![(Vec3::ZERO, Vec3::Z)];
    let with_truth = s.meshes();
    assert_eq!(with_truth.len(), 4);
    assert_eq!(with_truth[3].mesh.colors.as_ref().unwrap()[0], TRUTH_ROD);
    s.show_truth = false;
    assert_eq!(s.meshes().len(), 3);
}

#[test]
fn the_camera_frames_the_object_and_orbits() {
    let mut s = scene();
    let cam = s.camera(200, 100);
    let (px, _) = cam.project(s.centre).unwrap();
    assert!((px - glam::Vec2::new(100.0, 50.0)).length() < 1e-2, "{px}");
    let p0 = cam.position();
    s.orbit(50.0, 0.0);
    s.zoom(2.0);
    let p1 = s.camera(200, 100).position();
    assert!((p1 - s.centre).length() < (p0 - s.centre).length() * 0.6);
    s.orbit(0.0, 1e6);
    assert!(s.camera(10, 10).position().z > s.centre.z);
}

#[test]
fn the_play_phase_goes_from_start_to_end() {
    let mut s = scene();
    s.set_phase(0.5);
    let v = s.slider_values();
    assert!(
        (v[0] - 30.0).abs() < 1e-3 && (v[1] - 0.05).abs() < 1e-6,
        "{v:?}"
    );
    s.set_phase(1.0);
    let v = s.slider_values();
    assert!(
        (v[0] - 60.0).abs() < 1e-3 && (v[1] - 0.1).abs() < 1e-6,
        "{v:?}"
    );
    s.set_phase(f32::NAN);
    assert_eq!(s.slider_values(), vec![0.0, 0.0]);
}

#[test]
fn the_legend_names_each_part_in_its_render_colour() {
    let mut s = scene();
    let legend = s.legend();
    let names: Vec<&str> = legend.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["base", "part 1 (hinge)", "part 2 (slide)"]);
    assert_eq!(legend[1].link, "part_1");
    s.colour_by_part = true;
    s.show_axes = false;
    for (entry, mesh) in legend.iter().zip(s.meshes()) {
        assert_eq!(entry.part, mesh.part as usize);
        let drawn = mesh.mesh.colors.as_ref().unwrap()[0];
        assert_eq!(palette::css(drawn), entry.colour, "part {}", entry.part);
    }
    let mut colours: Vec<&str> = legend.iter().map(|e| e.colour.as_str()).collect();
    colours.dedup();
    assert_eq!(colours.len(), 3, "{colours:?}");
}

/// The scene's truth: the same parts, the hinge's axis the other way round (and its motion
/// with it), the slide 0.02 m off and longer.
fn with_truth() -> TwinScene {
    let mut s = scene();
    let start = GtMeshes {
        static_part: cube(Vec3::ZERO),
        movable: vec![
            cube(Vec3::new(0.3, 0.0, 0.0)),
            cube(Vec3::new(0.0, 0.32, 0.0)),
        ],
    };
    let joints = [
        GtJoint {
            kind: GtKind::Revolute,
            origin: Vec3::new(0.2, 0.0, 0.0),
            direction: -Vec3::Z,
            start: 0.0,
            end: -60.0,
        },
        GtJoint {
            kind: GtKind::Prismatic,
            origin: Vec3::new(0.0, 0.32, 0.0),
            direction: Vec3::Y,
            start: 0.0,
            end: 0.2,
        },
    ];
    let truth = Twin::from_truth("truth", &start, &joints);
    s.set_truth(truth.visual_object(), truth.end_configuration(), &[(0, 0)]);
    s
}

#[test]
fn the_true_parts_follow_the_sliders_and_states() {
    let mut s = with_truth();
    assert!(
        s.has_truth_parts() && s.truth_meshes().is_empty(),
        "hidden until asked"
    );
    s.show_truth_parts = true;
    let at_start = s.truth_meshes();
    assert_eq!(at_start.len(), 3);
    assert!(
        at_start
            .iter()
            .all(|m| m.mesh.colors.as_ref().unwrap()[0] == TRUTH_PART)
    );
    // The paired hinge turns with slider 0, the same way on screen though its axis is flipped.
    s.set_joint(0, 45.0);
    let fitted = s.meshes();
    let turned = s.truth_meshes();
    for (f, t) in fitted[1]
        .mesh
        .positions
        .iter()
        .zip(&turned[1].mesh.positions)
    {
        assert!((*f - *t).length() < 1e-4, "{f} vs {t}");
    }
    // The unpaired slide stays at its start until a state is picked, then goes to its own end.
    s.set_joint(1, 0.1);
    assert_eq!(
        s.truth_meshes()[2].mesh.positions,
        at_start[2].mesh.positions
    );
    s.set_state(true);
    let moved = s.truth_meshes()[2].mesh.positions[0] - at_start[2].mesh.positions[0];
    assert!(
        (moved - Vec3::new(0.0, 0.2, 0.0)).length() < 1e-5,
        "{moved}"
    );
    s.show_truth_parts = false;
    assert!(s.truth_meshes().is_empty());
}

/// An `n` × `n` render of one colour at one depth (part 1, or none where transparent): its
/// border is the part's outline, the rest inside it.
fn square_view(n: u32, rgba: [u8; 4], depth: f32) -> RenderedView {
    let id = if rgba[3] == 0 { -1 } else { 1 };
    let count = (n * n) as usize;
    RenderedView {
        rgba: RgbaImage {
            width: n,
            height: n,
            pixels: rgba.repeat(count),
        },
        depth: crate::data::DepthMap {
            width: n,
            height: n,
            millimetres: vec![(depth * 1000.0) as u16; count],
        },
        parts: crate::data::PartMap {
            width: n,
            height: n,
            ids: vec![id; count],
        },
        depth_metres: vec![depth; count],
    }
}

/// A 3 × 3 [`square_view`]: its centre is inside the part, the rest on its outline.
fn view(rgba: [u8; 4], depth: f32) -> RenderedView {
    square_view(3, rgba, depth)
}

#[test]
fn the_ghost_shows_through_more_in_front_than_behind_and_outlines_parts() {
    let fitted = view([200, 200, 200, 255], 1.0);
    let centre = |img: RgbaImage| img.pixels[16..20].to_vec();
    let corner = |img: RgbaImage| img.pixels[0..4].to_vec();
    let front = ghost_over(&fitted, &view([0, 0, 0, 255], 0.9));
    let behind = ghost_over(&fitted, &view([0, 0, 0, 255], 1.1));
    let none = ghost_over(&fitted, &view([0, 0, 0, 0], 0.0));
    assert_eq!(none, fitted.rgba);
    let (f, b) = (centre(front.clone()), centre(behind.clone()));
    assert!(f[0] < b[0] && b[0] < 200, "{f:?} {b:?}");
    assert_eq!((f[3], b[3]), (255, 255));
    // The outline is solid in front, half behind.
    assert_eq!(corner(front)[0], 0);
    assert_eq!(corner(behind)[0], 100);
    let alone = ghost_over(&view([0; 4], 0.0), &view([10, 20, 30, 255], 1.0));
    let a = centre(alone);
    assert_eq!(&a[..3], [10, 20, 30]);
    assert!(a[3] > 0 && a[3] < 255, "{a:?}");
    // Renders of different sizes are left alone.
    let small = view([0, 0, 0, 255], 0.5);
    let mut big = view([0, 0, 0, 255], 0.5);
    big.depth_metres.push(0.5);
    assert_eq!(ghost_over(&fitted, &big), fitted.rgba);
    assert_ne!(ghost_over(&fitted, &small), fitted.rgba);
}

#[test]
fn the_hatched_ghost_reads_over_any_grey() {
    // A true part in front of a grey fitted surface, light to dark: inside the part, the ghosted
    // stripes differ from the bare ones between them by a lightness step anyone sees (ΔL* ≥ 10;
    // 2 is a just-noticeable one), whatever the grey.
    let lightness = |v: u8| palette::lab([palette::decode(v); 3])[0];
    let n = 12;
    for grey in [40u8, 90, 128, 200, 240] {
        let fitted = square_view(n, [grey, grey, grey, 255], 1.0);
        let out = ghost_over(&fitted, &square_view(n, [5, 5, 8, 255], 0.9));
        let n = n as usize;
        let inside: Vec<u8> = (1..n - 1)
            .flat_map(|y| (1..n - 1).map(move |x| y * n + x))
            .map(|i| out.pixels[4 * i])
            .collect();
        let (lo, hi) = (*inside.iter().min().unwrap(), *inside.iter().max().unwrap());
        assert_eq!(
            hi, grey,
            "grey {grey}: bare stripes show the fitted surface"
        );
        let step = lightness(hi) - lightness(lo);
        assert!(
            step >= 10.0,
            "grey {grey}: stripes only ΔL* {step:.1} apart"
        );
    }
}
