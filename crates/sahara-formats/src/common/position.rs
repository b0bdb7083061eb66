//! Positions in scene files: the file, line and column every parse error
//! and warning names.

use std::sync::Arc;

use sahara_readers::FormatError;

/// Where something is in a scene file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Loc {
    /// The file as shown in messages.
    pub(crate) file: Arc<str>,
    /// 1-based line.
    pub(crate) line: u32,
    /// 1-based column (in characters).
    pub(crate) col: u32,
}

impl Loc {
    /// An error here: `file: line L: column C: message`, the form every
    /// Sahara scene error has.
    pub(crate) fn error(&self, message: impl std::fmt::Display) -> FormatError {
        let message = message.to_string().replace(['\n', '\r'], " ");
        FormatError::at_line(
            &self.file,
            self.line as usize,
            format!("column {}: {message}", self.col),
        )
    }

    /// `file:line:column`, for warnings.
    pub(crate) fn short(&self) -> String {
        format!("{}:{}:{}", self.file, self.line, self.col)
    }
}
