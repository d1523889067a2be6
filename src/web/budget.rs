//! The page's side of a fit's budget: each preset's numbers (from the preset module, the same
//! ones the CLI's budget flags start from) for the page to prefill its "Advanced: budgets"
//! fields, and the overrides the page sends back, read from JSON into `BudgetOverrides`.

use std::fmt;

use serde::Deserialize;
use wasm_bindgen::prelude::*;

use crate::fit::object::FitConfig;
use crate::fit::preset::{Budget, BudgetOverrides, Preset, UnknownPreset};
use crate::fit::work::{Capture, FitWork};

/// The page's budget overrides as JSON; a missing or `null` field keeps the preset's number.
/// Unknown fields are refused so that a misspelt one is not silently ignored.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct PageOverrides {
    max_size: Option<u32>,
    max_views: Option<usize>,
    reconstruction_iterations: Option<u32>,
    recovery_iterations: Option<u32>,
    max_faces: Option<usize>,
    articulation_iterations: Option<u32>,
}

impl From<PageOverrides> for BudgetOverrides {
    fn from(o: PageOverrides) -> Self {
        BudgetOverrides {
            max_size: o.max_size,
            max_views: o.max_views,
            reconstruction_iterations: o.reconstruction_iterations,
            recovery_iterations: o.recovery_iterations,
            max_faces: o.max_faces,
            articulation_iterations: o.articulation_iterations,
        }
    }
}

/// Why a preset name or a budget from the page was refused.
#[derive(Debug)]
pub(crate) enum BudgetError {
    /// Not one of the presets' names (the message lists them).
    Preset(UnknownPreset),
    /// Not a JSON object of known budget fields with non-negative whole numbers.
    Json(serde_json::Error),
    /// A count that must be at least 1 (a fit without steps or faces has nothing to do).
    Zero(&'static str),
}

impl fmt::Display for BudgetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BudgetError::Preset(e) => write!(f, "{e}"),
            BudgetError::Json(e) => write!(f, "budget overrides: {e}"),
            BudgetError::Zero(field) => write!(f, "budget overrides: {field} must be at least 1"),
        }
    }
}

impl std::error::Error for BudgetError {}

/// The named preset.
pub(crate) fn preset(name: &str) -> Result<Preset, BudgetError> {
    Preset::parse(name).map_err(BudgetError::Preset)
}

/// Overrides from the page's JSON; none (or blank) changes nothing.
pub(crate) fn overrides(json: Option<&str>) -> Result<BudgetOverrides, BudgetError> {
    let json = json.map(str::trim).filter(|s| !s.is_empty());
    let page: PageOverrides = match json {
        Some(text) => serde_json::from_str(text).map_err(BudgetError::Json)?,
        None => PageOverrides::default(),
    };
    // Zero means "all" / "full size" for the views and the working size; here it means no fit.
    let zero = if page.reconstruction_iterations == Some(0) {
        Some("reconstruction_iterations")
    } else if page.articulation_iterations == Some(0) {
        Some("articulation_iterations")
    } else if page.max_faces == Some(0) {
        Some("max_faces")
    } else {
        None
    };
    if let Some(field) = zero {
        return Err(BudgetError::Zero(field));
    }
    Ok(page.into())
}

/// Both phases' settings of the named preset with the page's overrides (JSON) applied: the
/// config `FitConfig::budgeted` builds, as the CLI's budget flags do.
pub(crate) fn fit_config(name: &str, json: Option<&str>) -> Result<FitConfig, BudgetError> {
    Ok(FitConfig::budgeted(preset(name)?, &overrides(json)?))
}

/// One line on what a budget spends, as the page shows it under a preset's name.
fn about(b: &Budget) -> String {
    let size = match b.max_size {
        0 => "full-size".to_string(),
        n => format!("{n} px"),
    };
    let views = match b.max_views {
        0 => "all views".to_string(),
        n => format!("{n} views per state"),
    };
    format!(
        "{size}, {views}, {} iterations per state + {} for the joints",
        b.reconstruction_iterations + b.recovery_iterations,
        b.articulation_iterations
    )
}

/// A preset's entry as the page reads it: `{name, about, budget}`.
pub(crate) fn preset_entry(p: Preset, overrides: &BudgetOverrides) -> serde_json::Value {
    let budget = p.budget().with(overrides);
    serde_json::json!({ "name": p.name(), "about": about(&budget), "budget": budget })
}

/// Every preset's entry (`Preset::ALL`, in order) with its own budget.
pub(crate) fn preset_entries() -> Vec<serde_json::Value> {
    Preset::ALL
        .into_iter()
        .map(|p| preset_entry(p, &BudgetOverrides::default()))
        .collect()
}

/// The budget `preset` spends with `overrides` (JSON, optional) applied, as JSON
/// `{name, about, budget: {max_size, max_views, reconstruction_iterations, recovery_iterations,
/// max_faces, articulation_iterations}}`. Throws for an unknown preset or a malformed override.
#[wasm_bindgen]
pub fn preset_budget(preset: String, overrides: Option<String>) -> Result<String, JsError> {
    let p = self::preset(&preset).map_err(super::js_error)?;
    let o = self::overrides(overrides.as_deref()).map_err(super::js_error)?;
    Ok(preset_entry(p, &o).to_string())
}

/// What a fit of `capture` (JSON of [`Capture`]) with `preset` and `overrides` will do: JSON of
/// [`FitWork`], for the page's time estimates.
#[wasm_bindgen]
pub fn fit_work(
    preset: String,
    overrides: Option<String>,
    capture: String,
) -> Result<String, JsError> {
    let config = fit_config(&preset, overrides.as_deref()).map_err(super::js_error)?;
    let capture: Capture = serde_json::from_str(&capture)
        .map_err(|e| JsError::new(&format!("fit work: capture: {e}")))?;
    Ok(serde_json::to_string(&FitWork::of(&config, &capture)).unwrap_or_default())
}

/// The capture the page's demo takes of an object with `movable_parts` at `preset`: JSON of
/// [`Capture`] (the demo photographs at never less than `fast`'s capture).
#[wasm_bindgen]
pub fn demo_capture(
    preset: String,
    overrides: Option<String>,
    movable_parts: u32,
) -> Result<String, JsError> {
    let config = fit_config(&preset, overrides.as_deref()).map_err(super::js_error)?;
    let spec = config.full_demo_capture(0);
    let capture = Capture {
        width: spec.width,
        height: spec.height,
        views: spec.train_views,
        movable_parts: movable_parts as usize,
        depth: true,
        part_pixels: Vec::new(),
    };
    Ok(serde_json::to_string(&capture).unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test]
    fn blank_overrides_keep_the_preset() {
        for json in [
            None,
            Some(""),
            Some("  "),
            Some("{}"),
            Some(r#"{"max_size": null}"#),
        ] {
            assert_eq!(overrides(json).unwrap(), BudgetOverrides::default());
        }
        let config = fit_config("fast", None).unwrap();
        assert_eq!(
            config.reconstruction.max_size,
            Preset::Fast.budget().max_size
        );
    }

    #[wasm_bindgen_test]
    fn overrides_reach_both_phases() {
        let json = r#"{"max_size": 128, "max_views": 0, "articulation_iterations": 500}"#;
        let config = fit_config("fast", Some(json)).unwrap();
        assert_eq!(config.reconstruction.max_size, 128);
        assert_eq!(config.reconstruction.max_views, 0);
        assert_eq!(config.articulation.iterations, 500);
        let fast = Preset::Fast.budget();
        assert_eq!(
            config.reconstruction.fit.iterations,
            fast.reconstruction_iterations
        );
    }

    #[wasm_bindgen_test]
    fn bad_overrides_are_named() {
        let msg = |json: &str| overrides(Some(json)).unwrap_err().to_string();
        assert!(msg(r#"{"max_sise": 1}"#).contains("max_sise"));
        assert!(msg(r#"{"max_size": -1}"#).contains("-1"));
        assert!(msg(r#"{"reconstruction_iterations": 0}"#).contains("reconstruction_iterations"));
        assert!(
            fit_config("huge", None)
                .unwrap_err()
                .to_string()
                .contains("tiny, fast, paper")
        );
    }

    #[wasm_bindgen_test]
    fn every_preset_is_listed_with_its_budget() {
        let entries = preset_entries();
        assert_eq!(entries.len(), Preset::ALL.len());
        let fast = &entries[1];
        assert_eq!(fast["name"], "fast");
        assert_eq!(fast["budget"]["max_size"], Preset::Fast.budget().max_size);
    }
}
