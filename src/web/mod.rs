//! The wasm-bindgen surface for `web/` (the page's API is written up in `web/API.md`): the
//! adapter report and GPU self-test, dataset loading and the demo capture, the fit with progress
//! events and pause/cancel ([`app`]), which files of a dropped folder to read and the page's file
//! budgets (`files`), each preset's budget and the page's overrides of it
//! (`budget`), and the result viewer ([`viewer`]).
//! Structured results cross the boundary as JSON strings or plain objects; images as
//! `Uint8ClampedArray` RGBA.
//!
//! One GPU context serves the whole page. Rust panics and a lost device are announced to the
//! page as `artmesh-panic` / `artmesh-device-lost` events on `window`, so it can say what
//! happened instead of going quiet.

pub mod app;
mod budget;
mod files;
mod object;
pub mod viewer;

use std::cell::RefCell;
use std::rc::Rc;

use wasm_bindgen::prelude::*;

use crate::gpu::{GpuContext, selftest};

thread_local! {
    /// The page's context and its serial number (which context a device-lost report is about).
    static CONTEXT: RefCell<Option<(u32, Rc<GpuContext>)>> = const { RefCell::new(None) };
    static SERIAL: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// Installs the panic hook: the panic goes to the console and to the page as an
/// `artmesh-panic` event whose `detail` is the message.
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(|info| {
        console_error_panic_hook::hook(info);
        announce("artmesh-panic", &info.to_string());
    }));
}

/// Dispatches a `CustomEvent` named `name` with `detail` on `window` (nothing without a window).
fn announce(name: &str, detail: &str) {
    let Some(window) = web_sys::window() else {
        return;
    };
    let init = web_sys::CustomEventInit::new();
    init.set_detail(&JsValue::from_str(detail));
    if let Ok(event) = web_sys::CustomEvent::new_with_event_init_dict(name, &init) {
        let _ = window.dispatch_event(&event);
    }
}

fn js_error(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// The page's GPU context, opened on first use. When the device of the current context is lost
/// the page hears `artmesh-device-lost` and the next call opens a fresh one. (A context that
/// lost a race to become the current one is dropped; its device's later loss is no news.)
async fn context() -> Result<Rc<GpuContext>, JsError> {
    if let Some((_, ctx)) = CONTEXT.with_borrow(|c| c.clone()) {
        return Ok(ctx);
    }
    let ctx = Rc::new(GpuContext::new().await.map_err(js_error)?);
    if let Some((_, current)) = CONTEXT.with_borrow(|c| c.clone()) {
        return Ok(current);
    }
    let serial = SERIAL.get() + 1;
    SERIAL.set(serial);
    ctx.device.set_device_lost_callback(move |reason, message| {
        let current = CONTEXT.with_borrow(|c| c.as_ref().map(|(s, _)| *s));
        if current == Some(serial) {
            CONTEXT.with_borrow_mut(|c| *c = None);
            announce(
                "artmesh-device-lost",
                &format!("the GPU device was lost ({reason:?}): {message}"),
            );
        }
    });
    CONTEXT.with_borrow_mut(|c| *c = Some((serial, ctx.clone())));
    Ok(ctx)
}

/// The WebGPU adapter and its limits, as JSON.
#[wasm_bindgen]
pub async fn adapter_report() -> Result<String, JsError> {
    let ctx = context().await?;
    serde_json::to_string(&ctx.adapter).map_err(js_error)
}

/// Runs the prefix-sum and radix-sort self-test for the default sizes up to `max_size`, as JSON
/// (`passed` tells the verdict).
#[wasm_bindgen]
pub async fn gpu_self_test(max_size: u32) -> Result<String, JsError> {
    let ctx = context().await?;
    let sizes: Vec<u32> = selftest::DEFAULT_SIZES
        .iter()
        .copied()
        .filter(|&n| n <= max_size)
        .collect();
    let report = selftest::run(&ctx, &sizes).await.map_err(js_error)?;
    let value = serde_json::json!({ "passed": report.passed(), "report": report });
    serde_json::to_string(&value).map_err(js_error)
}
