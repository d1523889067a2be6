//! The result viewer's opening view on the built-in demo cabinet (a door and a drawer, the
//! page's default demo): from the view the viewer picks, every movable part has pixels on the
//! real renderer's part map at both states, and no part shows less than from the old fixed view.
//! The truth stands in for a fit: the viewer scores a fitted twin the same way.

use std::time::Instant;

use artmesh::data::Camera;
use artmesh::export::Twin;
use artmesh::fit::object::FitConfig;
use artmesh::fit::preset::Preset;
use artmesh::gpu::GpuContext;
use artmesh::render::viewer::TwinScene;
use artmesh::render::{GtRenderer, capture_dataset};
use artmesh::synth::{Category, SynthParams, generate};
use pollster::block_on;

use crate::common::context;

/// The demo cabinet as the page's demo captures it (storage furniture, 2 parts, seed 0, tiny),
/// as a twin at its true shape and joints.
fn demo_cabinet(ctx: &GpuContext) -> Twin {
    let object = generate(&SynthParams {
        category: Category::StorageFurniture,
        movable_parts: Some(2),
        seed: 0,
    })
    .unwrap();
    let config = FitConfig::preset(Preset::Tiny);
    let dataset = block_on(capture_dataset(
        ctx,
        &object,
        &config.demo_capture(0),
        &mut |_| {},
    ))
    .unwrap();
    let meshes = dataset.gt_meshes[0]
        .as_ref()
        .expect("the demo has GT meshes");
    let joints = dataset.gt_joints.as_ref().expect("the demo has GT joints");
    Twin::from_truth("cabinet", meshes, joints)
}

/// Visible share of each movable part on the GPU's part map, at both states (min over them):
/// its pixels with everything drawn over its pixels drawn alone.
fn gpu_shares(ctx: &GpuContext, scene: &mut TwinScene, camera: &Camera) -> Vec<f32> {
    let (w, h) = (camera.intrinsics.width, camera.intrinsics.height);
    let renderer = GtRenderer::new(ctx, w, h).unwrap();
    let count = |meshes: &[artmesh::render::PartMesh], part: i16| {
        let view = block_on(renderer.render_view(ctx, meshes, camera)).unwrap();
        view.parts.ids.iter().filter(|&&id| id == part).count() as f32
    };
    let parts = scene.legend().len();
    let mut shares = vec![1.0f32; parts - 1];
    for end in [false, true] {
        scene.set_state(end);
        let meshes: Vec<_> = scene.meshes().into_iter().filter(|m| m.part >= 0).collect();
        for (k, share) in shares.iter_mut().enumerate() {
            let part = k as i16 + 1;
            let alone: Vec<_> = meshes.iter().filter(|m| m.part == part).cloned().collect();
            let seen = count(&meshes, part);
            assert!(seen > 0.0, "part {part} has no pixels (end state: {end})");
            *share = share.min(seen / count(&alone, part).max(1.0));
        }
    }
    shares
}

#[test]
fn the_opening_view_shows_the_door_and_the_drawer() {
    let ctx = context();
    let twin = demo_cabinet(&ctx);
    let mut scene = TwinScene::new(twin.visual_object(), twin.end_configuration());
    let kinds: Vec<&str> = scene.joints().iter().map(|j| j.kind).collect();
    assert!(
        kinds.contains(&"revolute") && kinds.contains(&"prismatic"),
        "the demo cabinet should have a door and a drawer: {kinds:?}"
    );
    let old_camera = scene.camera(160, 120);
    let t0 = Instant::now();
    let choice = scene.choose_opening_view();
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    println!(
        "opening view: yaw {:.2}, pitch {:.2}; smallest visible share {:.3} (old view {:.3}); chosen in {ms:.1} ms",
        choice.yaw, choice.pitch, choice.score, choice.old_score
    );
    assert!(choice.score >= choice.old_score, "{choice:?}");
    assert!(
        choice.score > 0.5,
        "a movable part stays mostly hidden: {choice:?}"
    );

    // The real renderer agrees: every movable part in sight at both states, and at least as
    // much of the worst-seen part as from the old view (a few pixels' slack for the scorer's
    // coarser grid).
    let new_camera = scene.camera(160, 120);
    let new = gpu_shares(&ctx, &mut scene, &new_camera);
    let old = gpu_shares(&ctx, &mut scene, &old_camera);
    println!("renderer's visible shares (door, drawer): chosen {new:?}, old {old:?}");
    let min = |v: &[f32]| v.iter().copied().fold(1.0, f32::min);
    assert!(
        min(&new) >= min(&old) - 0.02,
        "chosen {new:?} vs old {old:?}"
    );
    assert!(min(&new) > 0.5, "{new:?}");
}
