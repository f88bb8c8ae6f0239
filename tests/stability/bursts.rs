//! Energy bursts (issue 35): steps never grow by more than two rungs and the balance
//! stays within its bound; the seed's scene runs clean to 30 and 100 s.

use super::*;

/// Step sizes and the balance along a run: every step, the largest growth of the step
/// from one accepted step to the next, and the guard's record at the end.
#[derive(Default)]
struct Steps {
    h: Vec<f64>,
}

impl Observer for Steps {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        if snap.h > 0.0 {
            self.h.push(snap.h);
        }
        Ok(())
    }
}

/// The seed's scene through its torque pulse, the swing and the first impacts (0.6 s, the
/// contact's events landing steps at 2e-7 s and less): no step is more than twice the
/// one before it (the grid's return splits into equal steps, the steps after a landing
/// double back: `solver::grid_step`, `solver::regrowth`), and the guard's largest
/// accepted rise of the balance residual is within its bound and tiny against the energy
/// in play (measured 0.048 J at the first impact, 0.535 s, of ~170 J).
#[test]
fn steps_never_grow_by_more_than_two_and_the_balance_stays_within_its_bound() {
    let mut m = deck("pendulum.dat");
    set_steps(&mut m, 1e-4, 0.6, Some(-0.1));
    let mut steps = Steps::default();
    let mut integ = solver::prepare(&m).unwrap();
    let report = solver::run_prepared(&m, &mut integ, &mut steps).unwrap();
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let growth = steps.h.windows(2).map(|w| w[1] / w[0]).fold(0.0, f64::max);
    let shortest = steps.h.iter().copied().fold(f64::INFINITY, f64::min);
    let b = integ.balance;
    println!(
        "pendulum 0.6 s: {} steps, shortest {shortest:.3e} s, largest growth {growth:.4}, largest rise {:.3e} J (bound {:.3e} J)",
        steps.h.len(),
        b.largest_rise,
        b.its_bound
    );
    assert!(
        shortest < 1e-6,
        "the run should land contact events: {shortest:e}"
    );
    if scheme_override().is_none() {
        assert!(growth <= 2.0 * (1.0 + 1e-9), "a step grew by {growth}");
    }
    assert!(b.largest_rise <= b.its_bound, "{b:?}");
    assert!(b.largest_rise < 1.0, "{b:?}");
}

/// The seed's scene run long (`decks/pendulum.dat`, to 30 s and 100 s; issue 35): it runs
/// clean, the balance residual never rises by more than 1 J above its running minimum
/// (measured 0.048 J; before issue 35 the 30 s run completed with a burst of 66 J at
/// 23.18 s, 270 J per step-by-step accounting) and the guard's record stays within its
/// bound. Expensive (1.7 and 1.5 min of CPU in release): run on demand,
/// `cargo test --release --features failpoints --test stability -- --ignored seed_scene`.
#[test]
#[ignore]
fn seed_scene_runs_clean_to_30_and_100_s() {
    for end in [30.0, 100.0] {
        let mut m = deck("pendulum.dat");
        set_steps(&mut m, 1e-4, end, Some(-0.1));
        let mut rec = Rec::default();
        let mut integ = solver::prepare(&m).unwrap();
        let report = solver::run_prepared(&m, &mut integ, &mut rec).unwrap();
        assert!(report.failure.is_none(), "{end} s: {:?}", report.failure);
        // E − W_ext: its rise above its running minimum (the dampers only lower it).
        let (mut low, mut worst) = (f64::INFINITY, 0.0f64);
        for e in &rec.e {
            low = low.min(*e);
            worst = worst.max(e - low);
        }
        let b = integ.balance;
        println!(
            "pendulum to {end} s: {} steps ({} refused), rise of E − W above its running minimum {worst:.3e} J, guard's largest {:.3e} J (bound {:.3e} J)",
            report.stats.steps, report.stats.rejected_steps, b.largest_rise, b.its_bound
        );
        assert!(b.largest_rise <= b.its_bound, "{b:?}");
        assert!(b.largest_rise < 1.0, "{end} s: {b:?}");
    }
}
