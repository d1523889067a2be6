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

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.field {
            Some(field) => write!(f, "{}: {}: {}", self.file, field, self.message),
            None => write!(f, "{}: {}", self.file, self.message),
        }
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
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
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
