//! Development aid: assignment time of the default workload's point lights alone and spot
//! lights alone: `cargo bench --bench assign_kinds -- [LIGHTS]`.
use manylight_tools::workload::AssignWorkload;

fn main() {
    let count = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with("--"))
        .and_then(|a| a.parse().ok())
        .unwrap_or(1024);
    let all = AssignWorkload::default_view(count, 1);
    let (ms, n) = all.time(2000);
    println!(
        "all    {:5} lights: {ms:.4} ms, {n} indices",
        all.lights.len()
    );
    for (name, spots) in [("points", false), ("spots", true)] {
        let mut w = AssignWorkload::default_view(count, 1);
        w.lights.retain(|l| (l.spot_scale != 0.0) == spots);
        let (ms, n) = w.time(2000);
        println!(
            "{name:6} {:5} lights: {ms:.4} ms, {n} indices",
            w.lights.len()
        );
    }
}
