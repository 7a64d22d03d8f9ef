//! rayon's global pool as the command line builds it: its size from `RAYON_NUM_THREADS` (or
//! the older `RAYON_RS_NUM_CPUS`), checked, and the main thread one of its threads.

use manylight::scene::shown;

/// Most threads the pool takes: each costs a stack (2 MiB of address space), and past the
/// cores they only take turns. 5 000 made the GL driver fail to load under a 4 GB limit.
const MAX_POOL_THREADS: usize = 256;

/// Makes this thread (the one that renders and assigns lights) one of rayon's global pool, so
/// a parallel light assignment starts on it at once. From outside the pool the caller would
/// queue the work and wait, its own core idle, until a pool thread woke to take it
/// (milliseconds for a core that slept: docs/performance.md, `pool_wake`).
pub fn join_rayon_pool() {
    // Always a count of our own: rayon falls back to the deprecated `RAYON_RS_NUM_CPUS`
    // unchecked, and 3 000 there started 3 000 threads (10 s before `info` printed a line).
    // The first variable that is a count decides (`0`: the cores), as rayon reads them.
    let asked = ["RAYON_NUM_THREADS", "RAYON_RS_NUM_CPUS"]
        .into_iter()
        .find_map(|name| threads_asked(name, &std::env::var_os(name)?).ok())
        .flatten();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = asked.unwrap_or(cores.min(MAX_POOL_THREADS));
    let pool = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .num_threads(threads);
    if let Err(e) = pool.build_global() {
        log::warn!(
            "rayon's pool of {threads} threads could not start ({e}): the counts of threads \
             said may be wrong"
        );
    }
}

/// The pool size `name=value` asks for, as rayon reads it (`0`: one a core, `Ok(None)`
/// here), with a warning where it is no count (`Err`: rayon ignored it without a word) or past
/// [`MAX_POOL_THREADS`], a usize's included (taken as that).
fn threads_asked(name: &str, value: &std::ffi::OsStr) -> Result<Option<usize>, ()> {
    let text = value.to_string_lossy();
    // A count too large for a usize is still a count: past the most, as 5 000 is.
    let too_large = |e: &std::num::ParseIntError| *e.kind() == std::num::IntErrorKind::PosOverflow;
    match text.parse::<usize>() {
        Ok(0) => Ok(None),
        Ok(n) if n > MAX_POOL_THREADS => Ok(Some(most_threads(name, &n.to_string()))),
        Err(e) if too_large(&e) => Ok(Some(most_threads(name, &shown::name(&text)))),
        Ok(n) => Ok(Some(n)),
        Err(_) => {
            let value = shown::name(&text);
            log::warn!("{name}={value} is not a thread count: ignored");
            Err(())
        }
    }
}

/// [`MAX_POOL_THREADS`], with a warning that `name=asked` was taken as that.
fn most_threads(name: &str, asked: &str) -> usize {
    log::warn!(
        "{name}={asked} taken as {MAX_POOL_THREADS}, the most the pool takes (each thread \
         costs a stack)"
    );
    MAX_POOL_THREADS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thread_count_past_the_most_or_no_count_is_said_and_replaced() {
        let asked = |v: &str| threads_asked("RAYON_NUM_THREADS", std::ffi::OsStr::new(v));
        assert_eq!(asked("2"), Ok(Some(2)));
        assert_eq!(asked("0"), Ok(None));
        assert_eq!(asked("5000"), Ok(Some(MAX_POOL_THREADS)));
        // One past usize::MAX is a count too, past the most.
        assert_eq!(asked("18446744073709551616"), Ok(Some(MAX_POOL_THREADS)));
        assert_eq!(asked("+7"), Ok(Some(7)));
        assert_eq!(asked("-1"), Err(()));
        assert_eq!(asked("abc"), Err(()));
    }
}
