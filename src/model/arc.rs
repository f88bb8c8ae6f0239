//! A circular arc as a beam's reference axis (`ARC cx cy cz` on a BEAM card): the nodes of
//! a beam of order `p` placed on the arc, and the unit tangent there, so that a high-order
//! element represents a curved beam (the 45° bend of Bathe & Bolourchi 1979).
//!
//! The arc goes from the first end node `a` to the second `b` around the centre `c`, the
//! shorter way (angle `θ = ∠(a − c, b − c) ∈ (0, π)`), in the plane of `a`, `b`, `c` with
//! normal `n = (a − c) × (b − c)/|…|`. At the parametric position `s ∈ [0, 1]` (fraction of
//! the arc length) the point is `c + R (cos(sθ) e₁ + sin(sθ) e₂)`, `e₁ = (a − c)/R`,
//! `e₂ = n × e₁`, and the unit tangent `−sin(sθ) e₁ + cos(sθ) e₂`.

use nalgebra::Vector3;

/// A circular arc from `a` to `b` around a centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    centre: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    radius: f64,
    angle: f64,
}

/// Why three points do not make an arc.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ArcError {
    /// `|a − c|` and `|b − c|` differ by more than 1e-6 of the radius.
    #[error("the end nodes are at different distances from the centre ({0} and {1})")]
    Radii(f64, f64),
    /// The end nodes and the centre are (nearly) collinear: no plane, or a half circle
    /// whose direction is undefined.
    #[error("the end nodes and the centre are collinear (angle 0 or 180 degrees)")]
    Collinear,
}

impl Arc {
    /// The arc from `a` to `b` around `centre`.
    pub fn new(a: &Vector3<f64>, b: &Vector3<f64>, centre: &Vector3<f64>) -> Result<Arc, ArcError> {
        let (ra, rb) = (a - centre, b - centre);
        let (la, lb) = (ra.norm(), rb.norm());
        let equal = (la - lb).abs() <= 1e-6 * la.max(lb);
        if !equal || la == 0.0 || !la.is_finite() {
            return Err(ArcError::Radii(la, lb));
        }
        let n = ra.cross(&rb);
        if n.norm() <= 1e-9 * la * lb {
            return Err(ArcError::Collinear);
        }
        let n = n.normalize();
        let e1 = ra / la;
        let e2 = n.cross(&e1);
        let angle = rb.dot(&e2).atan2(rb.dot(&e1));
        Ok(Arc {
            centre: *centre,
            e1,
            e2,
            radius: la,
            angle,
        })
    }

    /// Point at the arc-length fraction `s`.
    pub fn point(&self, s: f64) -> Vector3<f64> {
        let t = s * self.angle;
        self.centre + (self.e1 * t.cos() + self.e2 * t.sin()) * self.radius
    }

    /// Unit tangent (from `a` towards `b`) at the arc-length fraction `s`.
    pub fn tangent(&self, s: f64) -> Vector3<f64> {
        let t = s * self.angle;
        self.e2 * t.cos() - self.e1 * t.sin()
    }

    /// Unit normal of the arc's plane, `(a − c) × (b − c)` normalised.
    pub fn normal(&self) -> Vector3<f64> {
        self.e1.cross(&self.e2)
    }

    /// Unit tangent at a point `x` of the arc's circle (in the sense from `a` to `b`).
    pub fn tangent_at(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.normal().cross(&(x - self.centre)).normalize()
    }

    /// Whether the direction `v` is parallel to the tangent somewhere on the arc: with
    /// `v = v₁e₁ + v₂e₂ + v₃n`, `v × t(φ) = (v₁ cos φ + v₂ sin φ) n + …` vanishes only if
    /// `v₃ = 0` (to 1e-6) and `φ ≡ atan2(−v₁, v₂) (mod π)` lies in `[0, θ]`.
    pub fn meets_tangent(&self, v: &Vector3<f64>) -> bool {
        let v = v.normalize();
        if v.dot(&self.normal()).abs() > 1e-6 {
            return false;
        }
        let phi = (-v.dot(&self.e1)).atan2(v.dot(&self.e2));
        let tol = 1e-6;
        [-1.0, 0.0, 1.0, 2.0]
            .iter()
            .map(|k| phi + k * std::f64::consts::PI)
            .any(|p| p >= -tol && p <= self.angle + tol)
    }

    /// Arc length.
    pub fn length(&self) -> f64 {
        self.radius * self.angle
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_eighth_of_a_circle() {
        let r = 100.0;
        let (a, c) = (Vector3::zeros(), Vector3::new(0.0, r, 0.0));
        let q = std::f64::consts::FRAC_PI_4;
        let b = Vector3::new(r * q.sin(), r * (1.0 - q.cos()), 0.0);
        let arc = Arc::new(&a, &b, &c).unwrap();
        assert!((arc.length() - r * q).abs() < 1e-12);
        assert!((arc.point(0.0) - a).norm() < 1e-12 && (arc.point(1.0) - b).norm() < 1e-12);
        assert!((arc.tangent(0.0) - Vector3::x()).norm() < 1e-15);
        let h = 0.5 * q;
        let mid = Vector3::new(r * h.sin(), r * (1.0 - h.cos()), 0.0);
        assert!((arc.point(0.5) - mid).norm() < 1e-12);
        assert!(!arc.meets_tangent(&Vector3::z()));
        assert!(arc.meets_tangent(&Vector3::new(1.0, 0.2, 0.0)));
        assert!(!arc.meets_tangent(&Vector3::y()));
        assert!((arc.tangent_at(&arc.point(0.3)) - arc.tangent(0.3)).norm() < 1e-15);
        assert_eq!(
            Arc::new(&a, &(b * 2.0), &c),
            Err(ArcError::Radii(r, (b * 2.0 - c).norm()))
        );
        assert_eq!(
            Arc::new(&a, &Vector3::new(0.0, 2.0 * r, 0.0), &c),
            Err(ArcError::Collinear)
        );
    }
}
