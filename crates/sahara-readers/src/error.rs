//! The one error type of the readers (and of `sahara-formats`, which
//! re-exports it): what went wrong, in which file, where.
//!
//! Every message is a single line of the form `<file>: <where>: <what>` so a
//! person can go straight to the offending spot.

use std::io;
use std::path::Path;

/// Why a file could not be loaded; `Display` is one actionable line naming the file.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// The file could not be opened or read.
    #[error("{path}: cannot read the file: {source}")]
    Io {
        /// The file, as given by the caller.
        path: String,
        /// What the operating system said.
        #[source]
        source: io::Error,
    },
    /// The file could not be written (or a temporary file beside it could not be made).
    #[error("{path}: cannot write the file: {source}")]
    Write {
        /// The file, as given by the caller.
        path: String,
        /// What the operating system said.
        #[source]
        source: io::Error,
    },
    /// A problem at a 1-based line of a text file (or of a PLY header).
    #[error("{path}: line {line}: {message}")]
    AtLine {
        /// The file, as given by the caller.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What was wrong.
        message: String,
    },
    /// A problem at a 0-based byte offset (from the start of the file) of binary data.
    #[error("{path}: byte {offset}: {message}")]
    AtByte {
        /// The file, as given by the caller.
        path: String,
        /// 0-based byte offset from the start of the file.
        offset: u64,
        /// What was wrong.
        message: String,
    },
    /// A problem that could not be pinned to a line or byte (the message says why).
    #[error("{path}: {message}")]
    InFile {
        /// The file, as given by the caller.
        path: String,
        /// What was wrong.
        message: String,
    },
    /// `load_mesh` was given a file whose extension is not a mesh format it knows.
    #[error("{path}: {}", unsupported_mesh(extension))]
    UnsupportedExtension {
        /// The file, as given by the caller.
        path: String,
        /// The extension found ("" if there is none).
        extension: String,
    },
}

impl FormatError {
    /// The same error with its message rewritten by `f` (the file and its
    /// line or byte offset are kept; errors without a message are unchanged).
    pub fn map_message(self, f: impl FnOnce(String) -> String) -> FormatError {
        match self {
            FormatError::AtLine {
                path,
                line,
                message,
            } => FormatError::AtLine {
                path,
                line,
                message: f(message),
            },
            FormatError::AtByte {
                path,
                offset,
                message,
            } => FormatError::AtByte {
                path,
                offset,
                message: f(message),
            },
            FormatError::InFile { path, message } => FormatError::InFile {
                path,
                message: f(message),
            },
            other => other,
        }
    }

    /// An I/O error while reading `path`.
    pub fn io(path: &Path, source: io::Error) -> Self {
        FormatError::Io {
            path: path.display().to_string(),
            source,
        }
    }

    /// An I/O error while writing `path`.
    pub fn write(path: &Path, source: io::Error) -> Self {
        FormatError::Write {
            path: path.display().to_string(),
            source,
        }
    }

    /// A problem at 1-based `line` of the file called `path`.
    pub fn at_line(path: &str, line: usize, message: impl Into<String>) -> Self {
        FormatError::AtLine {
            path: path.to_owned(),
            line,
            message: message.into(),
        }
    }

    /// A problem at 0-based byte `offset` of the file called `path`.
    pub fn at_byte(path: &str, offset: u64, message: impl Into<String>) -> Self {
        FormatError::AtByte {
            path: path.to_owned(),
            offset,
            message: message.into(),
        }
    }

    /// A problem in the file called `path` that has no known position.
    pub fn in_file(path: &str, message: impl Into<String>) -> Self {
        FormatError::InFile {
            path: path.to_owned(),
            message: message.into(),
        }
    }
}

/// The message of [`FormatError::UnsupportedExtension`].
fn unsupported_mesh(extension: &str) -> String {
    let expected = "expected a mesh (.obj, .ply, .gltf or .glb)";
    if extension.is_empty() {
        format!("the file name has no extension; {expected}")
    } else {
        format!("unsupported mesh file extension {extension:?}; {expected}")
    }
}

/// `error` with line breaks in its message shown as `\n` (and trailing ones
/// dropped), keeping the promise that every error is one line.
///
/// Messages quote the input (the toml and gltf crates quote values, the
/// image crate ends some messages with a newline), and a value can hold line
/// breaks: fuzzing found `name = """distribution` + newlines in a scene file
/// and a truncated JPEG giving multi-line errors. Used by the glTF and image
/// readers here and by `sahara-formats`' scene-file reader.
pub fn one_line(error: FormatError) -> FormatError {
    let fix = |message: String| {
        let trimmed = message.trim_end();
        if trimmed.contains(['\n', '\r']) {
            trimmed
                .replace("\r\n", "\\n")
                .replace('\n', "\\n")
                .replace('\r', "\\r")
        } else if trimmed.len() != message.len() {
            trimmed.to_owned()
        } else {
            message
        }
    };
    error.map_message(fix)
}

/// A serde message in a user's words: Rust's type names (`expected f32`,
/// `expected u32`) become `a number` / `a whole number`, and the position
/// serde_json appends (` at line 1 column 49`) is dropped (the caller
/// gives it once, in front). Used by the glTF reader here and by
/// `sahara-formats`' scene-file reader.
pub fn in_words(message: &str) -> String {
    let mut m = message.to_owned();
    if let Some(at) = m.rfind(" at line ") {
        let tail = &m[at + " at line ".len()..];
        let mut parts = tail.splitn(3, ' ');
        let position = (parts.next(), parts.next(), parts.next());
        let is_number = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        if let (Some(line), Some("column"), Some(column)) = position {
            if is_number(line) && is_number(column) {
                m.truncate(at);
            }
        }
    }
    let mut m = [
        ("index into child of root", "an index (a whole number)"),
        ("expected a boolean", "expected true or false"),
        ("expected a sequence", "expected a list [...]"),
    ]
    .iter()
    .fold(m, |m, (rust, words)| m.replace(rust, words));
    for (types, words) in [
        (&["f32", "f64"][..], "a number"),
        (
            &[
                "u8", "u16", "u32", "u64", "usize", "i8", "i16", "i32", "i64", "isize",
            ][..],
            "a whole number",
        ),
    ] {
        for t in types {
            m = replace_word(&m, &format!("expected {t}"), &format!("expected {words}"));
        }
    }
    m
}

/// `text` with every `word` that is not followed by a letter, digit or
/// `_` (so `f32` but not `f32x4`) replaced by `with`.
fn replace_word(text: &str, word: &str, with: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(word) {
        let after = &rest[at + word.len()..];
        let whole = !after.starts_with(|c: char| c.is_alphanumeric() || c == '_');
        out.push_str(&rest[..at]);
        out.push_str(if whole { with } else { word });
        rest = after;
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod words_tests {
    use super::in_words;

    #[test]
    fn type_names_and_positions_become_words() {
        assert_eq!(
            in_words("invalid type: string \"x\", expected f32 at line 1 column 82"),
            "invalid type: string \"x\", expected a number"
        );
        assert_eq!(
            in_words(
                "invalid type: integer `-1`, expected index into child of root at line 1 column 49"
            ),
            "invalid type: integer `-1`, expected an index (a whole number)"
        );
        assert_eq!(
            in_words("invalid value: expected u32"),
            "invalid value: expected a whole number"
        );
        assert_eq!(
            in_words("expected i64 here"),
            "expected a whole number here"
        );
        // Not a position: kept.
        assert_eq!(in_words("a name at line two"), "a name at line two");
        assert_eq!(in_words("expected f32x4"), "expected f32x4");
    }
}
