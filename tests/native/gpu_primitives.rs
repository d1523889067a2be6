//! The GPU primitives on the native adapter (lavapipe in CI): prefix sum and radix sort against
//! CPU results from 1 to 4M elements, the 2-D dispatch tiling path, and limit errors.

use artmesh::gpu::{GpuError, PrefixSum, RadixSort, selftest};

use crate::common::context;

fn assert_all_pass(checks: &[selftest::PrimitiveCheck]) {
    let failed: Vec<_> = checks.iter().filter(|c| !c.passed()).collect();
    assert!(failed.is_empty(), "mismatches against the CPU: {failed:#?}");
}

const SIZES: &[u32] = &[
    1, 2, 3, 255, 256, 257, 1000, 1023, 1024, 1025, 4097, 65_535, 65_537, 262_145, 1_000_003,
];

#[test]
fn prefix_sum_matches_cpu() {
    let ctx = context();
    let mut checks = Vec::new();
    for (i, &n) in SIZES.iter().chain(&[4_194_304, 4_000_037]).enumerate() {
        checks.push(pollster::block_on(selftest::check_prefix_sum(&ctx, n, i as u64)).unwrap());
    }
    assert_all_pass(&checks);
}

#[test]
fn radix_sort_matches_cpu_stable_sort() {
    let ctx = context();
    let mut checks = Vec::new();
    for (i, &n) in SIZES.iter().enumerate() {
        // 32 bits = 4 passes (even), 20 bits = 3 passes (odd: result copied back), 8 bits = 1 pass.
        for bits in [32, 20, 8] {
            checks.push(
                pollster::block_on(selftest::check_radix_sort(&ctx, n, bits, i as u64)).unwrap(),
            );
        }
    }
    assert_all_pass(&checks);
}

#[test]
fn radix_sort_4m_keys() {
    let ctx = context();
    let checks = [
        pollster::block_on(selftest::check_radix_sort(&ctx, 4_194_304, 32, 7)).unwrap(),
        pollster::block_on(selftest::check_radix_sort(&ctx, 4_000_037, 24, 8)).unwrap(),
    ];
    assert_all_pass(&checks);
}

#[test]
fn dispatches_tiled_in_2d_give_the_same_results() {
    let mut ctx = context();
    // With at most 7 workgroups per dimension, 98 blocks run on a 7 x 14 grid and 977 blocks on
    // 7 x 140 (which overshoots: the kernels must skip the extra workgroups).
    ctx.set_dispatch_dim_limit(7);
    assert_eq!(ctx.workgroup_grid(98), (7, 14));
    assert_eq!(ctx.workgroup_grid(977), (7, 140));
    let mut checks = Vec::new();
    for (i, &n) in [100_000u32, 1_000_003, 7 * 1024 + 1].iter().enumerate() {
        checks.push(pollster::block_on(selftest::check_prefix_sum(&ctx, n, i as u64)).unwrap());
        checks.push(pollster::block_on(selftest::check_radix_sort(&ctx, n, 32, i as u64)).unwrap());
    }
    assert_all_pass(&checks);
}

#[test]
fn limits_give_clear_errors() {
    let ctx = context();
    let err = RadixSort::new(&ctx, u32::MAX)
        .err()
        .expect("a 16 GiB key buffer must be refused");
    assert!(matches!(err, GpuError::BindingTooLarge { .. }), "{err}");
    assert!(err.to_string().contains("radix_sort.keys"), "{err}");

    let sorter = RadixSort::new(&ctx, 100).unwrap();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let err = sorter.encode(&ctx, &mut encoder, 101, 32).unwrap_err();
    assert!(
        matches!(
            err,
            GpuError::TooManyElements {
                count: 101,
                max: 100,
                ..
            }
        ),
        "{err}"
    );

    let data = ctx.storage_buffer("data", &[1u32; 10]).unwrap();
    let scan = PrefixSum::new(&ctx, &data, 10).unwrap();
    assert!(scan.encode(&ctx, &mut encoder, 11).is_err());
    ctx.check().unwrap();
}
