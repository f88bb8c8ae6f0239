//! Cost of the sparse modal analysis (issue 24's target: the lowest 20 modes of a model of
//! about 50,000 unknowns within 10× one factorisation plus 200 solves of it), and where the
//! dense and sparse solvers cross (docs/modes.md).
//!
//!   cargo bench --bench modes -- large        (the target; MODES_BENCH_BEAMS, default 8334)
//!   cargo bench --bench modes -- crossover    (dense vs sparse, 10 modes, 150–600 unknowns)
//!   MODES_BENCH_CPU=3 cargo bench --bench modes   (the target in CPU seconds, interleaved)
//!   MODES_BENCH_LARGE_SH=1 ...                    (benches/large.sh's 83 m geometry instead)
//!   MODES_BENCH_DAMPING=1e-4 ...                  (material damping: the state-space path)
//!
//! The model is a clamped steel cantilever of 10 m (square section 0.1 m) cut into n
//! two-node beams (6 unknowns per free node: 6n; 8334 beams = 50,004, the size of
//! `benches/large.sh`'s first case; see [`deck`] for why not its geometry). `large/modes_20` is the
//! whole analysis the `modes` command makes after building the system: the element
//! matrices (K, M, C), one factorisation of `K − σM` with partial pivoting, block Lanczos,
//! the checks. `large/factor_200_solves` is the reference: the same matrix factored with
//! pivoting and 200 solves. Each iteration starts from a freshly prepared system (its
//! preparation is not timed), so both make a first, pivoting factorisation. The
//! frequencies are not checked here (tests/mechanics/modes_sparse.rs does against the dense path).

use criterion::{BatchSize, Criterion, criterion_group};
use mecano::modes::{Solver, analyse};
use mecano::solver::Integrator;
use std::hint::black_box;
use std::time::Duration;

/// A steel cantilever of 10 m, square section 0.1 m, cut into `n` two-node beams.
/// (benches/large.sh's 83 m cantilever of 3 cm section and 1 cm beams was the first
/// choice: its lowest pair, 4.03e-3 Hz, has ω² = 6.4e-4 1/s², below the round-off
/// threshold 10 ε ω²_max = 1.8e-3 of its own stiffness, so it came out as two rigid
/// modes, its bending planes apart by 1.5e-6 — not a model whose modes can be computed.
/// Here ω₁² ≈ 28 1/s² against a threshold of ~1e-3.)
fn deck(n: usize) -> String {
    let text = geometry(n);
    // MODES_BENCH_DAMPING=η: the material a Kelvin–Voigt solid (the sparse state-space path).
    match std::env::var("MODES_BENCH_DAMPING") {
        Ok(eta) => text.replacen("RHO 7800", &format!("RHO 7800 DAMPING {eta}"), 1),
        Err(_) => text,
    }
}

fn geometry(n: usize) -> String {
    if std::env::var_os("MODES_BENCH_LARGE_SH").is_some() {
        // benches/large.sh's geometry, for comparison (docs/modes.md).
        return format!(
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
        );
    }
    format!(
        "TITLE cantilever of {n} beams
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
SECTIONS
  1 A 0.01 I2 8.333e-6 I3 8.333e-6 J 1.406e-5 K 0.8333333333333334
NODES
  1 0 0 0 FIX ALL
  2 10 0 0
ELEMENTS
  1 BEAM 1 2 MAT 1 SEC 1 AXIS2 0 0 1 DIVIDE {n}
ANALYSIS DYNAMIC STEP 1e-5 END 1e-4
"
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

/// CPU seconds (user + system) of this process so far.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

/// `MODES_BENCH_CPU=k cargo bench --bench modes`: the two timings of `large` measured in
/// CPU seconds (the 2-core machine is shared: wall time is not the process's), `k` rounds
/// interleaved, each from a freshly prepared system, with the sparse solve's counts and
/// the frequencies found.
fn cpu_rounds(rounds: usize) {
    let n: usize = std::env::var("MODES_BENCH_BEAMS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8334);
    let mut integ = prepared(n);
    let found = mecano::modes::sparse::lowest(
        &mut integ.sys,
        &integ.nodes,
        &integ.lambda,
        integ.scale,
        integ.t,
        20,
    )
    .expect("sparse modes");
    let tau = 2.0 * std::f64::consts::PI;
    let mut hz: Vec<String> = found
        .pairs
        .iter()
        .map(|p| format!("{:.6e}", p.0.max(0.0).sqrt() / tau))
        .collect();
    hz.extend(found.damped.iter().map(|m| {
        let w = m.s.0.hypot(m.s.1);
        format!("{:.6e} (zeta {:.3e})", w / tau, -m.s.0 / w)
    }));
    println!(
        "{} unknowns: {} solves, {} pivoting factorisations, block {}, shift {:.3e}, zero threshold {:.3e} 1/s², frequencies Hz {}",
        6 * n,
        found.solves,
        found.factorisations,
        found.block,
        found.shift,
        found.zero,
        hz.join(" ")
    );
    let (mut tm, mut tf) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        let i = prepared(n);
        let t0 = cpu_seconds();
        black_box(modes(i, 20, Solver::Sparse));
        tm.push(cpu_seconds() - t0);
        let i = prepared(n);
        let t0 = cpu_seconds();
        black_box(factor_and_solves(i, 200));
        tf.push(cpu_seconds() - t0);
    }
    for (k, (a, b)) in tm.iter().zip(&tf).enumerate() {
        println!(
            "round {}: modes_20 {a:.3} s CPU, factor_200_solves {b:.3} s CPU, ratio {:.2}",
            k + 1,
            a / b
        );
    }
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (a, b) = (med(&mut tm), med(&mut tf));
    println!(
        "median: modes_20 {a:.3} s, factor_200_solves {b:.3} s, ratio {:.2}",
        a / b
    );
}

fn main() {
    if let Some(k) = std::env::var("MODES_BENCH_CPU")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        cpu_rounds(k);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
