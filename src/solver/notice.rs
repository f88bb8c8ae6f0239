//! What the solver changed of a model or of its initial state before the first step (and
//! what it could not check during the run: the energy guard made void by Newton's tolerance), for
//! the user to know: printed as warnings by the command line, listed in `summary.json`
//! (`"notices"`), shown by `--check`.

use crate::model::{ElementId, NodeId};

/// One thing the solver did on its own before the first step.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Notice {
    /// Nodes whose rotations no element acts on: held ([`super::idle`]).
    HeldRotations {
        /// The nodes.
        nodes: Vec<NodeId>,
    },
    /// Constraint equations removed as redundant ([`super::redundancy`]).
    Redundant {
        /// The element.
        element: ElementId,
        /// Its equations (1-based).
        equations: Vec<usize>,
        /// The message.
        message: String,
    },
    /// Constraint groups too large for the redundancy check.
    Unchecked {
        /// Equations of the group.
        equations: usize,
        /// Degrees of freedom it touches.
        dofs: usize,
    },
    /// Initial positions and rotations moved onto the constraints ([`super::assembly`]).
    Assembled {
        /// Largest translation of a node, m, and the node.
        moved: f64,
        /// The node that moved most.
        node: NodeId,
        /// Largest rotation of a node, rad.
        turned: f64,
        /// The node that turned most.
        turned_node: NodeId,
        /// Constraint violation before, m or rad.
        violation: f64,
        /// Gauss–Newton iterations.
        iterations: u32,
    },
    /// Initial velocities changed to satisfy the constraints.
    VelocitiesProjected {
        /// Largest change of a node's velocity, m/s.
        change: f64,
        /// Largest change of a node's angular velocity, rad/s.
        angular_change: f64,
        /// The node whose velocity changed most.
        node: NodeId,
    },
    /// A complete run whose energy balance closes coarsely: its largest error above
    /// [`COARSE_BALANCE`] of the run's energy scale, within the bound of the energy guard
    /// (`super::energy_guard`) — said at the end of the run.
    CoarseBalance {
        /// The largest balance error relative to the run's energy scale.
        error: f64,
        /// The largest energy created above the balance residual's running minimum, J.
        created: f64,
        /// The bound it was checked against, J.
        bound: f64,
        /// Energy created above the guard's ceiling by steps accepted at the smallest
        /// step, J (`energy_guard::Balance::unverified`; 0 if none).
        unverified: f64,
        /// How many such steps.
        unverified_steps: u64,
        /// When the first of them ended, s.
        first_unverified: f64,
    },
}

/// The balance error, relative to the run's energy scale, above which a complete run is
/// said to close its energy balance coarsely ([`Notice::CoarseBalance`]): a tenth of the
/// energy in play created or lost with no work to account for it is an error of the
/// order of the motion's, not a detail of the scheme's.
pub const COARSE_BALANCE: f64 = 0.1;

impl std::fmt::Display for Notice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Notice::HeldRotations { nodes } => {
                let list: Vec<String> = nodes.iter().map(|n| n.0.to_string()).collect();
                write!(
                    f,
                    "node{} {}: no element acts on {} rotations (no rotary inertia, no beam, no joint, no moment); they are held, as FIX RX RY RZ would",
                    if nodes.len() > 1 { "s" } else { "" },
                    list.join(", "),
                    if nodes.len() > 1 { "their" } else { "its" }
                )
            }
            Notice::Redundant { message, .. } => write!(f, "redundant constraints: {message}"),
            Notice::Unchecked { equations, dofs } => write!(
                f,
                "a group of {equations} constraint equations on {dofs} degrees of freedom is too large to be checked for redundancy; a redundancy there is diagnosed only if the iteration matrix cannot be factored"
            ),
            Notice::Assembled {
                moved,
                node,
                turned,
                turned_node,
                violation,
                iterations,
            } => write!(
                f,
                "assembly: the initial positions violated the constraints by up to {violation:.3e}; {iterations} Gauss–Newton iterations moved them onto the constraints, node {} by up to {moved:.3e} m, node {} turned by up to {turned:.3e} rad",
                node.0, turned_node.0
            ),
            Notice::VelocitiesProjected {
                change,
                angular_change,
                node,
            } => write!(
                f,
                "the initial velocities were made consistent with the constraints and fixities (the smallest change in kinetic energy): by up to {change:.3e} m/s and {angular_change:.3e} rad/s (most at node {})",
                node.0
            ),
            Notice::CoarseBalance {
                error,
                created,
                bound,
                unverified,
                unverified_steps,
                first_unverified,
            } => {
                if *unverified_steps > 0 {
                    write!(
                        f,
                        "{unverified_steps} steps at the smallest step (MINSTEP), the first ending at t = {first_unverified:.6e} s, created {unverified:.3e} J above the share of the energy in play that the scheme's error explains (the energy guard's ceiling: docs/stability.md, \"The energy guard's bound\"); they were kept because no step the deck allows resolves the powers there. "
                    )?;
                }
                if *error <= COARSE_BALANCE {
                    return write!(
                        f,
                        "the run's energy balance closes to {error:.1e} of its energy scale"
                    );
                }
                write!(
                    f,
                    "the energy balance closes to {:.0} % of the run's energy scale (at most {created:.3e} J created above its running minimum, within the {bound:.3e} J the scheme's error allows: docs/stability.md, \"The energy guard's bound\"): the step resolves the motion, or the powers of the loads, drivers and dampers, coarsely, and the histories are those of this step, not converged ones; halve STEP (or ask ADAPTIVE) and compare",
                    100.0 * error
                )
            }
        }
    }
}
