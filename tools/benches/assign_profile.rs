//! Development aid: one workload assigned repeatedly with reused buffers (for profilers):
//! `cargo bench --bench assign_profile -- LIGHTS [REPEATS] [--fine]` (or run its binary under
//! a profiler); `--fine` takes the fine grid of [`AssignWorkload::fine_grid`].
use manylight::cluster::assign::Assigner;
use manylight_tools::workload::AssignWorkload;

fn main() {
    let mut args = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .map(|a| a.parse::<usize>().ok());
    let count = args.next().flatten().unwrap_or(65_536);
    let repeats = args.next().flatten().unwrap_or(20);
    let w = if std::env::args().any(|a| a == "--fine") {
        AssignWorkload::fine_grid(count, 1)
    } else {
        AssignWorkload::default_view(count, 1)
    };
    let mut assigner = Assigner::new();
    let mut total = 0;
    for _ in 0..repeats {
        total += w.assign_with(&mut assigner).indices.len();
    }
    println!("{total}");
}
