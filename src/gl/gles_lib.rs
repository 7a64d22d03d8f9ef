//! Which OpenGL ES implementation the process renders with: the system's `libEGL.so.1` (Mesa
//! on a Linux desktop or CI machine, the vendor's driver on a phone), or the `libEGL` and
//! `libGLESv2` of a folder named by [`select`] or the `MANYLIGHT_GLES_LIB` environment variable
//! (SwiftShader, ANGLE, a device's own driver; docs/drivers.md).
//!
//! The libraries are loaded once per process and stay loaded: EGL displays, contexts and the
//! GL function pointers handed to glow all point into them. One process uses one
//! implementation; `manylight matrix` compares several by running one child process each.
#![allow(unsafe_code)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use khronos_egl as egl;

use super::GlError;
use crate::scene::shown;

/// The environment variable naming the folder of the GLES implementation to load.
pub const GLES_LIB_ENV: &str = "MANYLIGHT_GLES_LIB";

pub(crate) type Egl = egl::DynamicInstance<egl::EGL1_4>;

/// The loaded implementation: its EGL entry points and, for a chosen folder, its GLES library.
pub struct GlesLibrary {
    egl: Egl,
    /// The folder's `libGLESv2`, loaded before its `libEGL` (whose own dependency on
    /// `libGLESv2.so` it satisfies) and searched for GL entry points EGL does not hand out.
    gles: Option<libloading::Library>,
    folder: Option<PathBuf>,
    /// Every entry point looked up so far, null ones included. EGL's addresses do not depend on
    /// the display or context, and SwiftShader's `eglGetProcAddress` tries to load a library
    /// on each call: glow's ~700 names took about 70 ms a context there.
    found: Mutex<HashMap<Box<str>, usize>>,
}

/// The folder chosen by [`select`] before the first load (it wins over the variable).
static SELECTED: Mutex<Option<PathBuf>> = Mutex::new(None);
static LOADED: OnceLock<Result<GlesLibrary, String>> = OnceLock::new();

/// Chooses the folder holding `libEGL.so[.1]` and `libGLESv2.so[.2]` for this process, over
/// `MANYLIGHT_GLES_LIB`: a folder that is not one or lacks either library is an error at once.
/// Must come before the first context; choosing another folder after that is an error (the
/// first stays loaded, or its failure stands).
pub fn select(folder: &Path) -> Result<(), GlError> {
    let folder = folder.to_path_buf();
    if let Some(loaded) = LOADED.get() {
        let current = match loaded {
            Ok(l) => l.folder.clone(),
            Err(e) => {
                return Err(GlError::GlesLibrary(format!(
                    "loading the GLES implementation failed already ({e}); {} must be chosen \
                     before the first context, and a process loads one implementation once",
                    shown::path(&folder)
                )))
            }
        };
        if !current.as_deref().is_some_and(|c| same_folder(c, &folder)) {
            return Err(GlError::GlesLibrary(format!(
                "the GLES implementation is already loaded ({}); {} must be chosen before the first context",
                current.map_or("the system's".into(), |f| shown::path(&f)),
                shown::path(&folder)
            )));
        }
        return Ok(());
    }
    library_files(&folder, Origin::Selected).map_err(GlError::GlesLibrary)?;
    *SELECTED.lock().unwrap_or_else(|e| e.into_inner()) = Some(folder);
    Ok(())
}

/// Whether two paths name one folder (`swiftshader` from its parent and its absolute path).
fn same_folder(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// Where a folder was named, for messages.
#[derive(Clone, Copy)]
enum Origin {
    /// [`select`] (the command line's `--gles-lib` calls it).
    Selected,
    /// The environment variable.
    Environment,
    /// Either (a folder `manylight matrix` compares).
    Either,
}

impl Origin {
    fn says(self) -> String {
        match self {
            Origin::Selected => "chosen with select_gles_library or --gles-lib".into(),
            Origin::Environment => format!("from {GLES_LIB_ENV}"),
            Origin::Either => format!("from --gles-lib or {GLES_LIB_ENV}"),
        }
    }
}

/// The folder this process loads (or will load) its implementation from, if not the system's.
pub fn chosen_folder() -> Option<PathBuf> {
    if let Some(Ok(l)) = LOADED.get() {
        return l.folder.clone();
    }
    SELECTED
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .clone()
        .or_else(|| {
            std::env::var_os(GLES_LIB_ENV)
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
        })
}

/// The process's implementation, loaded on first use.
pub fn library() -> Result<&'static GlesLibrary, GlError> {
    LOADED
        .get_or_init(|| {
            let selected = SELECTED.lock().unwrap_or_else(|e| e.into_inner()).is_some();
            let origin = if selected {
                Origin::Selected
            } else {
                Origin::Environment
            };
            GlesLibrary::load(chosen_folder(), origin)
        })
        .as_ref()
        .map_err(|e| match chosen_folder() {
            Some(_) => GlError::GlesLibrary(e.clone()),
            None => GlError::EglLoad(e.clone()),
        })
}

/// The `libGLESv2` and `libEGL` files of `folder`, loaded by nothing yet: an error naming
/// the folder when it is not one or lacks either.
pub fn files_in(folder: &Path) -> Result<(PathBuf, PathBuf), GlError> {
    library_files(folder, Origin::Either).map_err(GlError::GlesLibrary)
}

fn library_files(folder: &Path, origin: Origin) -> Result<(PathBuf, PathBuf), String> {
    if !folder.is_dir() {
        return Err(format!(
            "{} ({}) is not a folder",
            shown::path(folder),
            origin.says()
        ));
    }
    let gles_path = find_in(folder, &["libGLESv2.so.2", "libGLESv2.so"], origin)?;
    let egl_path = find_in(folder, &["libEGL.so.1", "libEGL.so"], origin)?;
    Ok((gles_path, egl_path))
}

/// The first of `names` that exists in `folder`.
fn find_in(folder: &Path, names: &[&str], origin: Origin) -> Result<PathBuf, String> {
    names
        .iter()
        .map(|n| folder.join(n))
        .find(|p| p.is_file())
        .ok_or_else(|| {
            format!(
                "{} ({}) holds none of {}",
                shown::path(folder),
                origin.says(),
                names.join(", ")
            )
        })
}

impl GlesLibrary {
    fn load(folder: Option<PathBuf>, origin: Origin) -> Result<GlesLibrary, String> {
        let Some(folder) = folder else {
            let egl = unsafe { Egl::load_required_from_filename("libEGL.so.1") }
                .or_else(|_| unsafe { Egl::load_required_from_filename("libEGL.so") })
                .map_err(|e| e.to_string())?;
            return Ok(GlesLibrary {
                egl,
                gles: None,
                folder: None,
                found: Mutex::default(),
            });
        };
        let (gles_path, egl_path) = library_files(&folder, origin)?;
        // SAFETY: loading a GLES implementation runs its initialisers; that is what the user
        // asked for by naming the folder.
        let gles = unsafe { libloading::Library::new(&gles_path) }
            .map_err(|e| format!("cannot load {}: {e}", shown::path(&gles_path)))?;
        let egl = unsafe { Egl::load_required_from_filename(&egl_path) }
            .map_err(|e| format!("cannot load {}: {e}", shown::path(&egl_path)))?;
        Ok(GlesLibrary {
            egl,
            gles: Some(gles),
            folder: Some(folder),
            found: Mutex::default(),
        })
    }

    pub(crate) fn egl(&self) -> &Egl {
        &self.egl
    }

    /// The folder it came from (`None`: the system's libraries).
    pub fn folder(&self) -> Option<&Path> {
        self.folder.as_deref()
    }

    /// A GL or EGL entry point: `eglGetProcAddress`, else (EGL 1.4 need not hand out core
    /// functions) the folder's `libGLESv2` itself. Null when neither has it. Each name is
    /// looked up once per process.
    pub fn proc_address(&self, name: &str) -> *const std::ffi::c_void {
        let mut found = self.found.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(&address) = found.get(name) {
            return address as *const std::ffi::c_void;
        }
        let address = self.look_up(name);
        found.insert(name.into(), address as usize);
        address
    }

    fn look_up(&self, name: &str) -> *const std::ffi::c_void {
        if let Some(f) = self.egl.get_proc_address(name) {
            return f as *const std::ffi::c_void;
        }
        let Some(gles) = &self.gles else {
            return std::ptr::null();
        };
        let Ok(cname) = std::ffi::CString::new(name) else {
            return std::ptr::null();
        };
        // SAFETY: the symbol is only turned into an address; callers give it the type the
        // GL specification gives that name.
        unsafe { gles.get::<*const std::ffi::c_void>(cname.as_bytes_with_nul()) }
            .map_or(std::ptr::null(), |s| *s)
    }
}

/// The implementation this process loaded, if it has loaded one (without loading it).
pub(crate) fn loaded() -> Option<&'static GlesLibrary> {
    LOADED.get().and_then(|l| l.as_ref().ok())
}

/// The EGL context current on this thread, as an address (`Some(None)`: none), when this
/// process loaded EGL; `None` when it cannot tell (a context from elsewhere, say WGL).
pub(crate) fn current_context() -> Option<Option<usize>> {
    match LOADED.get() {
        Some(Ok(lib)) => Some(lib.egl().get_current_context().map(|c| c.as_ptr() as usize)),
        _ => None,
    }
}

/// The EGL and GLES library files this process has mapped (from `/proc/self/maps`), for
/// `manylight info`: which files the implementation really is, whichever way it was chosen.
pub fn loaded_files() -> Vec<PathBuf> {
    let Ok(maps) = std::fs::read_to_string("/proc/self/maps") else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = Vec::new();
    for path in maps.lines().filter_map(|l| l.split_whitespace().nth(5)) {
        let name = path.rsplit('/').next().unwrap_or("");
        let gl_lib = [
            "libEGL",
            "libGLES",
            "libGLX",
            "libGLdispatch",
            "libgallium",
            "swrast",
            "_dri.so",
        ]
        .iter()
        .any(|p| name.contains(p));
        if gl_lib && !files.iter().any(|f| f == Path::new(path)) {
            files.push(PathBuf::from(path));
        }
    }
    files
}
