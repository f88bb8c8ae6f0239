//! Cost of the sparse modal analysis (issue 24's target: the lowest 20 modes of a model of
//! about 50,000 unknowns within 10× one factorisation plus 200 solves of it), and where the
//! dense and sparse solvers cross (docs/modes.md).
//!
//!   cargo bench --bench modes -- large        (the target; MODES_BENCH_BEAMS, default 8334)
//!   cargo bench --bench modes -- crossover    (dense vs sparse, 10 modes, 150–600 unknowns)
//!
//! The model is `benches/large.sh`'s cantilever (n two-node beams of 1 cm, clamped, 6
//! unknowns per free node: 6n unknowns; 8334 beams = 50,004). `large/modes_20` is the
//! whole analysis the `modes` command makes after building the system: the element
//! matrices (K, M, C), one factorisation of `K − σM` with partial pivoting, block Lanczos,
//! the checks. `large/factor_200_solves` is the reference: the same matrix factored with
//! pivoting and 200 solves. Each iteration starts from a freshly prepared system (its
//! preparation is not timed), so both make a first, pivoting factorisation. The
//! frequencies are not checked here (tests/modes_sparse.rs does against the dense path).

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use mecano::modes::{Solver, analyse};
use mecano::solver::Integrator;
use std::hint::black_box;
use std::time::Duration;

fn deck(n: usize) -> String {
    format!(
        "TITLE cantilever of {n} beams
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8 K 0.8333333333333334
NODES
  1 0 0 0 FIX ALL
  2 {len:.2} 0 0
ELEMENTS
  1 BEAM 1 2 MAT 1 SEC 1 AXIS2 0 0 1 DIVIDE {n}
ANALYSIS DYNAMIC STEP 1e-5 END 1e-4
",
        len = n as f64 * 0.01
    )
}

fn prepared(n: usize) -> Integrator {
    let model = mecano::deck::parse_deck(&deck(n), "bench").expect("generated deck");
    mecano::solver::prepare(&model).expect("prepare")
}

fn modes(mut integ: Integrator, count: usize, solver: Solver) -> usize {
    let groups = vec!["BEAM"; integ.sys.elements.len()];
    let a = analyse(
        &mut integ.sys,
        &integ.nodes,
        &integ.lambda,
        integ.scale,
        integ.t,
        &groups,
        count,
        solver,
    )
    .expect("modes");
    a.modes.len()
}

fn factor_and_solves(mut integ: Integrator, solves: usize) -> f64 {
    let ctx = integ.step_context(1e-5);
    let (nodes, lambda) = (integ.nodes.clone(), integ.lambda.clone());
    integ.sys.assemble(&ctx, &nodes, &lambda, true);
    integ.sys.matrix.factor().expect("regular");
    let mut x = integ.sys.rhs.clone();
    for _ in 0..solves {
        integ.sys.matrix.solve(&mut x).expect("solve");
        let norm = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        x.iter_mut().for_each(|v| *v /= norm);
    }
    x[0]
}

fn large(c: &mut Criterion) {
    let n: usize = std::env::var("MODES_BENCH_BEAMS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8334);
    let mut g = c.benchmark_group("large");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(20));
    g.bench_function("modes_20", |b| {
        b.iter_batched(
            || prepared(n),
            |i| black_box(modes(i, 20, Solver::Sparse)),
            BatchSize::PerIteration,
        )
    });
    g.bench_function("factor_200_solves", |b| {
        b.iter_batched(
            || prepared(n),
            |i| black_box(factor_and_solves(i, 200)),
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

fn crossover(c: &mut Criterion) {
    let mut g = c.benchmark_group("crossover");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(2));
    for n in [25, 50, 100] {
        for (name, solver) in [("dense", Solver::Dense), ("sparse", Solver::Sparse)] {
            g.bench_function(format!("{name}_{}", 6 * n), |b| {
                b.iter_batched(
                    || prepared(n),
                    |i| black_box(modes(i, 10, solver)),
                    BatchSize::PerIteration,
                )
            });
        }
    }
    g.finish();
}

criterion_group!(benches, crossover, large);
criterion_main!(benches);
