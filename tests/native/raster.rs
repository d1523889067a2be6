//! The differentiable rasterizer on the native adapter (lavapipe in CI): forward pass against the
//! CPU reference renderer, backward pass against central finite differences for every parameter
//! group, and buffer limits that give clear errors.

use artmesh::raster::check;

use crate::common::context;

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
fn buffer_limits_give_clear_errors() {
    use artmesh::gpu::GpuError;
    use artmesh::raster::{GpuField, MeshField, RasterState, Rasterizer};
    let ctx = context();
    // A 20000² render needs (5 + 1 + 1) planes of 1.6 GB: more than one storage binding.
    let err = RasterState::new(&ctx, 20_000, 20_000, 1)
        .err()
        .expect("a 20000² render must be refused");
    assert!(
        matches!(&err, GpuError::BindingTooLarge { what, .. } if what.contains("render")),
        "{err}"
    );
    // A million faces need 144 MB of face records, over lavapipe's 128 MiB binding limit.
    let limit = ctx.limits.max_storage_buffer_binding_size;
    let faces = (limit / 144 + 1000) as usize;
    if faces <= 4_000_000 {
        let mut scene = check::scene(1, 32, 32);
        let f = scene.field.faces[0];
        scene.field.faces = vec![f; faces];
        let field = GpuField::upload(&ctx, &scene.field).unwrap();
        let mut state = RasterState::new(&ctx, 32, 32, scene.field.num_parts as u32).unwrap();
        let raster = Rasterizer::new(&ctx);
        let err = pollster::block_on(raster.forward(
            &ctx,
            &field,
            &mut state,
            &scene.camera,
            &scene.settings,
        ))
        .expect_err("too many faces for one binding must be refused");
        assert!(
            matches!(&err, GpuError::BindingTooLarge { what, .. } if what.contains("face records")),
            "{err}"
        );
        ctx.check().expect("no device error after a refused render");
    }
    // A field without faces renders the background.
    let mut empty = check::scene(2, 24, 16);
    empty.field.faces.clear();
    let field = GpuField::upload(&ctx, &empty.field).unwrap();
    let mut state = RasterState::new(&ctx, 24, 16, empty.field.num_parts as u32).unwrap();
    let stats = pollster::block_on(Rasterizer::new(&ctx).forward(
        &ctx,
        &field,
        &mut state,
        &empty.camera,
        &empty.settings,
    ))
    .unwrap();
    let img = pollster::block_on(state.read_render(&ctx)).unwrap();
    assert_eq!(stats.pairs, 0);
    assert!(img.plane(4).iter().all(|&a| a == 0.0));
    assert!(
        (img.rgb(5, 5) - empty.settings.background)
            .abs()
            .max_element()
            < 1e-6
    );
    // Inconsistent inputs name the problem.
    let mut bad = MeshField::new(vec![glam::Vec3::ZERO; 3], vec![[0, 1, 5]], 2, 0.0);
    let err = GpuField::upload(&ctx, &bad).err().unwrap();
    assert!(err.to_string().contains("face 0"), "{err}");
    bad.faces = vec![[0, 1, 2]];
    bad.num_parts = 17;
    assert!(
        GpuField::upload(&ctx, &bad)
            .err()
            .unwrap()
            .to_string()
            .contains("num_parts")
    );
    let scene = check::scene(1, 40, 28);
    let field = GpuField::upload(&ctx, &scene.field).unwrap();
    let mut state = RasterState::new(&ctx, 20, 20, 3).unwrap();
    let err = pollster::block_on(Rasterizer::new(&ctx).forward(
        &ctx,
        &field,
        &mut state,
        &scene.camera,
        &scene.settings,
    ))
    .err()
    .unwrap();
    assert!(err.to_string().contains("40x28"), "{err}");
}
