//! Forces: the spring family of issue 25 §3 — `SPRING`, `BUSHING`, `RSPRING`
//! (`spring::from_model` builds all three).

pub mod bushing;
pub mod control;
pub mod rspring;
pub mod spring;

use crate::elements::{BuildError, Element};
use crate::model::{self, ElementKind, Model};
use spring::Spring;

/// Builds a SPRING, BUSHING or RSPRING of the model (the spring family of issue 25 §3).
pub fn from_model(model: &Model, el: &model::Element) -> Result<Box<dyn Element>, BuildError> {
    let idx = |k: usize| {
        model
            .nodes
            .get_index_of(&el.nodes[k])
            .expect("validated model: nodes exist")
    };
    let (nodes, x0) = if el.nodes.len() == 2 {
        let n = [idx(0), idx(1)];
        (n, [model.nodes[n[0]].position, model.nodes[n[1]].position])
    } else {
        return Err(BuildError::Invalid {
            element: el.id,
            message: format!("{} joins exactly two nodes", el.kind.keyword()),
        });
    };
    Ok(match &el.kind {
        ElementKind::Spring(d) => {
            let curve = d.curve.map(|f| model.functions[&f].function.clone());
            Box::new(Spring::new(el.id, nodes, x0, d, curve)?)
        }
        ElementKind::Bushing(d) => Box::new(bushing::Bushing::new(el.id, nodes, x0, d)),
        ElementKind::RSpring(d) => Box::new(rspring::RSpring::new(el.id, nodes, d)),
        other => {
            return Err(BuildError::Invalid {
                element: el.id,
                message: format!("{} is not a spring", other.keyword()),
            });
        }
    })
}
