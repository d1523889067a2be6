//! The GPU image loss, Adam and the FMA probe on the native adapter (lavapipe in CI): loss terms and
//! gradient against the f64 CPU reference, central finite differences of every term, Adam against a
//! CPU Adam (decaying lr, remap, reset), target views split over several buffers, input errors.

use artmesh::data::{DepthMap, PartMap, RgbaImage};
use artmesh::gpu::{GpuError, fma_peak};
use artmesh::loss::{ImageLoss, LossWeights, TargetImages, TargetView, check, render_channels};
use artmesh::optim::{Adam, AdamConfig, ExponentialDecay, check as adam_check};

use crate::common::context;

/// 23×17: no dimension or pixel count is a multiple of the 256-invocation workgroup.
const W: u32 = 23;
const H: u32 = 17;
const P: u32 = 3;

#[test]
fn loss_terms_and_gradient_match_cpu_reference() {
    let ctx = context();
    for (seed, (w, h, p)) in [(W, H, P), (40, 9, 1), (5, 70, 16)].into_iter().enumerate() {
        let c = pollster::block_on(check::check_values(&ctx, seed as u64, w, h, p)).unwrap();
        println!(
            "{w}×{h} P={p}: worst term error {:.2e}, worst gradient error {:.2e} (relative to the channel's max)",
            c.worst_term_error(),
            c.worst_grad_error()
        );
        assert!(
            c.passed(),
            "GPU loss differs from the CPU reference: {c:#?}"
        );
        // The scene really exercises every term.
        // (With one part channel the cross-entropy is identically 0.)
        assert!(
            c.terms
                .iter()
                .all(|t| t.cpu > 1e-3 || (p == 1 && t.term == "part")),
            "{c:#?}"
        );
        let (npix, (depth, labels)) = ((w * h) as usize, (c.depth_pixels.1, c.label_pixels.1));
        assert!(depth > 0 && depth < npix && labels > 0 && labels < npix);
    }
}

#[test]
fn loss_gradient_matches_central_finite_differences() {
    let ctx = context();
    let c = pollster::block_on(check::check_gradients(&ctx, 11, W, H, P, 4)).unwrap();
    println!(
        "{} samples ({} nonzero), worst relative error {:.2e}, worst |fd - g| {:.2e}",
        c.samples.len(),
        c.nonzero_samples(),
        c.worst_relative_error(),
        c.samples
            .iter()
            .map(|s| (s.fd - s.gpu).abs())
            .fold(0.0, f64::max)
    );
    let failures: Vec<String> = c
        .failures()
        .iter()
        .map(|s| {
            format!(
                "{} c{} p{}: fd {:.4e} gpu {:.4e}",
                s.term, s.channel, s.pixel, s.fd, s.gpu
            )
        })
        .collect();
    assert!(
        c.passed(),
        "finite differences disagree:\n{}",
        failures.join("\n")
    );
    // Every term has nonzero gradients among the samples, in every channel it touches.
    for term in check::TERM_NAMES {
        let nonzero: Vec<u32> = c
            .samples
            .iter()
            .filter(|s| s.term == term && s.gpu.abs() > 1e-6)
            .map(|s| s.channel)
            .collect();
        assert!(
            !nonzero.is_empty(),
            "no nonzero gradient sampled for {term}"
        );
    }
    let total_channels: std::collections::BTreeSet<u32> = c
        .samples
        .iter()
        .filter(|s| s.term == "total" && s.gpu != 0.0)
        .map(|s| s.channel)
        .collect();
    assert_eq!(
        total_channels.len() as u32,
        render_channels(P),
        "{total_channels:?}"
    );
}

#[test]
fn adam_matches_cpu_with_decay_remap_and_reset() {
    let ctx = context();
    let c = pollster::block_on(adam_check::check_adam(&ctx, 5)).unwrap();
    println!("Adam: worst deviation {:.2e}", c.worst_error());
    assert!(c.passed(), "{c:#?}");
}

#[test]
fn exponential_decay_is_log_linear_then_held() {
    let s = ExponentialDecay {
        start: 2e-4,
        end: 2e-6,
        steps: 100,
    };
    assert!((s.lr(0) - 2e-4).abs() < 1e-10);
    assert!((s.lr(50) - 2e-5).abs() < 1e-10, "{}", s.lr(50));
    assert!((s.lr(100) - 2e-6).abs() < 1e-12);
    assert_eq!(s.lr(1000), s.lr(100));
    assert_eq!(
        ExponentialDecay {
            start: 1.0,
            end: 0.0,
            steps: 4
        }
        .lr(1),
        0.75
    );
}

#[test]
fn adam_rejects_bad_remaps() {
    let ctx = context();
    let adam = Adam::new(&ctx).unwrap();
    let p = ctx.storage_buffer_zeroed("p", 64).unwrap();
    let g = ctx.storage_buffer_zeroed("g", 64).unwrap();
    let mut group = adam
        .group(&ctx, "test", &p, &g, 16, AdamConfig::with_lr(1e-3))
        .unwrap();
    // 4 elements of stride 4: old element 4 does not exist.
    let err = adam
        .remap(&ctx, &mut group, &p, &g, &[0, 4], 4)
        .unwrap_err();
    assert!(err.to_string().contains("old element 4"), "{err}");
    let err = adam.remap(&ctx, &mut group, &p, &g, &[0], 3).unwrap_err();
    assert!(err.to_string().contains("stride 3"), "{err}");
    // New buffers too small for 5 elements of 4 floats.
    let err = adam
        .remap(&ctx, &mut group, &p, &g, &[0, 1, 2, 3, 0], 4)
        .unwrap_err();
    assert!(err.to_string().contains("80"), "{err}");
    assert!(
        adam.group(&ctx, "big", &p, &g, 17, AdamConfig::with_lr(1e-3))
            .is_err()
    );
    ctx.check().unwrap();
}

fn solid_view(w: u32, h: u32, seed: u8) -> (RgbaImage, DepthMap, PartMap) {
    let n = (w * h) as usize;
    (
        RgbaImage {
            width: w,
            height: h,
            pixels: (0..n * 4).map(|i| (i as u8).wrapping_mul(seed)).collect(),
        },
        DepthMap {
            width: w,
            height: h,
            millimetres: (0..n).map(|i| (i % 7) as u16 * 300).collect(),
        },
        PartMap {
            width: w,
            height: h,
            ids: (0..n).map(|i| (i % 4) as i16 - 1).collect(),
        },
    )
}

/// With a binding limit of 3 views, 8 views land in 3 buffers, and the loss of each view is the
/// same as with all views in one buffer.
#[test]
fn target_views_split_over_buffers_past_the_binding_limit() {
    let ctx = context();
    let images: Vec<_> = (0..8).map(|i| solid_view(W, H, 3 + 2 * i as u8)).collect();
    let views: Vec<TargetView> = images
        .iter()
        .map(|(rgba, depth, parts)| TargetView {
            rgba,
            depth: Some(depth),
            parts: Some(parts),
        })
        .collect();
    let view_bytes = u64::from(W * H) * 8;
    let split = TargetImages::upload_with_limit(&ctx, W, H, &views, 3 * view_bytes + 5).unwrap();
    let whole = TargetImages::upload(&ctx, W, H, &views).unwrap();
    assert_eq!(
        (split.buffer_count(), whole.buffer_count(), split.len()),
        (3, 1, 8)
    );

    let loss = ImageLoss::new(&ctx, W, H, P).unwrap();
    let scene = check::Scene::random(1, W, H, P);
    let render = ctx.storage_buffer("render", &scene.render).unwrap();
    let grad = ctx
        .storage_buffer_zeroed("grad", loss.render_len() as u64 * 4)
        .unwrap();
    let eval = |targets: &TargetImages, view: usize| {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        loss.encode(
            &ctx,
            &mut encoder,
            &render,
            targets,
            view,
            &LossWeights::default(),
            scene.background,
            &grad,
        )
        .unwrap();
        ctx.queue.submit([encoder.finish()]);
        pollster::block_on(loss.read_terms(&ctx)).unwrap()
    };
    let mut totals = Vec::new();
    for (view, target) in views.iter().enumerate() {
        let (a, b) = (eval(&split, view), eval(&whole, view));
        assert_eq!(a, b, "view {view}");
        let expected = artmesh::loss::reference::image_loss(
            W,
            H,
            P,
            &scene.render,
            target,
            &LossWeights::default(),
            scene.background,
        )
        .unwrap();
        assert!(
            (f64::from(a.total) - expected.total).abs() < 1e-4 * expected.total,
            "view {view}"
        );
        totals.push(a.total);
    }
    // Different views really were read.
    totals.dedup();
    assert_eq!(totals.len(), 8, "{totals:?}");

    // One view larger than the limit: a clear error, no device crash.
    let err = TargetImages::upload_with_limit(&ctx, W, H, &views, view_bytes - 1)
        .err()
        .unwrap();
    assert!(matches!(err, GpuError::BindingTooLarge { .. }), "{err}");
    assert!(err.to_string().contains("target view 0"), "{err}");
    let err = loss
        .encode(
            &ctx,
            &mut ctx.device.create_command_encoder(&Default::default()),
            &render,
            &split,
            8,
            &LossWeights::default(),
            scene.background,
            &grad,
        )
        .unwrap_err();
    assert!(err.to_string().contains("view 8"), "{err}");
    ctx.check().unwrap();
}

#[test]
fn loss_input_errors_name_the_problem() {
    let ctx = context();
    let (rgba, depth, parts) = solid_view(W, H, 3);
    let (small, _, _) = solid_view(W, H - 1, 3);
    let views = [
        TargetView {
            rgba: &rgba,
            depth: Some(&depth),
            parts: Some(&parts),
        },
        TargetView {
            rgba: &small,
            depth: None,
            parts: None,
        },
    ];
    let err = TargetImages::upload(&ctx, W, H, &views).err().unwrap();
    assert!(
        err.to_string().contains("target view 1") && err.to_string().contains("23×16"),
        "{err}"
    );

    assert!(ImageLoss::new(&ctx, W, H, 0).is_err());
    assert!(ImageLoss::new(&ctx, W, H, 17).is_err());
    assert!(ImageLoss::new(&ctx, 0, H, 3).is_err());
    // Labels 1..=3 need 3 part channels.
    let targets = TargetImages::upload(&ctx, W, H, &views[..1]).unwrap();
    let loss = ImageLoss::new(&ctx, W, H, 2).unwrap();
    let render = ctx
        .storage_buffer_zeroed("render", loss.render_len() as u64 * 4)
        .unwrap();
    let grad = ctx
        .storage_buffer_zeroed("grad", loss.render_len() as u64 * 4)
        .unwrap();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let w = LossWeights::default();
    let err = loss
        .encode(
            &ctx,
            &mut encoder,
            &render,
            &targets,
            0,
            &w,
            [0.0; 3],
            &grad,
        )
        .unwrap_err();
    assert!(err.to_string().contains("part 2"), "{err}");
    let loss = ImageLoss::new(&ctx, W, H, 4).unwrap();
    let err = loss
        .encode(
            &ctx,
            &mut encoder,
            &render,
            &targets,
            0,
            &w,
            [0.0; 3],
            &grad,
        )
        .unwrap_err();
    assert!(err.to_string().contains("render buffer"), "{err}");
    let big = ctx
        .storage_buffer_zeroed("big", loss.render_len() as u64 * 4)
        .unwrap();
    let err = loss
        .encode(&ctx, &mut encoder, &big, &targets, 0, &w, [0.0; 3], &big)
        .unwrap_err();
    assert!(err.to_string().contains("different buffers"), "{err}");
    let err = loss
        .encode(
            &ctx,
            &mut encoder,
            &big,
            &targets,
            0,
            &w,
            [f32::NAN; 3],
            &render,
        )
        .unwrap_err();
    assert!(err.to_string().contains("gradient buffer"), "{err}");
    ctx.check().unwrap();
}

#[test]
fn fma_peak_is_positive_and_finite() {
    let ctx = context();
    let peak = pollster::block_on(fma_peak(&ctx)).unwrap();
    println!("fma_peak on {}: {peak:?}", ctx.adapter.name);
    assert!(peak.gflops.is_finite() && peak.gflops > 0.0, "{peak:?}");
    assert!(peak.seconds > 0.0 && peak.fmas > 0);
}

/// Loss encode + submit + wait at 128² and 800² (P = 3); prints milliseconds. `--ignored` to run.
#[test]
#[ignore]
fn loss_timing() {
    let ctx = context();
    for size in [128u32, 800] {
        let scene = check::Scene::random(3, size, size, P);
        let loss = ImageLoss::new(&ctx, size, size, P).unwrap();
        let targets = TargetImages::upload(&ctx, size, size, &[scene.target()]).unwrap();
        let render = ctx.storage_buffer("render", &scene.render).unwrap();
        let grad = ctx
            .storage_buffer_zeroed("grad", loss.render_len() as u64 * 4)
            .unwrap();
        let mut times = Vec::new();
        for _ in 0..6 {
            let start = std::time::Instant::now();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            loss.encode(
                &ctx,
                &mut encoder,
                &render,
                &targets,
                0,
                &LossWeights::default(),
                scene.background,
                &grad,
            )
            .unwrap();
            ctx.queue.submit([encoder.finish()]);
            ctx.poll_wait().unwrap();
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "loss {size}²: median {:.1} ms (min {:.1})",
            times[3], times[0]
        );
    }
}
