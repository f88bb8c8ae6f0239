//! `History`: an in-memory observer of a run, for tests and library users.

use crate::solver::{Observer, Snapshot};
use std::io;

/// An in-memory observer: keeps the time, node states and energies of every
/// `every`-th accepted state (for tests and programs that use the library directly).
#[derive(Debug, Clone, Default)]
pub struct History {
    /// Record every this many steps (0 or 1 = every step).
    pub every: u64,
    /// Times, s.
    pub t: Vec<f64>,
    /// Node states at each recorded time (dense node order).
    pub nodes: Vec<Vec<crate::elements::NodeState>>,
    /// Kinetic + strain + gravity energy at each recorded time, J.
    pub energy: Vec<f64>,
    /// Work of the applied loads since t = 0, J.
    pub external_work: Vec<f64>,
    /// Energy dissipated by element dampers since t = 0, J.
    pub damping_work: Vec<f64>,
    /// Largest constraint violation at each recorded time.
    pub violation: Vec<f64>,
}

impl History {
    /// Records every `every`-th step.
    pub fn new(every: u64) -> Self {
        History {
            every,
            ..Default::default()
        }
    }

    /// Position history of dense node `i`.
    pub fn positions(&self, i: usize) -> Vec<nalgebra::Vector3<f64>> {
        self.nodes.iter().map(|n| n[i].x).collect()
    }
}

impl Observer for History {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        if snap.step.is_multiple_of(self.every.max(1)) {
            let integ = snap.integ;
            let e = integ.energies();
            self.t.push(integ.t);
            self.nodes.push(integ.nodes.clone());
            self.energy.push(e.kinetic + e.strain + e.gravity);
            self.external_work.push(integ.external_work);
            self.damping_work.push(integ.damping_work);
            self.violation.push(integ.constraint_violation());
        }
        Ok(())
    }
}
