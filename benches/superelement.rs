//! Cost of a superelement (issue 38's target): the Craig–Bampton reduction of a
//! 100,000-dof mesh to 20 fixed-interface modes in ≤ 20× one sparse factorisation, and a
//! step of a mechanism with such a body costing what its modal coordinates cost, not its
//! mesh.
//!
//!   cargo bench --bench superelement              (130 × 130 grillage: 101,400 dofs)
//!   SE_BENCH_GRID=60 cargo bench --bench superelement   (a 60 × 60 grillage)
//!
//! The mesh is a steel grillage ([`frame_model::grillage`]: 130 × 130 nodes 1 cm apart
//! joined by Euler–Bernoulli beams, six dofs per node), interface: the corner node 1 (the
//! frame) and the opposite corner. Timed in CPU seconds of this process (the 2-core
//! machine is shared: wall time is not the process's):
//!
//! * `factor`: one sparse Cholesky of `K_II` (AMD ordering, symbolic and numeric), the
//!   reference the target is stated in;
//! * `reduce`: the whole sparse reduction — the partition, the same factorisation, the
//!   constraint modes `Ψ = −K_II⁻¹K_IB` (12 solves), the block Lanczos for 20 + 6 modes;
//! * `invariants`: the floating frame's inertia invariants from the basis (`Body::new`);
//! * `evaluate`: one residual-and-tangent evaluation of the element (what a Newton
//!   iteration asks of it), for this body and for a 10 × 10 grillage's body with the same
//!   interface and modes; their ratio is the step's dependence on the mesh.

use mecano::elements::superelement::frame_model::grillage;
use mecano::elements::superelement::invariants::Body;
use mecano::elements::superelement::{Superelement, reduce, sparse};
use mecano::elements::{Element, EvalContext, Local, NodeState};
use mecano::model::ElementId;
use nalgebra::Vector3;

/// CPU seconds (user + system) of this process so far.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

const MODES: usize = 20;

/// The reduced body of an `n × n` grillage and the CPU seconds of its stages.
fn body(n: usize, report: bool) -> Body {
    let fe = grillage(n, n, 0.01);
    let interface = [1, (n * n) as u32];
    let dofs = fe.dofs.len();
    let t0 = cpu_seconds();
    let part = reduce::partition(&fe, &interface, MODES).expect("partition");
    let blocks = sparse::blocks(&fe, &part);
    let llt = sparse::cholesky(part.interior.len(), &blocks.kii).expect("factor");
    let factor = cpu_seconds() - t0;
    drop(llt);
    let t1 = cpu_seconds();
    let red = sparse::reduce(&fe, &interface, MODES).expect("reduce");
    let t2 = cpu_seconds();
    let body = Body::new(&fe, &fe.m, &red, interface[0], &interface[1..]).expect("body");
    let t3 = cpu_seconds();
    if report {
        println!(
            "grillage {n} × {n}: {dofs} dofs, K {} and M {} lower-triangle entries",
            fe.k.entries.len(),
            fe.m.entries.len()
        );
        println!("  factor     {factor:8.3} s CPU (one sparse Cholesky of K_II)");
        println!(
            "  reduce     {:8.3} s CPU = {:.1} × factor (target ≤ 20)",
            t2 - t1,
            (t2 - t1) / factor
        );
        println!(
            "  invariants {:8.3} s CPU; reduction + invariants = {:.1} × factor",
            t3 - t2,
            (t3 - t1) / factor
        );
        println!(
            "  lowest fixed-interface frequencies, Hz: {:.4?}",
            red.omega2
                .iter()
                .take(4)
                .map(|w| w.sqrt() / std::f64::consts::TAU)
                .collect::<Vec<_>>()
        );
    }
    body
}

/// CPU seconds of one residual-and-tangent evaluation of `body`'s element at a
/// deformed, moving state (mean over `reps`), and the element's local size.
fn evaluate(body: Body, reps: usize) -> (f64, usize) {
    let n = body.n;
    let modal = n.div_ceil(3);
    let tip = body.s_iface[0];
    let el = Superelement::new(
        ElementId(1),
        (0..2 + modal).collect(),
        body,
        vec![Vector3::zeros(); modal],
    );
    let mut nodes = vec![
        NodeState::at_rest(Vector3::zeros()),
        NodeState::at_rest(tip),
    ];
    nodes.extend((0..modal).map(|i| {
        let mut s = NodeState::at_rest(Vector3::from_element(1e-6 * i as f64));
        s.v = Vector3::from_element(1e-3);
        s
    }));
    nodes[0].w = Vector3::new(0.3, -0.2, 1.0);
    nodes[1].x += Vector3::new(1e-5, 0.0, -2e-5);
    let ctx = EvalContext {
        t: 0.0,
        c_v: 2.1e3,
        c_a: 3.9e6,
        dynamic: true,
        gravity: Vector3::new(0.0, 0.0, -9.81),
        constraint_scale: 1.0,
        penalty: 0.0,
        h: 1e-3,
    };
    let size = 6 * el.nodes().len() + el.multipliers();
    let lambda = vec![0.0; el.multipliers()];
    let mut out = Local::new(size);
    let t0 = cpu_seconds();
    for _ in 0..reps {
        out.clear();
        el.evaluate(&ctx, &nodes, &lambda, true, &mut out);
        std::hint::black_box(&out);
    }
    ((cpu_seconds() - t0) / reps as f64, size)
}

fn main() {
    // `cargo test` runs benches' binaries with no `--bench`: nothing then (a 100,000-dof
    // reduction is not a test).
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let grid = std::env::var("SE_BENCH_GRID")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(130);
    let large = body(grid, true);
    let small = body(10, false);
    let reps = 2000;
    let (tl, size) = evaluate(large, reps);
    let (ts, _) = evaluate(small, reps);
    println!(
        "element evaluation (residual + tangent, local size {size}): {:.1} µs CPU for the {grid} × {grid} grillage's body, {:.1} µs for the 10 × 10's (600 dofs): ratio {:.2}",
        tl * 1e6,
        ts * 1e6,
        tl / ts
    );
}
