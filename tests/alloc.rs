//! No heap allocation in the step loop after the first steps (issue 7, "a fast step"):
//! a counting global allocator wraps the system one and counts every allocation and
//! reallocation while the pendulum of `decks/pendulum.dat` takes 50 steps.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

struct Counting;

static ALLOCS: AtomicU64 = AtomicU64::new(0);
static COUNTING: AtomicBool = AtomicBool::new(false);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
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
    COUNTING.store(true, Ordering::SeqCst);
    let mut ok = true;
    for _ in 0..50 {
        ok &= integ.try_step(h).is_ok();
    }
    COUNTING.store(false, Ordering::SeqCst);
    let n = ALLOCS.load(Ordering::SeqCst);
    assert!(ok, "a step failed");
    assert_eq!(n, 0, "{n} heap allocations in 50 steps");
}
