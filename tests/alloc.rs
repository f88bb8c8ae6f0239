//! No heap allocation in the step loop after the first steps (issue 7, "a fast step"):
//! a counting global allocator wraps the system one and counts every allocation and
//! reallocation while the pendulum of `decks/pendulum.dat` takes 50 steps — without
//! output, and writing every node and element at every step — and through its impact.

mod common;

use mecano::solver::{Observer, Snapshot};

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

// Per thread: the tests of this file run in parallel, and each counts its own thread's
// allocations only (const-initialised thread-locals do not allocate).
thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
    /// The largest single allocation (or reallocation's new size) while counting, bytes.
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    let on = COUNTING.try_with(Cell::get).unwrap_or(false);
    if on {
        let _ = ALLOCS.try_with(|a| a.set(a.get() + 1));
    }
}

fn size(bytes: usize) {
    if COUNTING.try_with(Cell::get).unwrap_or(false) {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(bytes)));
    }
}

/// The largest single allocation `f` makes on this thread, bytes.
fn largest_allocation_in<T>(f: impl FnOnce() -> T) -> (T, usize) {
    LARGEST.with(|l| l.set(0));
    COUNTING.with(|c| c.set(true));
    let out = f();
    COUNTING.with(|c| c.set(false));
    (out, LARGEST.with(Cell::get))
}

/// Counts the allocations `f` makes on this thread.
fn allocations_in<T>(f: impl FnOnce() -> T) -> (T, u64) {
    ALLOCS.with(|a| a.set(0));
    COUNTING.with(|c| c.set(true));
    let out = f();
    COUNTING.with(|c| c.set(false));
    (out, ALLOCS.with(Cell::get))
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        size(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        size(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        size(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_step_loop_does_not_allocate() {
    let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/decks/pendulum.dat"));
    let mut model = mecano::deck::load_deck(path).expect("seed deck");
    // OUTPUT NODES NONE ELEMENTS NONE (the step loop alone is measured).
    model.output.nodes = mecano::model::Selection::None;
    model.output.elements = mecano::model::Selection::None;
    let mut integ = mecano::solver::prepare(&model).expect("prepare");
    integ.initialize().expect("initial accelerations");
    let h = 1e-4;
    for _ in 0..5 {
        integ.try_step(h).expect("step");
    }
    let (ok, n) = allocations_in(|| (0..50).all(|_| integ.try_step(h).is_ok()));
    assert!(ok, "a step failed");
    assert_eq!(n, 0, "{n} heap allocations in 50 steps");
}

/// The adaptive ESDIRK5 step with `CARRY MODES` allocates nothing either: its embedded
/// errors and the filtered velocity error go to kept buffers, and its drift filter is rebuilt
/// (every 1/200 of the run: here a run said to last 0.2 s, so every 1 ms, ten times in the
/// 100 steps of 1e-4 s measured) into its own (`solver::integrator::drift`), once its LU has
/// grown to its fill: a rebuild that re-pivots may grow it, as the iteration matrix's LU
/// (`solver::linear`) — here once, at 5.3 ms, within the 60 steps before. The tolerance is
/// loose enough for every step to be accepted.
#[test]
fn the_adaptive_esdirk_step_with_carry_modes_does_not_allocate() {
    let path = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/decks/pendulum_adaptive.dat"
    ));
    let mut model = mecano::deck::load_deck(path).expect("deck");
    let mecano::model::Analysis::Dynamic {
        adaptive: Some(a), ..
    } = &mut model.analysis
    else {
        panic!("the deck is adaptive");
    };
    assert_eq!(a.carry, mecano::model::Carry::Modes);
    (a.tol_position, a.tol_rotation) = (1.0, 1.0);
    let adaptive = a.clone();
    let mut integ = mecano::solver::prepare(&model).expect("prepare");
    integ.initialize().expect("initial accelerations");
    integ.adaptive = Some(adaptive);
    integ.error_horizon = 0.2;
    let h = 1e-4;
    for _ in 0..60 {
        integ.try_step(h).expect("step");
    }
    let (ok, n) = allocations_in(|| (0..100).all(|_| integ.try_step(h).is_ok()));
    assert!(ok, "a step failed");
    assert_eq!(n, 0, "{n} heap allocations in 100 steps");
}

/// Writing the histories allocates nothing either: every node and element of the pendulum
/// (hinge, universal joint, 20 beams, the CAME contact, two masses) and the energies at
/// each of the 50 steps, through `output::Writer` (csv, ryu, one reused row buffer).
#[test]
fn writing_every_node_and_element_every_step_does_not_allocate() {
    let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/decks/pendulum.dat"));
    let mut model = mecano::deck::load_deck(path).expect("seed deck");
    model.output.nodes = mecano::model::Selection::All;
    model.output.elements = mecano::model::Selection::All;
    model.output.every = 1;
    let scratch = common::TempDir::new("alloc");
    let dir = scratch.path();
    let mut integ = mecano::solver::prepare(&model).expect("prepare");
    integ.initialize().expect("initial accelerations");
    let mut writer =
        mecano::output::Writer::create(dir, "pendulum.dat", &model, &integ.sys).expect("files");
    let h = 1e-4;
    let mut step = 0;
    let mut go = |integ: &mut mecano::solver::Integrator, writer: &mut mecano::output::Writer| {
        step += 1;
        let ok = integ.try_step(h).is_ok();
        writer
            .state(&Snapshot { integ, step, h })
            .expect("row written");
        ok
    };
    for _ in 0..5 {
        assert!(go(&mut integ, &mut writer));
    }
    let (ok, n) = allocations_in(|| (0..50).all(|_| go(&mut integ, &mut writer)));
    drop(writer);
    assert!(ok, "a step failed");
    assert_eq!(n, 0, "{n} heap allocations in 50 steps with their output");
}

/// The step loop of beams of order p allocates nothing either (the element's scratch
/// buffers are grown once per thread): the seed scene with two elements of order 6 per bar.
#[test]
fn the_step_loop_of_high_order_beams_does_not_allocate() {
    let s = mecano::scenes::PendulumSettings {
        output: false,
        ..Default::default()
    };
    let deck = mecano::scenes::pendulum_order_deck(2, 6, &s);
    let model = mecano::deck::parse_deck(&deck, "pendulum_p6.dat").expect("deck");
    let mut integ = mecano::solver::prepare(&model).expect("prepare");
    integ.initialize().expect("initial accelerations");
    let h = 1e-4;
    for _ in 0..5 {
        integ.try_step(h).expect("step");
    }
    let (ok, n) = allocations_in(|| (0..50).all(|_| integ.try_step(h).is_ok()));
    assert!(ok, "a step failed");
    assert_eq!(n, 0, "{n} heap allocations in 50 steps");
}

/// From the first accepted state at or after `from` to the first at or after `to`: this
/// thread's allocations in each step (between two states; the observer allocates nothing),
/// as `(allocations, the step restarted the accelerations at an event)`.
struct CountBetween {
    from: f64,
    to: f64,
    restarts: u64,
    steps: Vec<(u64, bool)>,
    done: bool,
}

impl Observer for CountBetween {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let (t, restarts) = (
            snap.integ.t,
            snap.integ.stats.restarts + snap.integ.stats.rejected_steps,
        );
        let on = COUNTING.with(Cell::get);
        COUNTING.with(|c| c.set(false));
        if on {
            let n = ALLOCS.with(Cell::get);
            self.steps.push((n, restarts > self.restarts));
        }
        self.restarts = restarts;
        if !self.done && t >= self.from && t < self.to {
            ALLOCS.with(|a| a.set(0));
            COUNTING.with(|c| c.set(true));
        } else if t >= self.to {
            self.done = true;
        }
        Ok(())
    }
}

/// The contact path (issue 27 §1d: the tests above cover steps 6–55, long before the
/// impact): the whole solver loop (`solver::run_prepared`: step controller, the CAME's event
/// landing and refused steps, the impact's shortened steps, the restarts of the
/// accelerations at the events) from t = 0.52 s to 0.56 s, through the first impact of node
/// 23 at 0.533 s. The window holds more steps than its 400 of h = 1e-4 s (the impact's
/// refined steps are in it) and at least one event.
///
/// Measured before the fix: 27 allocations in the window's 406 steps, 25 of them in the 4
/// steps that restart the accelerations or follow a refused attempt
/// (`Integrator::consistent_accelerations` built its vectors and a copy of the matrix
/// afresh; a refused attempt's residual history and worst-equation text were not given
/// back). Now 0.
#[test]
fn the_contact_path_does_not_allocate() {
    let mut model = common::deck("pendulum.dat");
    model.output.nodes = mecano::model::Selection::None;
    model.output.elements = mecano::model::Selection::None;
    assert!(model.set_fixed_step(1e-4, 0.57, None));
    let mut integ = mecano::solver::prepare(&model).expect("prepare");
    let mut obs = CountBetween {
        from: 0.52,
        to: 0.56,
        restarts: 0,
        steps: Vec::new(),
        done: false,
    };
    let r = mecano::solver::run_prepared(&model, &mut integ, &mut obs).expect("runs");
    COUNTING.with(|c| c.set(false));
    assert!(r.failure.is_none(), "{:?}", r.failure);
    let steps = &obs.steps;
    let events = steps.iter().filter(|s| s.1).count();
    let at_events: u64 = steps.iter().filter(|s| s.1).map(|s| s.0).sum();
    eprintln!(
        "0.52-0.56 s: {} steps, {events} with a restart or a refused attempt, {at_events} allocations in them",
        steps.len()
    );
    assert!(
        steps.len() > 400,
        "{} steps: no refined impact steps",
        steps.len()
    );
    assert!(events >= 1, "no contact event in 0.52-0.56 s");
    let elsewhere: u64 = steps.iter().filter(|s| !s.1).map(|s| s.0).sum();
    assert_eq!(
        at_events + elsewhere,
        0,
        "heap allocations through the impact: {at_events} in the {events} steps with a restart or \
         a refused attempt, {elsewhere} in the others"
    );
}

/// Memory asked before it is taken (issue 35 §2): a model too large for the memory the
/// process may take is refused before its nodes are generated, so that no refused input
/// allocates more than 100 MB at once — a deck dividing the pendulum's bars a million
/// times each, `--refine 1000000` of the pendulum, generations of a million nodes. The
/// limit is set here (1 GiB, as `--max-memory 1G`), so the refusal does not depend on the
/// machine; every other test of this file asks far less.
#[test]
fn a_refused_model_never_allocates_100_mb() {
    mecano::model::budget::set_max_memory(1 << 30);
    let seed = include_str!("../decks/pendulum.dat");
    let divided = seed.replace(
        "2 TO 11  BEAM 2 3  MAT 1 SEC 1",
        "2 TO 11  BEAM 2 3  MAT 1 SEC 1 DIVIDE 1000000",
    );
    assert_ne!(divided, seed);
    let generated = "NODES\n  1 TO 1000000 LINE 0 0 0 1 0 0\n  1000001 TO 2000000 LINE 0 0 0 1 0 0\nANALYSIS STATIC STEPS 1\n";
    let beams = "MATERIALS\n 1 E 2e11 NU 0.3 RHO 7800\nSECTIONS\n 1 A 1e-4 I2 1e-9 I3 1e-9 J 2e-9\nNODES\n 1 0 0 0\n 2 1 0 0\nELEMENTS\n 1 BEAM 1 2 MAT 1 SEC 1 DIVIDE 1000000\nANALYSIS STATIC STEPS 1\n";
    const BOUND: usize = 100_000_000;
    for (name, text) in [
        ("DIVIDE", divided.as_str()),
        ("TO", generated),
        ("one beam", beams),
    ] {
        let (r, largest) = largest_allocation_in(|| mecano::deck::parse_deck(text, "big.dat"));
        let e = r.expect_err(name);
        assert!(e.to_string().contains("--max-memory"), "{name}: {e}");
        assert!(largest < BOUND, "{name}: an allocation of {largest} bytes");
    }
    let mut model = mecano::deck::parse_deck(seed, "seed.dat").unwrap();
    let (r, largest) = largest_allocation_in(|| model.refine(1_000_000));
    let e = r.expect_err("--refine 1000000");
    assert!(e.to_string().contains("--max-memory"), "{e}");
    assert!(
        largest < BOUND,
        "--refine: an allocation of {largest} bytes"
    );
    mecano::model::budget::set_max_memory(0);
}
