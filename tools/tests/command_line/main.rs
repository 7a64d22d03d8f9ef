//! The `manylight` command line, run as a user runs it: rendering, outputs and their failures,
//! `bench` and `matrix`. One test program of one module per file (each file once a program of
//! its own, built and linked apart: docs/testing.md).

#[path = "../common/mod.rs"]
mod common;

mod bench_cli;
mod cli;
mod cli_output;
mod matrix;
mod output_failures;
