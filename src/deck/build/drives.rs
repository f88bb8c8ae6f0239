//! Stage 2, drivers: `DRIVE <f> [AMPLITUDE a]` on a HINGE or PRISMATIC card, the
//! `PRESCRIBED` element, and the checks that no two drivers fight over one motion
//! (model/drive.rs).

use super::cursor::*;
use super::*;
use crate::model::{Drive, NodeMotion};

/// The joints a `DRIVE` cannot take, and why.
const NOT_DRIVABLE: &str = "only a HINGE (its angle) or a PRISMATIC (its travel) can be driven: \
     this joint has no single relative motion to prescribe; prescribe a node's motion with a \
     PRESCRIBED element instead";

impl Builder<'_> {
    /// `DRIVE <function> [AMPLITUDE a]` at the cursor, if there: the function must exist
    /// and have exact derivatives (a driver needs `f, ḟ, f̈`).
    pub(super) fn drive_option(&self, c: &mut Cursor<'_, '_>) -> R<Option<Drive>> {
        let Some((_, ks)) = c.keyword(&["DRIVE"]) else {
            return Ok(None);
        };
        let drive = self.drive_value(c, ks)?;
        if let Some(t) = c.peek()
            && t.is_kw("DRIVE")
        {
            return Err(DeckError::new(
                K::BadDrive {
                    context: c.ctx.clone(),
                    reason: "a second DRIVE: one joint takes one driver (two would fight over \
                             one motion)"
                        .into(),
                },
                t.span,
            ));
        }
        Ok(Some(drive))
    }

    /// `<function> [AMPLITUDE a]` after `DRIVE` (at `ks`) or `FUNCTION`.
    fn drive_value(&self, c: &mut Cursor<'_, '_>, ks: Span) -> R<Drive> {
        let (f, fs) = c.uint("the driver's function number")?;
        let function = self.function_ref(f, fs)?;
        if !self.functions[&function].function.has_derivatives() {
            return Err(DeckError::new(
                K::BadDrive {
                    context: c.ctx.clone(),
                    reason: format!(
                        "function {f} has no derivatives (a TABLE is piecewise linear: its \
                         velocity jumps and its acceleration is impulsive); a driver needs a \
                         function with exact first and second derivatives"
                    ),
                },
                fs,
            ));
        }
        let mut amplitude = 1.0;
        if c.keyword(&["AMPLITUDE"]).is_some() {
            amplitude = c.number("AMPLITUDE (factor a of a·f(t))")?.0;
        }
        // A law that does not start at 0 (the deck's geometry) is met before the first
        // step: the solver's assembly moves the mechanism there (solver::assembly).
        Ok(Drive {
            function,
            amplitude,
            span: Span::new(ks.start, fs.end),
        })
    }

    /// A `DRIVE` on a joint that cannot take one (UJOINT, SPHERICAL, CLAMP, RIGID).
    pub(super) fn refuse_drive(c: &Cursor<'_, '_>) -> R<()> {
        match c.toks[c.pos..].iter().find(|t| t.is_kw("DRIVE")) {
            Some(t) => Err(DeckError::new(
                K::BadDrive {
                    context: c.ctx.clone(),
                    reason: NOT_DRIVABLE.into(),
                },
                t.span,
            )),
            None => Ok(()),
        }
    }

    /// `<id> PRESCRIBED <node> X|Y|Z FUNCTION <f> [AMPLITUDE a]` or
    /// `<id> PRESCRIBED <node> ROTATION AXIS <x> <y> <z> FUNCTION <f> [AMPLITUDE a]`, after
    /// the type keyword: the node and the element kind. A node's fixed degree of freedom,
    /// or one another `PRESCRIBED` already sets, is refused.
    pub(super) fn prescribed(&self, c: &mut Cursor<'_, '_>) -> R<((u32, Span), ElementKind)> {
        let n = c.uint("node number")?;
        let node = self.node_ref(n.0, n.1)?;
        let (kw, ks) = c.expect_keyword(&["X", "Y", "Z", "ROTATION"], "X, Y, Z or ROTATION")?;
        let motion = match kw {
            "X" => NodeMotion::Displacement(0),
            "Y" => NodeMotion::Displacement(1),
            "Z" => NodeMotion::Displacement(2),
            _ => {
                c.expect_keyword(&["AXIS"], "AXIS <x> <y> <z>")?;
                let (axis, _, _) = c.axis("PRESCRIBED ROTATION AXIS")?;
                NodeMotion::Rotation(axis)
            }
        };
        let (_, fk) = c.expect_keyword(&["FUNCTION"], "FUNCTION <function number>")?;
        let drive = self.drive_value(c, fk)?;
        c.finish()?;
        let fight = |reason: String| {
            DeckError::new(
                K::BadDrive {
                    context: c.ctx.clone(),
                    reason,
                },
                Span::new(n.1.start, ks.end),
            )
        };
        let dofs = |m: &NodeMotion| match m {
            NodeMotion::Displacement(i) => *i..*i + 1,
            NodeMotion::Rotation(_) => 3..6,
        };
        const NAMES: [&str; 6] = ["X", "Y", "Z", "RX", "RY", "RZ"];
        if let Some(k) = dofs(&motion).find(|&k| self.nodes[&node].fixed[k]) {
            return Err(fight(format!(
                "node {} is fixed in {}: a fixed degree of freedom cannot also be prescribed",
                n.0, NAMES[k]
            )));
        }
        for other in self.elements.values() {
            if let ElementKind::Prescribed { motion: m, .. } = &other.kind
                && other.nodes[0] == node
                && dofs(m).any(|k| dofs(&motion).contains(&k))
            {
                return Err(fight(format!(
                    "element {} already prescribes this motion of node {} (line {}): two \
                     drivers would fight over it",
                    other.id.0,
                    n.0,
                    self.line(other.span)
                )));
            }
        }
        Ok((n, ElementKind::Prescribed { motion, drive }))
    }
}

impl Builder<'_> {
    /// A driven HINGE or PRISMATIC and a `PRESCRIBED` node motion that set the same motion
    /// twice: the drive fixes its joint's whole relative rotation (HINGE: two blocked
    /// components and the driven angle) or relative translation (PRISMATIC); a
    /// `PRESCRIBED` rotation (translation component) of one of its nodes, when the other
    /// node's rotation (that component) is fixed or prescribed too, sets it again — the
    /// two equations are redundant and, unless their laws agree exactly, contradictory.
    /// Refused at the `PRESCRIBED` card (called once every element is read, so the cards'
    /// order does not matter).
    pub(super) fn check_drive_fights(&mut self) {
        let mut errors = Vec::new();
        let prescribed: Vec<(&Element, &NodeMotion)> = self
            .elements
            .values()
            .filter_map(|e| match &e.kind {
                ElementKind::Prescribed { motion, .. } => Some((e, motion)),
                _ => None,
            })
            .collect();
        // Is node `n`'s motion of the kind of `m` held by a fixity or another PRESCRIBED?
        let held = |n: NodeId, m: &NodeMotion, not: ElementId| -> bool {
            let fixed = self.nodes.get(&n).map_or([false; 6], |nd| nd.fixed);
            match m {
                NodeMotion::Rotation(_) => {
                    fixed[3..6].iter().all(|&f| f)
                        || prescribed.iter().any(|(e, mm)| {
                            e.id != not && e.nodes[0] == n && matches!(mm, NodeMotion::Rotation(_))
                        })
                }
                NodeMotion::Displacement(i) => {
                    fixed[*i]
                        || prescribed.iter().any(|(e, mm)| {
                            e.id != not
                                && e.nodes[0] == n
                                && matches!(mm, NodeMotion::Displacement(j) if j == i)
                        })
                }
            }
        };
        for (jid, _) in self.drives.iter() {
            let Some(joint) = self.elements.get(jid) else {
                continue;
            };
            let rotation = match joint.kind {
                ElementKind::Hinge { .. } => true,
                ElementKind::Prismatic { .. } => false,
                _ => continue,
            };
            for (p, m) in &prescribed {
                if matches!(m, NodeMotion::Rotation(_)) != rotation {
                    continue;
                }
                let node = p.nodes[0];
                let other = match joint.nodes.as_slice() {
                    [a, b] if *a == node => *b,
                    [a, b] if *b == node => *a,
                    _ => continue,
                };
                if !held(other, m, p.id) {
                    continue;
                }
                let what = if rotation { "rotation" } else { "translation" };
                errors.push(DeckError::new(
                    K::BadDrive {
                        context: format!("element {} (PRESCRIBED)", p.id.0),
                        reason: format!(
                            "the driven {} {} (line {}) already sets the relative {what} of \
                             nodes {} and {}, and node {}'s {what} is fixed or prescribed: two \
                             drivers would fight over one motion; drop the PRESCRIBED element \
                             or the DRIVE",
                            joint.kind.keyword(),
                            jid.0,
                            self.line(joint.span),
                            joint.nodes[0].0,
                            joint.nodes[1].0,
                            other.0
                        ),
                    },
                    p.span,
                ));
            }
        }
        self.errors.extend(errors);
    }
}
