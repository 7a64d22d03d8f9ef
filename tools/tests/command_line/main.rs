//! The `manylight` command line, run as a user runs it: rendering, outputs and their failures,
//! `bench` and `matrix`. One test program of one module per file, built and linked once
//! (docs/testing.md).

#[path = "../common/mod.rs"]
mod common;

mod bench_cli;
mod cli;
mod cli_output;
mod matrix;
mod output_failures;
mod timed_stats;
