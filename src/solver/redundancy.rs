//! Redundant constraints: which constraint equations of a system depend on the others,
//! their removal, and the reactions reported where they are not unique.
//!
//! A planar loop of spatial joints (a four-bar of four HINGEs, a slider-crank of three
//! HINGEs and a PRISMATIC) imposes some motions twice: the loop's out-of-plane equations
//! are linear combinations of one another, and the iteration matrix `[S, sBᵀ; sB, 0]` is
//! singular. As Adams does (and MBDyn and Exudyn do not), the dependent equations are
//! found by a rank-revealing factorisation of the constraint Jacobian `B` — modified
//! Gram–Schmidt, twice, on each connected group of constraint equations, in deck order, so
//! the equation removed is the later one: the loop-closing joint's — and removed: their
//! multipliers are held at zero ([`System::remove_equations`]). Where the rank of `B` is
//! constant (a structural redundancy) the kept equations define the same constraint
//! manifold, so the motion is unchanged; the run checks at each step that the removed
//! equations stay satisfied ([`Redundancy::removed_violation`]), which catches both a
//! redundancy that was only one of the initial position and equations that contradict
//! the others (two drivers of one motion with different laws).
//!
//! The reactions are then not unique: any multipliers `λ + N c`, `N` the left null space
//! of `B`, carry the same loads. The ones reported are the minimum-norm ones
//! ([`Redundancy::reported_multipliers`]), in a norm made of one unit by weighing the
//! forces by the model's reference length `L` (`‖(λ_F L, λ_M)‖`), which does not depend on
//! the deck's order of joints. (Géradin & Cardona, *Flexible Multibody Dynamics*, 2001,
//! § 11.4; García de Jalón & Bayo, *Kinematic and Dynamic Simulation of Multibody
//! Systems*, 1994, § 3.4 on redundant constraints.)
//!
//! The check reads the solver's [`System`] (dense numbering, free dofs) and asks each
//! element for its constraint rows `B` through the [`Element`] trait, so it belongs with
//! the solver: data flows elements → solver, never back.

use super::System;
use super::system::FIXED;
use crate::elements::{Element, EvalContext, Local, NodeState};
use crate::model::ElementId;
use nalgebra::{DMatrix, SymmetricEigen, Vector3};

/// A row is dependent when less than this fraction of its norm is left once the rows
/// before it are taken out (round-off of a Gram–Schmidt on rows of unit-order entries,
/// with margin).
const DEPENDENT: f64 = 1e-8;

/// Components larger than this many entries (rows × columns) are not checked densely
/// (200 MB): their redundancies, if any, are diagnosed when a factorisation fails.
const MAX_DENSE_ENTRIES: usize = 25_000_000;

/// The motion a constraint equation blocks, in the global frame at the state of the
/// check: what its row of `B` does to the element's last free node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// A translation along this unit vector.
    Translation(Vector3<f64>),
    /// A rotation about this unit vector.
    Rotation(Vector3<f64>),
}

impl std::fmt::Display for Motion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (what, v) = match self {
            Motion::Translation(v) => ("translation along", v),
            Motion::Rotation(v) => ("rotation about", v),
        };
        let c = |x: f64| {
            let r = (x * 1e4).round() / 1e4;
            if r == 0.0 { 0.0 } else { r }
        };
        write!(f, "{what} ({}, {}, {})", c(v.x), c(v.y), c(v.z))
    }
}

/// A constraint equation that is linearly dependent on the ones before it.
#[derive(Debug, Clone, PartialEq)]
pub struct Redundant {
    /// Dense element index.
    pub element: usize,
    /// The element's number.
    pub id: ElementId,
    /// Equation number within the element (0-based).
    pub equation: usize,
    /// Global equation number.
    pub global: usize,
    /// The motion it would block (already blocked by the others).
    pub motion: Motion,
}

/// A connected group of constraint equations with at least one removed: where the
/// reported reactions are made minimum-norm.
#[derive(Debug, Clone)]
struct Cluster {
    /// Global multiplier equations, kept and removed.
    eqs: Vec<usize>,
    /// Their elements (dense), each once.
    elements: Vec<usize>,
    /// Global nodal equations their rows touch.
    dofs: Vec<usize>,
    /// Per equation: a force (its row has translational entries) or a moment.
    force: Vec<bool>,
    /// Equations removed in this group.
    removed: usize,
}

/// The redundant equations of a system and what the run needs of them.
#[derive(Debug, Clone, Default)]
pub struct Redundancy {
    /// The removed (dependent) equations, in deck order.
    pub removed: Vec<Redundant>,
    /// Groups of constraint equations too large to check densely: (equations, columns).
    pub unchecked: Vec<(usize, usize)>,
    clusters: Vec<Cluster>,
}

fn static_context() -> EvalContext {
    EvalContext {
        t: 0.0,
        c_v: 0.0,
        c_a: 0.0,
        dynamic: false,
        gravity: Vector3::zeros(),
        constraint_scale: 1.0,
        penalty: 0.0,
        h: 0.0,
    }
}

/// The constraint rows of element `e` at `nodes` (sparse: global nodal equation, value),
/// and its local buffers' size.
fn element_rows(sys: &System, e: usize, nodes: &[NodeState], t: f64) -> Vec<Vec<(usize, f64)>> {
    let el = &sys.elements[e];
    let m = el.multipliers();
    let nn = 6 * el.nodes().len();
    let mut local = Local::new(nn + m);
    let ctx = EvalContext {
        t,
        ..static_context()
    };
    el.evaluate(&ctx, nodes, &vec![0.0; m], true, &mut local);
    (0..m)
        .map(|k| {
            let mut row: Vec<(usize, f64)> = Vec::new();
            for (a, &node) in el.nodes().iter().enumerate() {
                for comp in 0..6 {
                    let g = sys.node_dofs[node][comp];
                    let v = local.tan_at(nn + k, 6 * a + comp);
                    if g != FIXED && v != 0.0 {
                        match row.iter_mut().find(|(c, _)| *c == g) {
                            Some((_, x)) => *x += v,
                            None => row.push((g, v)),
                        }
                    }
                }
            }
            row
        })
        .collect()
}

/// The motion row `row` of element `el` blocks, read on its last node with free
/// degrees of freedom (rotations turned to the global frame).
fn motion_of(sys: &System, el: &dyn Element, nodes: &[NodeState], row: &[(usize, f64)]) -> Motion {
    let at = |g: usize| row.iter().find(|(c, _)| *c == g).map_or(0.0, |(_, v)| *v);
    for &node in el.nodes().iter().rev() {
        let d = &sys.node_dofs[node];
        if d.iter().all(|g| *g == FIXED) {
            continue;
        }
        let get = |c: usize| if d[c] == FIXED { 0.0 } else { at(d[c]) };
        let t = Vector3::new(get(0), get(1), get(2));
        let r = nodes[node].r * Vector3::new(get(3), get(4), get(5));
        if t.norm() > 1e-12 * (t.norm() + r.norm()) {
            return Motion::Translation(t.normalize());
        }
        if r.norm() > 0.0 {
            return Motion::Rotation(r.normalize());
        }
    }
    Motion::Translation(Vector3::zeros())
}

/// Union–find root with path halving.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The redundant constraint equations of a system at a state (see the module docs): for
/// each connected group of constraint equations (sharing free degrees of freedom), the
/// rows, in model (deck) order, that add nothing to the span of the preceding ones —
/// less than `1e-8` of the row's norm left after two passes of modified Gram–Schmidt.
/// Rows already removed from `sys` count like the others.
pub fn detect(sys: &System, nodes: &[NodeState], t: f64) -> Redundancy {
    detect_with(sys, nodes, t, DEPENDENT)
}

/// [`detect`] with the threshold `tol`: a row is dependent when less than `tol` of its
/// norm is left (`1e-3`: nearly dependent rows, as near a singular position).
pub fn detect_with(sys: &System, nodes: &[NodeState], t: f64, tol: f64) -> Redundancy {
    let nn = sys.n_node_eq;
    let n = sys.n_eq();
    // Rows of every multiplier equation, by global equation.
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n - nn];
    let mut owner: Vec<(usize, usize)> = vec![(0, 0); n - nn];
    for (e, el) in sys.elements.iter().enumerate() {
        if el.multipliers() == 0 {
            continue;
        }
        for (k, row) in element_rows(sys, e, nodes, t).into_iter().enumerate() {
            let g = sys.mult_offset[e] + k - nn;
            rows[g] = row;
            owner[g] = (e, k);
        }
    }
    // Groups: equations sharing a nodal degree of freedom.
    let mut parent: Vec<usize> = (0..rows.len()).collect();
    let mut first = vec![usize::MAX; nn];
    for (i, row) in rows.iter().enumerate() {
        for &(c, _) in row {
            if first[c] == usize::MAX {
                first[c] = i;
            } else {
                let (a, b) = (root(&mut parent, first[c]), root(&mut parent, i));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group_of = vec![usize::MAX; rows.len()];
    for i in 0..rows.len() {
        let r = root(&mut parent, i);
        if group_of[r] == usize::MAX {
            group_of[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[group_of[r]].push(i);
    }
    let mut out = Redundancy::default();
    for group in groups {
        let mut dofs: Vec<usize> = group
            .iter()
            .flat_map(|&i| rows[i].iter().map(|(c, _)| *c))
            .collect();
        dofs.sort_unstable();
        dofs.dedup();
        if group.len() * dofs.len() > MAX_DENSE_ENTRIES {
            out.unchecked.push((group.len(), dofs.len()));
            continue;
        }
        let col = |c: usize| dofs.binary_search(&c).expect("a dof of the group");
        let mut basis: Vec<Vec<f64>> = Vec::new();
        let mut removed_here = 0;
        for &i in &group {
            let mut row = vec![0.0; dofs.len()];
            for &(c, v) in &rows[i] {
                row[col(c)] = v;
            }
            let norm0 = row.iter().map(|v| v * v).sum::<f64>().sqrt();
            for _ in 0..2 {
                for b in &basis {
                    let d: f64 = row.iter().zip(b).map(|(x, y)| x * y).sum();
                    row.iter_mut().zip(b).for_each(|(x, y)| *x -= d * y);
                }
            }
            let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm <= tol * norm0 || norm0 == 0.0 {
                let (e, k) = owner[i];
                out.removed.push(Redundant {
                    element: e,
                    id: sys.elements[e].id(),
                    equation: k,
                    global: nn + i,
                    motion: motion_of(sys, sys.elements[e].as_ref(), nodes, &rows[i]),
                });
                removed_here += 1;
            } else {
                row.iter_mut().for_each(|x| *x /= norm);
                basis.push(row);
            }
        }
        if removed_here > 0 {
            let mut elements: Vec<usize> = group.iter().map(|&i| owner[i].0).collect();
            elements.dedup();
            out.clusters.push(Cluster {
                eqs: group.iter().map(|&i| nn + i).collect(),
                elements,
                force: group
                    .iter()
                    .map(|&i| rows[i].iter().any(|(c, _)| is_translation(sys, *c)))
                    .collect(),
                dofs,
                removed: removed_here,
            });
        }
    }
    out.removed.sort_by_key(|r| r.global);
    out
}

fn is_translation(sys: &System, g: usize) -> bool {
    matches!(sys.owners[g], super::system::DofOwner::Node { comp, .. } if comp < 3)
}

impl Redundancy {
    /// No equation is removed.
    pub fn is_empty(&self) -> bool {
        self.removed.is_empty()
    }

    /// The global equations removed.
    pub fn globals(&self) -> Vec<usize> {
        self.removed.iter().map(|r| r.global).collect()
    }

    /// The redundancy of a system whose equations `removed` were removed at the start of
    /// its run (a restart from a checkpoint): the groups rebuilt at `nodes`.
    pub fn restored(sys: &System, nodes: &[NodeState], t: f64, removed: &[usize]) -> Self {
        let mut r = detect(sys, nodes, t);
        r.removed.retain(|x| removed.contains(&x.global));
        r
    }

    /// The largest violation of a removed equation at the state (`|Φ_k|`, m or rad), with
    /// the equation: they follow from the kept ones as long as the redundancy is
    /// structural. `lambda` is not read (the rows' residuals do not depend on it).
    pub fn removed_violation(
        &self,
        sys: &System,
        nodes: &[NodeState],
        t: f64,
    ) -> Option<(f64, &Redundant)> {
        let mut worst: Option<(f64, &Redundant)> = None;
        let ctx = EvalContext {
            t,
            ..static_context()
        };
        let mut last: Option<(usize, Local)> = None;
        for r in &self.removed {
            let el = &sys.elements[r.element];
            let nn = 6 * el.nodes().len();
            if last.as_ref().is_none_or(|(e, _)| *e != r.element) {
                let m = el.multipliers();
                let mut local = Local::new(nn + m);
                el.evaluate(&ctx, nodes, &vec![0.0; m], false, &mut local);
                last = Some((r.element, local));
            }
            let v = last
                .as_ref()
                .map_or(0.0, |(_, l)| l.res[nn + r.equation].abs());
            if worst.is_none_or(|(w, _)| v > w) {
                worst = Some((v, r));
            }
        }
        worst
    }

    /// The multipliers to report (the run's, `lambda`, indexed by global equation): in
    /// each group with removed equations, the minimum-norm ones that carry the same loads,
    /// `μ ← μ − N Nᵀ μ` with `μ = (λ_F L, λ_M)` and `N` an orthonormal basis of the left
    /// null space of `B` weighed alike (`L` = `sys.ref_length`). Elsewhere, `lambda`.
    pub fn reported_multipliers(
        &self,
        sys: &System,
        nodes: &[NodeState],
        t: f64,
        lambda: &[f64],
    ) -> Vec<f64> {
        let mut out = lambda.to_vec();
        let l = sys.ref_length;
        for c in &self.clusters {
            let m = c.eqs.len();
            let weight: Vec<f64> = c.force.iter().map(|f| if *f { l } else { 1.0 }).collect();
            let mut b = DMatrix::<f64>::zeros(m, c.dofs.len());
            for &e in &c.elements {
                for (k, row) in element_rows(sys, e, nodes, t).into_iter().enumerate() {
                    let g = sys.mult_offset[e] + k;
                    let Some(i) = c.eqs.iter().position(|x| *x == g) else {
                        continue;
                    };
                    for (col, v) in row {
                        if let Ok(j) = c.dofs.binary_search(&col) {
                            b[(i, j)] = v / weight[i];
                        }
                    }
                }
            }
            let gram = &b * b.transpose();
            let eig = SymmetricEigen::new(gram);
            let mut order: Vec<usize> = (0..m).collect();
            order.sort_by(|x, y| eig.eigenvalues[*x].total_cmp(&eig.eigenvalues[*y]));
            let mu = nalgebra::DVector::from_iterator(
                m,
                c.eqs.iter().zip(&weight).map(|(g, w)| lambda[*g] * w),
            );
            let mut mu_n = mu.clone();
            for &k in order.iter().take(c.removed) {
                let v = eig.eigenvectors.column(k);
                mu_n -= v * v.dot(&mu);
            }
            for (i, g) in c.eqs.iter().enumerate() {
                out[*g] = mu_n[i] / weight[i];
            }
        }
        out
    }

    /// Per element with a removed equation: the message of a warning (the element and
    /// the motions it imposes that the other joints already impose).
    pub fn describe(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut i = 0;
        while i < self.removed.len() {
            let id = self.removed[i].id;
            let mut eqs = Vec::new();
            let mut motions = Vec::new();
            while i < self.removed.len() && self.removed[i].id == id {
                eqs.push((self.removed[i].equation + 1).to_string());
                motions.push(self.removed[i].motion.to_string());
                i += 1;
            }
            out.push(format!(
                "element {}: its equation{} {} ({}) repeat{} what the joints before it in the deck already impose; removed (the motion is unchanged, the reactions along {} are not unique: the minimum-norm ones are reported)",
                id.0,
                if eqs.len() > 1 { "s" } else { "" },
                eqs.join(", "),
                motions.join("; "),
                if eqs.len() > 1 { "" } else { "s" },
                if eqs.len() > 1 { "them" } else { "it" },
            ));
        }
        out
    }
}

/// The diagnosis of a run that failed near a singular position of its constraints: the
/// equations (other than those removed at the start) that are dependent on the others to
/// within `1e-3` of their norm at `nodes` (the failed step's last iterate), or `None`.
pub fn singular_position(sys: &System, nodes: &[NodeState], t: f64) -> Option<String> {
    near_dependent(sys, nodes, t, 1e-3).map(|list| {
        format!(
            "the constraints are nearly dependent here (a singular position: links aligned, a loop at its limit, where the joints block fewer motions than their equations, and the motion may not go on): {list}"
        )
    })
}

/// The equations of `r` not removed at the start, listed by element as
/// `E (equation k (motion), …)`, with their count; `None` when there are none.
fn listed_by_element(sys: &System, r: &Redundancy) -> Option<(usize, String)> {
    let removed = sys.removed_equations();
    let new: Vec<&Redundant> = r
        .removed
        .iter()
        .filter(|x| !removed.contains(&x.global))
        .collect();
    if new.is_empty() {
        return None;
    }
    let mut by_el: Vec<(ElementId, Vec<String>)> = Vec::new();
    for x in &new {
        let what = format!("{} ({})", x.equation + 1, x.motion);
        match by_el.last_mut() {
            Some((id, v)) if *id == x.id => v.push(what),
            _ => by_el.push((x.id, vec![what])),
        }
    }
    let list = by_el
        .iter()
        .map(|(id, eqs)| format!("{id} (equation {})", eqs.join(", ")))
        .collect::<Vec<_>>()
        .join("; ");
    Some((new.len(), list))
}

/// The equations dependent to within `tol`, not removed at the start, listed by element.
fn near_dependent(sys: &System, nodes: &[NodeState], t: f64, tol: f64) -> Option<String> {
    listed_by_element(sys, &detect_with(sys, nodes, t, tol)).map(|(_, list)| list)
}

/// The diagnosis of redundant constraints at a state where the iteration matrix could
/// not be factored, naming the joints and their equations, or `None` when the
/// constraints are independent there. Equations removed at the start do not count.
pub fn redundancy_error(sys: &System, nodes: &[NodeState]) -> Option<String> {
    let (count, list) = listed_by_element(sys, &detect(sys, nodes, 0.0))?;
    Some(format!(
        "redundant constraints at this position: {count} of the constraint equations depend on the others: {list}. The mechanism is at a singular position (links aligned, a loop that locks), where the joints block fewer motions than their equations",
    ))
}
