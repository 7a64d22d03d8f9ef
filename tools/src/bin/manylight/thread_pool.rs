//! rayon's global pool as the command line builds it: its size from `RAYON_NUM_THREADS`,
//! checked, and the main thread one of its threads.

use manylight::scene::shown;

/// Most threads the pool takes: each costs a stack (2 MiB of address space), and past the
/// cores they only take turns. 5 000 made the GL driver fail to load under a 4 GB limit.
const MAX_POOL_THREADS: usize = 256;

/// Makes this thread (the one that renders and assigns lights) one of rayon's global pool, so
/// a parallel light assignment starts on it at once. From outside the pool the caller would
/// queue the work and wait, its own core idle, until a pool thread woke to take it
/// (milliseconds for a core that slept: docs/performance.md, `pool_wake`).
pub fn join_rayon_pool() {
    let mut pool = rayon::ThreadPoolBuilder::new().use_current_thread();
    if let Some(threads) = std::env::var_os("RAYON_NUM_THREADS").and_then(|v| threads_asked(&v)) {
        pool = pool.num_threads(threads);
    }
    if let Err(e) = pool.build_global() {
        log::debug!("rayon's global pool left as it was: {e}");
    }
}

/// The pool size `RAYON_NUM_THREADS=value` asks for, as rayon reads it (`0`: one a core, `None`
/// here), with a warning where it is no count (rayon ignored it without a word: one a core)
/// or past [`MAX_POOL_THREADS`] (taken as that).
fn threads_asked(value: &std::ffi::OsStr) -> Option<usize> {
    let text = value.to_string_lossy();
    match text.parse::<usize>() {
        Ok(0) => None,
        Ok(n) if n > MAX_POOL_THREADS => {
            log::warn!(
                "RAYON_NUM_THREADS={n} taken as {MAX_POOL_THREADS}, the most the pool takes \
                 (each thread costs a stack)"
            );
            Some(MAX_POOL_THREADS)
        }
        Ok(n) => Some(n),
        Err(_) => {
            let value = shown::name(&text);
            log::warn!("RAYON_NUM_THREADS={value} is not a thread count: one thread a core");
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thread_count_past_the_most_or_no_count_is_said_and_replaced() {
        let asked = |v: &str| threads_asked(std::ffi::OsStr::new(v));
        assert_eq!(asked("2"), Some(2));
        assert_eq!(asked("0"), None);
        assert_eq!(asked("5000"), Some(MAX_POOL_THREADS));
        assert_eq!(asked("18446744073709551616"), None);
        assert_eq!(asked("-1"), None);
        assert_eq!(asked("abc"), None);
    }
}
