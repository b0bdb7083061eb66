//! Finding and loading the Open Image Denoise library, in the order the
//! crate's documentation gives: `OIDN_DIR`, the system loader, `pyoidn`.
//!
//! Asking an interpreter where `pyoidn` is (`importlib.util.find_spec`,
//! which does not import the package) costs one process start, some tens
//! of milliseconds; it happens only when the places before it fail, and at
//! most twice.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use libloading::Library;

use crate::error::DenoiseError;
use crate::ffi::Api;

/// The library's file names, most specific first.
#[cfg(all(unix, not(target_os = "macos")))]
pub(crate) const LIBRARY_NAMES: &[&str] = &["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];
/// The library's file names, most specific first.
#[cfg(target_os = "macos")]
pub(crate) const LIBRARY_NAMES: &[&str] =
    &["libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib"];
/// The library's file names, most specific first.
#[cfg(windows)]
pub(crate) const LIBRARY_NAMES: &[&str] = &["OpenImageDenoise.dll"];

/// The folder of a release (and of `pyoidn`'s `oidn/`) holding the library.
#[cfg(not(windows))]
const LIBRARY_FOLDER: &str = "lib";
/// The folder of a release (and of `pyoidn`'s `oidn/`) holding the library.
#[cfg(windows)]
const LIBRARY_FOLDER: &str = "bin";

/// How long an interpreter may take to say where `pyoidn` is.
const PYTHON_TIMEOUT: Duration = Duration::from_secs(10);

/// Where a loaded library was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FoundBy {
    /// Through the `OIDN_DIR` environment variable.
    OidnDir,
    /// By the system loader's search path.
    SystemPath,
    /// In an installed `pyoidn` Python package.
    Pyoidn,
}

impl std::fmt::Display for FoundBy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FoundBy::OidnDir => "OIDN_DIR",
            FoundBy::SystemPath => "the system library path",
            FoundBy::Pyoidn => "pyoidn",
        })
    }
}

/// The library a [`crate::Denoiser`] uses: its file and how it was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The library file; for the system loader, the file it chose where the
    /// platform can tell (else the name it was given).
    pub path: PathBuf,
    /// How it was found.
    pub found_by: FoundBy,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (through {})", self.path.display(), self.found_by)
    }
}

/// The places to search, read from the environment by
/// [`SearchRoots::from_env`]; tests make their own.
#[derive(Clone, Debug, Default)]
pub(crate) struct SearchRoots {
    /// `OIDN_DIR`, if set and not empty.
    pub(crate) oidn_dir: Option<PathBuf>,
    /// Whether to ask the system loader for the library by name.
    pub(crate) system: bool,
    /// `SAHARA_PYTHON`: an interpreter asked first.
    pub(crate) python_first: Option<OsString>,
    /// Python prefixes (virtual environments) whose `site-packages` are read
    /// before asking [`SearchRoots::python`]: `VIRTUAL_ENV`.
    pub(crate) venvs: Vec<PathBuf>,
    /// The interpreter asked after them: `python3`.
    pub(crate) python: Option<OsString>,
    /// Python prefixes (and `~/.local`) whose `site-packages` are read last.
    pub(crate) prefixes: Vec<PathBuf>,
}

impl SearchRoots {
    /// The places this process searches: see the module's documentation.
    pub(crate) fn from_env() -> SearchRoots {
        let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
        let mut prefixes = Vec::new();
        if let Some(path) = var("PATH") {
            for dir in std::env::split_paths(&path) {
                if has_python(&dir) {
                    // `/bin` is often `/usr/bin`: one prefix, `/usr`.
                    let dir = dir.canonicalize().unwrap_or(dir);
                    if let Some(prefix) = dir.parent() {
                        push_new(&mut prefixes, prefix.to_path_buf());
                    }
                }
            }
        }
        if let Some(home) = var("HOME") {
            push_new(&mut prefixes, Path::new(&home).join(".local"));
        }
        SearchRoots {
            oidn_dir: var("OIDN_DIR").map(PathBuf::from),
            system: true,
            python_first: var("SAHARA_PYTHON"),
            venvs: var("VIRTUAL_ENV").map(PathBuf::from).into_iter().collect(),
            python: Some(OsString::from(if cfg!(windows) {
                "python"
            } else {
                "python3"
            })),
            prefixes,
        }
    }
}

/// Pushes `path` unless it is there already.
fn push_new(paths: &mut Vec<PathBuf>, path: PathBuf) {
    if !paths.contains(&path) {
        paths.push(path);
    }
}

/// Whether `dir` holds a `python3*` (`python.exe` on Windows) executable.
fn has_python(dir: &Path) -> bool {
    if cfg!(windows) {
        return dir.join("python.exe").is_file();
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    entries.flatten().any(|e| {
        let name = e.file_name();
        let name = name.to_string_lossy();
        name.starts_with("python3") && !name.contains("-config")
    })
}

/// A library found and loaded, with its entry points.
#[derive(Clone)]
pub(crate) struct Loaded {
    pub(crate) api: Api,
    pub(crate) location: Location,
}

/// The library this process loaded through [`find_and_load_once`].
static LOADED: Mutex<Option<Loaded>> = Mutex::new(None);

/// [`find_and_load`] the first time it succeeds in this process, then the
/// library it found (it stays loaded, and the system loader would hand back
/// the same one by name).
pub(crate) fn find_and_load_once(roots: &SearchRoots) -> Result<Loaded, DenoiseError> {
    let mut loaded = LOADED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(found) = &*loaded {
        return Ok(found.clone());
    }
    let found = find_and_load(roots)?;
    *loaded = Some(found.clone());
    Ok(found)
}

/// Searches `roots` in order and loads the first library that is Open Image
/// Denoise 2 or newer.
///
/// A library file that exists but does not load (a missing dependency, an
/// older version) is remembered: if nothing else loads, that is the error,
/// rather than [`DenoiseError::NotFound`].
pub(crate) fn find_and_load(roots: &SearchRoots) -> Result<Loaded, DenoiseError> {
    let mut searched = Vec::new();
    let mut failure = None;

    if let Some(dir) = &roots.oidn_dir {
        searched.push(format!("OIDN_DIR={}", dir.display()));
        let files = library_files_in(&[dir.clone(), dir.join(LIBRARY_FOLDER)], dir);
        if let Some(loaded) = load_first(&files, FoundBy::OidnDir, &mut failure) {
            return Ok(loaded);
        }
    }

    if roots.system {
        searched.push(format!(
            "the system library path ({})",
            LIBRARY_NAMES.join(", ")
        ));
        for name in LIBRARY_NAMES {
            // SAFETY: loading runs the library's initialisers; a library
            // under Open Image Denoise's name is trusted to be it, as the
            // system loader would trust it for a program linked to it.
            if let Ok(library) = unsafe { Library::new(*name) } {
                match Api::load(library) {
                    Ok(api) => {
                        let path = loaded_path(&api).unwrap_or_else(|| PathBuf::from(name));
                        let found_by = FoundBy::SystemPath;
                        let location = Location { path, found_by };
                        return Ok(Loaded { api, location });
                    }
                    Err(missing) => {
                        failure.get_or_insert(not_oidn2(Path::new(name), missing));
                    }
                }
            }
        }
    }

    // pyoidn: each place gives the package's folder, or nothing.
    let mut places: Vec<(String, PackageFinder)> = Vec::new();
    if let Some(python) = &roots.python_first {
        let place = format!("pyoidn for SAHARA_PYTHON={}", python.to_string_lossy());
        places.push((place, Box::new(|| ask_python(python))));
    }
    for venv in &roots.venvs {
        let place = format!("pyoidn in {}", venv.display());
        places.push((place, Box::new(|| pyoidn_in_prefix(venv))));
    }
    // Each place once: the interpreter asked first may be the one on PATH,
    // and an activated virtual environment is also a prefix on PATH.
    if let Some(python) = roots
        .python
        .as_ref()
        .filter(|p| roots.python_first.as_ref() != Some(*p))
    {
        let place = format!("pyoidn for {}", python.to_string_lossy());
        places.push((place, Box::new(|| ask_python(python))));
    }
    let prefixes: Vec<&PathBuf> = roots
        .prefixes
        .iter()
        .filter(|p| !roots.venvs.iter().any(|v| same_folder(v, p)))
        .collect();
    if !prefixes.is_empty() {
        let list: Vec<String> = prefixes.iter().map(|p| p.display().to_string()).collect();
        let place = format!("pyoidn in {}", list.join(", "));
        places.push((
            place,
            Box::new(move || prefixes.iter().find_map(|p| pyoidn_in_prefix(p))),
        ));
    }
    for (place, package) in places {
        searched.push(place);
        if let Some(package) = package() {
            let oidn = package.join("oidn");
            let files = library_files_in(&[oidn.join(LIBRARY_FOLDER)], &oidn);
            if let Some(loaded) = load_first(&files, FoundBy::Pyoidn, &mut failure) {
                return Ok(loaded);
            }
        }
    }

    Err(failure.unwrap_or(DenoiseError::NotFound { searched }))
}

/// True if `a` and `b` name the same folder (as written, or once resolved).
fn same_folder(a: &Path, b: &Path) -> bool {
    a == b || matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// A way to find the `pyoidn` package's folder.
type PackageFinder<'a> = Box<dyn Fn() -> Option<PathBuf> + 'a>;

/// Loads the first of `files` that is Open Image Denoise 2; the first
/// failure is kept in `failure` (unless it holds one already).
fn load_first(
    files: &[PathBuf],
    found_by: FoundBy,
    failure: &mut Option<DenoiseError>,
) -> Option<Loaded> {
    for file in files {
        match load_file(file) {
            Ok(api) => {
                let location = Location {
                    path: file.clone(),
                    found_by,
                };
                return Some(Loaded { api, location });
            }
            Err(e) => {
                failure.get_or_insert(e);
            }
        }
    }
    None
}

/// The library files to try for a path that is either the library itself
/// (`path` a file) or a folder: each of `LIBRARY_NAMES` in each of `dirs`
/// that exists.
pub(crate) fn library_files_in(dirs: &[PathBuf], path: &Path) -> Vec<PathBuf> {
    if path.is_file() {
        return vec![path.to_path_buf()];
    }
    dirs.iter()
        .flat_map(|dir| LIBRARY_NAMES.iter().map(move |name| dir.join(name)))
        .filter(|file| file.is_file())
        .collect()
}

/// Loads the library file at `path` and resolves its entry points.
fn load_file(path: &Path) -> Result<Api, DenoiseError> {
    // SAFETY: as for the system loader's library in `find_and_load`: a file
    // under Open Image Denoise's name in a place named for it is trusted to
    // be that library; loading it runs its initialisers.
    let library = unsafe { Library::new(path) }.map_err(|e| DenoiseError::Load {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    Api::load(library).map_err(|missing| not_oidn2(path, missing))
}

/// The error for a library that lacks an Open Image Denoise 2 function.
fn not_oidn2(path: &Path, missing: &str) -> DenoiseError {
    DenoiseError::Load {
        path: path.to_path_buf(),
        reason: format!("it has no {missing}: Open Image Denoise 2 or newer is needed"),
    }
}

/// The file the system loader took the library from, where the platform
/// says (`dladdr` on one of its functions).
#[cfg(unix)]
fn loaded_path(api: &Api) -> Option<PathBuf> {
    use std::os::unix::ffi::OsStrExt;
    let mut info = std::mem::MaybeUninit::<libc::Dl_info>::zeroed();
    // SAFETY: `dladdr` only reads the address and fills `info`; the address
    // is a function of a library that stays loaded.
    let found = unsafe { libc::dladdr(api.new_device as *const libc::c_void, info.as_mut_ptr()) };
    if found == 0 {
        return None;
    }
    // SAFETY: `dladdr` succeeded, so it filled `info`.
    let info = unsafe { info.assume_init() };
    if info.dli_fname.is_null() {
        return None;
    }
    // SAFETY: `dli_fname` is a NUL-terminated string owned by the loader,
    // valid while the library is loaded (for the rest of the process).
    let name = unsafe { std::ffi::CStr::from_ptr(info.dli_fname) };
    Some(PathBuf::from(std::ffi::OsStr::from_bytes(name.to_bytes())))
}

/// The file the system loader took the library from: not asked on this
/// platform.
#[cfg(not(unix))]
fn loaded_path(_api: &Api) -> Option<PathBuf> {
    None
}

/// The `pyoidn` package folder in the `site-packages` of the Python prefix
/// (or virtual environment) `prefix`, if there is one.
pub(crate) fn pyoidn_in_prefix(prefix: &Path) -> Option<PathBuf> {
    let mut site_dirs = vec![prefix.join("Lib").join("site-packages")];
    if let Ok(entries) = std::fs::read_dir(prefix.join("lib")) {
        let mut versions: Vec<(u32, PathBuf)> = entries
            .flatten()
            .filter_map(|e| {
                let name = e.file_name();
                let minor = name.to_str()?.strip_prefix("python3.")?.parse().ok()?;
                Some((minor, e.path().join("site-packages")))
            })
            .collect();
        versions.sort();
        // The newest first (python3.12 before python3.9).
        site_dirs.extend(versions.into_iter().rev().map(|(_, dir)| dir));
    }
    site_dirs
        .into_iter()
        .map(|site| site.join("pyoidn"))
        .find(|package| package.join("oidn").is_dir())
}

/// Asks the interpreter `python` where the `pyoidn` package is, without
/// importing it; `None` if it cannot say within `PYTHON_TIMEOUT`.
fn ask_python(python: &std::ffi::OsStr) -> Option<PathBuf> {
    const SCRIPT: &str = "import importlib.util, os\n\
        s = importlib.util.find_spec('pyoidn')\n\
        print(os.path.dirname(s.origin) if s and s.origin else '')";
    let mut child = Command::new(python)
        .args(["-c", SCRIPT])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(_)) => break,
            Ok(None) if start.elapsed() < PYTHON_TIMEOUT => {
                std::thread::sleep(Duration::from_millis(5))
            }
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                return None;
            }
        }
    }
    let output = child.wait_with_output().ok()?;
    let dir = String::from_utf8(output.stdout).ok()?;
    let dir = dir.trim();
    (output.status.success() && !dir.is_empty()).then(|| PathBuf::from(dir))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `test` in a new empty folder `name` of this test process's own
    /// temporary folder, then removes it (kept if the test fails).
    fn in_scratch(name: &str, test: impl FnOnce(&Path)) {
        let process = format!("sahara-denoise-tests-{}", std::process::id());
        let dir = std::env::temp_dir().join(process).join(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        test(&dir);
        let _ = std::fs::remove_dir_all(&dir);
        // The process's folder goes with the last test's.
        let _ = std::fs::remove_dir(dir.parent().unwrap());
    }

    /// Roots that search only what a test names: no system loader, no
    /// interpreter.
    fn only(oidn_dir: Option<PathBuf>) -> SearchRoots {
        SearchRoots {
            oidn_dir,
            ..SearchRoots::default()
        }
    }

    #[test]
    fn an_empty_oidn_dir_is_not_found_and_says_how_to_get_the_library() {
        in_scratch("empty", |scratch| {
            let (dir, venv) = (scratch.join("oidn"), scratch.join("venv"));
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::create_dir_all(&venv).unwrap();
            let roots = SearchRoots {
                venvs: vec![venv.clone()],
                ..only(Some(dir.clone()))
            };
            let e = find_and_load(&roots)
                .err()
                .expect("an empty folder has no library");
            assert!(matches!(e, DenoiseError::NotFound { .. }), "{e}");
            assert_eq!(
                e.to_string(),
                format!(
                    "Open Image Denoise not found (looked in OIDN_DIR={}, pyoidn in {}); \
                     get it with `pip install pyoidn`, or set OIDN_DIR to the folder of an \
                     Open Image Denoise release",
                    dir.display(),
                    venv.display()
                )
            );
            assert!(!e.to_string().contains('\n'));
        });
    }

    #[test]
    fn the_not_found_message_names_every_place_in_order() {
        let roots = SearchRoots {
            oidn_dir: Some(PathBuf::from("/nonexistent/oidn")),
            python_first: Some(OsString::from("/nonexistent/python")),
            venvs: vec![PathBuf::from("/nonexistent/venv")],
            python: Some(OsString::from("/nonexistent/python3")),
            prefixes: vec![
                PathBuf::from("/nonexistent/a"),
                PathBuf::from("/nonexistent/b"),
            ],
            ..SearchRoots::default()
        };
        let message = find_and_load(&roots).err().unwrap().to_string();
        assert!(
            message.contains(
                "(looked in OIDN_DIR=/nonexistent/oidn, \
                 pyoidn for SAHARA_PYTHON=/nonexistent/python, pyoidn in /nonexistent/venv, \
                 pyoidn for /nonexistent/python3, pyoidn in /nonexistent/a, /nonexistent/b)"
            ),
            "{message}"
        );
    }

    #[test]
    fn the_not_found_message_names_each_place_once() {
        // SAHARA_PYTHON is the python3 on PATH, and the virtual environment
        // is activated (its bin on PATH, so a prefix too).
        let venv = PathBuf::from("/nonexistent/venv");
        let roots = SearchRoots {
            python_first: Some(OsString::from("python3")),
            venvs: vec![venv.clone()],
            python: Some(OsString::from("python3")),
            prefixes: vec![venv, PathBuf::from("/nonexistent/usr")],
            ..SearchRoots::default()
        };
        let message = find_and_load(&roots).err().unwrap().to_string();
        assert!(
            message.contains(
                "(looked in pyoidn for SAHARA_PYTHON=python3, pyoidn in /nonexistent/venv, \
                 pyoidn in /nonexistent/usr)"
            ),
            "{message}"
        );
    }

    #[test]
    fn a_file_that_is_not_the_library_is_a_load_error_naming_it() {
        in_scratch("bogus", |dir| {
            // OIDN_DIR as a release folder with a bogus library in lib/.
            std::fs::create_dir_all(dir.join(LIBRARY_FOLDER)).unwrap();
            let file = dir.join(LIBRARY_FOLDER).join(LIBRARY_NAMES[0]);
            std::fs::write(&file, b"not a shared library").unwrap();
            let e = find_and_load(&only(Some(dir.to_path_buf()))).err().unwrap();
            assert!(
                matches!(&e, DenoiseError::Load { path, .. } if path == &file),
                "{e}"
            );
            let start = format!(
                "could not load Open Image Denoise from {}: ",
                file.display()
            );
            assert!(e.to_string().starts_with(&start), "{e}");
            // OIDN_DIR as the file itself.
            let e = find_and_load(&only(Some(file.clone()))).err().unwrap();
            assert!(
                matches!(&e, DenoiseError::Load { path, .. } if path == &file),
                "{e}"
            );
        });
    }

    #[test]
    fn oidn_dir_may_be_the_library_its_folder_or_a_release() {
        in_scratch("release", |release| {
            let lib = release.join(LIBRARY_FOLDER);
            std::fs::create_dir_all(&lib).unwrap();
            let release_dirs = [release.to_path_buf(), lib.clone()];
            assert!(library_files_in(&release_dirs, release).is_empty());
            let file = lib.join(LIBRARY_NAMES[LIBRARY_NAMES.len() - 1]);
            std::fs::write(&file, b"").unwrap();
            let found = vec![file.clone()];
            assert_eq!(library_files_in(&release_dirs, release), found);
            assert_eq!(
                library_files_in(&[lib.clone(), lib.join("lib")], &lib),
                found
            );
            assert_eq!(library_files_in(&[], &file), found);
        });
    }

    #[test]
    fn pyoidn_is_found_in_a_prefix_newest_python_first() {
        in_scratch("prefix", |prefix| {
            assert_eq!(pyoidn_in_prefix(prefix), None);
            for version in ["python3.9", "python3.12"] {
                let package = prefix
                    .join("lib")
                    .join(version)
                    .join("site-packages/pyoidn");
                std::fs::create_dir_all(package.join("oidn")).unwrap();
            }
            // A package folder without the binaries does not count.
            std::fs::create_dir_all(prefix.join("lib/python3.13/site-packages/pyoidn")).unwrap();
            let newest = prefix.join("lib/python3.12/site-packages/pyoidn");
            assert_eq!(pyoidn_in_prefix(prefix), Some(newest));
        });
    }

    #[test]
    fn a_missing_interpreter_is_no_answer() {
        assert_eq!(
            ask_python(std::ffi::OsStr::new("/nonexistent/python3")),
            None
        );
    }

    #[test]
    fn a_pyoidn_package_without_a_usable_library_is_a_load_error() {
        in_scratch("pyoidn", |prefix| {
            let package = prefix.join("lib/python3.11/site-packages/pyoidn");
            let lib = package.join("oidn").join(LIBRARY_FOLDER);
            std::fs::create_dir_all(&lib).unwrap();
            std::fs::write(lib.join(LIBRARY_NAMES[0]), b"").unwrap();
            let roots = SearchRoots {
                prefixes: vec![prefix.to_path_buf()],
                ..only(None)
            };
            let e = find_and_load(&roots).err().unwrap();
            assert!(
                matches!(&e, DenoiseError::Load { path, .. } if path.starts_with(&lib)),
                "{e}"
            );
        });
    }
}
