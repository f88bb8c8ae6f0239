//! Cost of a time step of the seed scene (`decks/pendulum.dat`'s double pendulum) against
//! the mesh: one residual + iteration-matrix assembly, one LU factorisation + solve, one
//! full HHT step, and the whole 2 s run, each with 10, 20, 40 and 80 beam elements per bar
//! (the deck from [`mecano::scenes::pendulum_deck`]). `cargo bench --bench step`.
//!
//! The whole run takes seconds per sample (≈ 20,000 steps at h = 1e-4 s), so it uses
//! criterion's smallest sample size (10) and only 10 and 20 elements per bar by default;
//! set `MECANO_BENCH_RUN_ALL=1` to time 40 and 80 too (minutes per size).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use mecano::scenes::{PendulumSettings, pendulum_deck};
use mecano::solver::{Integrator, Observer, Snapshot};
use std::hint::black_box;
use std::time::{Duration, Instant};

const SIZES: [usize; 4] = [10, 20, 40, 80];
const H: f64 = 1e-4;

fn model(n: usize) -> mecano::model::Model {
    let s = PendulumSettings {
        output: false,
        ..Default::default()
    };
    mecano::deck::parse_deck(&pendulum_deck(n, &s), "pendulum").expect("generated deck")
}

/// The pendulum with `n` elements per bar, initialised and advanced by `steps` steps
/// (mid-swing, before the impact at t ≈ 0.53 s).
fn advanced(n: usize, steps: usize) -> Integrator {
    let mut integ = mecano::solver::prepare(&model(n)).expect("prepare");
    integ.initialize().expect("initialize");
    for _ in 0..steps {
        integ.try_step(H).expect("step");
    }
    integ
}

fn assembly(c: &mut Criterion) {
    let mut g = c.benchmark_group("assembly");
    for n in SIZES {
        let mut integ = advanced(n, 100);
        let ctx = integ.step_context(H);
        let (nodes, lambda) = (integ.nodes.clone(), integ.lambda.clone());
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| black_box(integ.sys.assemble(&ctx, &nodes, &lambda, true)))
        });
    }
    g.finish();
}

fn factor_solve(c: &mut Criterion) {
    let mut g = c.benchmark_group("factor_solve");
    for n in SIZES {
        let mut integ = advanced(n, 100);
        let ctx = integ.step_context(H);
        let (nodes, lambda) = (integ.nodes.clone(), integ.lambda.clone());
        integ.sys.assemble(&ctx, &nodes, &lambda, true);
        let rhs = integ.sys.rhs.clone();
        let mut x = rhs.clone();
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                integ.sys.matrix.factor().expect("regular");
                x.copy_from_slice(&rhs);
                integ.sys.matrix.solve(&mut x).expect("solve");
                black_box(x[0])
            })
        });
    }
    g.finish();
}

fn step(c: &mut Criterion) {
    let mut g = c.benchmark_group("step");
    for n in SIZES {
        let mut integ = advanced(n, 100);
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    // Stay in free flight (the impact is at t ≈ 0.53 s): start again,
                    // untimed, before it.
                    if integ.t > 0.4 {
                        integ = advanced(n, 100);
                    }
                    let t0 = Instant::now();
                    black_box(integ.try_step(H).expect("step"));
                    total += t0.elapsed();
                }
                total
            })
        });
    }
    g.finish();
}

struct Null;
impl Observer for Null {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        black_box(snap.integ.t);
        Ok(())
    }
}

fn whole_run(c: &mut Criterion) {
    let mut g = c.benchmark_group("run_2s");
    g.sample_size(10);
    let all = std::env::var_os("MECANO_BENCH_RUN_ALL").is_some();
    for n in SIZES.into_iter().filter(|&n| all || n <= 20) {
        let m = model(n);
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                let r = mecano::solver::run(&m, &mut Null).expect("run");
                assert!(r.failure.is_none(), "{:?}", r.failure);
                black_box(r.stats.steps)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, assembly, factor_solve, step, whole_run);
criterion_main!(benches);
