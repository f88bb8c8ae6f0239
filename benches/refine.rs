//! What a refinement costs against what it makes (`cargo bench --bench refine`, issue 35
//! §1): `Model::refine(2)` of a cantilever of one beam `DIVIDE n`, with an initial velocity
//! (so every generated node carries one) and beams of order 2 (so the interior nodes are
//! regenerated too), for n = 5,000 … 40,000. The time per generated node must stay flat:
//! `--refine 2` of a `DIVIDE 30000` deck took 14 s against 1.2 s for the deck itself when
//! removing and looking up entries was linear in the mesh each time (quadratic in all).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn deck(n: u32) -> String {
    format!(
        "MATERIALS\n 1 E 2.1e11 NU 0.3 RHO 7800\nSECTIONS\n 1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8\n\
         NODES\n 1 0 0 0 FIX ALL\n 2 1 0 0\nELEMENTS\n 1 BEAM 1 2 MAT 1 SEC 1 DIVIDE {n} ORDER 2\n\
         INITIAL\n 2 V 0 1 0\nANALYSIS STATIC STEPS 1\n"
    )
}

fn refine(c: &mut Criterion) {
    let mut g = c.benchmark_group("refine_2");
    g.sample_size(10);
    for n in [5_000u32, 10_000, 20_000, 40_000] {
        let model = mecano::deck::parse_deck(&deck(n), "cantilever").expect("deck");
        g.bench_with_input(BenchmarkId::from_parameter(n), &model, |b, m| {
            b.iter_batched(
                || m.clone(),
                |mut m| {
                    m.refine(2).expect("refine");
                    black_box(m.nodes.len())
                },
                criterion::BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, refine);
criterion_main!(benches);
