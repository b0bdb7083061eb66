//! Reading values from a PLY body, ascii or binary, with positions for errors.
//!
//! Both readers report problems at a [`Reader::here`] position: a byte offset
//! from the start of the file (binary) or a 1-based line (ascii).

use super::header::{shown, Scalar};
use crate::error::FormatError;

/// A source of PLY body values.
pub(crate) trait Reader {
    /// Position of the next value: byte offset (binary) or line (ascii).
    fn here(&mut self) -> u64;
    /// Reads a value of type `ty` as a coordinate.
    fn coord(&mut self, ty: Scalar) -> Result<f32, FormatError>;
    /// Reads a value of integer type `ty`.
    fn int(&mut self, ty: Scalar) -> Result<i64, FormatError>;
    /// Skips `n` values of type `ty`; the caller has checked [`Reader::fits`].
    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), FormatError>;
    /// Whether `n` values of type `ty` can possibly be in the rest of the body.
    fn fits(&self, n: u64, ty: Scalar) -> bool;
    /// Bytes left in the file.
    fn remaining(&self) -> usize;
    /// Fewest bytes a value of type `ty` can take in the body.
    fn smallest(&self, ty: Scalar) -> u64;
    /// Bytes a body may lack beyond the sum of smallest values (a final separator).
    fn slack(&self) -> u64;
    /// An error at position `at` (from [`Reader::here`]).
    fn error(&self, at: u64, message: String) -> FormatError;
    /// Starts a record of (at least) `values` values: an ascii record must
    /// be one line.
    fn begin_record(&mut self, _values: u64) {}
    /// The record holds `n` more values than announced (a list's items).
    fn more_values(&mut self, _n: u64) {}
    /// Ends the record: an ascii line must hold no more values.
    fn end_record(&mut self) -> Result<(), FormatError> {
        Ok(())
    }
}

/// Packed values in either byte order.
pub(crate) struct Binary<'a> {
    bytes: &'a [u8],
    pos: usize,
    big_endian: bool,
    name: &'a str,
}

impl<'a> Binary<'a> {
    /// A reader over the whole file `bytes`, starting at `pos`.
    pub(crate) fn new(bytes: &'a [u8], pos: usize, big_endian: bool, name: &'a str) -> Self {
        Binary {
            bytes,
            pos,
            big_endian,
            name,
        }
    }

    fn take<const N: usize>(&mut self, ty: Scalar) -> Result<[u8; N], FormatError> {
        let Some(slice) = self.bytes.get(self.pos..self.pos + N) else {
            return Err(self.error(
                self.pos as u64,
                format!(
                    "the file ends in the middle of a {} value ({N} bytes needed, {} left)",
                    ty.name(),
                    self.remaining()
                ),
            ));
        };
        let mut out = [0; N];
        out.copy_from_slice(slice);
        if self.big_endian {
            out.reverse();
        }
        self.pos += N;
        Ok(out)
    }

    /// Reads a value as either an integer or a float, whichever `ty` is.
    fn value(&mut self, ty: Scalar) -> Result<Value, FormatError> {
        Ok(match ty {
            Scalar::I8 => Value::Int(i8::from_le_bytes(self.take(ty)?).into()),
            Scalar::U8 => Value::Int(u8::from_le_bytes(self.take(ty)?).into()),
            Scalar::I16 => Value::Int(i16::from_le_bytes(self.take(ty)?).into()),
            Scalar::U16 => Value::Int(u16::from_le_bytes(self.take(ty)?).into()),
            Scalar::I32 => Value::Int(i32::from_le_bytes(self.take(ty)?).into()),
            Scalar::U32 => Value::Int(u32::from_le_bytes(self.take(ty)?).into()),
            Scalar::F32 => Value::F32(f32::from_le_bytes(self.take(ty)?)),
            Scalar::F64 => Value::F64(f64::from_le_bytes(self.take(ty)?)),
        })
    }
}

/// A value read from a binary body.
enum Value {
    Int(i64),
    F32(f32),
    F64(f64),
}

impl Reader for Binary<'_> {
    fn here(&mut self) -> u64 {
        self.pos as u64
    }

    fn coord(&mut self, ty: Scalar) -> Result<f32, FormatError> {
        Ok(match self.value(ty)? {
            Value::Int(i) => i as f32,
            Value::F32(f) => f,
            Value::F64(f) => f as f32,
        })
    }

    fn int(&mut self, ty: Scalar) -> Result<i64, FormatError> {
        let at = self.here();
        match self.value(ty)? {
            Value::Int(i) => Ok(i),
            Value::F32(_) | Value::F64(_) => Err(self.error(
                at,
                format!("expected an integer but the type is {}", ty.name()),
            )),
        }
    }

    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), FormatError> {
        let len = n.saturating_mul(ty.size() as u64);
        if len > self.remaining() as u64 {
            return Err(self.error(
                self.pos as u64,
                format!(
                    "the file ends early: {n} {} values need {len} bytes but only {} are left",
                    ty.name(),
                    self.remaining()
                ),
            ));
        }
        self.pos += len as usize;
        Ok(())
    }

    fn fits(&self, n: u64, ty: Scalar) -> bool {
        n.checked_mul(ty.size() as u64)
            .is_some_and(|len| len <= self.remaining() as u64)
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn smallest(&self, ty: Scalar) -> u64 {
        ty.size() as u64
    }

    fn slack(&self) -> u64 {
        0
    }

    fn error(&self, at: u64, message: String) -> FormatError {
        FormatError::at_byte(self.name, at, message)
    }
}

/// Whitespace-separated numbers, one record per line (a short or long line
/// is an error naming it: `expected 3 values, found 2`).
pub(crate) struct Ascii<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: u64,
    name: &'a str,
    /// The record being read: its line, values expected and values read.
    record: Option<(u64, u64, u64)>,
}

impl<'a> Ascii<'a> {
    /// A reader over the whole file `bytes`, starting at `pos`, which is on 1-based `line`.
    pub(crate) fn new(bytes: &'a [u8], pos: usize, line: usize, name: &'a str) -> Self {
        Ascii {
            bytes,
            pos,
            line: line as u64,
            name,
            record: None,
        }
    }

    /// Moves past whitespace, counting lines.
    fn skip_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// The next token, or an error saying a `ty` value was expected.
    fn token(&mut self, ty: Scalar) -> Result<&'a str, FormatError> {
        self.skip_space();
        if let Some((line, expected, found)) = &mut self.record {
            if self.line != *line || self.pos >= self.bytes.len() {
                let (line, expected, found) = (*line, *expected, *found);
                return Err(self.error(line, format!("expected {expected} values, found {found}")));
            }
            *found += 1;
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        let token = &self.bytes[start..self.pos];
        if token.is_empty() {
            return Err(self.error(
                self.line,
                format!("the file ends early: expected a {} value", ty.name()),
            ));
        }
        std::str::from_utf8(token).map_err(|_| self.not_a(token, ty))
    }

    fn not_a(&self, token: &[u8], ty: Scalar) -> FormatError {
        self.error(
            self.line,
            format!("'{}' is not a valid {} value", shown(token), ty.name()),
        )
    }

    /// Parses `token` as an integer that fits `ty`.
    fn parse_int(&self, token: &str, ty: Scalar) -> Result<i64, FormatError> {
        let (lo, hi) = ty.int_range();
        match token.parse::<i64>() {
            Ok(i) if (lo..=hi).contains(&i) => Ok(i),
            Ok(i) => Err(self.error(
                self.line,
                format!("{i} is out of range for type {} ({lo} to {hi})", ty.name()),
            )),
            Err(_) => Err(self.not_a(token.as_bytes(), ty)),
        }
    }
}

impl Reader for Ascii<'_> {
    fn here(&mut self) -> u64 {
        self.skip_space();
        self.line
    }

    fn coord(&mut self, ty: Scalar) -> Result<f32, FormatError> {
        let token = self.token(ty)?;
        // Parse floats straight to f32 (not via f64) so ascii and binary
        // files holding the same f32 values agree bit for bit.
        match ty {
            Scalar::F32 => token.parse::<f32>().ok(),
            Scalar::F64 => token.parse::<f64>().ok().map(|f| f as f32),
            _ => return Ok(self.parse_int(token, ty)? as f32),
        }
        .ok_or_else(|| self.not_a(token.as_bytes(), ty))
    }

    fn int(&mut self, ty: Scalar) -> Result<i64, FormatError> {
        let token = self.token(ty)?;
        if !ty.is_integer() {
            return Err(self.error(
                self.line,
                format!("expected an integer but the type is {}", ty.name()),
            ));
        }
        self.parse_int(token, ty)
    }

    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), FormatError> {
        for _ in 0..n {
            self.token(ty)?;
        }
        Ok(())
    }

    fn fits(&self, n: u64, ty: Scalar) -> bool {
        n.checked_mul(self.smallest(ty))
            .is_some_and(|len| len <= self.remaining() as u64 + self.slack())
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn smallest(&self, _ty: Scalar) -> u64 {
        // One character and one separator.
        2
    }

    fn slack(&self) -> u64 {
        // The last value of the file needs no separator.
        1
    }

    fn error(&self, at: u64, message: String) -> FormatError {
        FormatError::at_line(self.name, at as usize, message)
    }

    fn begin_record(&mut self, values: u64) {
        self.skip_space();
        self.record = Some((self.line, values, 0));
    }

    fn more_values(&mut self, n: u64) {
        if let Some((_, expected, _)) = &mut self.record {
            *expected += n;
        }
    }

    fn end_record(&mut self) -> Result<(), FormatError> {
        let Some((line, expected, _)) = self.record.take() else {
            return Ok(());
        };
        // The rest of the line must be blank.
        let rest = self.bytes[self.pos..]
            .iter()
            .take_while(|&&b| b != b'\n')
            .any(|b| !b.is_ascii_whitespace());
        if rest {
            return Err(self.error(line, format!("expected {expected} values, found more")));
        }
        Ok(())
    }
}
