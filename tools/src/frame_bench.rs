//! What the frame benchmarks (`cargo bench --bench first_frame`, `--bench still_frames`)
//! share: their arguments `[ROUNDS] [WxH] [METHOD] [es2|es3]` and the median they print.

use manylight::EsVersion;

/// A frame benchmark's arguments.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameBenchArgs {
    /// Rounds, at least 1 (default 5).
    pub rounds: usize,
    /// Frame size (default 640×360).
    pub size: (u32, u32),
    /// Shading method.
    pub method: String,
    /// Feature level (default ES 3.0).
    pub es: EsVersion,
    /// Seeded random lights (default 1 024).
    pub lights: usize,
}

impl FrameBenchArgs {
    /// From the process's arguments, cargo's own (`--bench`) left out; `method` unless one is
    /// given.
    pub fn from_env(method: &str) -> FrameBenchArgs {
        let args: Vec<String> = std::env::args()
            .skip(1)
            .filter(|a| !a.starts_with("--"))
            .collect();
        FrameBenchArgs::parse(&args, method)
    }

    /// From `args` (positional, in order); anything unreadable takes its default.
    pub fn parse(args: &[String], method: &str) -> FrameBenchArgs {
        let rounds = args.first().and_then(|a| a.parse().ok()).unwrap_or(5);
        let size = args
            .get(1)
            .and_then(|s| s.split_once('x'))
            .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
            .unwrap_or((640, 360));
        FrameBenchArgs {
            rounds: usize::max(rounds, 1),
            size,
            method: args.get(2).map_or(method, String::as_str).to_string(),
            es: match args.get(3).map(String::as_str) {
                Some("es2") => EsVersion::Es2,
                _ => EsVersion::Es3,
            },
            lights: args.get(4).and_then(|a| a.parse().ok()).unwrap_or(1024),
        }
    }
}

/// The median (the upper one of an even count); NaN for none.
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_in_order_with_defaults_for_the_rest() {
        let args = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let read = FrameBenchArgs::parse(&args(&["3", "1280x720", "tiled", "es2", "99"]), "auto");
        assert_eq!(read.rounds, 3);
        assert_eq!(read.size, (1280, 720));
        assert_eq!(read.method, "tiled");
        assert_eq!(read.es, EsVersion::Es2);
        assert_eq!(read.lights, 99);
        let none = FrameBenchArgs::parse(&args(&["0", "wide"]), "clustered");
        assert_eq!((none.rounds, none.size, none.lights), (1, (640, 360), 1024));
        assert_eq!(
            (none.method.as_str(), none.es),
            ("clustered", EsVersion::Es3)
        );
        assert_eq!(median(vec![3.0, 1.0, 2.0, 9.0]), 3.0);
        assert!(median(Vec::new()).is_nan());
    }
}
