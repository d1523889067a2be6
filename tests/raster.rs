//! The differentiable rasterizer on the native adapter (lavapipe in CI): forward pass against the
//! CPU reference renderer, backward pass against central finite differences for every parameter
//! group, and buffer limits that give clear errors.
#![cfg(not(target_arch = "wasm32"))]

use artmesh::gpu::GpuContext;
use artmesh::raster::check;

fn context() -> GpuContext {
    match pollster::block_on(GpuContext::new()) {
        Ok(ctx) => ctx,
        Err(e) => panic!("GPU tests need an adapter: {e}"),
    }
}

#[test]
fn forward_matches_cpu_reference() {
    let ctx = context();
    for (seed, gamma) in [(1u64, 1.0f32), (2, 0.3), (3, 2.0)] {
        let mut scene = check::scene(seed, 40, 28);
        scene.settings.gamma = gamma;
        let report = pollster::block_on(check::check_reference(&ctx, &scene, 2e-4)).unwrap();
        println!("{report:?}");
        assert!(report.passed(), "{report:#?}");
    }
}

#[test]
fn gradients_match_finite_differences() {
    let ctx = context();
    for (seed, gamma) in [(1u64, 1.0f32), (4, 2.0)] {
        let mut scene = check::scene(seed, 40, 28);
        scene.settings.gamma = gamma;
        let groups = pollster::block_on(check::check_gradients(&ctx, &scene, seed, 12)).unwrap();
        for g in &groups {
            println!("gamma {gamma}: {g:?}");
        }
        let failed: Vec<_> = groups.iter().filter(|g| !g.passed()).collect();
        assert!(failed.is_empty(), "gamma {gamma}: {failed:#?}");
    }
}

#[test]
#[ignore]
fn timing_probe() {
    use artmesh::raster::{GpuField, RasterState, Rasterizer};
    let ctx = context();
    for (faces, size) in [(20_000usize, 128u32), (100_000, 256)] {
        let scene = check::sphere_scene(faces, size, size, 1);
        let raster = Rasterizer::new(&ctx);
        let field = GpuField::upload(&ctx, &scene.field).unwrap();
        let mut state = RasterState::new(&ctx, size, size, 4).unwrap();
        state.set_profiling(true);
        for it in 0..3 {
            let stats = pollster::block_on(raster.forward(
                &ctx,
                &field,
                &mut state,
                &scene.camera,
                &scene.settings,
            ))
            .unwrap();
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            raster.encode_backward(&ctx, &mut enc, &field, &mut state);
            ctx.queue.submit([enc.finish()]);
            ctx.poll_wait().unwrap();
            let times: Vec<String> = state
                .clock
                .take()
                .iter()
                .map(|(s, t)| format!("{s} {t:.1}"))
                .collect();
            println!(
                "faces {} size {size} it {it} pairs {}: {}",
                scene.field.faces.len(),
                stats.pairs,
                times.join(", ")
            );
        }
    }
}
