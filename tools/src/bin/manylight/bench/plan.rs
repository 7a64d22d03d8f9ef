//! The sweep `manylight bench` runs: its options with the `--quick` or full defaults filled
//! in, and how many frames each row times.

use std::path::PathBuf;

use manylight::methods::METHODS;
use manylight::scene::{self, shown};
use manylight::EsVersion;

use super::BenchArgs;

/// The sweep, with the `--quick` or full defaults filled in.
pub(super) struct Plan {
    pub(super) scenes: Vec<String>,
    pub(super) lights: Vec<usize>,
    pub(super) methods: Vec<String>,
    pub(super) es: Vec<EsVersion>,
    pub(super) size: (u32, u32),
    pub(super) frames: Frames,
    pub(super) knobs: bool,
    pub(super) animated_frames: u32,
}

/// How many frames a configuration times.
#[derive(Clone, Copy, Debug)]
pub(super) enum Frames {
    /// What `--frames` (or `--quick`) says.
    Fixed(u32),
    /// Nine, or three for a configuration whose first (untimed) frame took over
    /// [`SLOW_FRAME_MS`]: the median of three lets one slow pool wake-up decide a fast row's
    /// assignment time, while nine frames of every slow row make the full sweep much longer.
    Adaptive,
}

/// A first frame slower than this makes an adaptive row time three frames, not nine.
const SLOW_FRAME_MS: f64 = 100.0;

/// The frames an adaptive row times, from an untimed frame of it: three where that frame took
/// over [`SLOW_FRAME_MS`], else nine; `None` where it built shader programs, whose compiling
/// says nothing of the configuration: the next frame decides.
pub(super) fn adaptive_frames(untimed: &manylight::FrameStats) -> Option<u32> {
    (untimed.programs_built == 0).then(|| frames_for(untimed.time.frame_ms))
}

/// Three frames for a configuration whose frame takes `ms` past [`SLOW_FRAME_MS`], else nine.
pub(super) fn frames_for(ms: f64) -> u32 {
    if ms > SLOW_FRAME_MS {
        3
    } else {
        9
    }
}

impl Plan {
    pub(super) fn from(args: &BenchArgs) -> Plan {
        let or = |given: &[String], default: Vec<String>| {
            if given.is_empty() {
                default
            } else {
                given.to_vec()
            }
        };
        let scenes = if !args.scenes.is_empty() {
            args.scenes.clone()
        } else if args.quick {
            vec![scene::builtin::DEFAULT.to_string()]
        } else {
            let mut s: Vec<String> = scene::builtin::NAMES
                .iter()
                .map(|n| n.to_string())
                .collect();
            if let Some(c) = conference() {
                s.push(c);
            }
            s
        };
        let lights = match (&args.lights[..], args.quick) {
            ([], true) => vec![0, 64, 1024],
            ([], false) => vec![0, 8, 64, 256, 1024, 4096],
            (given, _) => once("--lights", given.to_vec()),
        };
        let es = match (&args.es[..], args.quick) {
            ([], true) => vec![EsVersion::Es2, EsVersion::Es3],
            ([], false) => vec![EsVersion::Es2, EsVersion::Es3],
            (given, _) => once("--es", given.iter().map(|&e| e.into()).collect()),
        };
        let default_size = if args.quick { (320, 180) } else { (640, 360) };
        Plan {
            scenes,
            lights,
            methods: once(
                "--methods",
                or(
                    &args.methods,
                    METHODS.iter().map(|m| m.name.to_string()).collect(),
                ),
            ),
            es,
            size: args.size.unwrap_or(default_size),
            frames: match args.frames {
                Some(n) => Frames::Fixed(n),
                None if args.quick => Frames::Fixed(1),
                None => Frames::Adaptive,
            },
            knobs: !args.no_knobs,
            animated_frames: args
                .animated_frames
                .unwrap_or(if args.quick { 20 } else { 120 }),
        }
    }
}

/// The conference room of $MANYLIGHT_ASSETS, when set and present; otherwise says why the
/// row is left out.
fn conference() -> Option<String> {
    conference_in(std::env::var_os("MANYLIGHT_ASSETS"))
        .map_err(|why| eprintln!("bench: the conference-room rows are left out: {why}"))
        .ok()
}

/// The conference room's OBJ in the assets folder `assets`, as the scene name bench loads, or
/// why there is none. Scene names are UTF-8, so a folder whose path is not cannot be loaded.
fn conference_in(assets: Option<std::ffi::OsString>) -> Result<String, String> {
    const HOW: &str = "set MANYLIGHT_ASSETS to a folder with the real scenes \
        (scripts/fetch-assets; docs/assets.md)";
    let obj = assets
        .map(|dir| PathBuf::from(dir).join("conference/conference.obj"))
        .filter(|obj| obj.is_file())
        .ok_or_else(|| HOW.to_string())?;
    obj.into_os_string().into_string().map_err(|obj| {
        format!(
            "MANYLIGHT_ASSETS's {} is not UTF-8, which scene paths must be; {HOW}",
            shown::path(std::path::Path::new(&obj))
        )
    })
}

/// `items` with each value once, in their first order; a warning where `flag` listed one
/// twice (`--methods forward,forward` measured every row twice).
fn once<T: PartialEq>(flag: &str, items: Vec<T>) -> Vec<T> {
    let given = items.len();
    let mut kept: Vec<T> = Vec::with_capacity(given);
    for item in items {
        if !kept.contains(&item) {
            kept.push(item);
        }
    }
    if kept.len() < given {
        log::warn!("{flag} lists a value more than once: each is measured once");
    }
    kept
}

pub(super) fn scene_name(spec: &str) -> String {
    std::path::Path::new(spec)
        .file_stem()
        .map_or(spec.to_string(), |s| s.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use std::os::unix::ffi::OsStrExt;

    use super::*;

    #[test]
    fn the_conference_room_is_found_or_its_absence_explained() {
        let root = tempfile::tempdir().unwrap();
        let utf8 = root.path().join("assets");
        let other = root.path().join(std::ffi::OsStr::from_bytes(b"assets\xff"));
        for dir in [&utf8, &other] {
            std::fs::create_dir_all(dir.join("conference")).unwrap();
            std::fs::write(dir.join("conference/conference.obj"), "").unwrap();
        }
        let found = conference_in(Some(utf8.clone().into())).unwrap();
        assert!(std::path::Path::new(&found).is_file(), "{found}");
        let why = conference_in(Some(other.into())).unwrap_err();
        assert!(
            why.contains("is not UTF-8") && why.contains("/assets\u{fffd}/conference/"),
            "{why}"
        );
        let why = conference_in(None).unwrap_err();
        assert!(why.contains("set MANYLIGHT_ASSETS"), "{why}");
        let why = conference_in(Some(root.path().join("none").into())).unwrap_err();
        assert!(why.contains("set MANYLIGHT_ASSETS"), "{why}");
    }

    #[test]
    fn an_adaptive_row_is_timed_by_a_frame_that_built_no_shaders() {
        let frame = |ms: f64, built: usize| {
            let mut stats = manylight::FrameStats::default();
            stats.time.frame_ms = ms;
            stats.programs_built = built;
            stats
        };
        assert_eq!(adaptive_frames(&frame(150.0, 0)), Some(3));
        assert_eq!(adaptive_frames(&frame(50.0, 0)), Some(9));
        // Compiling made it slow: the next frame decides.
        assert_eq!(adaptive_frames(&frame(150.0, 3)), None);
    }
}
