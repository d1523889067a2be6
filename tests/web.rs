//! Browser tests (wasm-bindgen-test in headless Chromium, WebGPU on SwiftShader): the same GPU
//! primitives and dataset checks as the native tests, on the browser's adapter and in wasm.
#![cfg(target_arch = "wasm32")]

use artmesh::gpu::{GpuContext, selftest};
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

#[path = "web/budgets.rs"]
mod budgets;
#[path = "web/readers.rs"]
mod readers;

async fn context() -> GpuContext {
    match GpuContext::new().await {
        Ok(ctx) => ctx,
        Err(e) => panic!("browser tests need WebGPU: {e}"),
    }
}

fn assert_all_pass(checks: &[selftest::PrimitiveCheck]) {
    let failed: Vec<_> = checks.iter().filter(|c| !c.passed()).collect();
    assert!(failed.is_empty(), "mismatches against the CPU: {failed:#?}");
}

#[wasm_bindgen_test]
async fn prefix_sum_and_radix_sort_match_cpu_up_to_4m() {
    let ctx = context().await;
    let mut checks = Vec::new();
    for (i, &n) in [1u32, 3, 256, 1025, 65_537, 1_000_003, 4_194_304]
        .iter()
        .enumerate()
    {
        checks.push(selftest::check_prefix_sum(&ctx, n, i as u64).await.unwrap());
        checks.push(
            selftest::check_radix_sort(&ctx, n, 32, i as u64)
                .await
                .unwrap(),
        );
    }
    checks.push(
        selftest::check_radix_sort(&ctx, 300_001, 20, 99)
            .await
            .unwrap(),
    );
    assert_all_pass(&checks);
}

#[wasm_bindgen_test]
async fn tiled_dispatch_matches_cpu() {
    let mut ctx = context().await;
    ctx.set_dispatch_dim_limit(7);
    let checks = [
        selftest::check_prefix_sum(&ctx, 100_000, 1).await.unwrap(),
        selftest::check_radix_sort(&ctx, 100_000, 32, 1)
            .await
            .unwrap(),
    ];
    assert_all_pass(&checks);
}

#[wasm_bindgen_test]
fn dataset_round_trip_in_wasm() {
    use artmesh::data::{Dataset, fixture};
    let dataset = fixture::small_dataset(fixture::FixtureParams::default());
    let files = dataset.to_files().unwrap();
    assert_eq!(Dataset::from_files(&files).unwrap(), dataset);
}

#[wasm_bindgen_test]
fn malformed_datasets_give_clear_errors_in_wasm() {
    use artmesh::data::Dataset;
    use artmesh::fixtures::malformed;
    let cases = malformed::malformed_catalogue();
    assert!(cases.len() >= 15);
    for case in cases {
        match Dataset::from_files(&case.files()) {
            Ok(_) => panic!("{}: accepted a malformed dataset", case.name),
            Err(errors) => assert!(
                errors.0.iter().any(|e| case.matches(e)),
                "{}: expected {} / {:?} / '{}', got:\n{errors}",
                case.name,
                case.file,
                case.field,
                case.message
            ),
        }
    }
}

/// The capture path in the browser: a procedural object rendered by the ground-truth render pipeline on the
/// browser's adapter becomes a dataset the reader accepts, with the part ids of every movable part visible
/// and ground truth that scores zero against itself.
#[wasm_bindgen_test]
async fn procedural_object_captures_as_a_dataset_in_the_browser() {
    use artmesh::data::{Dataset, FileSet, State};
    use artmesh::eval::{EvalOptions, evaluate_object};
    use artmesh::render::{RenderSpec, render_dataset};
    use artmesh::synth::{Category, SynthParams, generate};
    let ctx = context().await;
    let object = generate(&SynthParams {
        category: Category::StorageFurniture,
        movable_parts: Some(3),
        seed: 2,
    })
    .unwrap();
    let spec = RenderSpec {
        width: 48,
        height: 48,
        train_views: 4,
        test_views: 1,
        ..RenderSpec::default()
    };
    let mut files = FileSet::new();
    render_dataset(
        &ctx,
        &object,
        &spec,
        &mut |batch| {
            files.extend(batch);
            Ok(())
        },
        &mut |_| {},
    )
    .await
    .unwrap();
    let dataset = Dataset::from_files(&files).unwrap();
    assert_eq!(dataset.num_parts, 4);
    let mut seen = [false; 4];
    for frame in dataset.frames() {
        for &id in &frame.parts.as_ref().unwrap().ids {
            if id >= 0 {
                seen[id as usize] = true;
            }
        }
    }
    assert_eq!(seen, [true; 4], "part ids seen in the browser's renders");
    let joints = dataset.gt_joints.as_ref().unwrap();
    let meshes = dataset.gt_meshes_for(State::Start).unwrap();
    let options = EvalOptions::default();
    let m = evaluate_object(
        "web",
        "StorageFurniture",
        joints,
        joints,
        Some((meshes, meshes)),
        &options,
    )
    .unwrap();
    assert_eq!((m.axis_ang, m.part_motion), (Some(0.0), Some(0.0)));
}

/// The differentiable rasterizer on the browser's adapter: the forward pass against the CPU
/// reference and the backward pass against finite differences, as `tests/raster.rs` does natively.
#[wasm_bindgen_test]
async fn rasterizer_matches_reference_and_finite_differences_in_the_browser() {
    use artmesh::raster::check;
    let ctx = context().await;
    for (seed, gamma) in [(1u64, 1.0f32), (3, 2.0)] {
        let mut scene = check::scene(seed, 40, 28);
        scene.settings.gamma = gamma;
        let report = check::check_reference(&ctx, &scene, 2e-4).await.unwrap();
        console_log!("{report:?}");
        assert!(report.passed(), "{report:#?}");
    }
    let scene = check::scene(1, 40, 28);
    let groups = check::check_gradients(&ctx, &scene, 1, 6).await.unwrap();
    for g in &groups {
        console_log!("{g:?}");
    }
    let failed: Vec<_> = groups.iter().filter(|g| !g.passed()).collect();
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The image loss and Adam on the browser's adapter: central finite differences of every loss term
/// and the total, the loss against the CPU reference, and Adam against a CPU Adam (decay, remap, reset).
#[wasm_bindgen_test]
async fn loss_gradients_and_adam_match_cpu_in_the_browser() {
    use artmesh::loss::check as loss_check;
    use artmesh::optim::check as adam_check;
    let ctx = context().await;
    let values = loss_check::check_values(&ctx, 0, 23, 17, 3).await.unwrap();
    assert!(values.passed(), "loss vs CPU reference: {values:#?}");
    let fd = loss_check::check_gradients(&ctx, 11, 23, 17, 3, 2)
        .await
        .unwrap();
    assert!(
        fd.passed(),
        "finite differences disagree: {:#?}",
        fd.failures()
    );
    let adam = adam_check::check_adam(&ctx, 5).await.unwrap();
    assert!(adam.passed(), "Adam vs CPU: {adam:#?}");
}

/// The photometric driver's short fit (the same as `tests/fit_photometric.rs`) on the browser's
/// adapter: capture, rasterizer, loss and Adam together must raise the training PSNR.
#[wasm_bindgen_test]
async fn a_short_photometric_fit_learns_and_repeats_in_the_browser() {
    use artmesh::fit::photometric;
    use artmesh::fixtures::photometric::{short_fit, synthetic_scene};
    let ctx = context().await;
    let (spec, config) = short_fit();
    let problem = synthetic_scene(&ctx, &spec).await.unwrap();
    let result = photometric::fit(&ctx, &problem, &config, &mut |_| {})
        .await
        .unwrap();
    let first = result.curve.first().unwrap().loss.total;
    let last = result.curve.last().unwrap().loss.total;
    console_log!(
        "short fit in the browser: PSNR {:.2} -> {:.2} dB, loss {first:.4} -> {last:.4}",
        result.psnr_start,
        result.psnr_end
    );
    assert!(
        result.psnr_end > result.psnr_start + 3.0 && last < 0.7 * first,
        "PSNR {} -> {}, loss {first} -> {last}",
        result.psnr_start,
        result.psnr_end
    );
    // A fit repeated lands on the same vertices, bit for bit: SwiftShader's compare-exchange sums
    // in the backward pass come in a fixed order, so browser fits are reproducible. (A quarter of
    // the schedule, twice, to keep the suite short.)
    let quarter = photometric::PhotometricConfig {
        iterations: config.iterations / 4,
        ..config
    };
    let once = photometric::fit(&ctx, &problem, &quarter, &mut |_| {})
        .await
        .unwrap();
    let again = photometric::fit(&ctx, &problem, &quarter, &mut |_| {})
        .await
        .unwrap();
    let moved = once
        .field
        .positions
        .iter()
        .zip(&again.field.positions)
        .filter(|(p, q)| p != q)
        .count();
    assert_eq!(moved, 0, "a repeated fit moved {moved} vertices elsewhere");
}

#[wasm_bindgen_test]
async fn a_tiny_reconstruction_runs_in_the_browser() {
    use artmesh::eval::mesh_quality::reconstruction_failures;
    use artmesh::fit::reconstruct::RemeshMode;
    use artmesh::fixtures::object::tiny_reconstruction;
    let ctx = context().await;
    let (reconstruction, report) = tiny_reconstruction(&ctx, RemeshMode::PartAware)
        .await
        .unwrap();
    for s in &report.states {
        let parts: Vec<String> = s
            .parts
            .iter()
            .map(|p| {
                format!(
                    "part {}: {} faces, {} piece(s), cd_mm {:?}",
                    p.part,
                    p.faces,
                    p.components,
                    p.chamfer.map(|c| c.cd_mm)
                )
            })
            .collect();
        console_log!(
            "reconstruction {:?}: PSNR {:.2} / {:.2} / {:.2} dB, cross-part {}, {}",
            s.state,
            s.psnr_optimised,
            s.psnr_remeshed,
            s.psnr_recovered,
            s.cross_part_faces,
            parts.join("; ")
        );
    }
    assert_eq!(reconstruction.states.len(), 2);
    let failures = reconstruction_failures(&report, 25.0, 14.0);
    assert!(failures.is_empty(), "{failures:#?}");
}

#[wasm_bindgen_test]
async fn motion_kernels_match_the_cpu_in_the_browser() {
    let ctx = context().await;
    artmesh::articulation::kernels::check_against_cpu(&ctx)
        .await
        .unwrap();
}

#[wasm_bindgen_test]
async fn a_tiny_fit_finds_the_laptop_hinge_in_the_browser() {
    use artmesh::data::JointKind;
    use artmesh::eval::{EvalOptions, evaluate_fit};
    use artmesh::fixtures::object::tiny_fit;
    let ctx = context().await;
    let (dataset, fit) = tiny_fit(
        &ctx,
        artmesh::synth::Category::Laptop,
        1,
        1005,
        &|_| {},
        &|_| {},
        &artmesh::fit::object::FitConfig::preset(artmesh::fit::preset::Preset::Tiny),
    )
    .await
    .unwrap();
    let metrics = evaluate_fit(&fit, &dataset, "tiny", "Laptop", &EvalOptions::default())
        .unwrap()
        .unwrap();
    console_log!(
        "tiny fit: joint {:?}, Axis Ang {:?}, Axis Pos {:?}, Part Motion {:?}, {:.1} s articulation",
        fit.articulation.joints[0].joint,
        metrics.axis_ang,
        metrics.axis_pos,
        metrics.part_motion,
        fit.articulation.times.total_s
    );
    assert_eq!(fit.articulation.joints[0].kind, JointKind::Revolute);
    assert!(metrics.axis_ang.unwrap() < 10.0, "{metrics:?}");

    // The downloads are made in wasm too: the GLB reads back with the base and its hinged lid, the
    // zip holds the URDF, its meshes, joints.json and the GLB.
    let twin = artmesh::export::Twin::from_fit(&fit, "laptop").unwrap();
    let joints = serde_json::to_vec(&artmesh::export::joint_records(&fit)).unwrap();
    let files =
        artmesh::export::export_twin(&twin.object(), &twin.end_configuration(), &joints).unwrap();
    let doc = gltf::Gltf::from_slice(&files.glb).unwrap().document;
    let base = doc.nodes().find(|n| n.name() == Some("base")).unwrap();
    assert_eq!(
        base.children()
            .map(|c| c.name().unwrap_or_default().to_string())
            .collect::<Vec<_>>(),
        ["part_1"]
    );
    assert_eq!(doc.animations().count(), 1);
    let zip = zip::ZipArchive::new(std::io::Cursor::new(files.zip)).unwrap();
    let names: Vec<String> = zip.file_names().map(|n| n.unwrap().to_string()).collect();
    for want in [
        "laptop/twin.urdf",
        "laptop/joints.json",
        "laptop/twin.glb",
        "laptop/meshes/part_1_collision_0.stl",
    ] {
        assert!(names.iter().any(|n| n == want), "{want} not in {names:?}");
    }
}
