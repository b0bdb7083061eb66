//! Checks shared by the fuzz targets.

#[cfg(feature = "parsers")]
use sahara_readers::FormatError;

/// Asserts the promise of `sahara_readers::error`: every error is one line
/// that starts with the file's name.
#[cfg(feature = "parsers")]
pub fn check_error(error: &FormatError, name: &str) {
    let message = error.to_string();
    assert!(
        message.starts_with(&format!("{name}: ")),
        "error does not start with the file name: {message:?}"
    );
    assert!(
        !message.contains('\n'),
        "error is not one line: {message:?}"
    );
}

/// Asserts a loaded mesh is usable: one triangle per index triple, every
/// index in range.
pub fn check_mesh(positions: &[glam::Vec3], indices: &[[u32; 3]]) {
    for (t, tri) in indices.iter().enumerate() {
        for &i in tri {
            assert!(
                (i as usize) < positions.len(),
                "triangle {t} has index {i} but there are {} positions",
                positions.len()
            );
        }
    }
}

/// The largest single allocation a target may make: libFuzzer's
/// `-rss_limit_mb` that `run.sh` passes.
const ALLOCATION_LIMIT: usize = 2048 << 20;

/// The system allocator, aborting on any single allocation over
/// [`ALLOCATION_LIMIT`] (which libFuzzer records as a crash, with its
/// input). libFuzzer's own `-malloc_limit_mb` works through a sanitizer's
/// allocator hooks, and the readers' targets are built without a
/// sanitizer (`run.sh`); an allocation sized from a file's header that
/// is never touched would not show in the resident size either.
struct Limited;

/// Aborts, allocating nothing, if `size` is over [`ALLOCATION_LIMIT`],
/// after saying so on the standard error.
fn check_size(size: usize) {
    use std::io::Write;
    if size > ALLOCATION_LIMIT {
        let _ = std::io::stderr().write_all(b"allocation over the fuzz targets' 2 GiB limit\n");
        std::process::abort()
    }
}

// SAFETY: every call is passed on to the system allocator unchanged; the
// limit only refuses, before any memory is handed out.
unsafe impl std::alloc::GlobalAlloc for Limited {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        check_size(layout.size());
        std::alloc::System.alloc(layout)
    }

    unsafe fn alloc_zeroed(&self, layout: std::alloc::Layout) -> *mut u8 {
        check_size(layout.size());
        std::alloc::System.alloc_zeroed(layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new_size: usize) -> *mut u8 {
        check_size(new_size);
        std::alloc::System.realloc(ptr, layout, new_size)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        std::alloc::System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static ALLOCATOR: Limited = Limited;
