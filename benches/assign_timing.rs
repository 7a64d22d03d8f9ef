//! Quick assignment timings for development: `cargo bench --bench assign_timing`.
use manylight::cluster::workload::AssignWorkload;

fn main() {
    for count in [1usize, 64, 1024, 16_384, 65_536, 1_048_576] {
        let w = AssignWorkload::default_view(count, 1);
        let (ms, indices) = w.time(if count > 100_000 { 5 } else { 50 });
        println!("{count:>8} lights: {ms:8.3} ms, {indices} indices");
    }
}
