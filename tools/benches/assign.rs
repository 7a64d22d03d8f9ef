//! Light assignment alone on the default view (`cargo bench`): 1 to 1 048 576 lights.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manylight::cluster::assign::Assigner;
use manylight_tools::workload::AssignWorkload;

fn assignment(c: &mut Criterion) {
    let mut group = c.benchmark_group("assign");
    for count in [1usize, 64, 1024, 16_384, 65_536, 1_048_576] {
        let work = AssignWorkload::default_view(count, 1);
        let indices = work.assign().indices.len();
        eprintln!("{count} lights → {indices} indices");
        group.throughput(Throughput::Elements(count as u64));
        if count >= 65_536 {
            group.sample_size(10);
        }
        // Buffers are reused across iterations, as a renderer reuses them across frames.
        let mut assigner = Assigner::new();
        group.bench_with_input(BenchmarkId::from_parameter(count), &work, |b, w| {
            b.iter(|| w.assign_with(&mut assigner).indices.len())
        });
    }
    group.finish();
}

criterion_group!(benches, assignment);
criterion_main!(benches);
