//! Error types of the dataset layer, and the collector used to report every problem rather than the first.

use std::fmt;

/// One problem found in the input: which file, which field or image property, and what was expected.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct DataError {
    /// Relative path of the file at fault (for a missing file: the file that refers to it, or the missing path).
    pub file: String,
    /// JSON field path (`frames[3].transform_matrix`) or image/file property (`bit depth`, `shape`), if any.
    pub field: Option<String>,
    /// What was expected and what was found.
    pub message: String,
}

impl DataError {
    /// An error about a whole file.
    pub fn file(file: impl Into<String>, message: impl Into<String>) -> Self {
        DataError {
            file: file.into(),
            field: None,
            message: message.into(),
        }
    }

    /// An error about one field or property of a file.
    pub fn field(
        file: impl Into<String>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        DataError {
            file: file.into(),
            field: Some(field.into()),
            message: message.into(),
        }
    }
}

/// Longest file name, field or message shown (in characters); the rest is counted.
const MAX_SHOWN_CHARS: usize = 400;

/// Most errors a [`DatasetErrors`] lists; the rest are counted.
pub(crate) const MAX_SHOWN_ERRORS: usize = 50;

/// `text` as it may go to a terminal or a page: control characters (from file names, say)
/// escaped, at most [`MAX_SHOWN_CHARS`] characters and a count of the rest.
fn shown(text: &str, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    let mut chars = text.chars();
    for c in chars.by_ref().take(MAX_SHOWN_CHARS) {
        if c.is_control() {
            write!(f, "{}", c.escape_default())?;
        } else {
            write!(f, "{c}")?;
        }
    }
    match chars.count() {
        0 => Ok(()),
        more => write!(f, "… ({more} more characters)"),
    }
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        shown(&self.file, f)?;
        if let Some(field) = &self.field {
            f.write_str(": ")?;
            shown(field, f)?;
        }
        f.write_str(": ")?;
        shown(&self.message, f)
    }
}

impl std::error::Error for DataError {}

/// Every problem found while reading a dataset, in the order found.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct DatasetErrors(pub Vec<DataError>);

impl DatasetErrors {
    /// The errors whose `file` is `file`.
    pub fn for_file<'a>(&'a self, file: &'a str) -> impl Iterator<Item = &'a DataError> + 'a {
        self.0.iter().filter(move |e| e.file == file)
    }
}

impl fmt::Display for DatasetErrors {
    /// The first [`MAX_SHOWN_ERRORS`] errors, a line each, then how many more there are.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().take(MAX_SHOWN_ERRORS).enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        if let Some(more) = self
            .0
            .len()
            .checked_sub(MAX_SHOWN_ERRORS)
            .filter(|&n| n > 0)
        {
            write!(f, "\n… and {more} more problems")?;
        }
        Ok(())
    }
}

impl std::error::Error for DatasetErrors {}

impl From<DataError> for DatasetErrors {
    fn from(e: DataError) -> Self {
        DatasetErrors(vec![e])
    }
}

/// Collects errors so readers can keep going after a problem and report all of them at the end.
#[derive(Debug, Default)]
pub(crate) struct Errors(Vec<DataError>);

impl Errors {
    pub(crate) fn push(&mut self, e: DataError) {
        self.0.push(e);
    }

    /// Records the error of `r`, if any, and hands back its value.
    pub(crate) fn keep<T>(&mut self, r: Result<T, DataError>) -> Option<T> {
        match r {
            Ok(v) => Some(v),
            Err(e) => {
                self.0.push(e);
                None
            }
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// `Ok(value)` when nothing was recorded, else all recorded errors.
    pub(crate) fn finish<T>(self, value: T) -> Result<T, DatasetErrors> {
        if self.0.is_empty() {
            Ok(value)
        } else {
            Err(DatasetErrors(self.0))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_are_shown_escaped_short_and_capped() {
        let e = DataError::field("rgba/\u{1b}[31mred\n.png", "size", "x".repeat(1000));
        let shown = e.to_string();
        assert!(
            shown.starts_with("rgba/\\u{1b}[31mred\\n.png: size: xxx"),
            "{shown}"
        );
        assert!(shown.ends_with("… (600 more characters)"), "{shown}");
        assert!(!shown.chars().any(char::is_control));
        let many = DatasetErrors(
            (0..200)
                .map(|i| DataError::file(format!("{i}.png"), "bad"))
                .collect(),
        );
        let text = many.to_string();
        assert_eq!(text.lines().count(), MAX_SHOWN_ERRORS + 1);
        assert!(text.ends_with("… and 150 more problems"), "{text}");
    }
}
