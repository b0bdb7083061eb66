//! The part of Open Image Denoise 2's C API (`OpenImageDenoise/oidn.h`) this
//! crate calls, resolved from a loaded library by name.

use std::ffi::{c_char, c_int, c_void};

use libloading::Library;

/// `OIDNDevice`: an opaque handle.
pub(crate) type Device = *mut c_void;
/// `OIDNFilter`: an opaque handle.
pub(crate) type Filter = *mut c_void;
/// `OIDNBuffer`: an opaque handle.
pub(crate) type Buffer = *mut c_void;

/// `OIDN_DEVICE_TYPE_DEFAULT`: the library picks the device (a supported
/// GPU if there is one, else the CPU).
pub(crate) const DEVICE_TYPE_DEFAULT: c_int = 0;
/// `OIDN_ERROR_NONE`.
pub(crate) const ERROR_NONE: c_int = 0;
/// `OIDN_FORMAT_FLOAT3`: three 32-bit floats a pixel.
pub(crate) const FORMAT_FLOAT3: c_int = 3;

/// The entry points, copied out of the library as plain function pointers.
///
/// They stay valid for the rest of the process: the library they come from
/// is never unloaded (see [`Api::load`]).
#[derive(Clone, Copy)]
pub(crate) struct Api {
    pub(crate) new_device: unsafe extern "C" fn(c_int) -> Device,
    pub(crate) commit_device: unsafe extern "C" fn(Device),
    pub(crate) release_device: unsafe extern "C" fn(Device),
    pub(crate) get_device_int: unsafe extern "C" fn(Device, *const c_char) -> c_int,
    pub(crate) get_device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> c_int,
    pub(crate) new_buffer: unsafe extern "C" fn(Device, usize) -> Buffer,
    pub(crate) release_buffer: unsafe extern "C" fn(Buffer),
    pub(crate) write_buffer: unsafe extern "C" fn(Buffer, usize, usize, *const c_void),
    pub(crate) read_buffer: unsafe extern "C" fn(Buffer, usize, usize, *mut c_void),
    pub(crate) new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    pub(crate) release_filter: unsafe extern "C" fn(Filter),
    #[allow(clippy::type_complexity)]
    pub(crate) set_filter_image: unsafe extern "C" fn(
        Filter,
        *const c_char,
        Buffer,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    pub(crate) set_filter_bool: unsafe extern "C" fn(Filter, *const c_char, bool),
    pub(crate) commit_filter: unsafe extern "C" fn(Filter),
    pub(crate) execute_filter: unsafe extern "C" fn(Filter),
}

impl Api {
    /// Resolves every entry point of `library`, then keeps the library
    /// loaded for the rest of the process.
    ///
    /// It is never unloaded because Open Image Denoise's thread pool (oneTBB)
    /// keeps worker threads running its code after a device is released;
    /// unloading under them would crash. Loading the same file again only
    /// raises the system loader's count, so nothing is loaded twice.
    ///
    /// Fails with the name of the first missing function (a library that is
    /// not Open Image Denoise 2 or newer: 1.x lacks `oidnSetFilterBool`).
    pub(crate) fn load(library: Library) -> Result<Api, &'static str> {
        macro_rules! resolve {
            ($name:literal) => {
                // SAFETY: the symbol is an Open Image Denoise 2 function and
                // the field it is stored in has that function's C signature
                // (`oidn.h`); the pointer is copied out of the `Symbol` and
                // stays valid because the library is never unloaded (below).
                unsafe {
                    *library
                        .get(concat!($name, "\0").as_bytes())
                        .map_err(|_| $name)?
                }
            };
        }
        let api = Api {
            new_device: resolve!("oidnNewDevice"),
            commit_device: resolve!("oidnCommitDevice"),
            release_device: resolve!("oidnReleaseDevice"),
            get_device_int: resolve!("oidnGetDeviceInt"),
            get_device_error: resolve!("oidnGetDeviceError"),
            new_buffer: resolve!("oidnNewBuffer"),
            release_buffer: resolve!("oidnReleaseBuffer"),
            write_buffer: resolve!("oidnWriteBuffer"),
            read_buffer: resolve!("oidnReadBuffer"),
            new_filter: resolve!("oidnNewFilter"),
            release_filter: resolve!("oidnReleaseFilter"),
            set_filter_image: resolve!("oidnSetFilterImage"),
            set_filter_bool: resolve!("oidnSetFilterBool"),
            commit_filter: resolve!("oidnCommitFilter"),
            execute_filter: resolve!("oidnExecuteFilter"),
        };
        std::mem::forget(library);
        Ok(api)
    }
}
