//! Cost of the seed scene's step against the polynomial order of the beams
//! (`cargo bench --bench order`): the residual assembly (every Newton iteration), the
//! assembly with the iteration matrix (at each factorisation) and one whole HHT step, for the
//! scene built by [`mecano::scenes::pendulum_order_deck`] with each bar `d` elements of order
//! `p`: `p` = 1, 2, 4, 8 at (about) 17 nodes per bar, and `p` = 4, 8 with `d` = 1, 2, 4 (the
//! cost at a fixed order must grow at most linearly with the nodes).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use mecano::scenes::{PendulumSettings, pendulum_order_deck};
use mecano::solver::Integrator;
use std::hint::black_box;
use std::time::{Duration, Instant};

const H: f64 = 1e-4;

/// (divide, order) pairs: equal node counts across orders, then growing meshes per order.
const MESHES: [(u32, u32); 8] = [
    (16, 1),
    (8, 2),
    (4, 4),
    (2, 8),
    (1, 4),
    (2, 4),
    (1, 8),
    (4, 8),
];

fn advanced(divide: u32, order: u32, steps: usize) -> Integrator {
    let s = PendulumSettings {
        output: false,
        ..Default::default()
    };
    let deck = pendulum_order_deck(divide, order, &s);
    let model = mecano::deck::parse_deck(&deck, "pendulum").expect("generated deck");
    let mut integ = mecano::solver::prepare(&model).expect("prepare");
    integ.initialize().expect("initialize");
    for _ in 0..steps {
        integ.try_step(H).expect("step");
    }
    integ
}

fn id(d: u32, p: u32) -> BenchmarkId {
    BenchmarkId::from_parameter(format!("p{p}_d{d}_nodes{}", d * p + 1))
}

fn assembly(c: &mut Criterion) {
    for (name, tangent) in [("residual", false), ("residual_and_matrix", true)] {
        let mut g = c.benchmark_group(format!("order_{name}"));
        for (d, p) in MESHES {
            let mut integ = advanced(d, p, 100);
            let ctx = integ.step_context(H);
            let (nodes, lambda) = (integ.nodes.clone(), integ.lambda.clone());
            g.bench_function(id(d, p), |b| {
                b.iter(|| black_box(integ.sys.assemble(&ctx, &nodes, &lambda, tangent)))
            });
        }
        g.finish();
    }
}

/// One HHT step of the swing before the impact: the integrator goes back to its state after
/// 100 steps (outside the timing) before it reaches the floor (first contact at 0.533 s), so
/// that every timed step is a free-swing step of the same kind however many criterion takes.
fn step(c: &mut Criterion) {
    let mut g = c.benchmark_group("order_step");
    for (d, p) in MESHES {
        let mut integ = advanced(d, p, 100);
        g.bench_function(id(d, p), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    if integ.t > 0.4 {
                        integ = advanced(d, p, 100);
                    }
                    let start = Instant::now();
                    black_box(integ.try_step(H).expect("step"));
                    total += start.elapsed();
                }
                total
            })
        });
    }
    g.finish();
}

criterion_group!(benches, assembly, step);
criterion_main!(benches);
