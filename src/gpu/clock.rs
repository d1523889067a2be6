//! A monotonic clock in seconds on both targets (`Instant` natively, `performance.now()` in the
//! browser), for benchmarks and stage timing.

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
