//! Development aid: one workload assigned repeatedly (for profilers).
use manylight::cluster::workload::AssignWorkload;

fn main() {
    let count: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(65_536);
    let w = AssignWorkload::default_view(count, 1);
    let mut total = 0;
    for _ in 0..20 {
        total += w.assign().indices.len();
    }
    println!("{total}");
}
