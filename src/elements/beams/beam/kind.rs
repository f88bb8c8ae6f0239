//! The element half of `BEAM` (`crate::kinds`): an elastic section builds the beam of
//! order p ([`super::beam_p`]), a `RIGID` one the rigid bar ([`super::rigid_bar`]).

use super::{beam_p, rigid_bar};
use crate::elements::registry::{Kind, node_index, not_mine};
use crate::elements::{BuildError, Element};
use crate::model::{self, ElementKind, Model};

/// The element half of `BEAM`.
pub const KIND: Kind = Kind {
    types: &["BEAM"],
    build,
};

fn build(model: &Model, el: &model::Element) -> Result<Box<dyn Element>, BuildError> {
    let ElementKind::Beam { section, order, .. } = &el.kind else {
        return Err(not_mine(el, "BEAM"));
    };
    let Some(sec) = model.sections.get(section) else {
        return Err(BuildError::Invalid {
            element: el.id,
            message: format!("section {} is not defined", section.0),
        });
    };
    let nodes: Vec<usize> = el.nodes.iter().map(|n| node_index(model, n)).collect();
    if *order as usize > beam_p::MAX_ORDER
        || (nodes.len() != 2 && nodes.len() != *order as usize + 1)
    {
        return Err(BuildError::Invalid {
            element: el.id,
            message: format!(
                "a beam of order {order} (at most {}) needs 2 or {} nodes, it has {}",
                beam_p::MAX_ORDER,
                order + 1,
                nodes.len()
            ),
        });
    }
    if sec.rigid {
        Ok(Box::new(rigid_bar::RigidBar::from_model(model, el, nodes)?))
    } else {
        Ok(beam_p::from_model(model, el, nodes))
    }
}
