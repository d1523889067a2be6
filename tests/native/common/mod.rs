//! Helpers shared by the native integration tests (each test file uses some of them).
#![allow(dead_code)]

use std::path::Path;
use std::sync::OnceLock;

use artmesh::data::{FileSet, read_dir};
use artmesh::gpu::GpuContext;

/// The real objects in `../shared/objects` (habitat-sim furniture, IsaacGym's Sektion cabinet), read once.
pub fn shared_objects() -> &'static FileSet {
    static FILES: OnceLock<FileSet> = OnceLock::new();
    FILES.get_or_init(|| {
        read_dir(Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/objects"
        )))
        .expect("../shared/objects is readable")
    })
}

/// A device on the native adapter (lavapipe in CI); a clear panic when there is none.
pub fn context() -> GpuContext {
    match pollster::block_on(GpuContext::new()) {
        Ok(ctx) => ctx,
        Err(e) => panic!("GPU tests need an adapter: {e}"),
    }
}
