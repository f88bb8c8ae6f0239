//! A dynamic step of the large cantilever against one factorisation and two solves of its
//! iteration matrix (issue 29's target: a step within 4× of one factorisation plus two
//! solves). The deck is `benches/large.sh`'s (n two-node beams, 6 unknowns per node).
//!
//!   cargo bench --bench large_step -- [n]        (default n = 166667: 1,000,002 unknowns)
//!
//! Times (wall clock, one thread): the first factorisation (with partial pivoting), a
//! refactorisation on its pivots (what the steps do when they refactor) and one solve,
//! each the best of 3; and the mean of the 5 steps after `initialize`, with the
//! factorisations and Newton iterations (one solve each) they made.

use std::time::Instant;

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
LOADS
  FORCE 2 0 -100 0
ANALYSIS DYNAMIC STEP 1e-5 END 1e-4
",
        len = n as f64 * 0.01
    )
}

fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(166_667);
    let h = 1e-5;
    let model = mecano::deck::parse_deck(&deck(n), "large").expect("generated deck");
    let mut integ = mecano::solver::prepare(&model).expect("prepare");
    let unknowns = integ.sys.matrix.dim();
    let ctx = integ.step_context(h);
    let (nodes, lambda) = (integ.nodes.clone(), integ.lambda.clone());
    integ.sys.assemble(&ctx, &nodes, &lambda, true);
    let t = Instant::now();
    integ.sys.matrix.factor().expect("regular");
    let pivoting = t.elapsed().as_secs_f64();
    let refactor = best(3, || integ.sys.matrix.factor().expect("regular"));
    let rhs = integ.sys.rhs.clone();
    let mut x = rhs.clone();
    let solve = best(3, || {
        x.copy_from_slice(&rhs);
        integ.sys.matrix.solve(&mut x).expect("solve")
    });
    integ.initialize().expect("initialize");
    let steps = 5;
    let (f0, s0) = (integ.stats.factorizations, integ.stats.newton_iterations);
    let t = Instant::now();
    for _ in 0..steps {
        integ.try_step(h).expect("step");
    }
    let step = t.elapsed().as_secs_f64() / steps as f64;
    let (f1, s1) = (integ.stats.factorizations, integ.stats.newton_iterations);
    println!("unknowns {unknowns}, nnz {}", integ.sys.matrix.nnz());
    println!(
        "factorisation with pivoting {pivoting:.3} s, refactorisation {refactor:.3} s, solve {solve:.3} s"
    );
    println!(
        "step {step:.3} s (mean of {steps}; {} factorisations, {} Newton iterations = solves in them)",
        f1 - f0,
        s1 - s0
    );
    for (what, f) in [("pivoting", pivoting), ("refactorisation", refactor)] {
        println!(
            "step / ({what} + 2 solves) = {:.2}",
            step / (f + 2.0 * solve)
        );
    }
}
