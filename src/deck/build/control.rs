//! Stage 2, ELEMENTS: `PID`, a controlled torque on a HINGE, and `CONTROL`, a torque on a
//! HINGE or a force on a node whose value is an expression of the time and of sensors
//! (issue 36 §6; [`crate::model::control`]).

use super::cursor::*;
use super::*;
use crate::model::control::{Actuator, ControlData, ControlLaw, Pid, Sensor};
use crate::model::{Analysis, TimeExpr};

/// What the card gives to the element loop: its nodes (the hinge's, resolved later) and kind.
type Parsed = (Vec<(u32, Span)>, ElementKind);

impl Builder<'_> {
    /// `PID <hinge> KP kp [KI ki] [KD kd] TARGET <function> [AMPLITUDE a]`: the torque
    /// `k_p e + k_i ∫e + k_d ė` about the hinge's axis, `e = a f(t) − θ`; the function must
    /// have exact derivatives (`ė` reads `ḟ`). The hinge is resolved after ELEMENTS.
    pub(super) fn pid_card(&mut self, c: &mut Cursor<'_, '_>, id: u32) -> R<Parsed> {
        let (hinge, hs) = c.uint("HINGE element number")?;
        const KW: [&str; 5] = ["KP", "KI", "KD", "TARGET", "AMPLITUDE"];
        let mut seen = Seen::default();
        let mut pid = Pid {
            kp: 0.0,
            ki: 0.0,
            kd: 0.0,
            target: crate::model::FunctionId(0),
            amplitude: 1.0,
        };
        let mut target = None;
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "KP" => {
                    pid.kp = c.number_in("KP (proportional gain)", ">= 0 N·m/rad", |v| v >= 0.0)?
                }
                "KI" => {
                    pid.ki =
                        c.number_in("KI (integral gain)", ">= 0 N·m/(rad·s)", |v| v >= 0.0)?
                }
                "KD" => {
                    pid.kd =
                        c.number_in("KD (derivative gain)", ">= 0 N·m·s/rad", |v| v >= 0.0)?
                }
                "AMPLITUDE" => {
                    pid.amplitude = c.number("AMPLITUDE (factor a of the target a·f(t))")?.0
                }
                _ => {
                    let (f, fs) = c.uint("the target's function number")?;
                    let function = self.function_ref(f, fs)?;
                    if !self.functions[&function].function.has_derivatives() {
                        return Err(DeckError::new(
                            K::BadDrive {
                                context: c.ctx.clone(),
                                reason: format!(
                                    "function {f} has no derivatives (a TABLE is piecewise \
                                     linear); a PID's derivative term reads the target's rate"
                                ),
                            },
                            fs,
                        ));
                    }
                    target = Some(function);
                }
            }
        }
        let Some(target) = target else {
            return Err(c.missing("TARGET <function> (the PID's target)"));
        };
        pid.target = target;
        self.hinge_refs.push((ElementId(id), hinge, hs));
        let h = ElementId(hinge);
        Ok((
            Vec::new(),
            ElementKind::Control(Box::new(ControlData {
                actuator: Actuator::HingeTorque(h),
                sensors: vec![Sensor::HingeAngle(h), Sensor::HingeRate(h)],
                law: ControlLaw::Pid(pid),
            })),
        ))
    }
}

impl Builder<'_> {
    /// `CONTROL TORQUE <hinge> LAW <expr>` or `CONTROL FORCE <node> X|Y|Z LAW <expr>`: a
    /// torque about the HINGE's axis (N·m) or a force on the node along the global axis
    /// (N) of value `<expr>`, an expression of `t` and of sensors (deck/expr.rs
    /// `parse_law`). Hinges (the actuator's, the sensors') are resolved after ELEMENTS,
    /// nodes here.
    pub(super) fn control_card(&mut self, c: &mut Cursor<'_, '_>, id: u32) -> R<Parsed> {
        let (what, _) =
            c.expect_keyword(&["TORQUE", "FORCE"], "TORQUE <hinge> or FORCE <node> X|Y|Z")?;
        let actuator = if what == "TORQUE" {
            let (h, hs) = c.uint("HINGE element number")?;
            self.hinge_refs.push((ElementId(id), h, hs));
            Actuator::HingeTorque(ElementId(h))
        } else {
            let (n, ns) = c.uint("node number")?;
            let node = self.node_ref(n, ns)?;
            let (axis, _) =
                c.expect_keyword(&["X", "Y", "Z"], "the force's direction X, Y or Z")?;
            Actuator::NodeForce(
                node,
                ["X", "Y", "Z"].iter().position(|a| *a == axis).unwrap_or(0),
            )
        };
        c.expect_keyword(&["LAW"], "LAW <expression of t and sensors>")?;
        let tok = c.next("the law: an expression of t and sensors")?;
        c.finish()?;
        let (expr, refs) = super::super::params::law_expression(tok, &self.parameters)?;
        let mut sensors = Vec::with_capacity(refs.len());
        for (sensor, at) in refs {
            let start = tok.span.start + at.start as usize;
            let span = Span::new(start, (start + at.len as usize).min(tok.span.end));
            match sensor {
                Sensor::HingeAngle(h) | Sensor::HingeRate(h) => {
                    self.hinge_refs.push((ElementId(id), h.0, span));
                }
                Sensor::Coordinate(n, _) | Sensor::Velocity(n, _) => {
                    self.node_ref(n.0, span)?;
                }
            }
            sensors.push(sensor);
        }
        Ok((
            Vec::new(),
            ElementKind::Control(Box::new(ControlData {
                actuator,
                sensors,
                law: ControlLaw::Expr(TimeExpr {
                    text: tok.text.to_string(),
                    expr,
                    field: tok.span,
                }),
            })),
        ))
    }

    /// Every CONTROL law shown finite, with its sensors at their values in the deck's
    /// drawing at rest (angles and rates 0, coordinates the NODES', velocities 0), on
    /// `t` in `[0, END + H/100]` (`[0, 1]` static) by interval arithmetic, and its
    /// derivatives with respect to the sensors finite there at t = 0; an error is located
    /// at the innermost part of the expression that is not. Elsewhere (a state the run
    /// reaches) a law that is not finite refuses the step, and the run fails with the
    /// diagnosis, never a NaN in a file.
    pub(super) fn check_controls(&mut self, analysis: &Analysis) {
        let end = match analysis {
            Analysis::Dynamic { end, max_step, .. } => end + 0.01 * max_step,
            Analysis::Static { .. } => 1.0,
        };
        let mut errors = Vec::new();
        for (id, e) in &self.elements {
            let ElementKind::Control(d) = &e.kind else {
                continue;
            };
            let ControlLaw::Expr(law) = &d.law else {
                continue;
            };
            let s0: Vec<f64> = d
                .sensors
                .iter()
                .map(|s| match *s {
                    Sensor::Coordinate(n, a) => self.nodes.get(&n).map_or(0.0, |n| n.position[a]),
                    _ => 0.0,
                })
                .collect();
            let fixed = law.expr.with_sensors(&s0);
            let blowup = fixed.prove_finite(0.0, end.max(0.0), 0).err();
            let mut grad = vec![0.0; s0.len()];
            let u = law.expr.law(0.0, &s0, Some(&mut grad));
            if let Some(b) = blowup {
                errors.push(super::functions::law_not_finite(id.0, law, (0.0, end), &b));
            } else if !u.is_finite() || grad.iter().any(|g| !g.is_finite()) {
                errors.push(DeckError::new(
                    K::BadDrive {
                        context: format!("element {} (CONTROL)", id.0),
                        reason: format!(
                            "the law {} has a derivative with respect to a sensor that is not finite at the deck's drawing at rest (t = 0): its tangent cannot be formed",
                            law.text
                        ),
                    },
                    law.field,
                ));
            }
        }
        self.errors.extend(errors);
    }
}
