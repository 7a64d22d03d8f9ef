//! # manylight-tools
//!
//! What the `manylight` command line measures and draws with, beside the renderer: the
//! benchmark's report (tables and error-against-run-time charts), heatmaps, contact sheets,
//! the animated workload's summary and the light-assignment workload of the benchmarks. A game
//! depends on the `manylight` library alone; nothing here ships in it.
#![warn(missing_docs)]

pub mod animated;
pub mod frame_bench;
pub mod heatmap;
pub mod output;
pub mod plot;
pub mod report;
pub mod sheet;
pub mod signals;
pub mod workload;
