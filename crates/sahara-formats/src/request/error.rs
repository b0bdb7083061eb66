//! Why a request is refused, naming what asked for the refused thing in
//! the words of the front end that asked: `--noise-threshold` on the
//! command line, `noise_threshold` in Python, "the scene file's
//! noise_threshold" for either.

use super::table::Setting;

/// What asked for something refused.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Asked {
    /// A setting the caller gave, with the value that matters where one
    /// does (`--split tiles`).
    Caller(&'static str, Option<&'static str>),
    /// The scene file, in its words (`noise_threshold`, `crop window`).
    File(&'static str),
    /// The scene itself (`integrator`, when the file or the default
    /// chose it).
    Scene(&'static str),
}

/// How a front end names what asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spelling {
    /// The command line's options: `--noise-threshold`, `--split tiles`.
    CommandLine,
    /// Python's keyword arguments: `noise_threshold`, `split="tiles"`.
    Python,
}

impl Asked {
    /// What asked, as `how` names it.
    pub fn spelled(&self, how: Spelling) -> String {
        match self {
            Asked::Caller(name, value) => {
                let setting = Setting::named(name);
                match (how, setting, value) {
                    (Spelling::CommandLine, Some(s), None) => s.flag(),
                    (Spelling::CommandLine, Some(s), Some(v)) => format!("{} {v}", s.flag()),
                    (Spelling::Python, Some(s), None) => s.keyword.to_string(),
                    (Spelling::Python, Some(s), Some(v)) => format!("{}=\"{v}\"", s.keyword),
                    (_, None, _) => name.to_string(),
                }
            }
            Asked::File(what) => format!("the scene file's {what}"),
            Asked::Scene(what) => format!("the scene's {what}"),
        }
    }
}

/// Why a render cannot be made as asked. Each is one line once spelled
/// ([`RequestError::message`]).
#[derive(Clone, Debug, PartialEq)]
pub enum RequestError {
    /// What `asked` for is refused, for `reason`.
    Refused {
        /// What asked for it.
        asked: Asked,
        /// Why it is refused.
        reason: String,
    },
    /// The render would not fit in the memory available; the message
    /// gives the estimate.
    Memory(String),
    /// A file is at fault: the output cannot be written, the scene is
    /// invalid, a part file cannot be written. The message names it.
    File(String),
    /// Open Image Denoise cannot be loaded, or failed.
    Denoiser {
        /// What asked for denoising.
        asked: Asked,
        /// What went wrong.
        reason: String,
    },
}

impl RequestError {
    /// What `asked` for is refused, for `reason`.
    pub(crate) fn refused(asked: Asked, reason: impl Into<String>) -> Self {
        RequestError::Refused {
            asked,
            reason: reason.into(),
        }
    }

    /// The error as one line, naming what asked as `how` spells it.
    pub fn message(&self, how: Spelling) -> String {
        match self {
            RequestError::Refused { asked, reason } | RequestError::Denoiser { asked, reason } => {
                format!("{}: {reason}", asked.spelled(how))
            }
            RequestError::Memory(m) | RequestError::File(m) => m.clone(),
        }
    }
}

impl From<sahara_readers::FormatError> for RequestError {
    fn from(e: sahara_readers::FormatError) -> Self {
        RequestError::File(e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_front_end_names_what_asked_its_way() {
        let cases = [
            (
                Asked::Caller("noise_threshold", None),
                "--noise-threshold",
                "noise_threshold",
            ),
            (Asked::Caller("aov", None), "--aov", "aovs"),
            (
                Asked::Caller("split", Some("tiles")),
                "--split tiles",
                "split=\"tiles\"",
            ),
            (
                Asked::File("crop window"),
                "the scene file's crop window",
                "the scene file's crop window",
            ),
        ];
        for (asked, cli, py) in cases {
            assert_eq!(asked.spelled(Spelling::CommandLine), cli);
            assert_eq!(asked.spelled(Spelling::Python), py);
        }
        let e = RequestError::refused(Asked::Caller("aov", None), "no passes here");
        assert_eq!(e.message(Spelling::CommandLine), "--aov: no passes here");
        assert_eq!(e.message(Spelling::Python), "aovs: no passes here");
    }
}
