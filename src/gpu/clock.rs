//! A monotonic clock in seconds on both targets (`Instant` natively, `performance.now()` in the
//! browser), for benchmarks and stage timing, and a sleep that yields to the browser's event loop.

#[cfg(not(target_arch = "wasm32"))]
static ORIGIN: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();

/// Seconds since an arbitrary fixed origin.
pub fn now_seconds() -> f64 {
    #[cfg(not(target_arch = "wasm32"))]
    {
        ORIGIN
            .get_or_init(std::time::Instant::now)
            .elapsed()
            .as_secs_f64()
    }
    #[cfg(target_arch = "wasm32")]
    {
        web_sys::window()
            .and_then(|w| w.performance())
            .map_or(0.0, |p| p.now() / 1000.0)
    }
}

/// Waits `millis` milliseconds. In the browser this returns to the event loop (a `setTimeout`
/// promise), so the page can repaint and handle clicks while a fit runs; natively it sleeps.
pub async fn sleep_ms(millis: u32) {
    #[cfg(not(target_arch = "wasm32"))]
    std::thread::sleep(std::time::Duration::from_millis(millis.into()));
    #[cfg(target_arch = "wasm32")]
    {
        let promise = js_sys::Promise::new(&mut |resolve, _reject| {
            if let Some(window) = web_sys::window() {
                let _ = window
                    .set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, millis as i32);
            } else {
                // No window (a worker): resolve at once rather than never.
                let _ = resolve.call0(&wasm_bindgen::JsValue::NULL);
            }
        });
        let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
    }
}
