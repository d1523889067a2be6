//! Helpers shared by the native integration tests.

use std::path::Path;
use std::sync::OnceLock;

use artmesh::data::{FileSet, read_dir};

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
