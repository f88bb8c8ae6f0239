//! Stage 2, ELEMENTS: `PID`, a controlled torque on a HINGE (issue 36 §6;
//! [`crate::model::control`]).

use super::cursor::*;
use super::*;
use crate::model::control::{Actuator, ControlData, ControlLaw, Pid, Sensor};

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
