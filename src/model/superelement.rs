//! The data of a `SUPERELEMENT` (issue 38): a linear elastic body reduced from a
//! finite-element model (files in a directory, `crate::elements::superelement`), in a
//! floating frame attached to its first interface node.

use super::{Model, Node, NodeId, Numbering};
use std::path::{Path, PathBuf};

/// A superelement's deck data. The element's model nodes are its interface nodes (in
/// `interface`'s order, the frame node first) followed by its generated modal nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct SuperelementData {
    /// The directory of the FE model's files (`K.mtx`, `M.mtx`, `nodes.csv`, `dofs.csv`);
    /// relative to the deck's directory once the deck is loaded from a file.
    pub dir: PathBuf,
    /// Fixed-interface normal modes kept.
    pub modes: u32,
    /// FE node number of each interface node (the first: the frame node).
    pub interface: Vec<u32>,
    /// The generated modal nodes: their translations carry the elastic coordinates (6 per
    /// non-frame interface node, then the modal amplitudes), three per node.
    pub modal: Vec<NodeId>,
    /// Interfaces over many FE nodes (`RBE2`, `RBE3`), in the deck's order; each `node` is
    /// one of `interface`'s FE numbers.
    pub rbe: Vec<RbeSpec>,
    /// `CACHE ON` (the default): the reduction is kept beside the FE files and read back
    /// by the next run of the same inputs (`crate::elements::superelement::cache`).
    pub cache: bool,
}

/// Which interface over many FE nodes (`crate::elements::bodies::superelement::rbe`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RbeKind {
    /// `RBE2`: the set follows the interface node rigidly.
    Rigid,
    /// `RBE3`: the interface node follows the set's weighted least-squares rigid fit.
    Average,
}

/// The FE nodes an `RBE2`/`RBE3` joins.
#[derive(Debug, Clone, PartialEq)]
pub enum SetSpec {
    /// `SET`: FE node numbers.
    Nodes(Vec<u32>),
    /// `WITHIN r`: every FE node within `r` (m) of the interface node.
    Within(f64),
}

/// An `RBE2`/`RBE3` clause of a `SUPERELEMENT`.
#[derive(Debug, Clone, PartialEq)]
pub struct RbeSpec {
    /// Rigid or averaging.
    pub kind: RbeKind,
    /// The interface node's FE number (named in `INTERFACE`, not a node of the mesh).
    pub node: u32,
    /// Its FE nodes.
    pub set: SetSpec,
    /// `RBE3 … WEIGHTS`: one per set node (empty: all 1).
    pub weights: Vec<f64>,
}

impl SuperelementData {
    /// Number of elastic coordinates: `6 (interface nodes − 1) + modes`.
    pub fn elastic_coordinates(&self) -> usize {
        6 * self.interface.len().saturating_sub(1) + self.modes as usize
    }

    /// Number of modal nodes: `⌈coordinates / 3⌉`.
    pub fn modal_node_count(&self) -> usize {
        self.elastic_coordinates().div_ceil(3)
    }
}

impl Model {
    /// Generates the modal nodes of every superelement (numbered past every other node,
    /// at the origin, so that a modal node's position *is* its three elastic coordinates;
    /// rotations and unused translations fixed) and appends them to the element's nodes.
    pub fn add_modal_nodes(&mut self, numbering: &mut Numbering) -> Result<(), super::MeshError> {
        let ids: Vec<super::ElementId> = self
            .elements
            .values()
            .filter(|e| matches!(e.kind, super::ElementKind::Superelement(_)))
            .map(|e| e.id)
            .collect();
        for id in ids {
            let (count, coords, span) = match &self.elements[&id].kind {
                super::ElementKind::Superelement(d) => (
                    d.modal_node_count(),
                    d.elastic_coordinates(),
                    self.elements[&id].span,
                ),
                _ => continue,
            };
            let mut made = Vec::with_capacity(count);
            for j in 0..count {
                let node = numbering.node()?;
                let mut fixed = [true; 6];
                for (c, f) in fixed.iter_mut().take(3).enumerate() {
                    *f = 3 * j + c >= coords;
                }
                self.nodes.insert(
                    node,
                    Node {
                        id: node,
                        position: nalgebra::Vector3::zeros(),
                        fixed,
                        span,
                    },
                );
                made.push(node);
            }
            let el = &mut self.elements[&id];
            el.nodes.extend(&made);
            if let super::ElementKind::Superelement(d) = &mut el.kind {
                d.modal = made;
            }
        }
        Ok(())
    }

    /// Makes every superelement's relative directory relative to `base` (the deck's
    /// directory).
    pub fn resolve_superelement_dirs(&mut self, base: &Path) {
        for e in self.elements.values_mut() {
            if let super::ElementKind::Superelement(d) = &mut e.kind
                && d.dir.is_relative()
            {
                d.dir = base.join(&d.dir);
            }
        }
    }

    /// The generated modal nodes of every superelement.
    pub fn modal_nodes(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.elements.values().flat_map(|e| match &e.kind {
            super::ElementKind::Superelement(d) => d.modal.clone(),
            _ => Vec::new(),
        })
    }
}
