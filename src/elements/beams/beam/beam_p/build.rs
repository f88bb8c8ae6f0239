//! The solver element of a model's beam card: the two-node beam or a [`BeamP`] of the
//! card's order, with the nodes at the Gauss–Lobatto–Legendre points and the reference
//! triads along the straight or curved (`ARC`) axis.

use super::super::two_node::{Beam, BeamProperties, default_axis2, reference_triad};
use super::BeamP;
use crate::elements::Element;
use crate::lagrange;
use crate::model::arc::Arc;
use crate::model::{ElementKind, Model};
use nalgebra::{Matrix3, Vector3};

/// The solver element of a model's beam whose nodes (dense indices, along the axis) are
/// `nodes`: the two-node [`super::beam::Beam`] for two nodes (fast path; an `ARC` beam of
/// order 1 is a chord of its arc), a [`BeamP`] of order `nodes.len() − 1` otherwise, with
/// the nodes at the GLL points and reference triads along the straight or curved axis:
/// `t₁` the unit tangent (chord direction, or the arc's tangent at the node), `t₂` the
/// `AXIS2` direction made normal to `t₁` (default: [`super::beam::default_axis2`] of the
/// chord, or the normal of the arc's plane), `t₃ = t₁ × t₂`.
pub fn from_model(
    model: &Model,
    el: &crate::model::Element,
    nodes: Vec<usize>,
) -> Box<dyn Element> {
    let ElementKind::Beam {
        material, section, ..
    } = &el.kind
    else {
        unreachable!("from_model is called on beams only")
    };
    let (props, eta) = model.beam_properties(*material, *section);
    with_properties(model, el, nodes, props, eta)
}

/// [`from_model`] with the given properties and damping coefficient `eta` (s; the
/// rigid bar of [`crate::elements::rigid_bar`] passes zero stiffness).
pub fn with_properties(
    model: &Model,
    el: &crate::model::Element,
    nodes: Vec<usize>,
    props: BeamProperties,
    eta: f64,
) -> Box<dyn Element> {
    let ElementKind::Beam { axis2, arc, .. } = &el.kind else {
        unreachable!("from_model is called on beams only")
    };
    let x0: Vec<Vector3<f64>> = nodes.iter().map(|&i| model.nodes[i].position).collect();
    let (xa, xb) = (x0[0], x0[x0.len() - 1]);
    // A damped two-node beam is the order-1 `BeamP` (the same element: tested equal in
    // `beam_p_tests.rs`), which carries the damping (`beam_p/damping.rs`).
    if nodes.len() == 2 && eta == 0.0 {
        return Box::new(Beam::new(
            el.id,
            [nodes[0], nodes[1]],
            &xa,
            &xb,
            *axis2,
            props,
        ));
    }
    // Two nodes: the chord of an `ARC` (as the two-node beam).
    let curved = arc
        .filter(|_| nodes.len() > 2)
        .and_then(|c| Arc::new(&xa, &xb, &c).ok());
    let triads: Vec<Matrix3<f64>> = x0
        .iter()
        .map(|x| match &curved {
            Some(a) => {
                let t1 = a.tangent_at(x);
                let ax = axis2.unwrap_or_else(|| a.normal());
                let t2 = (ax - t1 * t1.dot(&ax)).normalize();
                Matrix3::from_columns(&[t1, t2, t1.cross(&t2)])
            }
            None => reference_triad(
                &xa,
                &xb,
                &axis2.unwrap_or_else(|| default_axis2(&(xb - xa))),
            ),
        })
        .collect();
    let (xi, _) = lagrange::gll(nodes.len() - 1);
    Box::new(BeamP::new(el.id, nodes, &xi, &x0, &triads, props).with_damping(eta))
}
