//! Redundant constraints: which constraint equations of a system depend on the others.
//!
//! The check reads the solver's [`System`] (dense numbering, free dofs) and asks each element
//! for its constraint rows `B` through the [`Element`] trait, so it belongs with the solver:
//! data flows elements → solver, never back (it lived in `elements/joints.rs`, which made
//! elements and solver import each other).

use super::System;
use super::system::FIXED;
use crate::elements::{EvalContext, Local, NodeState};
use crate::model::ElementId;
use nalgebra::Vector3;

/// A constraint equation that is linearly dependent on the ones before it.
#[derive(Debug, Clone, PartialEq)]
pub struct Redundant {
    /// Dense element index.
    pub element: usize,
    /// The element's number.
    pub id: ElementId,
    /// Equation number within the element (0-based).
    pub equation: usize,
}

/// The redundant constraint equations of a system at a state: taking the constraint rows
/// `B` of every element with multipliers in model (deck) order, the rows that add nothing
/// to the span of the preceding ones (modified Gram–Schmidt, twice, on the free nodal
/// degrees of freedom; a row is dependent when less than `1e-8` of its norm is left).
///
/// Such equations make the iteration matrix `[S, sBᵀ; sB, 0]` singular (an
/// over-constrained mechanism, e.g. a planar four-bar of spatial hinges). Put the bodies
/// (`RIGID`, `CLAMP`) first and the loop-closing joint last in the deck, and the joint
/// named is the one that closes the loop.
pub fn redundant_constraints(sys: &System, nodes: &[NodeState]) -> Vec<Redundant> {
    let ctx = EvalContext {
        t: 0.0,
        c_v: 0.0,
        c_a: 0.0,
        dynamic: false,
        gravity: Vector3::zeros(),
        constraint_scale: 1.0,
        penalty: 0.0,
        h: 0.0,
    };
    let n = sys.n_node_eq;
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut out = Vec::new();
    for (e, el) in sys.elements.iter().enumerate() {
        let m = el.multipliers();
        if m == 0 {
            continue;
        }
        let nn = 6 * el.nodes().len();
        let mut local = Local::new(nn + m);
        el.evaluate(&ctx, nodes, &vec![0.0; m], true, &mut local);
        for k in 0..m {
            let mut row = vec![0.0; n];
            for (a, &node) in el.nodes().iter().enumerate() {
                for comp in 0..6 {
                    let g = sys.node_dofs[node][comp];
                    if g != FIXED {
                        row[g] += local.tan_at(nn + k, 6 * a + comp);
                    }
                }
            }
            let norm0 = row.iter().map(|v| v * v).sum::<f64>().sqrt();
            for _ in 0..2 {
                for b in &basis {
                    let d: f64 = row.iter().zip(b).map(|(x, y)| x * y).sum();
                    row.iter_mut().zip(b).for_each(|(x, y)| *x -= d * y);
                }
            }
            let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm <= 1e-8 * norm0 || norm0 == 0.0 {
                out.push(Redundant {
                    element: e,
                    id: el.id(),
                    equation: k,
                });
            } else {
                row.iter_mut().for_each(|x| *x /= norm);
                basis.push(row);
            }
        }
    }
    out
}

/// The diagnosis of redundant constraints (see [`redundant_constraints`]), naming the
/// joints and their equations, or `None` when the constraints are independent.
pub fn redundancy_error(sys: &System, nodes: &[NodeState]) -> Option<String> {
    let r = redundant_constraints(sys, nodes);
    if r.is_empty() {
        return None;
    }
    let mut by_el: Vec<(ElementId, Vec<usize>)> = Vec::new();
    for x in &r {
        match by_el.last_mut() {
            Some((id, v)) if *id == x.id => v.push(x.equation + 1),
            _ => by_el.push((x.id, vec![x.equation + 1])),
        }
    }
    let list: Vec<String> = by_el
        .iter()
        .map(|(id, eqs)| {
            let e: Vec<String> = eqs.iter().map(|k| k.to_string()).collect();
            format!("{id} (equation {})", e.join(", "))
        })
        .collect();
    Some(format!(
        "redundant constraints: {} of the {} constraint equations depend on the others \
         (an over-constrained mechanism): {}. Replace a joint by one that blocks fewer motions \
         (e.g. a HINGE by a SPHERICAL or UJOINT) to remove them",
        r.len(),
        sys.n_eq() - sys.n_node_eq,
        list.join("; ")
    ))
}
