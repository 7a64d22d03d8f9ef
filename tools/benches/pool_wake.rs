//! How late a sleeping worker of rayon's pool takes work, after the pool has been idle: `cargo
//! bench --bench pool_wake -- [IDLE_MS ...]` (default 0.05 1 5 10 100). For each idle time, 20
//! times: both workers of a pool of two busy for 2 ms, the pool idle that long, then a
//! `rayon::join` whose first half keeps its worker busy for 8 ms; prints when the second half
//! started (ms after the join), which is how long the other worker took to wake and steal
//! it. Why the assignment's bands are taken by whichever worker is free (`bands/shared.rs`):
//! a renderer's workers sleep between frames, and a core that sleeps may wake late.
use std::time::{Duration, Instant};

fn busy(ms: f64) {
    let started = Instant::now();
    while started.elapsed().as_secs_f64() * 1e3 < ms {
        std::hint::spin_loop();
    }
}

fn main() {
    let idle: Vec<f64> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .filter_map(|a| a.parse().ok())
        .collect();
    let idle = if idle.is_empty() {
        vec![0.05, 1.0, 5.0, 10.0, 100.0]
    } else {
        idle
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a pool of two");
    for ms in idle {
        let mut late: Vec<f64> = pool.install(|| {
            (0..20)
                .map(|_| {
                    rayon::join(|| busy(2.0), || busy(2.0));
                    std::thread::sleep(Duration::from_secs_f64(ms / 1e3));
                    let joined = Instant::now();
                    let (_, started) =
                        rayon::join(|| busy(8.0), || joined.elapsed().as_secs_f64() * 1e3);
                    started
                })
                .collect()
        });
        late.sort_by(f64::total_cmp);
        println!(
            "idle {ms:>7.2} ms: second worker started after median {:.3} ms, 90th percentile {:.3} ms, most {:.3} ms",
            late[late.len() / 2],
            late[late.len() * 9 / 10],
            late[late.len() - 1]
        );
    }
}
