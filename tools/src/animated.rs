//! The bench's animated workload: lights and camera moving over many frames, reported as the
//! frame-time spread a game sees (p50 / p95 / p99 / max) rather than a median of identical
//! frames.

use std::fmt::Write as _;

use serde::Serialize;

use manylight::metrics::spread::Spread;

/// One method over the animated frames of one (scene, ES version, light count).
#[derive(Clone, Debug, Serialize)]
pub struct AnimatedRow {
    /// Scene name.
    pub scene: String,
    /// Shading method.
    pub method: String,
    /// Feature level, "2.0" or "3.0".
    pub es: String,
    /// Lights in the scene.
    pub lights: usize,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Frames timed (after a warm-up frame).
    pub frames: usize,
    /// Frames per second of animation time between them.
    pub fps: f64,
    /// Frame time (wall clock around the frame and `glFinish`), milliseconds.
    pub frame_ms: Spread,
    /// CPU light-assignment time, milliseconds.
    pub assign_ms: Spread,
    /// Bytes uploaded per frame.
    pub upload_bytes: Spread,
    /// `frame_ms.p99 / frame_ms.p50`: how much slower the slow frames are.
    pub p99_over_p50: f64,
    /// Largest channel difference (8-bit steps) from plain forward over all lights on the
    /// last frame (`None` for forward itself).
    pub max_abs_err_vs_forward: Option<u8>,
}

impl AnimatedRow {
    /// The ratio of the row's p99 to its p50 frame time (0 for a zero median).
    pub fn tail_ratio(frame_ms: &Spread) -> f64 {
        if frame_ms.p50 > 0.0 {
            frame_ms.p99 / frame_ms.p50
        } else {
            0.0
        }
    }
}

/// The report.md section of the animated rows (empty without rows).
pub fn markdown(rows: &[AnimatedRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut s = String::from("## Animated workload: the frame times a game sees\n\n");
    let _ = writeln!(
        s,
        "{} frames at {} fps of animation time, {}×{}: every light moves (the scene's motion) \
         and the camera pans; each row is one method on one context. Frame and assignment \
         times are nearest-rank percentiles over the frames; `p99/p50` shows how much slower \
         the slow frames are than the typical one; the error is the last frame's against \
         plain forward at the same time.\n",
        first.frames, first.fps, first.width, first.height
    );
    s += "| scene | ES | method | lights | frame p50 | p95 | p99 | max | p99/p50 | assign p50 | assign p99 | upload KiB p50 | upload KiB max | max err (/255) |\n\
          |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.3} | {:.3} | {:.0} | {:.0} | {} |",
            crate::report::md_text(&r.scene),
            r.es,
            r.method,
            r.lights,
            r.frame_ms.p50,
            r.frame_ms.p95,
            r.frame_ms.p99,
            r.frame_ms.max,
            r.p99_over_p50,
            r.assign_ms.p50,
            r.assign_ms.p99,
            r.upload_bytes.p50 / 1024.0,
            r.upload_bytes.max / 1024.0,
            r.max_abs_err_vs_forward
                .map_or("—".to_string(), |e| e.to_string()),
        );
    }
    s += "\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spread(p50: f64, p99: f64) -> Spread {
        Spread {
            p50,
            p95: (p50 + p99) / 2.0,
            p99,
            max: p99 * 1.1,
            frames: 100,
        }
    }

    #[test]
    fn the_section_lists_every_row_with_its_tail() {
        let frame = spread(10.0, 15.0);
        let row = |method: &str, err| AnimatedRow {
            scene: "courtyard".into(),
            method: method.into(),
            es: "3.0".into(),
            lights: 1024,
            width: 320,
            height: 180,
            frames: 100,
            fps: 30.0,
            frame_ms: frame,
            assign_ms: spread(0.5, 0.9),
            upload_bytes: spread(2048.0, 4096.0),
            p99_over_p50: AnimatedRow::tail_ratio(&frame),
            max_abs_err_vs_forward: err,
        };
        let md = markdown(&[row("forward", None), row("clustered", Some(1))]);
        assert!(md.contains("| courtyard | 3.0 | clustered | 1024 | 10.00 | 12.50 | 15.00 | 16.50 | 1.50 | 0.500 | 0.900 | 2 | 4 | 1 |"), "{md}");
        assert!(md.contains("| forward |") && md.contains("| — |"), "{md}");
        assert!(markdown(&[]).is_empty());
        assert_eq!(AnimatedRow::tail_ratio(&spread(0.0, 1.0)), 0.0);
    }
}
