//! One run of a model, fresh or restarted: the observer that streams the histories, writes
//! checkpoints on a wall-time interval and at an interruption, and ends the run when a
//! signal asks; then the closing of the files and of `summary.json`.

use super::{EXIT_BAD_INPUT, EXIT_FAILED};
use crate::checkpoint::{self, Checkpoint, DeckIdentity};
use crate::interrupt::Interrupts;
use crate::model::Model;
use crate::output::Writer;
use crate::output::vtk::VtkWriter;
use crate::solver::{self, Integrator, LoopState, Observer, Pause, RunReport, Snapshot, Stats};
use std::io::{self, IsTerminal};
use std::path::Path;
use std::time::{Duration, Instant};

/// When a run writes checkpoints, and for which deck.
#[derive(Debug, Clone)]
pub struct CheckpointPlan {
    /// Wall time between two checkpoints (`None`: only at an interruption).
    pub every: Option<Duration>,
    /// The deck the checkpoints belong to.
    pub deck: DeckIdentity,
}

impl CheckpointPlan {
    /// The plan of `--checkpoint SECONDS` (0 = no periodic checkpoint).
    pub fn new(seconds: f64, deck: DeckIdentity) -> Self {
        CheckpointPlan {
            every: (seconds > 0.0).then(|| Duration::from_secs_f64(seconds)),
            deck,
        }
    }
}

/// Test hook: `MECANO_FAILPOINT=signal:NAME:STEP` (NAME `INT`, `TERM` or `KILL`) sends the
/// process that signal at the pause after step STEP, through the real handlers (and waits
/// until they have seen it), so that tests stop a run at a known step rather than at a
/// moment that depends on the machine's speed. (`checkpoint:N`: see [`crate::checkpoint`].) Unset,
/// or a build without the hook ([`crate::failpoint`]): nothing.
fn signal_failpoint() -> Option<(libc::c_int, u64)> {
    let v = crate::failpoint::var()?;
    let mut it = v.strip_prefix("signal:")?.split(':');
    let sig = match it.next()? {
        "INT" => libc::SIGINT,
        "TERM" => libc::SIGTERM,
        "KILL" => libc::SIGKILL,
        _ => return None,
    };
    Some((sig, it.next()?.parse().ok()?))
}

/// Streams states to the writers; at each pause between steps writes a checkpoint when
/// one is due, and stops the run when a signal asked.
struct Controlled<'a> {
    writer: &'a mut Writer,
    vtk: Option<&'a mut VtkWriter>,
    dir: &'a Path,
    plan: Option<&'a CheckpointPlan>,
    interrupts: &'a Interrupts,
    /// When the last checkpoint was written (`None`: none yet by this process).
    last: Option<Instant>,
    /// Checkpoints written by this process.
    count: u64,
    /// [`signal_failpoint`], read once.
    failpoint: Option<(libc::c_int, u64)>,
}

impl Controlled<'_> {
    fn checkpoint(
        &mut self,
        plan: &CheckpointPlan,
        integ: &Integrator,
        ctl: &LoopState,
    ) -> io::Result<()> {
        let integrator = integ.save_state().map_err(io::Error::other)?;
        // The histories first: the checkpoint records their lengths, which must be on the
        // disk before it is.
        let writer = self.writer.save_state()?;
        let vtk = match self.vtk.as_deref() {
            Some(v) => Some(v.save_state()?),
            None => None,
        };
        let c = Checkpoint {
            program: env!("CARGO_PKG_VERSION").to_string(),
            deck: plan.deck.clone(),
            time: integ.t,
            step: integ.stats.steps,
            control: *ctl,
            integrator,
            writer,
            vtk,
        };
        self.count += 1;
        checkpoint::write(self.dir, &c, self.count)?;
        self.last = Some(Instant::now());
        Ok(())
    }
}

impl Observer for Controlled<'_> {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        if snap.step == 0 {
            // What the solver changed before the first step (held rotations, removed
            // redundant equations, assembly, projected velocities): said once, at the
            // start, and kept in summary.json.
            for n in &snap.integ.notices {
                eprintln!("warning: {n}");
            }
            notices_into(self.writer, snap.integ);
            self.writer.write_notes()?;
        }
        self.writer.state(snap)?;
        if let Some(v) = self.vtk.as_deref_mut() {
            v.state(snap)?;
        }
        Ok(())
    }

    fn progress(&mut self, t: f64, end: f64, stats: &Stats) {
        self.writer.progress(t, end, stats);
    }

    /// The writer's rows (the VTK series reads positions and rotations only).
    fn reads_reactions(&self, snap: &Snapshot) -> bool {
        self.writer.reads_reactions(snap)
    }

    fn pause(&mut self, integ: &Integrator, ctl: &LoopState) -> io::Result<Pause> {
        if let Some((sig, step)) = self.failpoint
            && integ.stats.steps == step
        {
            // SAFETY: kill(2) on our own pid has no memory-safety preconditions.
            unsafe {
                libc::kill(libc::getpid(), sig);
            }
            // The handler's thread sets the flag soon, but on a loaded machine maybe some
            // steps later: wait for it, so that the stop is at this very step.
            let t0 = Instant::now();
            while !self.interrupts.stopping() && t0.elapsed() < Duration::from_secs(10) {
                std::thread::sleep(Duration::from_micros(100));
            }
        }
        let stop = self.interrupts.stopping_at(integ.t);
        if let Some(plan) = self.plan {
            let due = stop
                || match (plan.every, self.last) {
                    (None, _) => false,
                    (Some(_), None) => true,
                    (Some(every), Some(last)) => last.elapsed() >= every,
                };
            if due {
                self.checkpoint(plan, integ, ctl)?;
            }
        }
        Ok(if stop { Pause::Stop } else { Pause::Continue })
    }
}

/// A run to execute: the model, its integrator (prepared, or restored from a checkpoint
/// with the step controller's state in `resume`), its writers.
pub(crate) struct Session<'a> {
    pub model: &'a Model,
    pub dir: &'a Path,
    pub quiet: bool,
    pub integ: Integrator,
    pub writer: Writer,
    pub vtk: Option<VtkWriter>,
    pub plan: Option<CheckpointPlan>,
    pub interrupts: Interrupts,
    pub resume: Option<LoopState>,
    /// The output directory's lock (and manifest), held until the run ends.
    pub claim: super::outdir::OutDir,
}

impl Session<'_> {
    /// Runs to the end, a failure or an interruption, and closes the files. Returns the
    /// report, or an exit code and message for errors that stop the run from starting.
    pub fn execute(mut self) -> Result<RunReport, (u8, String)> {
        let dir = self.dir;
        debug_assert_eq!(
            self.claim.path(),
            dir,
            "the run holds its own directory's lock"
        );
        let bar = (!self.quiet && std::io::stderr().is_terminal()).then(|| {
            let pb = indicatif::ProgressBar::new(1000);
            pb.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {msg} [{elapsed} elapsed, ~{eta} left]",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            pb
        });
        if let Some(pb) = bar.clone() {
            self.writer.progress = Some(Box::new(move |t, end, st| {
                pb.set_position(((t / end) * 1000.0) as u64);
                pb.set_message(format!(
                    "t = {t:.4} s, {} steps, {} Newton iterations",
                    st.steps, st.newton_iterations
                ));
            }));
        }
        self.integ.abort = Some(self.interrupts.abort.clone());
        let result = {
            let mut obs = Controlled {
                writer: &mut self.writer,
                vtk: self.vtk.as_mut(),
                dir,
                plan: self.plan.as_ref(),
                interrupts: &self.interrupts,
                // A restart starts from a checkpoint: the next is due an interval later.
                last: self.resume.map(|_| Instant::now()),
                count: 0,
                failpoint: signal_failpoint(),
            };
            solver::run_from(self.model, &mut self.integ, &mut obs, self.resume)
        };
        if let Some(pb) = bar {
            pb.finish_and_clear();
        }
        let integ = &mut self.integ;
        // Whether the state could still go on: an interruption, or a disk that failed
        // the writers (once space is freed, a restart from the last checkpoint works).
        let mut resumable = false;
        let mut report = match result {
            Ok(r) => r,
            Err(solver::RunError::Output(e)) => {
                resumable = true;
                // The writer refused a row (non-finite value) or the disk failed: the run
                // stops here, its files marked incomplete.
                RunReport {
                    stats: integ.stats,
                    time: integ.t,
                    failure: Some(solver::Failure::output(integ, &e)),
                    interrupted: None,
                }
            }
            Err(e) => return Err((EXIT_BAD_INPUT, e.to_string())),
        };
        // The final state, written by `finish` when `EVERY` skipped it, with the reactions a
        // written row has (an ESDIRK's from the index-1 equations, `Observer::reads_reactions`);
        // an interrupted run writes no row there.
        let exact = report.interrupted.is_none() && integ.exact_reactions();
        report.stats = integ.stats;
        // The final row first: its balance counts (the fuzzer's case 17:12640 closed to
        // 0.22 at its last row alone, and said nothing).
        let last = self.writer.write_last(integ, &report);
        let error = self.writer.max_balance_error();
        let b = integ.balance;
        if report.failure.is_none()
            && report.interrupted.is_none()
            && (error > solver::notice::COARSE_BALANCE || b.unverified_steps > 0)
        {
            let coarse = solver::notice::Notice::CoarseBalance {
                error,
                created: b.largest_rise,
                bound: b.its_bound,
                unverified: b.unverified,
                unverified_steps: b.unverified_steps,
                first_unverified: b.first_unverified,
            };
            eprintln!("warning: {coarse}");
            integ.notices.push(coarse);
        }
        notices_into(&mut self.writer, integ);
        if report.interrupted.is_some() {
            let signal = self.interrupts.signal_name().unwrap_or("a stop request");
            self.writer
                .notes
                .insert("signal".into(), serde_json::json!(signal));
        }
        let finished = last.and(self.writer.finish(integ, &report));
        if exact {
            integ.restore_stage_values();
        }
        finished.map_err(|e| (EXIT_FAILED, format!("{}: {e}", dir.display())))?;
        if let Some(v) = self.vtk.as_mut() {
            v.finish(integ, report.interrupted.is_some())
                .map_err(|e| (EXIT_FAILED, format!("{}: {e}", dir.display())))?;
        }
        if report.interrupted.is_none() && !resumable {
            // A complete run is not resumed, and a failed one would fail again at the same
            // step (a restart is bit for bit): its checkpoint is of no more use.
            for name in [checkpoint::FILE_NAME, checkpoint::TMP_NAME] {
                let _ = crate::safe_file::remove_regular(&dir.join(name));
            }
        }
        Ok(report)
    }
}

/// The integrator's notices into the summary's `"notices"` (none: no entry).
fn notices_into(writer: &mut Writer, integ: &Integrator) {
    if !integ.notices.is_empty() {
        writer.notes.insert(
            "notices".into(),
            serde_json::to_value(&integ.notices).unwrap_or_default(),
        );
    }
}
