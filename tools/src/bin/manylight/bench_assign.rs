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
    /// Time each count on rayon pools of these sizes instead of the global pool (comma
    /// separated, at most 8 pools of 1 to 256 threads each; `1,2` for one worker against
    /// two): the pools take turns in five rounds, so a host whose speed drifts drifts under
    /// each alike, and each row after the first of a count gives its time as a ratio to the
    /// first pool's.
    #[arg(long, value_delimiter = ',', value_parser = parse_pool_size)]
    pub threads: Vec<usize>,
    /// Print JSON (an array of {lights, assign_ms, indices, clusters, runs, threads}, and
    /// `pool` with `--threads`) instead of a table. `threads`: what the median run took (the
    /// assignment picks one or more from the previous run's time).
    #[arg(long)]
    pub json: bool,
}

/// Most threads a `--threads` pool may have.
const MAX_POOL: usize = 256;

/// Most pools `--threads` may list (they all exist at once; more is a usage error).
pub const MAX_POOLS: usize = 8;

/// Parses a pool size of `--threads`: from 1 to [`MAX_POOL`].
fn parse_pool_size(s: &str) -> Result<usize, String> {
    count_within(s, 1, MAX_POOL, "a number of threads")
}

/// Parses a light count of `--lights`: at most what a scene may hold.
pub(crate) fn parse_light_count(s: &str) -> Result<usize, String> {
    count_within(s, 0, manylight::scene::input::MAX_LIGHTS, "a light count")
}

/// Parses `--runs`: from 1 to [`MAX_RUNS`] timed runs.
fn parse_runs(s: &str) -> Result<usize, String> {
    count_within(s, 1, MAX_RUNS, "a number of runs")
}

/// `s` as a whole number from `min` to `max`, or an error saying it is not `what` in that
/// range.
fn count_within(s: &str, min: usize, max: usize, what: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ => Err(format!("`{s}` is not {what} from {min} to {max}")),
    }
}

/// Runs the command.
pub fn run(args: &BenchAssignArgs) -> Result<(), Box<dyn std::error::Error>> {
    let pools = args
        .threads
        .iter()
        .map(|&n| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build();
            pool.map_err(|e| format!("--threads {n}: cannot start a pool of {n} threads: {e}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows = Vec::new();
    for &count in &args.lights {
        let work = AssignWorkload::try_default_view(count, args.seed)?;
        let runs = match args.runs {
            Some(runs) => runs,
            None if count > 100_000 => 7,
            None => 101,
        };
        let timings = if pools.is_empty() {
            vec![work.timing(runs)]
        } else {
            work.timing_on_pools(&pools, runs)
        };
        let first_ms = timings[0].median_ms;
        for (i, timing) in timings.iter().enumerate() {
            let (ms, indices, threads) = (timing.median_ms, timing.indices, timing.threads);
            let mut row = serde_json::json!({
                "lights": count,
                "assign_ms": ms,
                "indices": indices,
                "clusters": work.grid.total_cells,
                "runs": runs,
                "threads": threads,
            });
            let pool = args.threads.get(i).copied();
            if let Some(pool) = pool {
                row["pool"] = pool.into();
            }
            rows.push(row);
            if !args.json {
                let on = match pool {
                    Some(pool) => format!("pool of {pool}, on {threads}"),
                    None => format!("on {threads}"),
                };
                let ratio = match i {
                    0 => String::new(),
                    _ => format!("  {:.2}x the pool of {}", ms / first_ms, args.threads[0]),
                };
                print_stdout(&format!(
                    "{count:>9} lights  {ms:>9.3} ms  {indices:>9} indices  (median of {runs} runs, \
                     {on} thread{}){ratio}\n",
                    if threads == 1 { "" } else { "s" }
                ))?;
            }
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
