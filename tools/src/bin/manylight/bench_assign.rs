//! `manylight bench-assign`: light assignment alone on the default view, for scripts.

use clap::Parser;
use manylight_tools::output::print_stdout;
use manylight_tools::workload::{AssignWorkload, BENCH_SIZE, MAX_RUNS};

/// Options of `manylight bench-assign`.
#[derive(Parser, Debug)]
pub struct BenchAssignArgs {
    /// Light counts, comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1,64,1024,16384,65536,1048576",
        value_parser = parse_light_count
    )]
    pub lights: Vec<usize>,
    /// Timed runs per count, after 0.1 s of untimed ones (the median is reported), from 1 to
    /// 1 048 576. Default: 101, or 7 above 100 000 lights (the median is robust, and the huge
    /// counts stay quick).
    #[arg(long, value_parser = parse_runs)]
    pub runs: Option<usize>,
    /// Seed of the random lights.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON (an array of {lights, assign_ms, indices, clusters, runs, threads}) instead of
    /// a table. `threads`: what the median run took (the assignment picks one or more from the
    /// previous run's time).
    #[arg(long)]
    pub json: bool,
}

/// Parses a light count of `--lights`: at most what a scene may hold.
fn parse_light_count(s: &str) -> Result<usize, String> {
    let max = manylight::scene::input::MAX_LIGHTS;
    match s.parse::<usize>() {
        Ok(n) if n <= max => Ok(n),
        _ => Err(format!("`{s}` is not a light count from 0 to {max}")),
    }
}

/// Parses `--runs`: from 1 to [`MAX_RUNS`] timed runs.
fn parse_runs(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (1..=MAX_RUNS).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{s}` is not a number of runs from 1 to {MAX_RUNS}"
        )),
    }
}

/// Runs the command.
pub fn run(args: &BenchAssignArgs) -> Result<(), Box<dyn std::error::Error>> {
    let mut rows = Vec::new();
    for &count in &args.lights {
        let work = AssignWorkload::default_view(count, args.seed);
        let runs = match args.runs {
            Some(runs) => runs,
            None if count > 100_000 => 7,
            None => 101,
        };
        let timing = work.timing(runs);
        let (ms, indices, threads) = (timing.median_ms, timing.indices, timing.threads);
        rows.push(serde_json::json!({
            "lights": count,
            "assign_ms": ms,
            "indices": indices,
            "clusters": work.grid.total_cells,
            "runs": runs,
            "threads": threads,
        }));
        if !args.json {
            print_stdout(&format!(
                "{count:>9} lights  {ms:>9.3} ms  {indices:>9} indices  (median of {runs} runs, \
                 on {threads} thread{})\n",
                if threads == 1 { "" } else { "s" }
            ))?;
        }
    }
    if args.json {
        print_stdout(&(serde_json::to_string_pretty(&rows)? + "\n"))?;
    } else {
        let (w, h) = BENCH_SIZE;
        print_stdout(&format!(
            "default view ({w}x{h}), {} threads available, LP_NUM_THREADS does not apply (CPU only)\n",
            std::thread::available_parallelism().map_or(1, |n| n.get())
        ))?;
    }
    Ok(())
}
