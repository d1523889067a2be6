//! Where the suite benchmarks take their objects from: a suite folder as a user hands it over, or
//! the suite plan captured in memory for CI-sized runs.

use std::path::PathBuf;

use artmesh::data::{Dataset, SensorModel, read_dataset};
use artmesh::gpu::GpuContext;
use artmesh::render::{RenderSpec, capture_dataset};
use artmesh::synth::{SuiteEntry, SuiteKind, generate};
use serde::Serialize;

use crate::suite::{CaptureSettings, read_suite_listing};

/// Where `artmesh bench fit` takes its objects from.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SuiteSource {
    /// A suite folder written by `artmesh suite` (suite.json and one dataset folder per id):
    /// the objects as a user would hand them over.
    Dir(PathBuf),
    /// The plan captured in memory at `size`² with `views` training and 2 test views per state:
    /// CI-sized runs only.
    Capture {
        kind: SuiteKind,
        size: u32,
        views: usize,
    },
}

/// One object listed by a [`SuiteSource`].
pub struct SourceObject {
    pub id: String,
    pub category: String,
    entry: Option<SuiteEntry>,
}

impl SuiteSource {
    /// The objects, in suite order, and how they were captured.
    pub fn objects(&self) -> Result<(Vec<SourceObject>, CaptureSettings), String> {
        match self {
            SuiteSource::Capture { kind, size, views } => Ok((
                kind.plan()
                    .into_iter()
                    .map(|e| SourceObject {
                        id: e.id(),
                        category: e.category.to_string(),
                        entry: Some(e),
                    })
                    .collect(),
                CaptureSettings {
                    size: *size,
                    train_views: *views,
                    sensor: SensorModel::Ideal,
                },
            )),
            SuiteSource::Dir(dir) => {
                let listing = read_suite_listing(dir)?;
                let objects = listing
                    .objects
                    .into_iter()
                    .map(|(id, category)| {
                        // Ids name folders inside the suite: nothing that could leave it.
                        let plain = !id.is_empty()
                            && id
                                .chars()
                                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
                        if !plain {
                            return Err(format!(
                                "{}: object id {id:?} is not a plain folder name",
                                dir.join("suite.json").display()
                            ));
                        }
                        Ok(SourceObject {
                            id,
                            category,
                            entry: None,
                        })
                    })
                    .collect::<Result<_, _>>()?;
                let capture = listing.capture.ok_or_else(|| {
                    format!(
                        "{}: no \"capture\" settings (written by `artmesh suite`)",
                        dir.join("suite.json").display()
                    )
                })?;
                Ok((objects, capture))
            }
        }
    }

    /// One object's dataset.
    pub fn load(&self, ctx: &GpuContext, object: &SourceObject) -> Result<Dataset, String> {
        match (self, &object.entry) {
            (SuiteSource::Capture { size, views, .. }, Some(entry)) => {
                capture_entry(ctx, entry, *size, *views, 2)
            }
            (SuiteSource::Dir(dir), _) => {
                read_dataset(&dir.join(&object.id)).map_err(|e| e.to_string())
            }
            _ => Err(format!("{}: no capture plan", object.id)),
        }
    }
}

/// A suite entry's object captured in memory at `size`² with `views` training views per state.
pub fn capture_entry(
    ctx: &GpuContext,
    entry: &SuiteEntry,
    size: u32,
    views: usize,
    test_views: usize,
) -> Result<Dataset, String> {
    let id = entry.id();
    let object = generate(&entry.params()).map_err(|e| format!("{id}: {e}"))?;
    let spec = RenderSpec {
        width: size,
        height: size,
        train_views: views,
        test_views,
        seed: entry.seed,
        ..RenderSpec::default()
    };
    pollster::block_on(capture_dataset(ctx, &object, &spec, &mut |_| {}))
        .map_err(|e| format!("{id}: {e}"))
}
