//! `KEYWORDS`: the single list of the keywords the parser accepts, each with its section and
//! documentation; `grammar.md` is tested against it (`tests/grammar_doc.rs`).

/// Documentation of one keyword the parser accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KeywordDoc {
    /// The keyword (upper case; the parser is case-insensitive).
    pub name: &'static str,
    /// Where it is used: the section (or card) it belongs to.
    pub section: &'static str,
    /// One-line description.
    pub doc: &'static str,
}

use std::sync::LazyLock;

const fn kw(name: &'static str, section: &'static str, doc: &'static str) -> KeywordDoc {
    KeywordDoc { name, section, doc }
}

/// Every keyword the parser accepts, with where it is used: the single source of truth
/// for `grammar.md` (a test checks that each one is documented there). In debug builds the
/// parser asserts that every keyword it matches is listed here. The rows below, then the
/// rows of the registered element kinds (`crate::kinds`, each kind's `CARD`).
pub static KEYWORDS: LazyLock<Vec<KeywordDoc>> =
    LazyLock::new(|| ROWS.iter().copied().chain(super::build::rows()).collect());

/// The keywords of the sections and of the fields several element kinds share (each kind's
/// own are its `CARD`'s rows).
const ROWS: &[KeywordDoc] = &[
    // sections
    kw(
        "TITLE",
        "deck",
        "one-line section: the rest of the line is the deck's title",
    ),
    kw("MATERIALS", "deck", "section header: material cards follow"),
    kw(
        "SECTIONS",
        "deck",
        "section header: cross-section cards follow",
    ),
    kw("NODES", "deck", "section header: node cards follow"),
    kw("ELEMENTS", "deck", "section header: element cards follow"),
    kw(
        "FUNCTIONS",
        "deck",
        "section header: time-function cards follow",
    ),
    kw(
        "LOADS",
        "deck",
        "section header: GRAVITY, FORCE and MOMENT cards follow",
    ),
    kw(
        "INITIAL",
        "deck",
        "section header: initial-velocity cards follow",
    ),
    kw("V", "INITIAL", "initial velocity, global, m/s"),
    kw("W", "INITIAL", "initial angular velocity, global, rad/s"),
    kw(
        "ABOUT",
        "INITIAL",
        "centre of a rigid-body velocity field V + W × (x − c)",
    ),
    kw("ANALYSIS", "deck", "one-line section: the analysis to run"),
    kw(
        "OUTPUT",
        "deck",
        "one-line section: what to write and where",
    ),
    kw(
        "END",
        "deck",
        "end of the deck: no card after it is read (the file is still checked: UTF-8, limits)",
    ),
    kw(
        "PARAMETERS",
        "deck",
        "section header: `name value` cards; fields use them as `$name` in expressions",
    ),
    // materials
    kw("E", "MATERIALS", "Young's modulus, N/m² (> 0)"),
    kw(
        "NU",
        "MATERIALS",
        "Poisson's ratio (-1 < nu < 0.5); G = E/(2(1+nu))",
    ),
    kw("G", "MATERIALS", "shear modulus, N/m² (> 0), instead of NU"),
    kw("RHO", "MATERIALS", "density, kg/m³ (>= 0)"),
    kw(
        "DAMPING",
        "MATERIALS",
        "stiffness-proportional damping coefficient, s (>= 0, default 0; also on a PROPERTIES section)",
    ),
    // sections
    kw("A", "SECTIONS", "area, m² (> 0)"),
    kw(
        "I2",
        "SECTIONS",
        "second moment of area about local axis 2, m⁴",
    ),
    kw(
        "I3",
        "SECTIONS",
        "second moment of area about local axis 3, m⁴",
    ),
    kw("J", "SECTIONS", "torsion constant, m⁴"),
    kw(
        "K",
        "SECTIONS",
        "shear correction factor (0 < k <= 1, default 5/6); in ELEMENTS a stiffness (CAME, SPRING, BUSHING, RSPRING)",
    ),
    kw(
        "RIGID",
        "SECTIONS",
        "rigid bar section (also an element type in ELEMENTS)",
    ),
    kw(
        "PROPERTIES",
        "SECTIONS",
        "the section is given by its stiffness and inertia per unit length (no material)",
    ),
    kw("EA", "SECTIONS", "PROPERTIES: axial stiffness EA, N (> 0)"),
    kw(
        "GA2",
        "SECTIONS",
        "PROPERTIES: shear stiffness along local axis 2, N (> 0)",
    ),
    kw(
        "GA3",
        "SECTIONS",
        "PROPERTIES: shear stiffness along local axis 3, N (> 0)",
    ),
    kw(
        "GJ",
        "SECTIONS",
        "PROPERTIES: torsional stiffness, N·m² (> 0)",
    ),
    kw(
        "EI2",
        "SECTIONS",
        "PROPERTIES: bending stiffness about local axis 2, N·m² (> 0)",
    ),
    kw(
        "EI3",
        "SECTIONS",
        "PROPERTIES: bending stiffness about local axis 3, N·m² (> 0)",
    ),
    kw(
        "RHOA",
        "SECTIONS",
        "PROPERTIES: mass per unit length, kg/m (>= 0)",
    ),
    kw(
        "RHOJ",
        "SECTIONS",
        "PROPERTIES: polar rotary inertia per unit length, kg·m (>= 0)",
    ),
    kw(
        "RHOI2",
        "SECTIONS",
        "PROPERTIES: rotary inertia about local axis 2 per unit length, kg·m (>= 0)",
    ),
    kw(
        "RHOI3",
        "SECTIONS",
        "PROPERTIES: rotary inertia about local axis 3 per unit length, kg·m (>= 0)",
    ),
    // nodes
    kw(
        "TO",
        "NODES",
        "generation: `<id1> TO <id2>` (also in ELEMENTS)",
    ),
    kw(
        "LINE",
        "NODES",
        "nodes evenly spaced on a segment (also a CAME profile)",
    ),
    kw("FIX", "NODES", "fix degrees of freedom of a node"),
    kw(
        "ALL",
        "NODES",
        "all six degrees of freedom (also in OUTPUT: every entity)",
    ),
    kw("TRANS", "NODES", "the three translations"),
    kw("ROT", "NODES", "the three rotations"),
    kw(
        "X",
        "NODES",
        "translation along global X (also PRESCRIBED's and CONTROL FORCE's direction)",
    ),
    kw(
        "Y",
        "NODES",
        "translation along global Y (also PRESCRIBED's and CONTROL FORCE's direction)",
    ),
    kw(
        "Z",
        "NODES",
        "translation along global Z (also PRESCRIBED's and CONTROL FORCE's direction)",
    ),
    kw("RX", "NODES", "rotation about global X"),
    kw("RY", "NODES", "rotation about global Y"),
    kw("RZ", "NODES", "rotation about global Z"),
    // elements
    kw(
        "AXIS2",
        "ELEMENTS",
        "BEAM: local axis 2 direction; UJOINT: axis on the second node",
    ),
    kw("AXIS", "ELEMENTS", "axis of a HINGE or PRISMATIC joint"),
    kw(
        "AMPLITUDE",
        "ELEMENTS",
        "DRIVE or PRESCRIBED: the factor a of a·f(t), rad or m (default 1)",
    ),
    kw(
        "SPLINE",
        "ELEMENTS",
        "CAME profile: a cubic spline through points (FUNCTIONS: the C² time function)",
    ),
    kw(
        "C",
        "ELEMENTS",
        "CAME: contact damping, N·s/m (>= 0, default 0)",
    ),
    kw(
        "MU",
        "ELEMENTS",
        "CAME: Coulomb friction coefficient (>= 0, default 0)",
    ),
    kw(
        "VREG",
        "ELEMENTS",
        "CAME: friction regularisation speed, m/s (> 0, default 1e-3)",
    ),
    kw(
        "IMPACT_STEPS",
        "ELEMENTS",
        "CAME: minimum steps per impact (>= 1, default 10)",
    ),
    kw(
        "LAW",
        "ELEMENTS",
        "CLEARANCE: the normal force law (KV or LN); CONTROL: the input's value, an expression of t and sensors",
    ),
    // functions
    kw(
        "TABLE",
        "FUNCTIONS",
        "piecewise-linear table of (t, f) pairs",
    ),
    kw("CONSTANT", "FUNCTIONS", "a constant function"),
    kw(
        "HAVERSINE",
        "FUNCTIONS",
        "a smooth pulse sin²(π(t−t0)/T) on [t0, t0+T]",
    ),
    kw(
        "SLOPES",
        "FUNCTIONS",
        "SPLINE: clamped end slopes (default: natural ends)",
    ),
    kw("SINE", "FUNCTIONS", "A sin(ω(t − t0) + φ)"),
    kw("COSINE", "FUNCTIONS", "A cos(ω(t − t0) + φ)"),
    kw("FREQ", "FUNCTIONS", "SINE/COSINE: frequency, Hz"),
    kw(
        "OMEGA",
        "FUNCTIONS",
        "SINE/COSINE: circular frequency, rad/s",
    ),
    kw(
        "PHASE",
        "FUNCTIONS",
        "SINE/COSINE: phase φ, rad (default 0)",
    ),
    kw(
        "START",
        "FUNCTIONS",
        "SINE/COSINE: start time t0, s (0 before it)",
    ),
    kw(
        "RAMP",
        "FUNCTIONS",
        "quintic C² step from (t0, f0) to (t1, f1)",
    ),
    kw(
        "EXPR",
        "FUNCTIONS",
        "an expression of t (exact derivatives)",
    ),
    // loads
    kw("GRAVITY", "LOADS", "gravity acceleration vector, m/s²"),
    kw(
        "FORCE",
        "LOADS",
        "nodal force, N, global frame (also ELEMENTS CONTROL FORCE: a controlled force)",
    ),
    kw("MOMENT", "LOADS", "nodal moment, N·m, global frame"),
    kw(
        "FUNCTION",
        "LOADS",
        "time function scaling a FORCE or MOMENT",
    ),
    // analysis
    kw(
        "DYNAMIC",
        "ANALYSIS",
        "implicit dynamics (HHT-alpha, or generalized-alpha with GENALPHA)",
    ),
    kw("STATIC", "ANALYSIS", "static equilibrium with load steps"),
    kw(
        "MODES",
        "ANALYSIS",
        "modal analysis: the lowest n modes about the initial state; SUPERELEMENT: fixed-interface modes kept",
    ),
    kw(
        "ROTATING",
        "ANALYSIS",
        "after MODES n: about the relative equilibrium of a hub driven at constant speed, modes in the rotating frame",
    ),
    kw(
        "ALPHA",
        "ANALYSIS",
        "HHT alpha (-1/3 <= alpha <= 0, default -0.1)",
    ),
    kw(
        "GENALPHA",
        "ANALYSIS",
        "generalized-alpha time integration instead of HHT",
    ),
    kw(
        "RHOINF",
        "ANALYSIS",
        "generalized-alpha: spectral radius at infinity (0 <= rho <= 1, default 0.8)",
    ),
    kw("STEP", "ANALYSIS", "time step, s (> 0)"),
    kw(
        "ESDIRK3",
        "ANALYSIS",
        "third-order L-stable ESDIRK time integrator instead of HHT",
    ),
    kw(
        "ESDIRK5",
        "ANALYSIS",
        "fifth-order L-stable ESDIRK time integrator instead of HHT",
    ),
    kw(
        "MINSTEP",
        "ANALYSIS",
        "smallest step when cutting, s (default STEP/1024)",
    ),
    kw("MAXSTEP", "ANALYSIS", "largest step, s (default STEP)"),
    kw("ADAPTIVE", "ANALYSIS", "adaptive time stepping"),
    kw(
        "TOLPOS",
        "ANALYSIS",
        "adaptive: local error tolerance on positions, m",
    ),
    kw(
        "TOLROT",
        "ANALYSIS",
        "adaptive: local error tolerance on rotations, rad",
    ),
    kw(
        "GROWTH",
        "ANALYSIS",
        "adaptive: largest step growth factor (>= 1, default 2)",
    ),
    kw(
        "CARRY",
        "ANALYSIS",
        "adaptive ESDIRK: how a step's velocity error counts, RUN (END x |e_v|, default) or MODES (by the linearised modes)",
    ),
    kw(
        "RUN",
        "ANALYSIS",
        "CARRY RUN: a velocity error counts for the run's length (default)",
    ),
    kw(
        "TOL",
        "ANALYSIS",
        "Newton residual tolerance (> 0, default 1e-8)",
    ),
    kw(
        "TOLINC",
        "ANALYSIS",
        "Newton increment tolerance (> 0, default 1e-10)",
    ),
    kw(
        "MAXIT",
        "ANALYSIS",
        "Newton iteration limit (>= 1, default 20)",
    ),
    kw(
        "NEWTON",
        "ANALYSIS",
        "FULL (new matrix every iteration) or MODIFIED (default: kept while it contracts)",
    ),
    kw("FULL", "ANALYSIS", "NEWTON FULL: full Newton-Raphson"),
    kw(
        "MODIFIED",
        "ANALYSIS",
        "NEWTON MODIFIED: modified Newton (default)",
    ),
    kw(
        "STEPS",
        "ANALYSIS",
        "number of static load steps (>= 1, default 1)",
    ),
    kw(
        "PROPORTIONAL",
        "ANALYSIS",
        "STATIC: gravity and the loads without a function grow with the load factor",
    ),
    // output
    kw("NONE", "OUTPUT", "no entity"),
    kw(
        "EVERY",
        "OUTPUT",
        "write a row every n steps (>= 1, default 1)",
    ),
    kw(
        "SUBSTEPS",
        "OUTPUT",
        "also write the states of the steps shorter than STEP (an impact's sub-steps)",
    ),
    kw(
        "DIR",
        "OUTPUT",
        "output directory (the command line's -o wins)",
    ),
    kw("VTK", "OUTPUT", "also write a ParaView series of VTK files"),
    kw(
        "FORMAT",
        "OUTPUT",
        "CSV (default: node_<N>.csv, element_<N>.csv) or NETCDF (one histories.nc)",
    ),
    kw(
        "CSV",
        "OUTPUT",
        "FORMAT CSV: one CSV file per node and element",
    ),
    kw(
        "NETCDF",
        "OUTPUT",
        "FORMAT NETCDF: every history in one NetCDF file, histories.nc",
    ),
];

/// In debug builds, checks that the parser only matches keywords listed in [`KEYWORDS`].
#[inline]
pub(crate) fn debug_check_keyword(kw: &str) {
    debug_assert!(
        KEYWORDS.iter().any(|k| k.name == kw),
        "keyword {kw} is accepted by the parser but missing from KEYWORDS"
    );
}
