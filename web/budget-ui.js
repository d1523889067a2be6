// The "Advanced: budgets" section: a number field per budget (working size, views per state,
// iteration counts, face cap), prefilled from a preset's budget as the wasm `catalogue()` lists it
// (the crate's preset module, the same numbers the CLI starts from), and the overrides the fields
// make, as the JSON the wasm `fit` and `Dataset.demo` take. Only the numbers the user typed count:
// a field left empty, untouched (it follows the preset) or at the running preset's value overrides
// nothing.
import { $ } from "./util.js";

let presets = [];       // catalogue presets: [{name, about, budget: {max_size, ...}}]
let shown = null;       // the preset whose budget the fields show
let describe = null;    // (preset, overridesJson) => one line on what that budget spends

const fields = () => [...$("budget-form").querySelectorAll("input[name]")];
const budgetOf = (name) => presets.find((p) => p.name === name)?.budget ?? {};
const labelOf = (input) => document.querySelector(`label[for="${input.id}"]`)?.textContent ?? input.name;

/** Highlights a typed number that differs from the shown preset's. */
function highlight(input) {
  const v = input.value.trim();
  input.classList.toggle("changed", !!input.dataset.edited && v !== "" && Number(v) !== budgetOf(shown)[input.name]);
}

/** A field the user typed in keeps its number when the preset changes; emptied, it follows again. */
function markEdited(input) {
  if (input.value.trim() === "" && !input.validity?.badInput) delete input.dataset.edited;
  else input.dataset.edited = "1";
  highlight(input);
}

function summarise() {
  let text;
  try {
    const overrides = budgetOverrides(shown);
    text = overrides ? `With these numbers ${shown} spends: ${describe(shown, overrides)}.`
      : `The ${shown} preset's budget: ${describe(shown, undefined)}.`;
  } catch (e) {
    text = String(e?.message ?? e);
  }
  $("budget-summary").textContent = text;
}

/** The preset whose budget the fields show. */
export const shownPreset = () => shown;

/** Shows `name`'s budget in the fields the user has not changed. */
export function showPresetBudget(name) {
  if (!presets.some((p) => p.name === name)) return;
  shown = name;
  $("budget-preset").textContent = name;
  const budget = budgetOf(name);
  for (const input of fields()) {
    const value = budget[input.name];
    if (value === undefined) continue;
    input.placeholder = String(value);
    if (!input.dataset.edited) input.value = String(value);
    highlight(input);
  }
  summarise();
}

/**
 * Wires the section: `catalogPresets` from `catalogue()`, `preset` the one shown first,
 * `describeFn(preset, overridesJson)` the one-line summary of a budget (wasm `preset_budget`).
 */
export function setupBudgets(catalogPresets, preset, describeFn) {
  presets = catalogPresets ?? [];
  describe = describeFn;
  const known = new Set(fields().map((f) => f.name));
  for (const key of Object.keys(presets[0]?.budget ?? {})) {
    if (!known.has(key)) console.warn(`budget "${key}" has no field on the page`);
  }
  for (const input of fields()) {
    input.addEventListener("input", () => { markEdited(input); summarise(); });
  }
  $("budget-form").addEventListener("submit", (e) => e.preventDefault());
  $("budget-reset").addEventListener("click", () => {
    for (const input of fields()) delete input.dataset.edited;
    showPresetBudget(shown);
  });
  showPresetBudget(preset);
}

/**
 * The fields' overrides of `preset`'s budget as JSON (undefined when none): every number the user
 * typed that differs from the preset's. The fields show `preset`'s budget first, so what the page
 * shows is what runs. Throws naming a field that is not a whole number in range.
 */
export function budgetOverrides(preset) {
  if (preset !== shown) showPresetBudget(preset);
  const budget = budgetOf(preset);
  const out = {};
  for (const input of fields()) {
    if (!input.dataset.edited) continue;
    if (input.validity?.badInput) throw new Error(`${labelOf(input)}: expected a whole number`);
    const v = input.value.trim();
    if (v === "") continue;
    const n = Number(v);
    const min = Number(input.min) || 0;
    if (!Number.isSafeInteger(n) || n < min) throw new Error(`${labelOf(input)}: expected a whole number of at least ${min}, not ${v}`);
    if (n !== budget[input.name]) out[input.name] = n;
  }
  return Object.keys(out).length ? JSON.stringify(out) : undefined;
}
