//! The Python literal subset of `.npy` header dicts: strings, booleans, whole numbers, tuples and `None`,
//! read by a small recursive-descent parser (errors as text, turned into a `DataError` by the caller).

/// Value of the Python literal subset used by `.npy` headers.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Py {
    Str(String),
    Bool(bool),
    Int(u64),
    Tuple(Vec<Py>),
    Other(&'static str),
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

    fn expect(&mut self, c: u8) -> Result<(), String> {
        match self.peek() {
            Some(x) if x == c => {
                self.pos += 1;
                Ok(())
            }
            Some(x) => Err(format!(
                "expected '{}' at offset {}, found '{}'",
                c as char, self.pos, x as char
            )),
            None => Err(format!(
                "expected '{}', found the end of the header",
                c as char
            )),
        }
    }

    fn dict(&mut self) -> Result<Vec<(String, Py)>, String> {
        self.expect(b'{')?;
        let mut items = Vec::new();
        loop {
            if self.peek() == Some(b'}') {
                self.pos += 1;
                return Ok(items);
            }
            let key = match self.value(0)? {
                Py::Str(k) => k,
                other => return Err(format!("expected a string key, found {other:?}")),
            };
            self.expect(b':')?;
            let value = self.value(0)?;
            items.push((key, value));
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b'}') => {}
                _ => return Err(format!("expected ',' or '}}' at offset {}", self.pos)),
            }
        }
    }

    fn value(&mut self, depth: usize) -> Result<Py, String> {
        if depth > 8 {
            return Err("nesting too deep".into());
        }
        match self.peek() {
            Some(q @ (b'\'' | b'"')) => {
                self.pos += 1;
                let start = self.pos;
                while self.s.get(self.pos).is_some_and(|&c| c != q) {
                    self.pos += 1;
                }
                let text = self.s.get(start..self.pos).ok_or("unterminated string")?;
                self.expect(q)
                    .map_err(|_| "unterminated string".to_string())?;
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
                            return Err(format!(
                                "expected ',' or '{}' at offset {}",
                                close as char, self.pos
                            ));
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
                        .ok_or("integer too large")?;
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
                Err(format!("unexpected text at offset {}", self.pos))
            }
            None => Err("unexpected end of header".into()),
        }
    }
}

/// Parses the header dict text `{'descr': ..., 'fortran_order': ..., 'shape': (...), }` into its entries.
pub(super) fn parse_dict(text: &[u8]) -> Result<Vec<(String, Py)>, String> {
    Lit { s: text, pos: 0 }.dict()
}
