//! What a model declares: counts and active effects (`mecano-rs --check`).

use super::{Analysis, ElementKind, Model};
use std::collections::BTreeMap;
use std::fmt;

/// The physical effects a deck declares. Anything not listed here is not computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Effects {
    /// A GRAVITY card is present.
    pub gravity: bool,
    /// At least one nodal FORCE or MOMENT.
    pub applied_loads: bool,
    /// At least one MASS element.
    pub point_masses: bool,
    /// At least one CAME element.
    pub contact: bool,
    /// A CAME with μ > 0.
    pub friction: bool,
    /// A material with non-zero damping.
    pub material_damping: bool,
    /// At least one flexible BEAM.
    pub flexible_beams: bool,
    /// At least one rigid bar or RIGID body.
    pub rigid_bodies: bool,
    /// At least one kinematic joint.
    pub joints: bool,
}

impl Effects {
    /// Names of the active effects, in a fixed order.
    pub fn names(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        let list = [
            (self.gravity, "gravity"),
            (self.applied_loads, "applied loads"),
            (self.point_masses, "point masses"),
            (self.contact, "contact"),
            (self.friction, "friction"),
            (self.material_damping, "material damping"),
            (self.flexible_beams, "flexible beams"),
            (self.rigid_bodies, "rigid bodies"),
            (self.joints, "joints"),
        ];
        for (on, name) in list {
            if on {
                v.push(name);
            }
        }
        v
    }
}

/// Counts and effects of a model.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Summary {
    /// Title.
    pub title: String,
    /// Number of nodes.
    pub nodes: usize,
    /// Number of elements by type keyword.
    pub elements: BTreeMap<&'static str, usize>,
    /// Free nodal degrees of freedom (6 per node minus fixed ones).
    pub dofs: usize,
    /// Constraint equations (Lagrange multipliers) from joints.
    pub constraints: usize,
    /// Active effects.
    pub effects: Effects,
    /// "dynamic" or "static".
    pub analysis: &'static str,
}

impl Model {
    /// The effects this model declares.
    pub fn effects(&self) -> Effects {
        let mut e = Effects {
            gravity: self.gravity.is_some(),
            applied_loads: !self.loads.is_empty(),
            ..Effects::default()
        };
        for el in self.elements.values() {
            match &el.kind {
                ElementKind::Mass { .. } => e.point_masses = true,
                ElementKind::Came(c) => {
                    e.contact = true;
                    e.friction |= c.friction > 0.0;
                }
                ElementKind::Beam {
                    material, section, ..
                } => {
                    let rigid = self.sections.get(section).is_some_and(|s| s.rigid);
                    if rigid {
                        e.rigid_bodies = true;
                    } else {
                        e.flexible_beams = true;
                        e.material_damping |= self
                            .materials
                            .get(material)
                            .is_some_and(|m| m.damping > 0.0);
                    }
                }
                ElementKind::Rigid => e.rigid_bodies = true,
                ElementKind::Hinge { .. }
                | ElementKind::UJoint { .. }
                | ElementKind::Spherical
                | ElementKind::Clamp
                | ElementKind::Prismatic { .. } => e.joints = true,
            }
        }
        e
    }

    /// Counts of nodes, elements, degrees of freedom and constraints, and the effects.
    pub fn summary(&self) -> Summary {
        let mut elements = BTreeMap::new();
        let mut constraints = 0;
        for el in self.elements.values() {
            *elements.entry(el.kind.keyword()).or_insert(0) += 1;
            constraints += el.kind.constraint_count(el.nodes.len());
        }
        let dofs = self
            .nodes
            .values()
            .map(|n| n.fixed.iter().filter(|f| !**f).count())
            .sum();
        Summary {
            title: self.title.clone(),
            nodes: self.nodes.len(),
            elements,
            dofs,
            constraints,
            effects: self.effects(),
            analysis: match self.analysis {
                Analysis::Dynamic { .. } => "dynamic",
                Analysis::Static { .. } => "static",
            },
        }
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "title:       {}", self.title)?;
        writeln!(f, "analysis:    {}", self.analysis)?;
        writeln!(f, "nodes:       {}", self.nodes)?;
        let total: usize = self.elements.values().sum();
        let parts: Vec<String> = self
            .elements
            .iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect();
        writeln!(f, "elements:    {total} ({})", parts.join(", "))?;
        writeln!(
            f,
            "dofs:        {} free nodal degrees of freedom",
            self.dofs
        )?;
        writeln!(f, "constraints: {} equations", self.constraints)?;
        let eff = self.effects.names();
        writeln!(
            f,
            "effects:     {}",
            if eff.is_empty() {
                "none".to_string()
            } else {
                eff.join(", ")
            }
        )
    }
}
