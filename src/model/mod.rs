//! The numbered, validated model: what a deck means.
//!
//! Built from the raw cards of [`crate::deck`] by [`crate::deck::build_model`]; every
//! reference is resolved (a [`NodeId`] in an element is known to exist), every default
//! applied and every range checked. The solver reads a `Model` and nothing else.
//!
//! **Invariant:** maps keep deck order; keys are the user's numbers.

pub mod arc;
pub mod budget;
mod clearance;
pub mod control;
mod drive;
mod expr;
mod function;
mod ids;
mod mesh;
pub mod order;
mod output;
mod scheme;
mod section;
mod springs;
mod summary;
mod superelement;

pub use clearance::{ClearanceData, ContactLaw};
pub use drive::{Drive, NodeMotion};
pub use expr::{At, BinOp, Blowup, Expr, Func, IJet, Kink, TimeExpr};
pub use function::{CubicSpline, Function, SplineError};
pub use ids::{ElementId, FunctionId, MaterialId, NodeId, SectionId};
pub use mesh::{Division, MeshError, Numbering, axis_points, uniform_params};
pub use output::{LARGE_MODEL, OutputRequest, Selection};
pub use scheme::{Scheme, SchemeNameError};
pub use section::{BeamProperties, Geometry, Section, SectionData};
pub use springs::{BushingData, RSpringData, SpringData, SpringLength};
pub use summary::{Effects, Generated, Summary};
pub use superelement::{RbeKind, RbeSpec, SetSpec, SuperelementData};

use indexmap::IndexMap;
use nalgebra::{Matrix3, Vector3};

/// A byte range in the deck's source text (for diagnostics that point back to the deck).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte.
    pub end: usize,
}

impl Span {
    /// A span from `start` to `end` (bytes).
    pub fn new(start: usize, end: usize) -> Self {
        Span { start, end }
    }
}

/// Which of a node's six degrees of freedom are fixed: `[x, y, z, rx, ry, rz]`.
pub type Fixity = [bool; 6];

/// A node: reference position and the degrees of freedom held fixed.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// The user's number.
    pub id: NodeId,
    /// Reference (initial) position, global frame, m.
    pub position: Vector3<f64>,
    /// Fixed degrees of freedom `[x, y, z, rx, ry, rz]`.
    pub fixed: Fixity,
    /// Where the node was defined.
    pub span: Span,
}

/// An isotropic linear-elastic material.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// The user's number.
    pub id: MaterialId,
    /// Young's modulus E, N/m² (> 0).
    pub young: f64,
    /// Shear modulus G, N/m² (> 0); from `G = E / (2(1+ν))` when ν is given.
    pub shear: f64,
    /// Density ρ, kg/m³ (≥ 0).
    pub density: f64,
    /// Stiffness-proportional (Rayleigh) damping coefficient, s (≥ 0; 0 = none).
    pub damping: f64,
    /// Where the material was defined.
    pub span: Span,
}

/// A named function with its span.
#[derive(Debug, Clone, PartialEq)]
pub struct FunctionDef {
    /// The user's number.
    pub id: FunctionId,
    /// The function.
    pub function: Function,
    /// Where it was defined.
    pub span: Span,
}

/// A planar curve of a CAME profile, in its node's local frame (plane of local axes 1–2,
/// extruded along local axis 3).
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// A single point at `offset`.
    Point,
    /// A straight line through `offset` along local direction `(cos θ, sin θ)`, θ the
    /// profile's in-plane angle.
    Line,
    /// A circle of radius `r` centred at `offset`.
    Circle {
        /// Radius, m (> 0).
        radius: f64,
    },
    /// A cubic spline through points (local plane coordinates, m).
    Spline {
        /// Interpolated points (at least 2; at least 3 when closed).
        points: Vec<[f64; 2]>,
        /// Closed (periodic) curve.
        closed: bool,
    },
}

/// A profile placed in its node's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedProfile {
    /// The curve.
    pub profile: Profile,
    /// Offset of the profile's origin from the node, in the node's local frame, m.
    pub offset: Vector3<f64>,
    /// Orientation of the profile plane in the node frame: the profile's local axes
    /// (columns) expressed in the node frame. Identity by default: profile plane = node's
    /// 1–2 plane, extrusion along axis 3.
    pub frame: Matrix3<f64>,
}

/// Data of a CAME (cam–follower contact) element.
#[derive(Debug, Clone, PartialEq)]
pub struct CameData {
    /// Contact stiffness `k_cont`, N/m (> 0).
    pub stiffness: f64,
    /// Contact damping `c_cont`, N·s/m (≥ 0).
    pub damping: f64,
    /// Coulomb friction coefficient μ (≥ 0; 0 = frictionless).
    pub friction: f64,
    /// Regularisation speed of friction, m/s (> 0).
    pub friction_speed: f64,
    /// Clip the tensile (adhesive) part of the force at the end of an impact.
    pub clip_tension: bool,
    /// Minimum number of time steps that must resolve each impact (adaptive cutting).
    pub impact_steps: u32,
    /// The cam's profile, on the first node.
    pub cam: PlacedProfile,
    /// The follower's profile, on the second node.
    pub follower: PlacedProfile,
}

/// What an element is, with its type-specific data.
#[derive(Debug, Clone, PartialEq)]
pub enum ElementKind {
    /// Geometrically exact beam of order `order` (`order + 1` nodes along the axis: the
    /// two ends the user named and, for `order > 1`, generated interior nodes).
    Beam {
        /// Material: `Some` exactly when the section is given by its geometry
        /// ([`Section::needs_material`]); a section of properties per unit length has none.
        material: Option<MaterialId>,
        /// Section.
        section: SectionId,
        /// Direction of the section's local axis 2 in the reference configuration
        /// (global); `None` = the documented default.
        axis2: Option<Vector3<f64>>,
        /// Polynomial order `p ≥ 1` (`ORDER p`; 1 = the two-node beam).
        order: u32,
        /// Centre of the circular arc that is the reference axis (`ARC`); `None` = straight.
        arc: Option<Vector3<f64>>,
    },
    /// A point mass with optional rotary inertia (global frame at t = 0).
    Mass {
        /// Mass, kg (≥ 0).
        mass: f64,
        /// Rotary inertia tensor about the node, kg·m², global frame at t = 0.
        inertia: Matrix3<f64>,
    },
    /// Revolute joint: rotation only about `axis` (global at t = 0).
    Hinge {
        /// Hinge axis (unit), global frame at t = 0.
        axis: Vector3<f64>,
    },
    /// Universal (Cardan) joint: `axis1` fixed to the first node, `axis2` to the second;
    /// perpendicular at t = 0.
    UJoint {
        /// Axis on the first body (unit), global at t = 0.
        axis1: Vector3<f64>,
        /// Axis on the second body (unit), global at t = 0.
        axis2: Vector3<f64>,
    },
    /// Spherical joint: relative translation blocked.
    Spherical,
    /// Two nodes welded: no relative motion.
    Clamp,
    /// Prismatic joint: relative rotation blocked, translation only along `axis`.
    Prismatic {
        /// Sliding axis (unit), global at t = 0.
        axis: Vector3<f64>,
    },
    /// A rigid body: all listed nodes move with the first one.
    Rigid,
    /// Cam–follower contact (first node: cam, second: follower).
    Came(Box<CameData>),
    /// Two-node spring–damper along the line of its nodes.
    Spring(Box<SpringData>),
    /// Six-component linear bushing (nodes 1, 2).
    Bushing(Box<BushingData>),
    /// Rotational spring, damper and friction on a HINGE (the hinge's nodes).
    RSpring(Box<RSpringData>),
    /// A prescribed motion of one node (`PRESCRIBED`, [`drive`](self::Drive)).
    Prescribed {
        /// What is prescribed.
        motion: NodeMotion,
        /// Its value `a f(t)`.
        drive: Drive,
    },
    /// Revolute joint with radial clearance (first node: bearing, second: journal).
    Clearance(Box<ClearanceData>),
    /// A controlled input: a hinge torque or nodal force depending on sensors of the
    /// state ([`control`]); its nodes are the actuator's and the sensors'.
    Control(Box<control::ControlData>),
    /// A linear elastic body reduced from a finite-element model (Craig–Bampton in a
    /// floating frame; `crate::elements::superelement`): its nodes are its interface nodes,
    /// then its generated modal nodes.
    Superelement(Box<SuperelementData>),
}

impl ElementKind {
    /// The deck keyword of this element type.
    pub fn keyword(&self) -> &'static str {
        match self {
            ElementKind::Beam { .. } => "BEAM",
            ElementKind::Mass { .. } => "MASS",
            ElementKind::Hinge { .. } => "HINGE",
            ElementKind::UJoint { .. } => "UJOINT",
            ElementKind::Spherical => "SPHERICAL",
            ElementKind::Clamp => "CLAMP",
            ElementKind::Prismatic { .. } => "PRISMATIC",
            ElementKind::Rigid => "RIGID",
            ElementKind::Came(_) => "CAME",
            ElementKind::Spring(_) => "SPRING",
            ElementKind::Bushing(_) => "BUSHING",
            ElementKind::RSpring(_) => "RSPRING",
            ElementKind::Prescribed { .. } => "PRESCRIBED",
            ElementKind::Clearance(_) => "CLEARANCE",
            ElementKind::Control(c) => match c.law {
                control::ControlLaw::Pid(_) => "PID",
                _ => "CONTROL",
            },
            ElementKind::Superelement(_) => "SUPERELEMENT",
        }
    }

    /// Number of constraint equations (Lagrange multipliers) the element adds.
    pub fn constraint_count(&self, node_count: usize) -> usize {
        match self {
            ElementKind::Hinge { .. } => 5,
            ElementKind::UJoint { .. } => 4,
            ElementKind::Spherical => 3,
            ElementKind::Clamp => 6,
            ElementKind::Prismatic { .. } => 5,
            ElementKind::Rigid => 6 * node_count.saturating_sub(1),
            ElementKind::Prescribed { motion, .. } => motion.equations(),
            ElementKind::Superelement(d) => 6 * d.interface.len().saturating_sub(1),
            _ => 0,
        }
    }
}

/// An element: number, type, nodes (in the order the type defines).
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// The user's number.
    pub id: ElementId,
    /// Connected nodes.
    pub nodes: Vec<NodeId>,
    /// Type and data.
    pub kind: ElementKind,
    /// Where it was defined.
    pub span: Span,
}

/// A nodal load `value · f(t)` in the global frame.
#[derive(Debug, Clone, PartialEq)]
pub struct NodalLoad {
    /// Loaded node.
    pub node: NodeId,
    /// `true` = moment (N·m), `false` = force (N).
    pub moment: bool,
    /// Components, global frame.
    pub value: Vector3<f64>,
    /// Time function scaling the load; `None` = constant 1.
    pub function: Option<FunctionId>,
    /// Where it was defined.
    pub span: Span,
}

/// An initial velocity of a node (global frame), from the deck's INITIAL section.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialVelocity {
    /// The node.
    pub node: NodeId,
    /// Velocity, m/s.
    pub velocity: Vector3<f64>,
    /// Angular velocity, rad/s (global frame).
    pub angular: Vector3<f64>,
    /// Where it was defined.
    pub span: Span,
}

/// Newton–Raphson settings.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonSettings {
    /// Tolerance on the residual, relative to the model's reference force (default 1e-8).
    pub tol_residual: f64,
    /// Tolerance on the increment, relative to the model's reference length (default 1e-10).
    pub tol_increment: f64,
    /// Iteration limit per step (default 20).
    pub max_iterations: u32,
    /// Modified Newton (default): the factored iteration matrix is kept, across iterations
    /// and steps of the same size, while it contracts the residual; `false` = full Newton,
    /// a new matrix at every iteration (deck: `NEWTON FULL`).
    pub modified: bool,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings {
            tol_residual: 1e-8,
            tol_increment: 1e-10,
            max_iterations: 20,
            modified: true,
        }
    }
}

/// Adaptive time stepping settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Adaptive {
    /// Local error tolerance on positions, m.
    pub tol_position: f64,
    /// Local error tolerance on rotations, rad.
    pub tol_rotation: f64,
    /// Largest step growth factor per step (default 2).
    pub max_growth: f64,
    /// How the ESDIRK schemes' embedded velocity error counts as a position error
    /// (`CARRY`; the α family's estimate has no velocity term).
    pub carry: Carry,
}

/// How far an adaptive ESDIRK step's velocity error `e_v` is taken to carry the positions
/// by the run's end `T` (`ANALYSIS … ADAPTIVE … CARRY RUN|MODES`, docs/accuracy.md,
/// "Accuracy asked for").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Carry {
    /// `T |e_v|`, as if it were a drift, whatever it is: the default, conservative (the
    /// errors measured 1e-3 … 1e-2 of the tolerance on flexible models).
    #[default]
    Run,
    /// By the linearised model's modes: `T |e_v|` for a drift, `|e_v|/ω` for a vibration
    /// of frequency `ω` (`solver::integrator::drift`).
    Modes,
}

/// The analysis to run.
#[derive(Debug, Clone, PartialEq)]
pub enum Analysis {
    /// Implicit dynamics.
    Dynamic {
        /// The time integration scheme (HHT-α, generalized-α, …).
        scheme: Scheme,
        /// Time step h (initial step when adaptive), s.
        step: f64,
        /// End time, s.
        end: f64,
        /// Smallest step allowed when cutting, s (default h/1024).
        min_step: f64,
        /// Largest step when adaptive, s (default = step).
        max_step: f64,
        /// Adaptive stepping; `None` = fixed steps.
        adaptive: Option<Adaptive>,
        /// Newton settings.
        newton: NewtonSettings,
    },
    /// Static equilibrium with load steps (loads scaled by their functions at
    /// `t = i / steps`, i = 1..steps).
    Static {
        /// Number of load steps (≥ 1).
        steps: u32,
        /// Newton settings.
        newton: NewtonSettings,
        /// `PROPORTIONAL`: gravity and the loads without a function grow in proportion to
        /// the load factor (else they are applied whole from the first step, and only the
        /// loads' functions of the load factor change from step to step).
        proportional: bool,
    },
}

impl Model {
    /// Switches a dynamic analysis to fixed steps `h` (minimum step `h/1024`) up to `end`,
    /// with the time integration `scheme` if given; returns `false` (and changes nothing)
    /// for a static one. For studies and tests that rerun a deck at other steps.
    pub fn set_fixed_step(&mut self, h: f64, end: f64, scheme: Option<Scheme>) -> bool {
        let Analysis::Dynamic {
            step,
            end: e,
            min_step,
            max_step,
            scheme: a,
            adaptive,
            ..
        } = &mut self.analysis
        else {
            return false;
        };
        *step = h;
        *e = end;
        *min_step = h / 1024.0;
        *max_step = h;
        *adaptive = None;
        if let Some(v) = scheme {
            *a = v;
        }
        true
    }
}

/// A validated model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// The deck's title.
    pub title: String,
    /// Nodes in deck order.
    pub nodes: IndexMap<NodeId, Node>,
    /// Materials in deck order.
    pub materials: IndexMap<MaterialId, Material>,
    /// Sections in deck order.
    pub sections: IndexMap<SectionId, Section>,
    /// Time functions in deck order.
    pub functions: IndexMap<FunctionId, FunctionDef>,
    /// Elements in deck order.
    pub elements: IndexMap<ElementId, Element>,
    /// Nodal forces and moments.
    pub loads: Vec<NodalLoad>,
    /// Gravity acceleration vector, m/s²; `None` = no gravity.
    pub gravity: Option<Vector3<f64>>,
    /// Initial velocities (nodes not listed start at rest).
    pub initial: Vec<InitialVelocity>,
    /// The analysis.
    pub analysis: Analysis,
    /// `ANALYSIS MODES n`: the deck asks for a modal analysis, the lowest `n` modes about
    /// the initial state (`mecano-rs DECK` runs `mecano-rs modes DECK --count n`;
    /// docs/modes.md). `analysis` is then the static analysis of one load step with the
    /// default Newton settings (what `modes --static` solves). `None`: the deck runs its
    /// `analysis`.
    pub modes: Option<u32>,
    /// `ANALYSIS MODES n ROTATING`: the modes about the relative equilibrium of the deck's
    /// hub driven at constant speed, seen in the rotating frame (as `mecano-rs modes
    /// --rotating`; [`crate::modes::rotating`]).
    pub modes_rotating: bool,
    /// `ANALYSIS MODES n STATIC [STEPS k]`: the modes about the static equilibrium under
    /// the deck's loads, reached in `k` load steps (`analysis` is that static analysis),
    /// as `mecano-rs modes --static`.
    pub modes_static: bool,
    /// Where the deck asks for the modes: the span of its `ANALYSIS MODES n` card (the
    /// default span when it does not), so that a refusal of the count or of the rotating
    /// state points at it.
    pub modes_span: Span,
    /// Output requests.
    pub output: OutputRequest,
    /// The user's beams divided into several elements (`DIVIDE`, `--refine`), by the
    /// beam's number, in deck order; their generated nodes and elements are in `nodes` and
    /// `elements` (see [`mesh`](self::Division) for the numbering).
    pub divisions: IndexMap<ElementId, Division>,
    /// Deck parameters (`PARAMETERS`), name → value in force (the deck's value or an
    /// override), in deck order. The fields that use them already hold their values.
    pub parameters: IndexMap<String, f64>,
    /// The interior nodes generated for beams of order > 1 (`ORDER p`), by element, along
    /// the axis (see [`order`](self::order)).
    pub order_nodes: IndexMap<ElementId, Vec<NodeId>>,
    /// Driven joints (`HINGE … DRIVE f`, `PRISMATIC … DRIVE f`), by the joint's number:
    /// one more constraint each (model/drive.rs).
    pub drives: IndexMap<ElementId, Drive>,
}
