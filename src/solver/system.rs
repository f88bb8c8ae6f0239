//! The assembled system: dense node numbering, degrees of freedom, sparsity pattern and
//! the assembly of element contributions into the global residual and iteration matrix.

use super::linear::{LinearError, SparseSystem};
use crate::elements::{self, Element, Local};
use crate::model::{Function, Model, NodeId};
use nalgebra::Vector3;

mod assemble;

/// Marks a fixed degree of freedom (no equation).
pub const FIXED: usize = usize::MAX;
const NONE: u32 = u32::MAX;

/// What a global equation is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DofOwner {
    /// Component `comp` (0–2 translation x, y, z; 3–5 rotation) of dense node `node`.
    Node {
        /// Dense node index.
        node: usize,
        /// Component 0..6.
        comp: usize,
    },
    /// Multiplier `k` of dense element `element`.
    Multiplier {
        /// Dense element index.
        element: usize,
        /// Multiplier number within the element.
        k: usize,
    },
}

/// A nodal load resolved to dense indices.
#[derive(Debug, Clone)]
pub struct AppliedLoad {
    /// Dense node index.
    pub node: usize,
    /// Moment (true) or force.
    pub moment: bool,
    /// Global components at `f = 1`.
    pub value: Vector3<f64>,
    /// Time function (`None` = 1, or the load factor in statics: `ramp`).
    pub function: Option<Function>,
    /// A static analysis's load without a function: in proportion to the load factor `t`.
    pub ramp: bool,
}

impl AppliedLoad {
    /// Global load vector at time `t` (statics: load factor `t`).
    pub fn at(&self, t: f64) -> Vector3<f64> {
        let f = match &self.function {
            Some(f) => f.eval(t),
            None if self.ramp => t.clamp(0.0, 1.0),
            None => 1.0,
        };
        self.value * f
    }
}

/// Errors while building the system.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// An element could not be built.
    #[error(transparent)]
    Elements(#[from] elements::BuildError),
    /// The linear solver could not analyse the pattern.
    #[error(transparent)]
    Linear(#[from] LinearError),
    /// Nodes with free translations that no element acts on ([`super::idle`]).
    #[error("{}", .0.iter().map(|n| n.to_string()).collect::<Vec<_>>().join("\n"))]
    Undetermined(Vec<super::idle::UndeterminedNode>),
}

/// The discretised model ready for time integration.
pub struct System {
    /// The user's node numbers, dense order.
    pub node_ids: Vec<NodeId>,
    /// Reference positions.
    pub x0: Vec<Vector3<f64>>,
    /// Elements, dense order (model order).
    pub elements: Vec<Box<dyn Element>>,
    /// Global equation of each node dof, or [`FIXED`].
    pub node_dofs: Vec<[usize; 6]>,
    /// First global equation of each element's multipliers.
    pub mult_offset: Vec<usize>,
    /// Number of nodal (non-multiplier) equations; they come first.
    pub n_node_eq: usize,
    /// Owner of each global equation.
    pub owners: Vec<DofOwner>,
    /// Applied loads.
    pub loads: Vec<AppliedLoad>,
    /// Gravity (zero when none).
    pub gravity: Vector3<f64>,
    /// Iteration matrix with its LU.
    pub matrix: SparseSystem,
    /// Global residual.
    pub rhs: Vec<f64>,
    /// One set of local buffers per element size, shared by the elements of that size
    /// (`local_of[e]`): the assembly fills and scatters one element at a time, and a
    /// tangent assembly clears them per element. One set per element took 2.4 kB per
    /// two-node beam, 0.4 kB per unknown (issue 29).
    locals: Vec<Local>,
    local_of: Vec<u32>,
    rows: Vec<Vec<u32>>,
    maps: Vec<Vec<u32>>,
    moment_blocks: Vec<[u32; 9]>,
    /// Largest |load| or weight: the model's reference force, N.
    pub ref_force: f64,
    /// Size of the model's bounding box (≥ the longest element), m.
    pub ref_length: f64,
    /// `ANALYSIS STATIC … PROPORTIONAL`: gravity and the loads without a function are
    /// scaled by the load factor.
    pub proportional: bool,
    /// Multiplier equations removed as redundant ([`System::remove_equations`]), sorted,
    /// with the matrix position of each one's diagonal.
    removed: Vec<(usize, u32)>,
}

/// Magnitudes seen during an assembly (for convergence tests).
#[derive(Debug, Clone, Copy, Default)]
pub struct AssemblyInfo {
    /// Largest absolute nodal contribution of any element (force scale).
    pub force_scale: f64,
    /// Largest applied load at the assembly's time, N (moments divided by the reference
    /// length), its norm computed without overflow.
    pub load_scale: f64,
}

/// `|v|` without overflow or underflow of the squares: `m |v/m|`, `m = max |vᵢ|` (an
/// infinite or NaN component gives infinity or NaN).
pub fn safe_norm(v: &Vector3<f64>) -> f64 {
    let m = v.iter().fold(0.0f64, |a, x| {
        if a.is_nan() || x.is_nan() {
            f64::NAN
        } else {
            a.max(x.abs())
        }
    });
    if m == 0.0 || !m.is_finite() {
        m
    } else {
        m * (v / m).norm()
    }
}

impl System {
    /// Builds the system of a validated model.
    pub fn new(model: &Model) -> Result<Self, BuildError> {
        let node_ids: Vec<NodeId> = model.nodes.keys().copied().collect();
        let x0: Vec<Vector3<f64>> = model.nodes.values().map(|n| n.position).collect();
        let elements = elements::build(model)?;
        let mut node_dofs = Vec::with_capacity(node_ids.len());
        let mut owners = Vec::new();
        for (i, node) in model.nodes.values().enumerate() {
            let mut d = [FIXED; 6];
            for (comp, slot) in d.iter_mut().enumerate() {
                if !node.fixed[comp] {
                    *slot = owners.len();
                    owners.push(DofOwner::Node { node: i, comp });
                }
            }
            node_dofs.push(d);
        }
        let n_node_eq = owners.len();
        let mut mult_offset = Vec::with_capacity(elements.len());
        for (e, el) in elements.iter().enumerate() {
            mult_offset.push(owners.len());
            for k in 0..el.multipliers() {
                owners.push(DofOwner::Multiplier { element: e, k });
            }
        }
        let n = owners.len();
        // Local → global rows.
        let rows: Vec<Vec<u32>> = elements
            .iter()
            .enumerate()
            .map(|(e, el)| {
                let mut r = Vec::new();
                for &node in el.nodes() {
                    for comp in 0..6 {
                        let d = node_dofs[node][comp];
                        r.push(if d == FIXED { NONE } else { d as u32 });
                    }
                }
                for k in 0..el.multipliers() {
                    r.push((mult_offset[e] + k) as u32);
                }
                r
            })
            .collect();
        // Pattern: element blocks, node diagonal blocks (moment loads), and the diagonal.
        let mut columns: Vec<Vec<usize>> = vec![Vec::new(); n];
        for r in &rows {
            for &j in r.iter().filter(|j| **j != NONE) {
                for &i in r.iter().filter(|i| **i != NONE) {
                    columns[j as usize].push(i as usize);
                }
            }
        }
        for d in &node_dofs {
            for a in 3..6 {
                for b in 3..6 {
                    if d[a] != FIXED && d[b] != FIXED {
                        columns[d[b]].push(d[a]);
                    }
                }
            }
        }
        for (j, col) in columns.iter_mut().enumerate() {
            col.push(j);
            col.sort_unstable();
            col.dedup();
        }
        let matrix = SparseSystem::new(&columns)?;
        let maps = rows
            .iter()
            .map(|r| {
                let mut m = Vec::with_capacity(r.len() * r.len());
                for &j in r {
                    for &i in r {
                        m.push(if i == NONE || j == NONE {
                            NONE
                        } else {
                            matrix
                                .position(i as usize, j as usize)
                                .map_or(NONE, |p| p as u32)
                        });
                    }
                }
                m
            })
            .collect();
        let moment_blocks = node_dofs
            .iter()
            .map(|d| {
                let mut b = [NONE; 9];
                for c in 0..3 {
                    for r in 0..3 {
                        let (i, j) = (d[3 + r], d[3 + c]);
                        if i != FIXED && j != FIXED {
                            b[3 * c + r] = matrix.position(i, j).map_or(NONE, |p| p as u32);
                        }
                    }
                }
                b
            })
            .collect();
        let mut locals: Vec<Local> = Vec::new();
        let local_of = elements
            .iter()
            .map(|el| {
                let n = 6 * el.nodes().len() + el.multipliers();
                let k = locals.iter().position(|l| l.n == n).unwrap_or_else(|| {
                    locals.push(Local::new(n));
                    locals.len() - 1
                });
                k as u32
            })
            .collect();
        let index_of = |id: &NodeId| model.nodes.get_index_of(id).expect("validated model");
        let loads: Vec<AppliedLoad> = model
            .loads
            .iter()
            .map(|l| AppliedLoad {
                node: index_of(&l.node),
                moment: l.moment,
                value: l.value,
                function: l
                    .function
                    .and_then(|f| model.functions.get(&f))
                    .map(|f| f.function.clone()),
                ramp: l.function.is_none()
                    && matches!(
                        model.analysis,
                        crate::model::Analysis::Static {
                            proportional: true,
                            ..
                        }
                    ),
            })
            .collect();
        let gravity = model.gravity.unwrap_or_else(Vector3::zeros);
        let (mut lo, mut hi) = (Vector3::repeat(f64::MAX), Vector3::repeat(f64::MIN));
        for x in &x0 {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        let ref_length = if x0.is_empty() {
            1.0
        } else {
            (hi - lo).norm().max(1e-6)
        };
        let mut ref_force: f64 = 0.0;
        // The span the loads' functions are evaluated over (static: the load steps' t ≤ 1).
        let t_end = match &model.analysis {
            crate::model::Analysis::Dynamic { end, .. } => *end,
            crate::model::Analysis::Static { .. } => 1.0,
        };
        for l in &loads {
            let fmax = l.function.as_ref().map_or(1.0, |f| f.max_abs(0.0, t_end));
            let scale = if l.moment { 1.0 / ref_length } else { 1.0 };
            ref_force = ref_force.max(safe_norm(&l.value) * fmax * scale);
        }
        Ok(System {
            rhs: vec![0.0; n],
            node_ids,
            x0,
            elements,
            node_dofs,
            mult_offset,
            n_node_eq,
            owners,
            loads,
            gravity,
            matrix,
            locals,
            local_of,
            rows,
            maps,
            moment_blocks,
            ref_force,
            ref_length,
            removed: Vec::new(),
            proportional: matches!(
                model.analysis,
                crate::model::Analysis::Static {
                    proportional: true,
                    ..
                }
            ),
        })
    }

    /// Removes the multiplier equations `eqs` (global numbers) from the system: no
    /// element's row or column reaches them any more, and each keeps only the equation
    /// `s λ_k = 0` (its diagonal), so its multiplier is held at zero. For constraint
    /// equations that depend on the others ([`super::redundancy`]): the numbering, the
    /// elements' multiplier slices and the pattern stay as they are. Nodal equations are
    /// refused (hold them by fixing the degree of freedom).
    pub fn remove_equations(&mut self, eqs: &[usize]) {
        for &g in eqs {
            assert!(
                matches!(self.owners.get(g), Some(DofOwner::Multiplier { .. })),
                "only multiplier equations are removed"
            );
            if self.removed.iter().any(|(r, _)| *r == g) {
                continue;
            }
            let pos = self
                .matrix
                .position(g, g)
                .expect("the pattern holds the diagonal");
            self.removed.push((g, pos as u32));
            let DofOwner::Multiplier { element, k } = self.owners[g] else {
                unreachable!()
            };
            let nl = 6 * self.elements[element].nodes().len() + k;
            let rows = &mut self.rows[element];
            rows[nl] = NONE;
            let size = rows.len();
            let map = &mut self.maps[element];
            for j in 0..size {
                map[nl * size + j] = NONE;
                map[j * size + nl] = NONE;
            }
        }
        self.removed.sort_unstable();
    }

    /// The multiplier equations removed ([`System::remove_equations`]), sorted.
    pub fn removed_equations(&self) -> Vec<usize> {
        self.removed.iter().map(|(g, _)| *g).collect()
    }

    /// Number of global equations.
    pub fn n_eq(&self) -> usize {
        self.owners.len()
    }

    /// Multipliers of element `e` within the global multiplier-bearing vector `lambda`
    /// (indexed by global equation).
    pub fn element_lambda<'a>(&self, e: usize, lambda: &'a [f64]) -> &'a [f64] {
        let k = self.elements[e].multipliers();
        let o = self.mult_offset[e];
        &lambda[o..o + k]
    }

    /// Human-readable name of a global equation, e.g. `node 23 uy`.
    pub fn describe(&self, eq: usize) -> String {
        const NAMES: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];
        match self.owners.get(eq) {
            Some(DofOwner::Node { node, comp }) => {
                format!("{} {}", self.node_ids[*node], NAMES[*comp])
            }
            Some(DofOwner::Multiplier { element, k }) => {
                format!("{} constraint {}", self.elements[*element].id(), k + 1)
            }
            None => format!("equation {eq}"),
        }
    }
}
