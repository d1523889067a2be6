//! The page's main job: a dataset (dropped, zipped, or the demo's procedural capture), its fit
//! with progress events, previews and pause/cancel, and the fit's files for download. Each step
//! is the crate's own pipeline, the same the CLI runs; this file only converts at the boundary.

use std::rc::Rc;

use js_sys::{Array, Function, Object, Reflect, Uint8Array, Uint8ClampedArray};
use wasm_bindgen::prelude::*;

use super::{budget, context, js_error};
use crate::data::{
    FileSet, JointKind, SensorModel, Split, State, read_zip, rebase_on_dataset_root,
};
use crate::export::{FitFolder, GLB_FILE, JOINTS_FILE, REPORT_FILE, ZIP_FILE};
use crate::fit::object::FitConfig;
use crate::fit::observer::{BakeOffView, Command, Marks, Observer, Preview, Progress};
use crate::fit::work::Capture;
use crate::gpu::now_seconds;
use crate::pipeline::object::archive_stem;
use crate::pipeline::preview::PREVIEW_FILE;
use crate::pipeline::{self, FitInput, PipelineError};
use crate::render::{RenderProgress, RenderSpec};
use crate::synth::Category;

/// Seconds between two previews the page is sent.
const PREVIEW_EVERY_S: f64 = 1.5;

/// A plain JS object from key/value pairs.
pub(super) fn js_object(pairs: &[(&str, JsValue)]) -> JsValue {
    let o = Object::new();
    for (k, v) in pairs {
        let _ = Reflect::set(&o, &JsValue::from_str(k), v);
    }
    o.into()
}

pub(super) fn number(v: impl Into<f64>) -> JsValue {
    JsValue::from_f64(v.into())
}

/// RGB8 or RGBA8 pixels as the RGBA `Uint8ClampedArray` an `ImageData` takes.
fn rgba_array(pixels: &[u8], channels: usize) -> Uint8ClampedArray {
    let rgba: Vec<u8> = if channels == 4 {
        pixels.to_vec()
    } else {
        pixels
            .chunks_exact(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect()
    };
    Uint8ClampedArray::from(rgba.as_slice())
}

/// "revolute" or "prismatic", as the page names joint types.
fn kind_name(kind: JointKind) -> &'static str {
    match kind {
        JointKind::Revolute => "revolute",
        JointKind::Prismatic => "prismatic",
    }
}

/// A picture's per-pixel parts as a `Uint8Array` (255: nothing there).
fn marks_parts(marks: &Marks) -> JsValue {
    Uint8Array::from(marks.parts.as_slice()).into()
}

/// A picture's axes as `[{part, kind, from: [x, y], to: [x, y]}]` in its pixels.
fn marks_axes(marks: &Marks) -> JsValue {
    let point = |p: [f32; 2]| -> JsValue { Array::of2(&number(p[0]), &number(p[1])).into() };
    marks
        .axes
        .iter()
        .map(|a| {
            js_object(&[
                ("part", number(a.part as u32)),
                ("kind", kind_name(a.kind).into()),
                ("from", point(a.from)),
                ("to", point(a.to)),
            ])
        })
        .collect::<Array>()
        .into()
}

/// Pairs dropped files' paths (relative, '/'-separated) with their contents.
fn file_set(paths: Vec<String>, contents: Vec<js_sys::Uint8Array>) -> Result<FileSet, JsError> {
    if paths.len() != contents.len() {
        return Err(JsError::new(&format!(
            "{} paths for {} file contents",
            paths.len(),
            contents.len()
        )));
    }
    Ok(paths
        .into_iter()
        .zip(contents.iter().map(|c| c.to_vec()))
        .collect())
}

/// The demo's choices as JSON: categories with their part counts, presets (`Preset::ALL`, each
/// with its budget, see `preset_budget`), defaults.
#[wasm_bindgen]
pub fn catalogue() -> String {
    let categories: Vec<_> = Category::ALL
        .iter()
        .map(|c| {
            let parts = c.movable_parts();
            serde_json::json!({
                "name": c.slug(),
                "label": c.name(),
                "parts": [parts.start(), parts.end()],
                "default_parts": 2.clamp(*parts.start(), *parts.end()),
            })
        })
        .collect();
    serde_json::json!({
        "categories": categories,
        "presets": budget::preset_entries(),
        "default": {"category": Category::StorageFurniture.slug(), "parts": 2, "preset": "fast", "seed": 0},
    })
    .to_string()
}

/// How the page captures a generated or dropped object for `config`: as `artmesh demo` does
/// ([`FitConfig::full_demo_capture`]), through the sensor model named `sensor` (absent: ideal).
pub(super) fn page_capture(
    config: &FitConfig,
    seed: u64,
    sensor: Option<&str>,
) -> Result<RenderSpec, JsError> {
    let mut spec = config.full_demo_capture(seed);
    if let Some(name) = sensor {
        spec.sensor = name.parse::<SensorModel>().map_err(js_error)?;
    }
    Ok(spec)
}

/// A capture's progress for `on_progress`: `{done, total}` views.
pub(super) fn view_progress(on_progress: &Function) -> impl FnMut(RenderProgress) + '_ {
    move |p| {
        let ev = js_object(&[
            ("done", number(p.done as u32)),
            ("total", number(p.total as u32)),
        ]);
        let _ = on_progress.call1(&JsValue::NULL, &ev);
    }
}

/// A validated dataset held in wasm memory, with the names its fit carries.
#[wasm_bindgen(js_name = Dataset)]
pub struct WebDataset(pub(super) Rc<FitInput>);

fn dataset_from(files: &FileSet, name: String) -> Result<WebDataset, JsError> {
    let input = pipeline::dataset_from_files(files, name, &Default::default())
        .map_err(|e| JsError::new(&e.to_string()))?;
    Ok(WebDataset(Rc::new(input)))
}

#[wasm_bindgen(js_class = Dataset)]
impl WebDataset {
    /// A dataset from dropped files (`paths[i]` relative to the dataset folder holds
    /// `contents[i]`), named `name`. Throws with every problem found, one per line.
    pub fn from_files(
        paths: Vec<String>,
        contents: Vec<js_sys::Uint8Array>,
        name: Option<String>,
    ) -> Result<WebDataset, JsError> {
        let files = rebase_on_dataset_root(file_set(paths, contents)?);
        dataset_from(&files, name.unwrap_or_else(|| "dataset".into()))
    }

    /// A dataset from a `.zip` of its folder. Throws naming the archive or the files at fault.
    pub fn from_zip(file_name: String, bytes: js_sys::Uint8Array) -> Result<WebDataset, JsError> {
        let files = read_zip(&file_name, &bytes.to_vec()).map_err(js_error)?;
        dataset_from(&files, archive_stem(&file_name).to_string())
    }

    /// Generates the procedural `category` object with `parts` movable parts from `seed` and
    /// captures both states as `artmesh demo` does for the `preset`: four times the working size
    /// of `budget` (the preset's budget overrides as JSON, optional: see `fit`, at most 512 px),
    /// its views per state and 4 test views, through the sensor model `sensor` (`"ideal"`,
    /// `"consumer"`, `"consumer-tracked"`; absent: ideal); `on_progress` hears `{done, total}`
    /// views.
    pub async fn demo(
        category: String,
        parts: u32,
        preset: String,
        seed: u32,
        on_progress: Function,
        budget: Option<String>,
        sensor: Option<String>,
    ) -> Result<WebDataset, JsError> {
        let category = Category::parse(&category).map_err(js_error)?;
        let config = budget::fit_config(&preset, budget.as_deref()).map_err(js_error)?;
        let object =
            pipeline::demo::demo_object(category, parts as usize, seed.into()).map_err(js_error)?;
        let spec = page_capture(&config, seed.into(), sensor.as_deref())?;
        let ctx = context().await?;
        let mut on_view = view_progress(&on_progress);
        let input = pipeline::demo::capture_demo(&ctx, &object, category, &spec, &mut on_view)
            .await
            .map_err(js_error)?;
        Ok(WebDataset(Rc::new(input)))
    }

    pub fn name(&self) -> String {
        self.0.id.clone()
    }

    /// What `artmesh info` prints about it.
    pub fn summary(&self) -> String {
        self.0.dataset.summary().to_string()
    }

    /// The first `per_state` training images of each state:
    /// `[{state, view, width, height, rgba}]`.
    pub fn thumbnails(&self, per_state: u32) -> Array {
        let out = Array::new();
        for state in State::ALL {
            let Some(views) = self.0.dataset.views(state, Split::Train) else {
                continue;
            };
            for (i, frame) in views.frames.iter().take(per_state as usize).enumerate() {
                let img = &frame.rgba;
                out.push(&js_object(&[
                    ("state", JsValue::from_str(state.name())),
                    ("view", number(i as u32)),
                    ("width", number(img.width)),
                    ("height", number(img.height)),
                    ("rgba", rgba_array(&img.pixels, 4).into()),
                ]));
            }
        }
        out
    }

    /// Its capture (training views' size and count, movable parts) as JSON, for the time
    /// estimates; `null` without training views.
    pub fn capture(&self) -> String {
        serde_json::to_string(&Capture::of(&self.0.dataset)).unwrap_or_default()
    }

    /// Another handle to the same dataset (`fit` consumes the handle it is given).
    pub fn share(&self) -> WebDataset {
        WebDataset(self.0.clone())
    }
}

/// The page as a fit's observer: events and previews go to `on_event`, `control()` is asked
/// for "run" / "pause" / "cancel" at every checkpoint.
struct PageObserver {
    config: FitConfig,
    on_event: Function,
    control: Function,
    t0: f64,
    last_preview: Option<f64>,
}

impl PageObserver {
    fn send(&self, event: &JsValue) {
        let _ = self.on_event.call1(&JsValue::NULL, event);
    }
}

impl Observer for PageObserver {
    fn progress(&mut self, e: &Progress) {
        let elapsed = now_seconds() - self.t0;
        let fraction = self.config.fraction_done(e);
        let state = if e.is_articulation() {
            "both"
        } else {
            e.state.name()
        };
        let opt = |v: Option<f64>| v.map_or(JsValue::NULL, JsValue::from_f64);
        self.send(&js_object(&[
            ("kind", "progress".into()),
            ("state", state.into()),
            ("phase", e.phase.name().into()),
            ("stage", e.phase.stage().into()),
            ("iteration", number(e.iteration)),
            ("iterations", number(e.iterations)),
            ("loss", opt(e.loss.map(f64::from))),
            ("psnr", opt(e.psnr)),
            ("vertices", number(e.vertices as u32)),
            ("faces", number(e.faces as u32)),
            ("elapsed_s", number(elapsed)),
            ("fraction", number(fraction)),
            ("open", number(e.open)),
            (
                "candidate",
                e.candidate.map_or(JsValue::NULL, |k| match k {
                    JointKind::Revolute => "hinge".into(),
                    JointKind::Prismatic => "slide".into(),
                }),
            ),
        ]));
    }

    fn wants_preview(&mut self) -> bool {
        let now = now_seconds();
        let due = self.last_preview.is_none_or(|t| now - t >= PREVIEW_EVERY_S);
        if due {
            self.last_preview = Some(now);
        }
        due
    }

    fn preview(&mut self, p: Preview) {
        let moved_by = p.moved_by.map_or(JsValue::NULL, JsValue::from);
        self.send(&js_object(&[
            ("kind", "preview".into()),
            ("state", p.state.name().into()),
            ("view", number(p.view as u32)),
            ("iteration", number(p.iteration)),
            ("phase", p.phase.name().into()),
            ("stage", p.phase.stage().into()),
            ("moved_by", moved_by),
            ("width", number(p.width)),
            ("height", number(p.height)),
            ("render", rgba_array(&p.render, 3).into()),
            ("target", rgba_array(&p.target, 3).into()),
            ("parts", marks_parts(&p.marks)),
            ("axes", marks_axes(&p.marks)),
        ]));
    }

    fn wants_articulation_views(&self) -> bool {
        true
    }

    fn bake_off(&mut self, b: BakeOffView) {
        let opt = |v: Option<f64>| v.map_or(JsValue::NULL, JsValue::from_f64);
        self.send(&js_object(&[
            ("kind", "bake-off".into()),
            ("part", number(b.part as u32)),
            ("view", number(b.view as u32)),
            ("width", number(b.width)),
            ("height", number(b.height)),
            ("revolute", rgba_array(&b.revolute, 3).into()),
            ("prismatic", rgba_array(&b.prismatic, 3).into()),
            ("target", rgba_array(&b.target, 3).into()),
            ("revolute_parts", marks_parts(&b.revolute_marks)),
            ("revolute_axes", marks_axes(&b.revolute_marks)),
            ("prismatic_parts", marks_parts(&b.prismatic_marks)),
            ("prismatic_axes", marks_axes(&b.prismatic_marks)),
            ("revolute_loss", opt(b.revolute_loss)),
            ("prismatic_loss", opt(b.prismatic_loss)),
            (
                "revolute_residual_mm",
                opt(b.revolute_residual.map(|r| r * 1e3)),
            ),
            (
                "prismatic_residual_mm",
                opt(b.prismatic_residual.map(|r| r * 1e3)),
            ),
            ("winner", kind_name(b.kind).into()),
            ("decided_by", b.decided_by.into()),
        ]));
    }

    fn command(&mut self) -> Command {
        let answer = self.control.call0(&JsValue::NULL).ok();
        match answer.and_then(|v| v.as_string()).as_deref() {
            Some("pause") => Command::Pause,
            Some("cancel") => Command::Cancel,
            _ => Command::Run,
        }
    }
}

/// Fits `dataset` with `preset` on the page's GPU (reconstruction of both states, then
/// articulation), telling `on_event` about progress and previews and asking `control` whether
/// to go on. `budget` (optional) overrides some of the preset's budget, as JSON with any of
/// `max_size`, `max_views`, `reconstruction_iterations`, `recovery_iterations`, `max_faces`,
/// `articulation_iterations` (what the CLI's flags of those names set). Rejects with a message
/// starting "cancelled" when cancelled.
#[wasm_bindgen]
pub async fn fit(
    dataset: WebDataset,
    preset: String,
    on_event: Function,
    control: Function,
    budget: Option<String>,
) -> Result<FitResult, JsError> {
    let config = budget::fit_config(&preset, budget.as_deref()).map_err(js_error)?;
    let ctx = context().await?;
    let mut observer = PageObserver {
        config,
        on_event,
        control,
        t0: now_seconds(),
        last_preview: None,
    };
    let run = pipeline::fit_and_export(&ctx, &dataset.0, &config, &mut observer)
        .await
        .map_err(|e| match e {
            // The page reads a message starting "cancelled" as the cancel it asked for.
            PipelineError::Fit { source, .. } => js_error(source),
            other => js_error(other),
        })?;
    Ok(FitResult(Rc::new(run.folder)))
}

/// A finished fit: its report, joints, twin and downloadable files.
#[wasm_bindgen]
pub struct FitResult(pub(super) Rc<FitFolder>);

/// What the page offers for download.
const DOWNLOADS: [&str; 5] = [GLB_FILE, ZIP_FILE, JOINTS_FILE, REPORT_FILE, PREVIEW_FILE];

#[wasm_bindgen]
impl FitResult {
    /// `report.json`.
    pub fn report(&self) -> Result<String, JsError> {
        serde_json::to_string(&self.0.report).map_err(js_error)
    }

    /// `joints.json`.
    pub fn joints(&self) -> Result<String, JsError> {
        serde_json::to_string(&self.0.joints).map_err(js_error)
    }

    /// The downloadable files' names.
    pub fn file_names(&self) -> Vec<String> {
        DOWNLOADS.iter().map(|s| s.to_string()).collect()
    }

    /// One downloadable file's bytes; throws for a name [`FitResult::file_names`] does not list.
    pub fn file(&self, name: String) -> Result<js_sys::Uint8Array, JsError> {
        match self.0.files.get(&name) {
            Some(bytes) if DOWNLOADS.contains(&name.as_str()) => {
                Ok(js_sys::Uint8Array::from(bytes.as_slice()))
            }
            _ => Err(JsError::new(&format!(
                "no download named '{name}': expected one of {}",
                DOWNLOADS.join(", ")
            ))),
        }
    }

    /// Another handle to the same result (the viewer consumes the handle it is given).
    pub fn share(&self) -> FitResult {
        FitResult(self.0.clone())
    }
}
