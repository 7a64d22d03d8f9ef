//! `render`'s animated path: frames of a moving scene at a fixed frame rate, timed one by one
//! (p50/p95/p99/max of frame time, assignment time and upload bytes) and optionally recorded
//! as a numbered PNG sequence or an animated GIF.

use std::cell::RefCell;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};
use manylight::metrics::spread::Spread;
use manylight::renderer::FrameStats;
use manylight::scene::{shown, Scene};
use manylight::{RenderOptions, Renderer};
use manylight_tools::output::{self, OutputFile};

/// When and how many frames.
pub struct Timeline {
    /// Time of the first frame, seconds.
    pub start_s: f64,
    /// Frames per second of animation time.
    pub fps: f64,
    /// Frames after the warm-up.
    pub frames: u32,
}

impl Timeline {
    /// Animation time of frame `k`.
    pub fn time_of(&self, k: u32) -> f64 {
        self.start_s + f64::from(k) / self.fps
    }

    /// Animation time of the untimed warm-up frame: `start_s` without timed frames (it is then
    /// the picture), else one frame before the first, so that the first assigns the lights it
    /// shows as every later frame does (posed at the first's own time, it would redraw the
    /// warm-up's lists without assigning).
    pub fn warm_up_time(&self) -> f64 {
        match self.frames {
            0 => self.start_s,
            _ => self.start_s - 1.0 / self.fps,
        }
    }
}

/// Where recorded frames go.
enum Recorder {
    /// `DIR/frame_00000.png` …
    Pngs { dir: PathBuf, digits: usize },
    /// One animated GIF.
    Gif(Box<GifEncoder<SharedFile>>, SharedFile),
}

/// The GIF's file, shared with its encoder, which cannot hand its writer back: once the
/// encoder is dropped (writing the trailer), the file is committed through the other handle.
#[derive(Clone)]
struct SharedFile(Rc<RefCell<OutputFile>>);

impl Write for SharedFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.borrow_mut().flush()
    }
}

/// Whether `--record PATH` records an animated GIF (else a folder of PNG frames): a name ending
/// in `.gif`, `.gif` alone included; a trailing `/` names a folder.
pub fn records_gif(path: &Path) -> bool {
    let ends_in_gif =
        |bytes: &[u8]| bytes.len() >= 4 && bytes[bytes.len() - 4..].eq_ignore_ascii_case(b".gif");
    !path.as_os_str().as_encoded_bytes().ends_with(b"/")
        && path
            .file_name()
            .is_some_and(|name| ends_in_gif(name.as_encoded_bytes()))
}

impl Recorder {
    /// A `.gif` path records an animated GIF, anything else is a directory for PNGs.
    fn open(path: &Path, timeline: &Timeline) -> Result<Recorder, String> {
        if records_gif(path) {
            if let Some(warning) = gif_timing_warning(timeline.fps) {
                log::warn!("--record {}: {warning}", shown::path(path));
            }
            let file = OutputFile::create(path).map_err(|e| format!("--record: {e}"))?;
            let file = SharedFile(Rc::new(RefCell::new(file)));
            let mut encoder = GifEncoder::new_with_speed(file.clone(), 10);
            encoder
                .set_repeat(Repeat::Infinite)
                .map_err(|e| format!("--record {}: {e}", shown::path(path)))?;
            return Ok(Recorder::Gif(Box::new(encoder), file));
        }
        // A device or file there said only "File exists".
        if path.exists() && !path.is_dir() {
            return Err(format!(
                "--record {}: not a folder (frames go into a folder as PNGs; a name ending in \
                 .gif records an animated GIF)",
                shown::path(path)
            ));
        }
        std::fs::create_dir_all(path)
            .map_err(|e| format!("--record: cannot create {}: {e}", shown::path(path)))?;
        let last = timeline.frames.saturating_sub(1);
        let digits = frame_digits(timeline.frames);
        let stale = stale_frames(path, timeline.frames, digits);
        if stale > 0 {
            log::warn!(
                "--record {}: {stale} frame_*.png from before stay beside this recording's \
                 {} frames (this run writes frame_{:0digits$} to frame_{last:0digits$}): \
                 record into an empty folder",
                shown::path(path),
                timeline.frames,
                0
            );
        }
        Ok(Recorder::Pngs {
            dir: path.to_path_buf(),
            digits,
        })
    }

    fn add(&mut self, k: u32, image: RgbaImage, fps: f64) -> Result<(), String> {
        match self {
            Recorder::Pngs { dir, digits } => {
                let path = dir.join(format!("frame_{k:0width$}.png", width = *digits));
                output::save_png(&path, &image).map_err(|e| e.to_string())
            }
            Recorder::Gif(encoder, file) => {
                // GIF delays are whole hundredths of a second: each frame ends at the hundredth
                // nearest its true end, so the rounding never adds up (30 fps: 3, 3, 4, …).
                let end = |k: u32| (f64::from(k) * 100.0 / fps).round();
                let centis = (end(k + 1) - end(k)).clamp(1.0, 65_535.0) as u32;
                let path = || shown::path(file.0.borrow().path());
                // The encoder quantizes a copy of the frame into indices and compresses them.
                let raw = image.as_raw().len() as u64;
                output::encoding_fits(2 * raw, image.dimensions())
                    .map_err(|e| format!("cannot write {}: {e}", path()))?;
                let frame =
                    Frame::from_parts(image, 0, 0, Delay::from_numer_denom_ms(centis * 10, 1));
                encoder
                    .encode_frame(frame)
                    .map_err(|e| format!("cannot write {}: {e}", path()))
            }
        }
    }

    /// Completes the recording: the GIF's trailer written, its file flushed and put in place.
    fn finish(self) -> Result<(), String> {
        if let Recorder::Gif(encoder, file) = self {
            drop(encoder);
            let file = Rc::try_unwrap(file.0)
                .ok()
                .expect("the encoder held the only other handle");
            file.into_inner().commit().map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

/// Where a GIF cannot keep `fps`: its delays are whole hundredths of a second up to 65 535,
/// and most viewers show a delay under 2 as 10.
fn gif_timing_warning(fps: f64) -> Option<String> {
    let why = if fps > 50.0 {
        "under 1/50 s, which GIF viewers show at 1/10 s or 1/100 s, so it plays slower"
    } else if fps < 100.0 / 65_535.0 {
        "over 655.35 s, the longest a GIF frame lasts, so it plays faster"
    } else {
        return None;
    };
    Some(format!(
        "at --fps {fps} a frame lasts {why} than the animation (a folder of PNG frames keeps \
         any rate)"
    ))
}

/// Digits of a recording's frame numbers: five, or as many as its last frame needs.
fn frame_digits(frames: u32) -> usize {
    frames.saturating_sub(1).to_string().len().max(5)
}

/// Whether `name` is one of the `frames` PNGs a recording with `digits`-digit numbers writes.
fn is_recorded_frame(name: &str, frames: u32, digits: usize) -> bool {
    let Some(number) = name
        .strip_prefix("frame_")
        .and_then(|n| n.strip_suffix(".png"))
    else {
        return false;
    };
    number.len() == digits
        && number.bytes().all(|b| b.is_ascii_digit())
        && number.parse::<u32>().is_ok_and(|k| k < frames)
}

/// How many files in `dir` look like recorded frames (`frame_*.png`) but are not among the
/// `frames` this recording writes with `digits`-digit numbers: left over from another one.
fn stale_frames(dir: &Path, frames: u32, digits: usize) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|name| name.starts_with("frame_") && name.ends_with(".png"))
        .filter(|name| !is_recorded_frame(name, frames, digits))
        .count()
}

/// The first of the files the scene `read` (as [`output::identity`] spells them) that
/// `--record path` would overwrite: the GIF itself, or one of the folder's frame PNGs this
/// recording writes, a symbolic link among them through to its target (the frame is written
/// there).
pub fn overwritten_input(path: &Path, frames: u32, read: &[PathBuf]) -> Option<PathBuf> {
    if records_gif(path) {
        let id = output::identity(path);
        return read.contains(&id).then_some(id);
    }
    let digits = frame_digits(frames);
    // A file the scene read exists: only the folder's existing frames can be one.
    std::fs::read_dir(path)
        .ok()?
        .flatten()
        .filter(|e| {
            e.file_name()
                .to_str()
                .is_some_and(|n| is_recorded_frame(n, frames, digits))
        })
        .map(|e| output::identity(&e.path()))
        .find(|id| read.contains(id))
}

/// What a sequence keeps of its timed frames besides their stats.
pub enum Keep<'a> {
    /// Nothing.
    Stats,
    /// The last one, in [`Rendered::last`].
    Last,
    /// Every one, recorded to this path (see `--record`).
    Record(&'a Path),
}

/// What a sequence produced.
pub struct Rendered {
    /// The picture at `start_s`: the first timed frame, or the warm-up frame where none is
    /// timed.
    pub first: RgbaImage,
    /// The last timed frame where the caller asked for it and it did not go to the recording
    /// (kept without a copy: at 8192² a frame is 256 MiB).
    pub last: Option<RgbaImage>,
    /// The last frame's stats, frame and assignment time replaced by the medians and the
    /// spreads (frame, assignment, upload bytes) filled in.
    pub stats: FrameStats,
}

/// Renders the warm-up frame (at [`Timeline::warm_up_time`]) and then `timeline.frames` timed
/// frames, each after `pose(scene, t)` (for instance [`Scene::set_time`]), recording them into
/// `record` when given.
pub fn render(
    renderer: &mut Renderer,
    scene: &mut Scene,
    (width, height): (u32, u32),
    options: &RenderOptions,
    timeline: &Timeline,
    pose: &mut dyn FnMut(&mut Scene, f64),
    keep: Keep<'_>,
) -> Result<Rendered, Box<dyn std::error::Error>> {
    let one_frame = RenderOptions {
        measure: manylight::MeasureOptions {
            timed_frames: 0,
            ..options.measure
        },
        ..options.clone()
    };
    let mut recorder = match keep {
        Keep::Record(path) => Some(Recorder::open(path, timeline)?),
        Keep::Last | Keep::Stats => None,
    };
    let keep_last = matches!(keep, Keep::Last);
    pose(scene, timeline.warm_up_time());
    // The warm-up frame compiles shaders and uploads meshes: not timed.
    let (mut first, warm_up) = renderer.render_offscreen(scene, width, height, &one_frame)?;
    let mut last = None;
    let mut timed = Vec::with_capacity(timeline.frames.min(1 << 20) as usize);
    for k in 0..timeline.frames {
        pose(scene, timeline.time_of(k));
        let (image, s) = renderer.render_offscreen(scene, width, height, &one_frame)?;
        timed.push(s);
        let is_last = k + 1 == timeline.frames;
        // Frame 0 is the picture: copied only where it goes on to the recording or `last`.
        let image = match (k, &recorder) {
            (0, None) if !(keep_last && is_last) => {
                first = image;
                continue;
            }
            (0, _) => {
                first = image.clone();
                image
            }
            _ => image,
        };
        match &mut recorder {
            Some(r) => r.add(k, image, timeline.fps)?,
            None if keep_last && is_last => last = Some(image),
            None => {}
        }
    }
    if let Some(recorder) = recorder {
        recorder.finish()?;
    }
    let upload = Spread::of(timed.iter().map(|s| s.memory.upload_bytes as f64));
    // The programs the whole run built, the warm-up's too, as a still scene's timed frames
    // report them (`render_offscreen`).
    let built = warm_up.programs_built + timed.iter().map(|s| s.programs_built).sum::<usize>();
    let mut stats = FrameStats::summarize(timed).unwrap_or(warm_up);
    stats.memory.upload_bytes_spread = upload;
    stats.programs_built = built;
    Ok(Rendered { first, last, stats })
}

#[cfg(test)]
mod tests {
    use super::{gif_timing_warning, records_gif};
    use std::path::Path;

    #[test]
    fn a_gif_warns_of_rates_its_delays_cannot_keep() {
        for fps in [0.5, 1.0, 30.0, 50.0, 0.002] {
            assert_eq!(gif_timing_warning(fps), None, "{fps}");
        }
        assert!(gif_timing_warning(60.0).unwrap().contains("plays slower"));
        assert!(gif_timing_warning(10_000.0)
            .unwrap()
            .contains("plays slower"));
        assert!(gif_timing_warning(0.001).unwrap().contains("plays faster"));
    }

    #[test]
    fn a_name_ending_in_gif_records_a_gif() {
        for gif in ["a.gif", "dir/a.GIF", ".gif", "dir/.gif"] {
            assert!(records_gif(Path::new(gif)), "{gif}");
        }
        for folder in ["frames", "a.gif/", "gif", "dir/gif", "a.gif.d", "."] {
            assert!(!records_gif(Path::new(folder)), "{folder}");
        }
    }
}
