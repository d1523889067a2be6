//! The Python literal subset of `.npy` header dicts: strings, booleans, whole numbers, tuples and `None`,
//! read by a small recursive-descent parser (its [`DictError`] becomes a `DataError` in the caller).

/// Value of the Python literal subset used by `.npy` headers.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Py {
    Str(String),
    Bool(bool),
    Int(u64),
    Tuple(Vec<Py>),
    Other(&'static str),
}

/// Why the header dict text is not the Python literal subset, with the byte offset where known.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum DictError {
    /// A specific character was needed and another one found.
    #[error("expected '{want}' at offset {at}, found '{found}'")]
    Expected { want: char, at: usize, found: char },
    /// A specific character was needed and the text ended.
    #[error("expected '{0}', found the end of the header")]
    ExpectedAtEnd(char),
    /// A dict key that is not a string.
    #[error("expected a string key, found {0:?}")]
    KeyNotString(Py),
    /// Neither a comma nor the closing bracket `close` after an item.
    #[error("expected ',' or '{close}' at offset {at}")]
    Separator { close: char, at: usize },
    /// Containers nested deeper than the parser follows.
    #[error("nesting too deep")]
    TooDeep,
    /// A string without its closing quote.
    #[error("unterminated string")]
    Unterminated,
    /// A whole number beyond `u64`.
    #[error("integer too large")]
    IntegerTooLarge,
    /// Text that starts no value of the subset.
    #[error("unexpected text at offset {0}")]
    UnexpectedText(usize),
    /// The text ended where a value was needed.
    #[error("unexpected end of header")]
    UnexpectedEnd,
}

/// Recursive-descent parser for the header dict.
struct Lit<'a> {
    s: &'a [u8],
    pos: usize,
}

impl<'a> Lit<'a> {
    fn skip_ws(&mut self) {
        while self
            .s
            .get(self.pos)
            .is_some_and(|c| c.is_ascii_whitespace())
        {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.pos).copied()
    }

    fn expect(&mut self, c: u8) -> Result<(), DictError> {
        match self.peek() {
            Some(x) if x == c => {
                self.pos += 1;
                Ok(())
            }
            Some(x) => Err(DictError::Expected {
                want: c as char,
                at: self.pos,
                found: x as char,
            }),
            None => Err(DictError::ExpectedAtEnd(c as char)),
        }
    }

    fn dict(&mut self) -> Result<Vec<(String, Py)>, DictError> {
        self.expect(b'{')?;
        let mut items = Vec::new();
        loop {
            if self.peek() == Some(b'}') {
                self.pos += 1;
                return Ok(items);
            }
            let key = match self.value(0)? {
                Py::Str(k) => k,
                other => return Err(DictError::KeyNotString(other)),
            };
            self.expect(b':')?;
            let value = self.value(0)?;
            items.push((key, value));
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b'}') => {}
                _ => {
                    return Err(DictError::Separator {
                        close: '}',
                        at: self.pos,
                    });
                }
            }
        }
    }

    fn value(&mut self, depth: usize) -> Result<Py, DictError> {
        if depth > 8 {
            return Err(DictError::TooDeep);
        }
        match self.peek() {
            Some(q @ (b'\'' | b'"')) => {
                self.pos += 1;
                let start = self.pos;
                while self.s.get(self.pos).is_some_and(|&c| c != q) {
                    self.pos += 1;
                }
                let text = self.s.get(start..self.pos).ok_or(DictError::Unterminated)?;
                self.expect(q).map_err(|_| DictError::Unterminated)?;
                Ok(Py::Str(String::from_utf8_lossy(text).into_owned()))
            }
            Some(open @ (b'(' | b'[')) => {
                self.pos += 1;
                let close = if open == b'(' { b')' } else { b']' };
                let mut items = Vec::new();
                loop {
                    if self.peek() == Some(close) {
                        self.pos += 1;
                        return Ok(if open == b'(' {
                            Py::Tuple(items)
                        } else {
                            Py::Other("a list")
                        });
                    }
                    items.push(self.value(depth + 1)?);
                    match self.peek() {
                        Some(b',') => self.pos += 1,
                        Some(c) if c == close => {}
                        _ => {
                            return Err(DictError::Separator {
                                close: close as char,
                                at: self.pos,
                            });
                        }
                    }
                }
            }
            Some(b'{') => {
                self.dict()?;
                Ok(Py::Other("a dict"))
            }
            Some(c) if c.is_ascii_digit() => {
                let mut n: u64 = 0;
                while let Some(d) = self.s.get(self.pos).filter(|c| c.is_ascii_digit()) {
                    n = n
                        .checked_mul(10)
                        .and_then(|n| n.checked_add(u64::from(d - b'0')))
                        .ok_or(DictError::IntegerTooLarge)?;
                    self.pos += 1;
                }
                // Python 2 wrote long integers as `480L`.
                if self.s.get(self.pos) == Some(&b'L') {
                    self.pos += 1;
                }
                Ok(Py::Int(n))
            }
            Some(_) => {
                let rest = &self.s[self.pos.min(self.s.len())..];
                for (word, v) in [
                    ("True", Py::Bool(true)),
                    ("False", Py::Bool(false)),
                    ("None", Py::Other("None")),
                ] {
                    if rest.starts_with(word.as_bytes()) {
                        self.pos += word.len();
                        return Ok(v);
                    }
                }
                Err(DictError::UnexpectedText(self.pos))
            }
            None => Err(DictError::UnexpectedEnd),
        }
    }
}

/// Parses the header dict text `{'descr': ..., 'fortran_order': ..., 'shape': (...), }` into its entries.
pub(super) fn parse_dict(text: &[u8]) -> Result<Vec<(String, Py)>, DictError> {
    Lit { s: text, pos: 0 }.dict()
}
