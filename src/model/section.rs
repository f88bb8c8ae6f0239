//! Beam cross-sections and the per-unit-length properties the beam elements consume.
//!
//! A section is given either by its **geometry** (A, I₂, I₃, J, k), its stiffness and
//! inertia then following from the beam's material (E, G, ρ), or directly by its
//! **properties per unit length** (EA, GA₂, GA₃, GJ, EI₂, EI₃, ρA, ρJ, ρI₂, ρI₃), as
//! BeamDyn and MBDyn accept them (a section's data in the literature is often given so,
//! with inertias no material and geometry can produce: the right-angle cantilever of Simo
//! & Vu-Quoc 1988 has EI = 10³, ρI = 10, ρJ = 20, ρA = 1). Both resolve into one
//! [`BeamProperties`] ([`Section::properties`]); the elements read only that.
//!
//! The properties form is the diagonal of the 6 × 6 sectional stiffness and mass matrices
//! in the section's principal axes with the centroid, shear centre and centre of mass on
//! the beam's axis: off-diagonal couplings and offsets (BeamDyn's full matrices, MBDyn's
//! centre-of-mass offset) are not accepted.

use super::{Material, SectionId, Span};
use nalgebra::Vector3;

/// Stiffness and inertia of a beam per unit length: the diagonal sectional matrices
/// `C_N = diag(EA, GA₂, GA₃)`, `C_M = diag(GJ, EI₂, EI₃)` of the resultants
/// `N = C_N Γ`, `M = C_M K` (physics.md §2, paper eqs. [5]–[9]), the mass `ρA` and the
/// rotary inertia `diag(ρJ, ρI₂, ρI₃)` (paper eqs. [10]–[11]), all in the section's local
/// axes (1 along the beam).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamProperties {
    /// `(EA, GA₂, GA₃)`, N (GA with the shear correction factor included).
    pub cn: Vector3<f64>,
    /// `(GJ, EI₂, EI₃)`, N·m².
    pub cm: Vector3<f64>,
    /// Mass per unit length `ρA`, kg/m.
    pub mass: f64,
    /// Rotary inertia per unit length `(ρJ, ρI₂, ρI₃)`, kg·m.
    pub inertia: Vector3<f64>,
}

/// A section's geometry; the stiffness and inertia follow from the beam's material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Area A, m².
    pub area: f64,
    /// Second moment about local axis 2, I2, m⁴.
    pub i2: f64,
    /// Second moment about local axis 3, I3, m⁴.
    pub i3: f64,
    /// Torsion constant J, m⁴.
    pub torsion: f64,
    /// Shear correction factor k (default 5/6).
    pub shear_factor: f64,
}

impl Geometry {
    /// The properties of this geometry in material `mat`:
    /// `C_N = (EA, kGA, kGA)`, `C_M = (GJ, EI₂, EI₃)`, `ρA`, `ρ(I₂ + I₃, I₂, I₃)`
    /// (the polar moment of the rotary inertia is `I₂ + I₃`, not the torsion constant).
    pub fn properties(&self, mat: &Material) -> BeamProperties {
        BeamProperties {
            cn: Vector3::new(
                mat.young * self.area,
                self.shear_factor * mat.shear * self.area,
                self.shear_factor * mat.shear * self.area,
            ),
            cm: Vector3::new(
                mat.shear * self.torsion,
                mat.young * self.i2,
                mat.young * self.i3,
            ),
            mass: mat.density * self.area,
            inertia: Vector3::new(self.i2 + self.i3, self.i2, self.i3) * mat.density,
        }
    }
}

/// How a section is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SectionData {
    /// By its geometry (`A I2 I3 J K`): the beam names a material (`MAT`).
    Geometry(Geometry),
    /// By its properties per unit length (`PROPERTIES EA … RHOI3`): the beam names no
    /// material. A rigid section's stiffness entries are zero.
    Properties {
        /// The properties.
        props: BeamProperties,
        /// Stiffness-proportional damping coefficient η, s (≥ 0; 0 = none): the
        /// `DAMPING` of a material, given on the section since there is no material.
        damping: f64,
    },
}

/// A beam cross-section.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// The user's number.
    pub id: SectionId,
    /// Geometry, or properties per unit length.
    pub data: SectionData,
    /// A rigid section: the bar keeps its shape (its stiffness is not used).
    pub rigid: bool,
    /// Where the section was defined.
    pub span: Span,
}

impl Section {
    /// Whether a beam of this section names a material (`MAT`): the geometric sections.
    pub fn needs_material(&self) -> bool {
        matches!(self.data, SectionData::Geometry(_))
    }

    /// The geometry, for a section given so.
    pub fn geometry(&self) -> Option<&Geometry> {
        match &self.data {
            SectionData::Geometry(g) => Some(g),
            SectionData::Properties { .. } => None,
        }
    }

    /// The damping coefficient η (s) of a beam of this section and material `mat`: the
    /// material's `DAMPING` for a geometric section (0 without a material), the section's
    /// own for a section of properties.
    pub fn damping(&self, mat: Option<&Material>) -> f64 {
        match &self.data {
            SectionData::Properties { damping, .. } => *damping,
            SectionData::Geometry(_) => mat.map_or(0.0, |m| m.damping),
        }
    }

    /// The properties per unit length of a beam of this section and material `mat`
    /// (`None` for a properties section; a validated model gives a geometric section's
    /// beam a material), and its damping coefficient η (s): the material's `DAMPING` or
    /// the section's.
    ///
    /// # Panics
    /// For a geometric section without a material (a model the deck builder refuses).
    pub fn properties(&self, mat: Option<&Material>) -> (BeamProperties, f64) {
        match (&self.data, mat) {
            (SectionData::Properties { props, damping }, _) => (*props, *damping),
            (SectionData::Geometry(g), Some(m)) => (g.properties(m), m.damping),
            (SectionData::Geometry(_), None) => {
                panic!("{}: a geometric section needs a material", self.id)
            }
        }
    }
}

impl super::Model {
    /// The properties per unit length and damping coefficient η (s) of a beam of
    /// `material` and `section` ([`Section::properties`]).
    ///
    /// # Panics
    /// For ids the model does not hold, or a geometric section without a material: a
    /// validated model has neither.
    pub fn beam_properties(
        &self,
        material: Option<super::MaterialId>,
        section: SectionId,
    ) -> (BeamProperties, f64) {
        let mat = material.map(|m| &self.materials[&m]);
        self.sections[&section].properties(mat)
    }
}
