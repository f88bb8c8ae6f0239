//! Mesh generation on the model: a user's beam divided into elements (`DIVIDE n` on a
//! BEAM card, `--refine k` on the command line), with nodes generated on its axis.
//!
//! **Numbering.** Generated nodes and elements are numbered beyond the user's: from one past
//! the largest user node number and one past the largest user element number, in the order
//! of the divided beams in the deck, each beam's nodes and elements from its first node to
//! its second. The user's nodes keep their numbers, so `node_12.csv` is the same point of the
//! structure at every refinement. A divided beam `N` keeps its number for its **first**
//! sub-element (the one that starts at its first node): `element_N.csv` holds the resultants
//! at the midpoint of that sub-element.
//!
//! **Geometry.** The interior nodes of a straight beam lie on the segment between its end
//! nodes, at parametric positions `s ∈ (0, 1)`: `x(s) = x_a + s (x_b − x_a)`
//! ([`axis_points`]). [`Model::add_axis_nodes`] is the one function that places and numbers
//! such nodes: `DIVIDE` passes `s = i/n`; an element of higher order can pass its
//! Gauss–Lobatto abscissae, and a curved axis can replace [`axis_points`].
//!
//! **What the generated entities inherit.** Each sub-element has the beam's material, section
//! and `AXIS2` (the default local axis 2 depends only on the axis direction, which the
//! sub-elements share). Generated nodes are free (no `FIX`), carry no load or mass (loads,
//! masses, joints and contacts stay on the user's nodes) and, when an end node has an
//! initial velocity, start with the linear interpolation of the end nodes' initial
//! velocities and angular velocities — exact for the rigid-body fields `V + W × (x − c)` that
//! `INITIAL ... ABOUT` defines, since those are affine in `x`.

use super::{Element, ElementId, ElementKind, InitialVelocity, Model, Node, NodeId};
use indexmap::IndexMap;
use nalgebra::Vector3;

/// How one user beam was divided.
#[derive(Debug, Clone, PartialEq)]
pub struct Division {
    /// The beam's end nodes, as the user wrote them.
    pub ends: [NodeId; 2],
    /// Sub-elements from `ends[0]` to `ends[1]`; the first keeps the user's number.
    pub elements: Vec<ElementId>,
    /// Generated interior nodes, from `ends[0]` to `ends[1]`.
    pub interior: Vec<NodeId>,
}

impl Division {
    /// Number of elements the beam was divided into (`DIVIDE n` times `--refine k`).
    pub fn count(&self) -> u32 {
        self.elements.len() as u32
    }
}

/// A mesh operation that cannot be carried out.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// Generated numbers would exceed the largest number a deck may use.
    #[error("generated {what} numbers would exceed 4294967295")]
    Overflow {
        /// "node" or "element".
        what: &'static str,
    },
    /// The element to divide is not a two-node beam of the model.
    #[error("{0} is not a beam of the model")]
    NotABeam(ElementId),
    /// The end nodes and the centre of a beam's `ARC` do not make an arc.
    #[error("{0}: ARC: {1}")]
    Arc(ElementId, super::arc::ArcError),
    /// A parametric position outside (0, 1).
    #[error("parametric position {0} is not inside (0, 1)")]
    BadParameter(f64),
    /// A division factor of zero.
    #[error("a beam must be divided into at least one element")]
    ZeroCount,
}

/// Points of the straight axis from `xa` to `xb` at parametric positions `s`:
/// `x(s) = x_a + s (x_b − x_a)` (so `s = 0` gives `x_a` exactly; interior points lie on the
/// segment to round-off).
pub fn axis_points(xa: &Vector3<f64>, xb: &Vector3<f64>, params: &[f64]) -> Vec<Vector3<f64>> {
    let d = xb - xa;
    params.iter().map(|s| xa + d * *s).collect()
}

/// The interior parametric positions of `n` equal elements: `s_i = i/n`, `i = 1 … n−1`.
pub fn uniform_params(n: u32) -> Vec<f64> {
    (1..n).map(|i| f64::from(i) / f64::from(n)).collect()
}

/// Next free numbers for generated nodes and elements.
#[derive(Debug, Clone, Copy)]
pub struct Numbering {
    next_node: u64,
    next_element: u64,
}

impl Numbering {
    /// One past the largest node and element numbers of `model` (generated ones included).
    pub fn after(model: &Model) -> Self {
        Numbering {
            next_node: model
                .nodes
                .keys()
                .map(|n| u64::from(n.0) + 1)
                .max()
                .unwrap_or(1),
            next_element: model
                .elements
                .keys()
                .map(|e| u64::from(e.0) + 1)
                .max()
                .unwrap_or(1),
        }
    }

    fn node(&mut self) -> Result<NodeId, MeshError> {
        let n = u32::try_from(self.next_node).map_err(|_| MeshError::Overflow { what: "node" })?;
        self.next_node += 1;
        Ok(NodeId(n))
    }

    fn element(&mut self) -> Result<ElementId, MeshError> {
        let n = u32::try_from(self.next_element)
            .map_err(|_| MeshError::Overflow { what: "element" })?;
        self.next_element += 1;
        Ok(ElementId(n))
    }
}

impl Model {
    /// Adds free nodes on the straight axis from node `a` to node `b` at the parametric
    /// positions `params` (each in (0, 1)), numbered from `numbering`; returns their numbers
    /// in the order of `params`. Their span is `span`; when `a` or `b` has an initial
    /// velocity, each new node gets the linear interpolation `(1 − s) v_a + s v_b` (and the
    /// same for ω), exact for rigid-body fields. `a` and `b` must be nodes of the model.
    pub fn add_axis_nodes(
        &mut self,
        a: NodeId,
        b: NodeId,
        params: &[f64],
        numbering: &mut Numbering,
        span: super::Span,
    ) -> Result<Vec<NodeId>, MeshError> {
        if let Some(s) = params.iter().find(|s| !(**s > 0.0 && **s < 1.0)) {
            return Err(MeshError::BadParameter(*s));
        }
        let (xa, xb) = (self.nodes[&a].position, self.nodes[&b].position);
        let initial = |n: NodeId| self.initial.iter().rev().find(|iv| iv.node == n).cloned();
        let (ia, ib) = (initial(a), initial(b));
        let velocity = |iv: &Option<InitialVelocity>| {
            iv.as_ref()
                .map_or((Vector3::zeros(), Vector3::zeros()), |iv| {
                    (iv.velocity, iv.angular)
                })
        };
        let ((va, wa), (vb, wb)) = (velocity(&ia), velocity(&ib));
        let mut ids = Vec::with_capacity(params.len());
        for (x, s) in axis_points(&xa, &xb, params).into_iter().zip(params) {
            let id = numbering.node()?;
            self.nodes.insert(
                id,
                Node {
                    id,
                    position: x,
                    fixed: [false; 6],
                    span,
                },
            );
            if ia.is_some() || ib.is_some() {
                self.initial.push(InitialVelocity {
                    node: id,
                    velocity: va * (1.0 - s) + vb * *s,
                    angular: wa * (1.0 - s) + wb * *s,
                    span,
                });
            }
            ids.push(id);
        }
        Ok(ids)
    }

    /// Divides the user beam `beam` (not yet divided) into `n` equal elements: `n − 1`
    /// nodes at `s = i/n` ([`Model::add_axis_nodes`]) and `n − 1` new elements; the beam
    /// keeps its number for the first one. Records the [`Division`].
    pub fn divide_beam(
        &mut self,
        beam: ElementId,
        n: u32,
        numbering: &mut Numbering,
    ) -> Result<(), MeshError> {
        if n == 0 {
            return Err(MeshError::ZeroCount);
        }
        let Some(el) = self.elements.get(&beam).cloned() else {
            return Err(MeshError::NotABeam(beam));
        };
        if !matches!(el.kind, ElementKind::Beam { .. }) || el.nodes.len() != 2 {
            return Err(MeshError::NotABeam(beam));
        }
        if n == 1 {
            return Ok(());
        }
        let ends = [el.nodes[0], el.nodes[1]];
        let interior =
            self.add_axis_nodes(ends[0], ends[1], &uniform_params(n), numbering, el.span)?;
        let mut chain = vec![ends[0]];
        chain.extend(&interior);
        chain.push(ends[1]);
        let mut elements = vec![beam];
        self.elements[&beam].nodes = vec![chain[0], chain[1]];
        for w in chain.windows(2).skip(1) {
            let id = numbering.element()?;
            self.elements.insert(
                id,
                Element {
                    id,
                    nodes: vec![w[0], w[1]],
                    kind: el.kind.clone(),
                    span: el.span,
                },
            );
            elements.push(id);
        }
        self.divisions.insert(
            beam,
            Division {
                ends,
                elements,
                interior,
            },
        );
        Ok(())
    }

    /// Divides the user beams: `counts` gives, per beam (deck order), the number of
    /// elements; beams not listed are left whole. Numbers are allocated after the model's
    /// current largest ones, in the order of `counts`. The model must not be divided yet.
    pub fn divide_beams(&mut self, counts: &IndexMap<ElementId, u32>) -> Result<(), MeshError> {
        let mut numbering = Numbering::after(self);
        for (beam, n) in counts {
            self.divide_beam(*beam, *n, &mut numbering)?;
        }
        Ok(())
    }

    /// Removes every generated node and element and gives each divided beam back its end
    /// nodes: the model as the user wrote it (each beam whole). Returns the element count of
    /// each beam that was divided.
    pub fn undivide(&mut self) -> IndexMap<ElementId, u32> {
        let divisions = std::mem::take(&mut self.divisions);
        let mut counts = IndexMap::new();
        let mut generated = std::collections::HashSet::new();
        for (beam, d) in &divisions {
            counts.insert(*beam, d.count());
            for e in d.elements.iter().skip(1) {
                self.elements.shift_remove(e);
            }
            for n in &d.interior {
                self.nodes.shift_remove(n);
                generated.insert(*n);
            }
            if let Some(el) = self.elements.get_mut(beam) {
                el.nodes = d.ends.to_vec();
            }
        }
        self.initial.retain(|iv| !generated.contains(&iv.node));
        counts
    }

    /// `--refine k`: divides every user beam into `k` times as many elements as it has now
    /// (a beam with `DIVIDE n` into `k·n`, an undivided one into `k`); numbering as a deck
    /// whose BEAM cards say `DIVIDE k·n` would give, so the result equals that deck's model.
    pub fn refine(&mut self, k: u32) -> Result<(), MeshError> {
        if k == 0 {
            return Err(MeshError::ZeroCount);
        }
        if k == 1 {
            return Ok(());
        }
        // Beams of order p are divided as two-node beams, then raised again (order.rs).
        self.lower_orders();
        let old = self.undivide();
        let counts: IndexMap<ElementId, u32> = self
            .elements
            .values()
            .filter(|e| matches!(e.kind, ElementKind::Beam { .. }))
            .map(|e| {
                let n = old.get(&e.id).copied().unwrap_or(1);
                n.checked_mul(k)
                    .map(|c| (e.id, c))
                    .ok_or(MeshError::Overflow { what: "element" })
            })
            .collect::<Result<_, _>>()?;
        self.divide_beams(&counts)?;
        self.raise_orders(&mut Numbering::after(self))
    }

    /// Numbers of the generated nodes and elements: (nodes, elements).
    pub fn generated_counts(&self) -> (usize, usize) {
        self.divisions.values().fold((0, 0), |(n, e), d| {
            (n + d.interior.len(), e + d.elements.len() - 1)
        })
    }

    /// Whether `node` was generated by a division (not written by the user).
    pub fn is_generated_node(&self, node: NodeId) -> bool {
        self.divisions.values().any(|d| d.interior.contains(&node))
    }

    /// Whether `element` was generated by a division (a sub-element other than the first).
    pub fn is_generated_element(&self, element: ElementId) -> bool {
        self.divisions
            .values()
            .any(|d| d.elements.iter().skip(1).any(|e| *e == element))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deck::parse_deck;

    const DECK: &str = "TITLE t\nMATERIALS\n 1 E 2e11 NU 0.3 RHO 7800\nSECTIONS\n 1 A 1e-4 I2 1e-9 I3 1e-9 J 2e-9\n\
        NODES\n 1 0 0 0 FIX ALL\n 7 1 2 3\n 3 2 2 2\nELEMENTS\n 5 BEAM 1 7 MAT 1 SEC 1 AXIS2 0 0 1 DIVIDE 3\n\
        2 BEAM 7 3 MAT 1 SEC 1\n 9 MASS 7 M 1\nINITIAL\n 7 V 1 0 0 W 0 0 2\n\
        ANALYSIS DYNAMIC STEP 1e-3 END 1e-2\n";

    /// DIVIDE 3 on beam 5 (nodes 1 → 7): two nodes at s = 1/3, 2/3 on the segment,
    /// numbered 8, 9 (past the largest user node, 7), two elements 10, 11 (past 9); beam 5
    /// keeps its number for the first third and its AXIS2; the generated nodes start with
    /// the interpolated initial velocity; beam 2 and the mass are untouched.
    #[test]
    fn divide_numbers_beyond_the_user_and_places_nodes_on_the_axis() {
        let m = parse_deck(DECK, "t").expect("parses");
        assert_eq!(m.nodes.len(), 5);
        let x = |n: u32| m.nodes[&NodeId(n)].position;
        for (id, s) in [(8, 1.0 / 3.0), (9, 2.0 / 3.0)] {
            let want = Vector3::new(1.0, 2.0, 3.0) * s;
            // x_a + s (x_b − x_a) with x_a = 0: one rounding of each product.
            assert!((x(id) - want).norm() <= 4.0 * f64::EPSILON * want.norm());
            assert!(m.is_generated_node(NodeId(id)));
        }
        let d = &m.divisions[&ElementId(5)];
        assert_eq!(d.ends, [NodeId(1), NodeId(7)]);
        assert_eq!(d.interior, vec![NodeId(8), NodeId(9)]);
        assert_eq!(d.elements, vec![ElementId(5), ElementId(10), ElementId(11)]);
        let nodes = |e: u32| m.elements[&ElementId(e)].nodes.clone();
        assert_eq!(nodes(5), vec![NodeId(1), NodeId(8)]);
        assert_eq!(nodes(10), vec![NodeId(8), NodeId(9)]);
        assert_eq!(nodes(11), vec![NodeId(9), NodeId(7)]);
        assert_eq!(nodes(2), vec![NodeId(7), NodeId(3)]);
        for e in [5, 10, 11] {
            assert_eq!(
                m.elements[&ElementId(e)].kind,
                m.elements[&ElementId(5)].kind
            );
        }
        assert!(matches!(
            m.elements[&ElementId(11)].kind,
            ElementKind::Beam { axis2: Some(a), .. } if a == Vector3::new(0.0, 0.0, 1.0)
        ));
        // Node 1 at rest, node 7 at (1, 0, 0) m/s and 2 rad/s: node 8 (s = 1/3) gets 1/3 of it.
        let iv = m.initial.iter().find(|iv| iv.node == NodeId(8)).expect("v");
        assert!((iv.velocity - Vector3::new(1.0 / 3.0, 0.0, 0.0)).norm() < 1e-15);
        assert!((iv.angular - Vector3::new(0.0, 0.0, 2.0 / 3.0)).norm() < 1e-15);
        assert_eq!(m.generated_counts(), (2, 2));
    }

    /// `refine(k)` multiplies DIVIDE (3 → 6) and divides the other beams (1 → 2), with the
    /// numbering of the deck that says so; `undivide` gives the user's model back.
    #[test]
    fn refine_equals_the_deck_with_multiplied_divide() {
        let mut m = parse_deck(DECK, "t").expect("parses");
        m.refine(2).expect("refines");
        let written = DECK
            .replace("DIVIDE 3", "DIVIDE 6")
            .replace("2 BEAM 7 3 MAT 1 SEC 1", "2 BEAM 7 3 MAT 1 SEC 1 DIVIDE 2");
        let mut direct = parse_deck(&written, "t").expect("parses");
        crate::deck::strip_spans(&mut m);
        crate::deck::strip_spans(&mut direct);
        assert_eq!(m, direct);
        assert_eq!(m.generated_counts(), (5 + 1, 5 + 1));
        m.undivide();
        let mut user = parse_deck(&DECK.replace(" DIVIDE 3", ""), "t").expect("parses");
        crate::deck::strip_spans(&mut user);
        assert_eq!(m, user);
    }

    /// A beam that starts with a rigid-body field V + W × (x − c) gives its generated nodes
    /// exactly that field: the interpolation is exact because the field is affine in x.
    #[test]
    fn generated_nodes_inherit_a_rigid_body_initial_field() {
        let field = "V 1 2 3 W 0.5 -1 2 ABOUT 0.3 0.1 0";
        let deck = DECK
            .replace(" 7 V 1 0 0 W 0 0 2", &format!(" 1 {field}\n 7 {field}"))
            .replace("1 0 0 0 FIX ALL", "1 0 0 0");
        let m = parse_deck(&deck, "t").expect("parses");
        let (v, w, c) = (
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(0.5, -1.0, 2.0),
            Vector3::new(0.3, 0.1, 0.0),
        );
        for id in [8, 9] {
            let iv = m
                .initial
                .iter()
                .find(|iv| iv.node == NodeId(id))
                .expect("v");
            let x = m.nodes[&NodeId(id)].position;
            assert!((iv.velocity - (v + w.cross(&(x - c)))).norm() < 1e-14);
            assert!((iv.angular - w).norm() < 1e-15);
        }
    }

    #[test]
    fn bad_parameters_and_counts_are_refused() {
        let mut m = parse_deck(DECK, "t").expect("parses");
        let mut num = Numbering::after(&m);
        let span = m.nodes[&NodeId(1)].span;
        for s in [0.0, 1.0, -0.1, f64::NAN] {
            assert!(matches!(
                m.add_axis_nodes(NodeId(1), NodeId(7), &[s], &mut num, span),
                Err(MeshError::BadParameter(_))
            ));
        }
        assert_eq!(m.refine(0), Err(MeshError::ZeroCount));
        assert_eq!(
            m.divide_beam(ElementId(9), 2, &mut num),
            Err(MeshError::NotABeam(ElementId(9)))
        );
        // Numbers past 4294967295 are refused, not wrapped.
        let mut big = parse_deck(
            &DECK
                .replace(" DIVIDE 3", "")
                .replace(" 3 2 2 2", " 4294967295 2 2 2")
                .replace("7 3 MAT", "7 4294967295 MAT"),
            "t",
        )
        .expect("parses");
        assert_eq!(big.refine(2), Err(MeshError::Overflow { what: "node" }));
    }

    /// Gauss–Lobatto-like positions (any list in (0, 1)) are placed at x_a + s (x_b − x_a).
    #[test]
    fn axis_points_are_affine_in_s() {
        let (a, b) = (Vector3::new(1.0, -1.0, 0.5), Vector3::new(2.0, 3.0, -0.5));
        let s = [
            0.5 - 0.5 * (0.2f64).sqrt(),
            0.5,
            0.5 + 0.5 * (0.2f64).sqrt(),
        ];
        let p = axis_points(&a, &b, &s);
        for (p, s) in p.iter().zip(s) {
            let q = a * (1.0 - s) + b * s;
            assert!((p - q).norm() < 1e-15);
        }
        assert_eq!(uniform_params(4), vec![0.25, 0.5, 0.75]);
        assert!(uniform_params(1).is_empty());
    }
}
