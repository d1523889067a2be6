//! The articulation phase on lavapipe: the motion kernels against the CPU, and the joint-type
//! bake-off and whole phase on small procedural objects.

mod common;

#[test]
fn motion_kernels_match_the_cpu() {
    let ctx = common::context();
    pollster::block_on(artmesh::articulation::kernels::check_against_cpu(&ctx)).unwrap();
}
