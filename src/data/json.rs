//! Small helpers to walk a `serde_json::Value` and report type errors with the file and field path.
//!
//! Python's `json` module writes `NaN` / `Infinity`, which strict JSON parsers reject; we accept those tokens at
//! parse time so the error can name the field that holds them ("expected a finite number, found NaN").

use serde_json::{Map, Value};

use super::error::DataError;

/// Marker strings standing in for Python's non-finite literals after [`parse`].
const NON_FINITE: [(&str, &str); 3] = [
    ("-Infinity", "\u{0}-Infinity"),
    ("Infinity", "\u{0}Infinity"),
    ("NaN", "\u{0}NaN"),
];

/// Parses JSON bytes, naming `file` in the error.
pub(crate) fn parse(file: &str, bytes: &[u8]) -> Result<Value, DataError> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| DataError::file(file, format!("invalid JSON: not UTF-8 text ({e})")))?;
    let text = quote_non_finite(text);
    serde_json::from_str(&text).map_err(|e| DataError::file(file, format!("invalid JSON: {e}")))
}

/// Replaces bare `NaN`, `Infinity`, `-Infinity` tokens (outside strings) by marker strings.
fn quote_non_finite(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.contains("NaN") && !text.contains("Infinity") {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 16);
    let mut in_string = false;
    let mut escaped = false;
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        if in_string {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
        } else if c == '"' {
            in_string = true;
        } else if let Some((token, marker)) = NON_FINITE.iter().find(|(t, _)| rest.starts_with(t)) {
            out.push('"');
            // A JSON string cannot hold a raw NUL; write it escaped.
            out.push_str(&marker.replace('\u{0}', "\\u0000"));
            out.push('"');
            rest = &rest[token.len()..];
            continue;
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    std::borrow::Cow::Owned(out)
}

/// JSON number for an `f32`, written with the shortest decimal that reads back to the same `f32`
/// (`serde_json` would otherwise widen to `f64` first and write `0.10000000149011612` for `0.1`).
/// Non-finite values become `null`.
pub(crate) fn f32_value(x: f32) -> Value {
    x.to_string()
        .parse::<f64>()
        .ok()
        .and_then(serde_json::Number::from_f64)
        .map_or(Value::Null, Value::Number)
}

/// [`f32_value`] for each element.
pub(crate) fn f32_array(xs: &[f32]) -> Value {
    Value::Array(xs.iter().map(|&x| f32_value(x)).collect())
}

/// Short description of a JSON value for "found ..." messages.
pub(crate) fn describe(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("{b}"),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => match non_finite(s) {
            Some(x) => format!("{x}"),
            None if s.chars().count() > 40 => {
                format!("a string \"{}...\"", s.chars().take(40).collect::<String>())
            }
            None => format!("a string \"{s}\""),
        },
        Value::Array(a) => format!("an array of {} elements", a.len()),
        Value::Object(_) => "an object".into(),
    }
}

fn non_finite(s: &str) -> Option<f64> {
    NON_FINITE
        .iter()
        .find(|(_, m)| *m == s)
        .map(|(t, _)| match *t {
            "NaN" => f64::NAN,
            "Infinity" => f64::INFINITY,
            _ => f64::NEG_INFINITY,
        })
}

/// `parent.key` (or `key` at the top level).
pub(crate) fn join(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// Reader context: the file being read, so every error names it.
#[derive(Clone, Copy)]
pub(crate) struct Json<'a> {
    pub(crate) file: &'a str,
}

impl<'a> Json<'a> {
    pub(crate) fn err(&self, field: &str, message: impl Into<String>) -> DataError {
        if field.is_empty() {
            DataError::file(self.file, message)
        } else {
            DataError::field(self.file, field, message)
        }
    }

    pub(crate) fn object<'v>(
        &self,
        field: &str,
        v: &'v Value,
    ) -> Result<&'v Map<String, Value>, DataError> {
        v.as_object()
            .ok_or_else(|| self.err(field, format!("expected an object, found {}", describe(v))))
    }

    pub(crate) fn array<'v>(&self, field: &str, v: &'v Value) -> Result<&'v Vec<Value>, DataError> {
        v.as_array()
            .ok_or_else(|| self.err(field, format!("expected an array, found {}", describe(v))))
    }

    pub(crate) fn string<'v>(&self, field: &str, v: &'v Value) -> Result<&'v str, DataError> {
        match v {
            Value::String(s) if non_finite(s).is_none() => Ok(s),
            _ => Err(self.err(field, format!("expected a string, found {}", describe(v)))),
        }
    }

    /// A finite number.
    pub(crate) fn number(&self, field: &str, v: &Value) -> Result<f64, DataError> {
        match v {
            Value::Number(n) => match n.as_f64() {
                Some(x) if x.is_finite() => Ok(x),
                _ => Err(self.err(field, format!("expected a finite number, found {n}"))),
            },
            Value::String(s) => match non_finite(s) {
                Some(x) => Err(self.err(field, format!("expected a finite number, found {x}"))),
                None => Err(self.err(field, format!("expected a number, found {}", describe(v)))),
            },
            _ => Err(self.err(field, format!("expected a number, found {}", describe(v)))),
        }
    }

    /// A positive integer that fits `u32` (an integral float such as `800.0` is accepted).
    pub(crate) fn positive_u32(&self, field: &str, v: &Value) -> Result<u32, DataError> {
        let x = self.number(field, v)?;
        if x >= 1.0 && x <= f64::from(u32::MAX) && x.fract() == 0.0 {
            Ok(x as u32)
        } else {
            Err(self.err(
                field,
                format!("expected a positive whole number of pixels, found {x}"),
            ))
        }
    }

    /// An array of exactly `N` finite numbers.
    pub(crate) fn numbers<const N: usize>(
        &self,
        field: &str,
        v: &Value,
    ) -> Result<[f64; N], DataError> {
        let a = self.array(field, v)?;
        if a.len() != N {
            return Err(self.err(
                field,
                format!("expected {N} numbers, found {} elements", a.len()),
            ));
        }
        let mut out = [0.0; N];
        for (i, (slot, x)) in out.iter_mut().zip(a).enumerate() {
            *slot = self.number(&format!("{field}[{i}]"), x)?;
        }
        Ok(out)
    }

    /// A required member of an object.
    pub(crate) fn required<'v>(
        &self,
        parent: &str,
        map: &'v Map<String, Value>,
        key: &str,
        what: &str,
    ) -> Result<&'v Value, DataError> {
        map.get(key)
            .ok_or_else(|| self.err(&join(parent, key), format!("missing (expected {what})")))
    }
}

/// An optional member: absent and `null` both mean "not given".
pub(crate) fn optional<'v>(map: &'v Map<String, Value>, key: &str) -> Option<&'v Value> {
    map.get(key).filter(|v| !v.is_null())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_tokens_become_markers_outside_strings_only() {
        let v = parse(
            "a.json",
            br#"{"x": NaN, "y": [-Infinity, Infinity], "s": "NaN \" Infinity"}"#,
        )
        .unwrap();
        let j = Json { file: "a.json" };
        let e = j.number("x", &v["x"]).unwrap_err();
        assert!(
            e.message.contains("finite") && e.message.contains("NaN"),
            "{e}"
        );
        assert!(
            j.number("y[0]", &v["y"][0])
                .unwrap_err()
                .message
                .contains("-inf")
        );
        assert_eq!(v["s"], "NaN \" Infinity");
    }

    #[test]
    fn type_errors_name_field_and_found_type() {
        let v = parse("a.json", br#"{"x": "0.5"}"#).unwrap();
        let e = Json { file: "a.json" }.number("x", &v["x"]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.json: x: expected a number, found a string \"0.5\""
        );
    }

    #[test]
    fn f32_values_are_short_and_exact() {
        assert_eq!(serde_json::to_string(&f32_value(0.1)).unwrap(), "0.1");
        let mut x: u32 = 0x9e37_79b9;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let f = f32::from_bits(x);
            if f.is_finite() {
                let text = serde_json::to_string(&f32_value(f)).unwrap();
                let back: Value = serde_json::from_str(&text).unwrap();
                assert_eq!(
                    (back.as_f64().unwrap() as f32).to_bits(),
                    f.to_bits(),
                    "{f:e} -> {text}"
                );
            }
        }
    }
}
