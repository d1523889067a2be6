//! The result viewer: the fitted twin ([`TwinScene`]) rendered by the ground-truth renderer on
//! the page's WebGPU device and shown on the page's canvas, redrawn when the page changes a
//! joint, the state (or the play button's phase), the camera or the canvas size. With the truth
//! known, the true parts can be laid over it as a ghost (a second render, [`ghost_over`]). It
//! opens on the view that shows every movable part best ([`TwinScene::choose_opening_view`]).
//!
//! The frame is read back and put on a 2-D canvas rather than presented through a WebGPU
//! canvas context: in headless Chromium on SwiftShader (our CI browser) presenting to a
//! configured `webgpu` canvas destroyed the device after the first frames (measured
//! 2026-12-01), while the same renders read back work everywhere.

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use wasm_bindgen::prelude::*;

use super::app::FitResult;
use super::{context, js_error};
use crate::export::Twin;
use crate::gpu::GpuContext;
use crate::render::GtRenderer;
use crate::render::viewer::palette::{PALETTE_LEN, part_css};
use crate::render::viewer::{OpeningView, TwinScene, ghost_over};

/// The part palette "Colour by part" draws with, as CSS colours (`#rrggbb`): part `k` has
/// entry `k % length`. The legend's swatches come from here, so they match the picture.
#[wasm_bindgen]
pub fn part_colours() -> Vec<String> {
    (0..PALETTE_LEN).map(part_css).collect()
}

/// A twin on a canvas.
#[wasm_bindgen]
pub struct Viewer {
    ctx: Rc<GpuContext>,
    canvas: web_sys::HtmlCanvasElement,
    renderer: Rc<RefCell<Rc<GtRenderer>>>,
    scene: Rc<RefCell<TwinScene>>,
    /// A frame is being rendered; `again` asks it to render once more when done.
    busy: Rc<Cell<bool>>,
    again: Rc<Cell<bool>>,
    /// The opening view's choice and what it took (ms).
    opening: (OpeningView, f64),
}

#[wasm_bindgen]
impl Viewer {
    /// A viewer of `result`'s twin on `canvas` (drawn at the canvas's pixel size), at the
    /// start state.
    pub async fn create(
        canvas: web_sys::HtmlCanvasElement,
        result: FitResult,
    ) -> Result<Viewer, JsError> {
        let ctx = context().await?;
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        let renderer = GtRenderer::new(&ctx, width, height).map_err(js_error)?;
        let twin = &result.0.twin;
        let mut scene = TwinScene::new(twin.visual_object(), twin.end_configuration());
        let folder = &result.0;
        if let Some(truth) = &folder.truth {
            scene.truth_axes = truth
                .iter()
                .map(|j| (j.origin, j.unit_direction()))
                .collect();
            // The true parts need one mesh per joint, as the preview's truth does.
            if let Some(meshes) = &folder.truth_meshes
                && meshes.movable.len() == truth.len()
            {
                let twin = Twin::from_truth("truth", meshes, truth);
                // The scored pairs: fitted joint `pred` is true joint `gt`.
                let pairs: Vec<(usize, usize)> = folder
                    .metrics
                    .iter()
                    .flat_map(|m| m.joints.iter().map(|j| (j.pred, j.gt)))
                    .collect();
                scene.set_truth(twin.visual_object(), twin.end_configuration(), &pairs);
            }
        }
        let t0 = js_sys::Date::now();
        let opening = scene.choose_opening_view();
        let opening = (opening, js_sys::Date::now() - t0);
        Ok(Viewer {
            ctx,
            canvas,
            renderer: Rc::new(RefCell::new(Rc::new(renderer))),
            scene: Rc::new(RefCell::new(scene)),
            busy: Rc::default(),
            again: Rc::default(),
            opening,
        })
    }

    /// The sliders: `[{index, name, type, lower, upper, start, end, unit}]` as JSON.
    pub fn joints(&self) -> Result<String, JsError> {
        serde_json::to_string(self.scene.borrow().joints()).map_err(js_error)
    }

    /// The sliders' current values (degrees / metres).
    pub fn values(&self) -> Vec<f32> {
        self.scene.borrow().slider_values()
    }

    /// Sets slider `i` (clamped to its range); throws for a slider that does not exist.
    pub fn set_joint(&self, i: u32, value: f32) -> Result<(), JsError> {
        let mut scene = self.scene.borrow_mut();
        if scene.set_joint(i as usize, value) {
            Ok(())
        } else {
            Err(JsError::new(&format!(
                "no joint slider {i} (there are {}), or {value} is not a number",
                scene.joints().len()
            )))
        }
    }

    /// Every joint at the "start" or "end" state.
    pub fn set_state(&self, state: String) -> Result<(), JsError> {
        let end = match state.as_str() {
            "start" => false,
            "end" => true,
            other => {
                return Err(JsError::new(&format!(
                    "unknown state '{other}': expected start or end"
                )));
            }
        };
        self.scene.borrow_mut().set_state(end);
        Ok(())
    }

    /// Every joint `t` of the way from the start state (0) to the end state (1): the play
    /// button's animation.
    pub fn set_phase(&self, t: f32) {
        self.scene.borrow_mut().set_phase(t);
    }

    /// The legend of "Colour by part": `[{part, name, link, colour}]` as JSON, one entry per
    /// part, `colour` a CSS `#rrggbb` from [`part_colours`].
    pub fn legend(&self) -> Result<String, JsError> {
        serde_json::to_string(&self.scene.borrow().legend()).map_err(js_error)
    }

    /// The opening view: `{yaw, pitch, score, old_score, ms}` as JSON, `score` the smallest
    /// visible share of a movable part from it (both states), `old_score` the same from the
    /// old fixed view, `ms` what choosing took.
    pub fn opening_view(&self) -> String {
        let (v, ms) = self.opening;
        serde_json::json!({
            "yaw": v.yaw, "pitch": v.pitch, "score": v.score, "old_score": v.old_score, "ms": ms,
        })
        .to_string()
    }

    /// Turns the camera by a drag of `dx`, `dy` pixels.
    pub fn orbit(&self, dx: f32, dy: f32) {
        self.scene.borrow_mut().orbit(dx, dy);
    }

    /// Moves the camera closer (`factor` > 1) or further away.
    pub fn zoom(&self, factor: f32) {
        self.scene.borrow_mut().zoom(factor);
    }

    /// Colours each part in its palette colour ([`part_colours`]) instead of its own.
    pub fn colour_by_part(&self, on: bool) {
        self.scene.borrow_mut().colour_by_part = on;
    }

    /// Draws the fitted joint axes (orange hinge, blue slide).
    pub fn show_axes(&self, on: bool) {
        self.scene.borrow_mut().show_axes = on;
    }

    /// Whether the result knows the true joints (then `show_truth` draws their axes).
    pub fn has_truth(&self) -> bool {
        !self.scene.borrow().truth_axes.is_empty()
    }

    /// Draws the true joint axes (near black) beside the fitted ones.
    pub fn show_truth(&self, on: bool) {
        self.scene.borrow_mut().show_truth = on;
    }

    /// Whether the result knows the true parts' meshes (then `show_truth_parts` draws them).
    pub fn has_truth_parts(&self) -> bool {
        self.scene.borrow().has_truth_parts()
    }

    /// Lays the true parts over the fitted twin as a hatched, see-through dark ghost, articulated
    /// along.
    pub fn show_truth_parts(&self, on: bool) {
        self.scene.borrow_mut().show_truth_parts = on;
    }

    /// Follows the canvas to a new pixel size.
    pub fn resize(&self, width: u32, height: u32) -> Result<(), JsError> {
        let (width, height) = (width.max(1), height.max(1));
        if self.renderer.borrow().size() != (width, height) {
            let renderer = GtRenderer::new(&self.ctx, width, height).map_err(js_error)?;
            *self.renderer.borrow_mut() = Rc::new(renderer);
        }
        Ok(())
    }

    /// Draws the scene as it is now; resolves when it is on the canvas. A draw asked for while
    /// one is running is folded into one more frame after it.
    pub fn draw(&self) -> js_sys::Promise {
        if self.busy.get() {
            self.again.set(true);
            return js_sys::Promise::resolve(&JsValue::UNDEFINED);
        }
        self.busy.set(true);
        let (ctx, canvas) = (self.ctx.clone(), self.canvas.clone());
        let (renderer, scene) = (self.renderer.clone(), self.scene.clone());
        let (busy, again) = (self.busy.clone(), self.again.clone());
        wasm_bindgen_futures::future_to_promise(async move {
            let result = async {
                loop {
                    again.set(false);
                    let renderer = renderer.borrow().clone();
                    let (w, h) = renderer.size();
                    let (meshes, truth, camera) = {
                        let scene = scene.borrow();
                        (scene.meshes(), scene.truth_meshes(), scene.camera(w, h))
                    };
                    let err = |e: crate::gpu::GpuError| JsValue::from_str(&e.to_string());
                    let frame = renderer.render_view(&ctx, &meshes, &camera).await;
                    let frame = frame.map_err(err)?;
                    if truth.is_empty() {
                        put_on_canvas(&canvas, &frame.rgba)?;
                    } else {
                        let ghost = renderer.render_view(&ctx, &truth, &camera).await;
                        let ghost = ghost.map_err(err)?;
                        put_on_canvas(&canvas, &ghost_over(&frame, &ghost))?;
                    }
                    if !again.get() {
                        return Ok(JsValue::UNDEFINED);
                    }
                }
            }
            .await;
            busy.set(false);
            result
        })
    }
}

/// Puts `image` on the canvas's 2-D context at its top-left corner (the canvas's CSS background
/// shows through where nothing was drawn).
fn put_on_canvas(
    canvas: &web_sys::HtmlCanvasElement,
    image: &crate::data::RgbaImage,
) -> Result<(), JsValue> {
    let context: web_sys::CanvasRenderingContext2d = canvas
        .get_context("2d")?
        .ok_or_else(|| JsValue::from_str("the viewer canvas has no 2-D context"))?
        .dyn_into()?;
    let data = web_sys::ImageData::new_with_u8_clamped_array_and_sh(
        wasm_bindgen::Clamped(&image.pixels),
        image.width,
        image.height,
    )?;
    context.put_image_data(&data, 0.0, 0.0)
}
