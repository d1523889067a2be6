//! What a real capture's depth maps say about space: the demo cabinet rendered by the GPU, its
//! depth deciding what of the true base the views see (`eval::seen`, and the CD-s bound that sets)
//! and where they saw through (`fit::reconstruct::free_space`, which keeps openings open).

use artmesh::data::{Dataset, State};
use artmesh::eval::{ChamferOptions, seen_by, static_bound};
use artmesh::fit::object::FitConfig;
use artmesh::fit::preset::Preset;
use artmesh::fit::reconstruct::free_space::FreeSpace;
use artmesh::render::capture_dataset;
use artmesh::synth::{Category, SynthParams, generate};
use glam::Vec3;
use pollster::block_on;

use crate::common::context;

/// The demo cabinet (a door and a drawer) at 64² with 8 training views per state.
fn cabinet() -> Dataset {
    let ctx = context();
    let object = generate(&SynthParams {
        category: Category::StorageFurniture,
        movable_parts: Some(2),
        seed: 0,
    })
    .unwrap();
    let mut spec = FitConfig::preset(Preset::Tiny).demo_capture(0);
    (spec.width, spec.height, spec.train_views) = (64, 64, 8);
    block_on(capture_dataset(&ctx, &object, &spec, &mut |_| {})).unwrap()
}

#[test]
fn views_see_part_of_the_base_and_its_bound_lies_above_the_floor() {
    let mut dataset = cabinet();
    let options = ChamferOptions {
        samples: 2000,
        ..ChamferOptions::default()
    };
    let all = static_bound(&dataset, State::Start, &options).expect("the capture has depth");
    eprintln!("all views: {all:?}");
    // The base stands on the ground and hides its inside behind the door and the drawer.
    assert!(all.seen_share > 0.2 && all.seen_share < 0.95, "{all:?}");
    assert!(all.floor_mm > 0.0, "{all:?}");
    assert!(all.seen_only_mm > all.floor_mm, "{all:?}");

    // Without every other view's depth, the views see no more, and a fit of it can do no better.
    for view in dataset.views.iter_mut() {
        for frame in view.frames.iter_mut().skip(1).step_by(2) {
            frame.depth = None;
        }
    }
    let half = static_bound(&dataset, State::Start, &options).expect("half the views have depth");
    eprintln!("half the views: {half:?}");
    assert!(half.seen_share <= all.seen_share, "{half:?} vs {all:?}");
    assert!(half.seen_only_mm >= all.seen_only_mm, "{half:?} vs {all:?}");
    assert_eq!(half.floor_mm, all.floor_mm, "the floor needs no views");

    for view in dataset.views.iter_mut() {
        view.frames.iter_mut().for_each(|f| f.depth = None);
    }
    assert_eq!(
        static_bound(&dataset, State::Start, &options),
        None,
        "no depth, no bound"
    );
}

#[test]
fn the_true_surface_is_not_free_and_the_air_in_front_of_it_is() {
    let dataset = cabinet();
    let space = FreeSpace::from_dataset(&dataset).expect("the capture has depth");
    let truth = &dataset.gt_meshes_for(State::Start).unwrap().static_part;
    let frames: Vec<_> = dataset.views.iter().flat_map(|v| &v.frames).collect();
    // Face centroids of the true base that some view sees, with their faces' normals.
    let faces: Vec<(Vec3, Vec3)> = truth
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| truth.positions[i as usize]);
            ((a + b + c) / 3.0, (b - a).cross(c - a).normalize_or_zero())
        })
        .filter(|(_, n)| *n != Vec3::ZERO)
        .collect();
    let centroids: Vec<Vec3> = faces.iter().map(|f| f.0).collect();
    let seen = seen_by(&centroids, frames.iter().copied());
    let seen: Vec<(Vec3, Vec3)> = faces
        .iter()
        .zip(&seen)
        .filter(|s| *s.1)
        .map(|s| *s.0)
        .collect();
    assert!(seen.len() > 20, "{} seen faces", seen.len());
    let states = [State::Start, State::End];
    let spacing = 0.02;
    let share = |points: &mut dyn Iterator<Item = Vec3>| {
        let free: Vec<bool> = points
            .map(|p| space.is_free(&states, p, 0, spacing))
            .collect();
        free.iter().filter(|&&f| f).count() as f32 / free.len() as f32
    };
    let on = share(&mut seen.iter().map(|(p, _)| *p));
    // 15 cm out along the outward normal (the fixture's faces wind outward) is air in front of a
    // seen wall.
    let out = share(&mut seen.iter().map(|(p, n)| *p + 0.15 * *n));
    eprintln!("free: {on:.3} of seen true faces, {out:.3} of points 15 cm in front of them");
    // At 64² a centroid at a silhouette can fall on background pixels: a few percent, which a
    // fill's one-fifth share absorbs.
    assert!(on < 0.05, "{on}");
    assert!(out > 0.6, "{out}");
}
