//! Validation throughput: a generated 20,000-material .gltf and a folder of 500 small files,
//! each validated in one process with the built-in schemas (compiled once, outside the timing
//! loop, as a run does).

use criterion::{criterion_group, criterion_main, Criterion};
use velvet::diagnostics::Settings;
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

#[path = "../examples/corpus.rs"]
mod corpus;

fn validate(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    corpus::write(dir.path(), 20_000, 500).expect("corpus written");
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let large = vec![dir.path().join("large.gltf")];
    let small = vec![dir.path().join("small")];
    let mut group = c.benchmark_group("validate");
    group.sample_size(20);
    group.bench_function("large_20000_materials", |b| {
        b.iter(|| validator.validate_inputs(&large))
    });
    group.bench_function("folder_500_files", |b| {
        b.iter(|| validator.validate_inputs(&small))
    });
    group.finish();
}

criterion_group!(benches, validate);
criterion_main!(benches);
