//! What can go wrong: the library missing or unusable, images of the wrong
//! size, and Open Image Denoise's own errors.

use std::path::PathBuf;

/// Why a [`crate::Denoiser`] could not be made or could not denoise. Each
/// displays as one line.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    /// No Open Image Denoise library was found in any of the places searched.
    #[error(
        "Open Image Denoise not found (looked in {}); get it with `pip install pyoidn`, \
         or set OIDN_DIR to the folder of an Open Image Denoise release",
        .searched.join(", ")
    )]
    NotFound {
        /// The places searched, in order, each as a short phrase
        /// (`OIDN_DIR=/opt/oidn`, `the system library path`, ...).
        searched: Vec<String>,
    },
    /// A library was found but could not be loaded or is not Open Image
    /// Denoise 2 or newer.
    #[error("could not load Open Image Denoise from {}: {reason}", .path.display())]
    Load {
        /// The library file (or, for the system loader, its name).
        path: PathBuf,
        /// The system loader's message, or what the library lacks.
        reason: String,
    },
    /// Open Image Denoise reported an error.
    #[error("Open Image Denoise could not {doing}: {message}")]
    Oidn {
        /// What was being done (`create a device`, `denoise the image`, ...).
        doing: &'static str,
        /// Open Image Denoise's error code (`OIDNError`).
        code: i32,
        /// Open Image Denoise's own message.
        message: String,
    },
    /// The image has no pixels.
    #[error("the image to denoise is empty ({width}x{height})")]
    Empty {
        /// The image's width in pixels.
        width: usize,
        /// The image's height in pixels.
        height: usize,
    },
    /// A buffer's length is not three floats per pixel of the image.
    #[error("the {buffer} buffer has {len} values; a {width}x{height} RGB image needs {expected}")]
    Size {
        /// Which buffer: `beauty`, `albedo` or `normal`.
        buffer: &'static str,
        /// Its length in floats.
        len: usize,
        /// The image's width in pixels.
        width: usize,
        /// The image's height in pixels.
        height: usize,
        /// The length it should have (`width * height * 3`), saturated at
        /// `usize::MAX` where that overflows.
        expected: usize,
    },
    /// A normal buffer was given without an albedo buffer, a combination
    /// Open Image Denoise does not take.
    #[error("a normal buffer needs an albedo buffer too (Open Image Denoise takes normals only with albedo)")]
    NormalWithoutAlbedo,
}
