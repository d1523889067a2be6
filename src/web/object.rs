//! The page's own object: a dropped `.zip` of a URDF with its meshes (told from a dataset's
//! archive by [`WebDataset::zip_holds_object`]) is imported in wasm and captured in both states on
//! the visitor's GPU as the demo's objects are, then offered like a dataset, ground truth
//! included, so its fit is scored. The work is the pipeline's (`pipeline::object`).

use std::rc::Rc;

use js_sys::Function;
use wasm_bindgen::prelude::*;

use super::app::{WebDataset, page_capture, view_progress};
use super::{budget, context, js_error};
use crate::data::{FileLimits, zip_holds_object};
use crate::pipeline::object::{capture_zipped, object_from_zip};

#[wasm_bindgen(js_class = Dataset)]
impl WebDataset {
    /// Whether the `.zip` `bytes` holds an object (a `.urdf` and no dataset transforms file)
    /// rather than a dataset; only the archive's entry names are read. False for bytes that are
    /// not a readable zip (`from_zip` then says why).
    pub fn zip_holds_object(bytes: &[u8]) -> bool {
        zip_holds_object(bytes)
    }

    /// The object in the `.zip` `bytes` (named `file_name`): its URDF and meshes imported, then
    /// both states captured as the `preset`'s demo does ([`WebDataset::demo`]; `budget` as
    /// there, `sensor` the sensor model), the end state from the joints' limits. `on_progress`
    /// hears `{done, total}` views.
    /// Throws naming the archive, the URDF and what is wrong: a missing mesh, XML that is not
    /// well-formed, no movable joint, an archive past the page's budgets.
    pub async fn from_object_zip(
        file_name: String,
        bytes: js_sys::Uint8Array,
        preset: String,
        seed: u32,
        on_progress: Function,
        budget: Option<String>,
        sensor: Option<String>,
    ) -> Result<WebDataset, JsError> {
        let config = budget::fit_config(&preset, budget.as_deref()).map_err(js_error)?;
        let spec = page_capture(&config, seed.into(), sensor.as_deref())?;
        // The archive's bytes are dropped once its files are out: only the object stays.
        let zipped = object_from_zip(&file_name, &bytes.to_vec(), &FileLimits::default())
            .map_err(js_error)?;
        for w in &zipped.object.warnings {
            web_sys::console::warn_1(&format!("{file_name}: {w}").into());
        }
        let ctx = context().await?;
        let mut on_view = view_progress(&on_progress);
        let input = capture_zipped(&ctx, &zipped, &spec, &mut on_view)
            .await
            .map_err(js_error)?;
        Ok(WebDataset(Rc::new(input)))
    }
}
