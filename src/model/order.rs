//! Beams of order `p > 1` (`ORDER p` on a BEAM card) and beams on a circular arc (`ARC`).
//!
//! **Interior nodes.** A beam of order `p` has `p + 1` nodes: its two end nodes and `p − 1`
//! generated inside, at the Gauss–Lobatto–Legendre points `s = (1 + ξᵢ)/2` of its span
//! ([`gll_params`]; `ξᵢ` the roots of `P_p'`), placed by [`Model::add_axis_nodes`] — the
//! same function, numbering and inherited initial velocities as the nodes of `DIVIDE` — and
//! listed in the element's `nodes` along the axis: `[first end, interior…, second end]`.
//! With `DIVIDE n` each of the `n` sub-elements gets its own `p − 1` interior nodes; they are
//! numbered after the division's nodes, element by element in model order.
//!
//! **Arcs.** With `ARC c` the reference axis is the arc from the beam's first end to its
//! second around the centre `c` ([`super::arc::Arc`]): the division nodes and the interior
//! nodes are moved from the chord onto the arc at the same arc-length fraction `s`. A moved
//! node that has an initial velocity gets `v(x_chord) + ω × (x_arc − x_chord)` (its chord
//! interpolation, `ω` interpolated too): exact for a rigid-body initial field
//! `V + W × (x − c)`, as on a straight axis.

use super::arc::Arc;
use super::mesh::InitialIndex;
use super::{ElementId, ElementKind, MeshError, Model, NodeId, Numbering};
use nalgebra::Vector3;

/// The largest `ORDER` a deck may ask (17 nodes).
pub const MAX_ORDER: u32 = 16;

/// The interior Gauss–Lobatto–Legendre positions `s = (1 + ξᵢ)/2 ∈ (0, 1)` of order `p`
/// (`p − 1` of them, increasing).
pub fn gll_params(p: u32) -> Vec<f64> {
    if p < 2 {
        return Vec::new();
    }
    let (xi, _) = crate::lagrange::gll(p as usize);
    xi[1..p as usize].iter().map(|x| 0.5 * (1.0 + x)).collect()
}

impl Model {
    /// Generates the interior nodes of every beam of order > 1 that has only its two end
    /// nodes, and moves the nodes of divided `ARC` beams onto their arcs. Numbers come from
    /// `numbering` (past every existing number). Called once, after the divisions.
    pub fn raise_orders(&mut self, numbering: &mut Numbering) -> Result<(), MeshError> {
        // Linear in the nodes generated (issue 35 §1): the initial velocities and each
        // sub-element's place on its user beam are looked up, not searched.
        let mut index = InitialIndex::of(self);
        // Division nodes of arc beams onto the arc.
        let divided: Vec<(ElementId, [NodeId; 2], Vec<NodeId>)> = self
            .divisions
            .iter()
            .map(|(b, d)| (*b, d.ends, d.interior.clone()))
            .collect();
        for (beam, ends, interior) in &divided {
            if let Some(arc) = self.arc_of(*beam, ends)? {
                let n = interior.len() + 1;
                for (j, node) in interior.iter().enumerate() {
                    self.move_onto(*node, &arc, (j + 1) as f64 / n as f64, ends, &index);
                }
            }
        }
        // Sub-element → (its user beam, the beam's ends, its place k of n).
        let mut place = std::collections::HashMap::new();
        for (u, d) in &self.divisions {
            for (k, e) in d.elements.iter().enumerate() {
                place.insert(*e, (*u, d.ends, k, d.elements.len()));
            }
        }
        let ids: Vec<ElementId> = self.elements.keys().copied().collect();
        for id in ids {
            let el = &self.elements[&id];
            let ElementKind::Beam { order, .. } = el.kind else {
                continue;
            };
            if order < 2 || el.nodes.len() != 2 {
                continue;
            }
            let (a, b, span) = (el.nodes[0], el.nodes[1], el.span);
            // The span of this element on its user beam's arc: [k/n, (k+1)/n] for
            // sub-element k of a beam divided in n, [0, 1] otherwise.
            let (user, range) =
                place
                    .get(&id)
                    .map_or(((id, [a, b]), (0.0, 1.0)), |&(u, ends, k, n)| {
                        let n = n as f64;
                        ((u, ends), (k as f64 / n, (k + 1) as f64 / n))
                    });
            let params = gll_params(order);
            let interior =
                self.add_axis_nodes_indexed(a, b, &params, numbering, span, &mut index)?;
            if let Some(arc) = self.arc_of(user.0, &user.1)? {
                for (node, s) in interior.iter().zip(&params) {
                    let s_user = range.0 + (range.1 - range.0) * s;
                    self.move_onto_between(*node, &arc, s_user, *s, [a, b], &index);
                }
            }
            let mut nodes = vec![a];
            nodes.extend(&interior);
            nodes.push(b);
            self.elements[&id].nodes = nodes;
            self.order_nodes.insert(id, interior);
        }
        Ok(())
    }

    /// Sets every beam, divided or not, to order `p` (`mecano-rs study --order`): the interior
    /// nodes of the old orders are removed and those of order `p` generated at its GLL points
    /// (numbered past every existing number; arcs are kept).
    pub fn set_beam_order(&mut self, p: u32) -> Result<(), MeshError> {
        if p == 0 || p > MAX_ORDER {
            return Err(MeshError::Order { order: p });
        }
        self.lower_orders();
        for el in self.elements.values_mut() {
            if let ElementKind::Beam { order, .. } = &mut el.kind {
                *order = p;
            }
        }
        self.raise_orders(&mut Numbering::after(self))
    }

    /// Removes the interior nodes of beams of order > 1 (each beam keeps its end nodes).
    pub fn lower_orders(&mut self) {
        let order_nodes = std::mem::take(&mut self.order_nodes);
        let mut generated = std::collections::HashSet::new();
        for (id, interior) in &order_nodes {
            generated.extend(interior.iter().copied());
            if let Some(el) = self.elements.get_mut(id) {
                let (a, b) = (el.nodes[0], el.nodes[el.nodes.len() - 1]);
                el.nodes = vec![a, b];
            }
        }
        // One pass (an IndexMap's shift_remove per node is quadratic in the mesh).
        self.nodes.retain(|id, _| !generated.contains(id));
        self.initial.retain(|iv| !generated.contains(&iv.node));
    }

    /// Whether `node` is an interior node of a beam of order > 1.
    pub fn is_order_node(&self, node: NodeId) -> bool {
        self.order_nodes.values().any(|v| v.contains(&node))
    }

    /// The arc of user beam `beam` between its end nodes `ends`, if it has `ARC`.
    fn arc_of(&self, beam: ElementId, ends: &[NodeId; 2]) -> Result<Option<Arc>, MeshError> {
        let Some(ElementKind::Beam {
            arc: Some(centre), ..
        }) = self.elements.get(&beam).map(|e| &e.kind)
        else {
            return Ok(None);
        };
        let (xa, xb) = (self.nodes[&ends[0]].position, self.nodes[&ends[1]].position);
        Arc::new(&xa, &xb, centre)
            .map(Some)
            .map_err(|e| MeshError::Arc(beam, e))
    }

    /// Moves a node generated on the chord `ends` at fraction `s` onto `arc` at `s`.
    fn move_onto(
        &mut self,
        node: NodeId,
        arc: &Arc,
        s: f64,
        ends: &[NodeId; 2],
        index: &InitialIndex,
    ) {
        self.move_onto_between(node, arc, s, s, *ends, index);
    }

    /// Moves a node generated at fraction `s_chord` of the chord between `ends` onto `arc`
    /// at the arc's fraction `s_arc`, correcting its initial velocity (module doc).
    fn move_onto_between(
        &mut self,
        node: NodeId,
        arc: &Arc,
        s_arc: f64,
        s_chord: f64,
        ends: [NodeId; 2],
        index: &InitialIndex,
    ) {
        let (xa, xb) = (self.nodes[&ends[0]].position, self.nodes[&ends[1]].position);
        let chord: Vector3<f64> = xa + (xb - xa) * s_chord;
        let x = arc.point(s_arc);
        if let Some(n) = self.nodes.get_mut(&node) {
            n.position = x;
        }
        if let Some(iv) = index.get_mut(self, node) {
            iv.velocity += iv.angular.cross(&(x - chord));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gll_params_are_symmetric_and_inside() {
        assert!(gll_params(1).is_empty());
        assert_eq!(gll_params(2), vec![0.5]);
        for p in 2..=MAX_ORDER {
            let s = gll_params(p);
            assert_eq!(s.len(), p as usize - 1);
            for (a, b) in s.iter().zip(s.iter().rev()) {
                assert!((a + b - 1.0).abs() < 1e-15 && *a > 0.0 && *a < 1.0);
            }
        }
    }
}
