//! `sahara-denoise`: Intel Open Image Denoise (OIDN), loaded at run time.
//!
//! [`Denoiser::load`] finds the OIDN 2 library and makes a device;
//! [`Denoiser::denoise`] runs OIDN's "RT" filter on a linear RGB image
//! ([`Image`]), guided by albedo and normal images when given ([`Aux`]),
//! and returns the denoised pixels. Plain `f32` buffers in and out; no other
//! Sahara crate is needed.
//!
//! OIDN is a C library that this crate neither links nor downloads: a build
//! works without it, and [`Denoiser::load`] says in one line how to get it
//! when it is missing ([`DenoiseError::NotFound`]). It looks, in order, in
//!
//! 1. `OIDN_DIR`: the library file, a folder holding it, or an unpacked
//!    OIDN release (the library in its `lib/`);
//! 2. the system loader's search path (`LD_LIBRARY_PATH`, the system's
//!    library folders), as `libOpenImageDenoise.so.2`, then `.so`;
//! 3. an installed `pyoidn` Python package (`pip install pyoidn`: the
//!    official binaries and their trained weights, in `pyoidn/oidn/lib/`):
//!    asking the interpreter `SAHARA_PYTHON` names, then reading the active
//!    virtual environment (`VIRTUAL_ENV`), then asking `python3`, then
//!    reading the `site-packages` of the other `python3*` on `PATH` and of
//!    `~/.local`.
//!
//! The first library that loads and is OIDN 2 or newer is used for the rest
//! of the process (it is never unloaded); [`Denoiser::location`] and
//! [`Denoiser::version`] say which, for the log.
//!
//! ```no_run
//! use sahara_denoise::{Aux, Denoiser, Image};
//!
//! # fn main() -> Result<(), sahara_denoise::DenoiseError> {
//! let (width, height) = (64, 48);
//! let color = vec![0.5f32; width * height * 3];
//! let albedo = vec![0.8f32; width * height * 3];
//! let normal = [0.0f32, 0.0, 1.0].repeat(width * height);
//! let denoiser = Denoiser::load()?;
//! eprintln!("Open Image Denoise {} from {}", denoiser.version(), denoiser.location());
//! let image = Image { width, height, color: &color, hdr: true };
//! let denoised = denoiser.denoise(&image, Aux::albedo_normal(&albedo, &normal))?;
//! assert_eq!(denoised.len(), color.len());
//! # Ok(())
//! # }
//! ```

#![deny(missing_docs)]

mod denoiser;
mod error;
mod ffi;
mod search;

pub use denoiser::{Aux, Denoiser, Image, Version};
pub use error::DenoiseError;
pub use search::{FoundBy, Location};
