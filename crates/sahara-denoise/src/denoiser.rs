//! The denoiser: one Open Image Denoise device, and its "RT" filter run on
//! plain RGB buffers.

use std::ffi::{c_char, c_void, CStr};
use std::fmt;

use crate::error::DenoiseError;
use crate::ffi::{self, Api};
use crate::search::{find_and_load_once, Loaded, Location, SearchRoots};

/// An image to denoise: linear RGB, three `f32` a pixel, rows top to bottom,
/// `width * height * 3` values.
#[derive(Clone, Copy, Debug)]
pub struct Image<'a> {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The beauty image: `width * height * 3` values, row-major, RGB.
    pub color: &'a [f32],
    /// Whether the values are linear radiance of any magnitude (HDR, a
    /// renderer's output); `false` means linear values in `[0, 1]`.
    pub hdr: bool,
}

/// Auxiliary images that guide the denoiser, each the size of the
/// [`Image`] (`width * height * 3` values), and what to assume about them.
///
/// Open Image Denoise takes an albedo alone, or an albedo and a normal; a
/// normal alone is refused ([`DenoiseError::NormalWithoutAlbedo`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Aux<'a> {
    /// The albedo (the surface's colour independent of lighting) of the
    /// first visible hit, RGB in `[0, 1]`.
    pub albedo: Option<&'a [f32]>,
    /// The shading normal of the first visible hit, world- (or view-) space,
    /// components in `[-1, 1]`.
    pub normal: Option<&'a [f32]>,
    /// The albedo and normal are free of noise (Open Image Denoise's
    /// `cleanAux`): sharper results, but any noise in them stays in the
    /// output. Set it only for noise-free buffers, e.g. rendered without
    /// depth of field or motion blur. It matters only when both albedo and
    /// normal are given.
    pub clean_aux: bool,
    /// Denoise the albedo and normal first, each with its own filter, then
    /// denoise the beauty with them as clean (`cleanAux`), as Open Image
    /// Denoise recommends for final frames whose auxiliary buffers are noisy
    /// (averaged over a pixel's samples, which see different surfaces
    /// through depth of field or motion blur).
    ///
    /// It pays where the auxiliary buffers are visibly noisy and the frame
    /// is final: it removes the residual noise they would leave and keeps
    /// texture detail sharper. It is expensive: three networks run instead
    /// of one, each (at Open Image Denoise's default, highest quality)
    /// larger than the one without prefiltering; on a 2-core CPU it took 7
    /// to 12 times as long (`docs/clean-image.md`). With clean
    /// buffers it gains nothing: set [`Aux::clean_aux`] instead. It applies
    /// only when both albedo and normal are given (Open Image Denoise has no
    /// clean-albedo-only mode); otherwise it is ignored.
    pub prefilter_aux: bool,
}

impl<'a> Aux<'a> {
    /// No auxiliary images: the beauty alone.
    pub fn none() -> Aux<'a> {
        Aux::default()
    }

    /// An albedo and a normal buffer, taken as noisy (neither `clean_aux`
    /// nor `prefilter_aux`).
    pub fn albedo_normal(albedo: &'a [f32], normal: &'a [f32]) -> Aux<'a> {
        Aux {
            albedo: Some(albedo),
            normal: Some(normal),
            ..Aux::default()
        }
    }
}

/// Open Image Denoise's version, as the device reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Version {
    /// Major version.
    pub major: u32,
    /// Minor version.
    pub minor: u32,
    /// Patch version.
    pub patch: u32,
}

impl Version {
    /// From the device's combined `version` (two decimal digits a part:
    /// 20501 is 2.5.1).
    pub(crate) fn from_combined(v: u32) -> Version {
        Version {
            major: v / 10000,
            minor: v / 100 % 100,
            patch: v % 100,
        }
    }
}

impl fmt::Display for Version {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}.{}", self.major, self.minor, self.patch)
    }
}

/// Intel Open Image Denoise, loaded at run time, with one device.
///
/// The device is the library's default choice: a supported GPU if there is
/// one, else the CPU (all its cores). Images go through the library's own
/// buffers, so either works.
///
/// `Denoiser` is `Send` and `Sync`: Open Image Denoise's calls are
/// thread-safe (those on one device run one at a time), errors are kept per
/// thread, and each [`Denoiser::denoise`] makes and releases its own filters
/// and buffers. Calls from several threads therefore queue on the device;
/// a denoiser per thread gains nothing on one device.
pub struct Denoiser {
    api: Api,
    device: ffi::Device,
    location: Location,
    version: Version,
}

// SAFETY: the device handle is used only through Open Image Denoise's API,
// whose calls are all thread-safe ("All API calls are thread-safe, but
// operations that use the same device will be serialized", the API
// documentation); errors are stored per thread, so each call reads its own.
// Nothing else in a `Denoiser` is tied to a thread.
unsafe impl Send for Denoiser {}
// SAFETY: as for `Send`: `&Denoiser` only reaches thread-safe API calls, and
// the filters and buffers of a call are never shared with another.
unsafe impl Sync for Denoiser {}

impl fmt::Debug for Denoiser {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Denoiser")
            .field("location", &self.location)
            .field("version", &self.version)
            .finish_non_exhaustive()
    }
}

impl Drop for Denoiser {
    fn drop(&mut self) {
        // SAFETY: `device` is the live device this `Denoiser` created and
        // owns; nothing uses it after this.
        unsafe { (self.api.release_device)(self.device) };
    }
}

/// An Open Image Denoise buffer or filter, released when dropped.
struct Handle {
    ptr: *mut c_void,
    release: unsafe extern "C" fn(*mut c_void),
}

impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: `ptr` is a live buffer or filter (never null: see
        // `Denoiser::handle`) that this `Handle` owns, and `release` is the
        // release function of its kind.
        unsafe { (self.release)(self.ptr) };
    }
}

impl Denoiser {
    /// Finds Open Image Denoise, loads it and makes a device: from
    /// `OIDN_DIR`, else the system library path, else an installed `pyoidn`
    /// Python package (the search and its order: the crate's
    /// documentation).
    ///
    /// Fails with [`DenoiseError::NotFound`] (one line: where it looked, how
    /// to get the library), [`DenoiseError::Load`] for a library that is
    /// there but unusable, or [`DenoiseError::Oidn`] with the library's
    /// message when it cannot make a device.
    ///
    /// The library found first is kept for the rest of the process: later
    /// calls make a new device on it without searching.
    pub fn load() -> Result<Denoiser, DenoiseError> {
        Denoiser::with_library(find_and_load_once(&SearchRoots::from_env())?)
    }

    /// A denoiser with a device on `loaded`.
    fn with_library(loaded: Loaded) -> Result<Denoiser, DenoiseError> {
        let Loaded { api, location } = loaded;
        // SAFETY: a plain call with a valid device type.
        let device = unsafe { (api.new_device)(ffi::DEVICE_TYPE_DEFAULT) };
        if device.is_null() {
            // Why a device could not be made is kept as a global error.
            return Err(error(&api, std::ptr::null_mut(), "create a device")
                .unwrap_or_else(|| oidn_error("create a device", 1, "no device and no message")));
        }
        let mut denoiser = Denoiser {
            api,
            device,
            location,
            version: Version::from_combined(0),
        };
        // SAFETY: `device` is live and not yet committed.
        unsafe { (api.commit_device)(device) };
        denoiser.check("set up the device")?;
        // SAFETY: a live device and a NUL-terminated parameter name.
        let combined = unsafe { (api.get_device_int)(device, c"version".as_ptr()) };
        denoiser.check("report its version")?;
        denoiser.version = Version::from_combined(u32::try_from(combined).unwrap_or(0));
        Ok(denoiser)
    }

    /// The library's version, e.g. 2.5.1.
    pub fn version(&self) -> Version {
        self.version
    }

    /// The library file in use and how it was found, for the log.
    pub fn location(&self) -> &Location {
        &self.location
    }

    /// Denoises `image` with the auxiliary images of `aux`, returning the
    /// denoised beauty: `width * height * 3` values, linear RGB, as given.
    ///
    /// Uses Open Image Denoise's "RT" filter (for Monte Carlo ray-traced
    /// images), at its default (highest) quality. The sizes are checked
    /// before the library sees anything ([`DenoiseError::Size`],
    /// [`DenoiseError::Empty`], [`DenoiseError::NormalWithoutAlbedo`]);
    /// the library's own failures come back as [`DenoiseError::Oidn`] with
    /// its message.
    pub fn denoise(&self, image: &Image, aux: Aux) -> Result<Vec<f32>, DenoiseError> {
        let len = validate(image, &aux)?;
        let (width, height) = (image.width, image.height);
        // Clear an error a panicked earlier call on this thread may have left.
        let _ = error(&self.api, self.device, "");

        let color = self.buffer(image.color, "hold the beauty image")?;
        let albedo = aux
            .albedo
            .map(|a| self.buffer(a, "hold the albedo"))
            .transpose()?;
        let normal = aux
            .normal
            .map(|n| self.buffer(n, "hold the normal"))
            .transpose()?;

        let mut clean_aux = aux.clean_aux;
        if let (true, Some(albedo), Some(normal)) = (aux.prefilter_aux, &albedo, &normal) {
            // Each auxiliary image is the only input of its own filter and
            // is denoised in place (in the library's buffer, not the
            // caller's).
            for (name, buffer, doing) in [
                (c"albedo", albedo, "denoise the albedo"),
                (c"normal", normal, "denoise the normal"),
            ] {
                let filter = self.filter(&[(name, buffer)], buffer, &[], width, height, doing)?;
                self.execute(&filter, doing)?;
            }
            clean_aux = true;
        }

        let mut inputs = vec![(c"color", &color)];
        inputs.extend(albedo.as_ref().map(|a| (c"albedo", a)));
        inputs.extend(normal.as_ref().map(|n| (c"normal", n)));
        let options = [(c"hdr", image.hdr), (c"cleanAux", clean_aux)];
        let doing = "denoise the image";
        let filter = self.filter(&inputs, &color, &options, width, height, doing)?;
        self.execute(&filter, doing)?;

        let mut out = vec![0f32; len];
        // SAFETY: `color` holds `len` floats (made from the validated
        // beauty) and `out` has room for exactly that many bytes' worth.
        unsafe {
            (self.api.read_buffer)(
                color.ptr,
                0,
                std::mem::size_of_val(out.as_slice()),
                out.as_mut_ptr().cast(),
            )
        };
        self.check("read the denoised image")?;
        Ok(out)
    }

    /// The device's first pending error as a [`DenoiseError::Oidn`].
    fn check(&self, doing: &'static str) -> Result<(), DenoiseError> {
        match error(&self.api, self.device, doing) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Wraps a buffer or filter just made, or returns the device's error
    /// (also when the handle is null without one).
    fn handle(
        &self,
        ptr: *mut c_void,
        release: unsafe extern "C" fn(*mut c_void),
        doing: &'static str,
    ) -> Result<Handle, DenoiseError> {
        let checked = self.check(doing);
        let handle = (!ptr.is_null()).then_some(Handle { ptr, release });
        checked?;
        handle.ok_or_else(|| oidn_error(doing, 1, "no object and no message"))
    }

    /// A device buffer holding a copy of `data`.
    fn buffer(&self, data: &[f32], doing: &'static str) -> Result<Handle, DenoiseError> {
        let bytes = std::mem::size_of_val(data);
        // SAFETY: a live device; any size is allowed.
        let ptr = unsafe { (self.api.new_buffer)(self.device, bytes) };
        let buffer = self.handle(ptr, self.api.release_buffer, doing)?;
        // SAFETY: the buffer holds `bytes` bytes and `data` is that long.
        unsafe { (self.api.write_buffer)(buffer.ptr, 0, bytes, data.as_ptr().cast()) };
        self.check(doing)?;
        Ok(buffer)
    }

    /// A committed "RT" filter over `width x height` RGB float images:
    /// `inputs` by name, `output`, and boolean options.
    fn filter(
        &self,
        inputs: &[(&CStr, &Handle)],
        output: &Handle,
        options: &[(&CStr, bool)],
        width: usize,
        height: usize,
        doing: &'static str,
    ) -> Result<Handle, DenoiseError> {
        // SAFETY: a live device and a NUL-terminated filter type.
        let ptr = unsafe { (self.api.new_filter)(self.device, c"RT".as_ptr()) };
        let filter = self.handle(ptr, self.api.release_filter, doing)?;
        let images = inputs.iter().copied().chain([(c"output", output)]);
        for (name, buffer) in images {
            // SAFETY: a live filter, a NUL-terminated name, and a live
            // buffer of `width * height` three-float pixels (each buffer is
            // made from a slice validated to that length); zero strides
            // mean packed pixels and rows. The filter holds its own
            // reference to the buffer.
            unsafe {
                (self.api.set_filter_image)(
                    filter.ptr,
                    name.as_ptr(),
                    buffer.ptr,
                    ffi::FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    0,
                    0,
                )
            };
        }
        for (name, value) in options {
            // SAFETY: a live filter and a NUL-terminated parameter name.
            unsafe { (self.api.set_filter_bool)(filter.ptr, name.as_ptr(), *value) };
        }
        // SAFETY: a live filter with its images set.
        unsafe { (self.api.commit_filter)(filter.ptr) };
        self.check(doing)?;
        Ok(filter)
    }

    /// Runs a committed filter to completion.
    fn execute(&self, filter: &Handle, doing: &'static str) -> Result<(), DenoiseError> {
        // SAFETY: a live, committed filter whose buffers are alive; the call
        // blocks until the filter is done.
        unsafe { (self.api.execute_filter)(filter.ptr) };
        self.check(doing)
    }
}

/// Checks the sizes of `image` and `aux` against each other; the number of
/// floats of each buffer.
pub(crate) fn validate(image: &Image, aux: &Aux) -> Result<usize, DenoiseError> {
    let (width, height) = (image.width, image.height);
    if width == 0 || height == 0 {
        return Err(DenoiseError::Empty { width, height });
    }
    let expected = width
        .checked_mul(height)
        .and_then(|pixels| pixels.checked_mul(3))
        // The byte count must fit as well.
        .filter(|floats| floats.checked_mul(size_of::<f32>()).is_some());
    let buffers = [
        ("beauty", Some(image.color)),
        ("albedo", aux.albedo),
        ("normal", aux.normal),
    ];
    for (buffer, data) in buffers {
        let Some(data) = data else { continue };
        if Some(data.len()) != expected {
            return Err(DenoiseError::Size {
                buffer,
                len: data.len(),
                width,
                height,
                expected: expected.unwrap_or(usize::MAX),
            });
        }
    }
    if aux.normal.is_some() && aux.albedo.is_none() {
        return Err(DenoiseError::NormalWithoutAlbedo);
    }
    Ok(expected.unwrap_or(0))
}

/// The first pending error of `device` (null: the thread's global errors)
/// as a [`DenoiseError::Oidn`], clearing it; `None` if there is none.
fn error(api: &Api, device: ffi::Device, doing: &'static str) -> Option<DenoiseError> {
    let mut message: *const c_char = std::ptr::null();
    // SAFETY: `device` is live or null (allowed: the global errors);
    // `message` is a valid place for the library to store a pointer.
    let code = unsafe { (api.get_device_error)(device, &mut message) };
    if code == ffi::ERROR_NONE {
        return None;
    }
    let message = if message.is_null() {
        String::from("no message")
    } else {
        // SAFETY: a non-null message is a NUL-terminated string that stays
        // valid until the next call on this device from this thread; it is
        // copied at once.
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    };
    Some(oidn_error(doing, code, &message))
}

/// A [`DenoiseError::Oidn`].
fn oidn_error(doing: &'static str, code: i32, message: &str) -> DenoiseError {
    DenoiseError::Oidn {
        doing,
        code,
        message: message.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: usize, height: usize, color: &[f32]) -> Image<'_> {
        Image {
            width,
            height,
            color,
            hdr: true,
        }
    }

    #[test]
    fn sizes_are_checked_before_the_library_is_called() {
        let rgb = vec![0.0f32; 4 * 3 * 3];
        let short = vec![0.0f32; 4 * 3 * 3 - 1];
        assert_eq!(validate(&image(4, 3, &rgb), &Aux::none()).unwrap(), 36);
        let aux = Aux::albedo_normal(&rgb, &rgb);
        assert_eq!(validate(&image(4, 3, &rgb), &aux).unwrap(), 36);

        let e = validate(&image(4, 3, &short), &Aux::none()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the beauty buffer has 35 values; a 4x3 RGB image needs 36"
        );
        let e = validate(&image(4, 3, &rgb), &Aux::albedo_normal(&rgb, &short)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the normal buffer has 35 values; a 4x3 RGB image needs 36"
        );
        let e = validate(&image(3, 4, &rgb), &Aux::albedo_normal(&short, &rgb)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the albedo buffer has 35 values; a 3x4 RGB image needs 36"
        );
    }

    #[test]
    fn empty_and_overflowing_images_are_refused() {
        let e = validate(&image(0, 3, &[]), &Aux::none()).unwrap_err();
        assert_eq!(e.to_string(), "the image to denoise is empty (0x3)");
        let rgb = [0.0f32; 3];
        let e = validate(&image(usize::MAX / 2, 3, &rgb), &Aux::none()).unwrap_err();
        assert!(
            matches!(
                e,
                DenoiseError::Size {
                    expected: usize::MAX,
                    len: 3,
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn a_normal_needs_an_albedo() {
        let rgb = vec![0.0f32; 2 * 2 * 3];
        let aux = Aux {
            normal: Some(&rgb),
            ..Aux::none()
        };
        let e = validate(&image(2, 2, &rgb), &aux).unwrap_err();
        assert!(matches!(e, DenoiseError::NormalWithoutAlbedo), "{e}");
    }

    #[test]
    fn versions_read_two_digits_a_part() {
        let v = Version::from_combined(20501);
        assert_eq!((v.major, v.minor, v.patch), (2, 5, 1));
        assert_eq!(v.to_string(), "2.5.1");
        assert_eq!(Version::from_combined(100203).to_string(), "10.2.3");
    }
}
