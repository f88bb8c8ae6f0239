//! `PID <hinge> KP … TARGET <f> [AMPLITUDE a]` and `CONTROL (TORQUE <hinge> | FORCE <node>
//! <X|Y|Z>) LAW <expression>`: a controlled input (issue 36). Their readers stay in
//! `build/control.rs` beside the sensors and laws they share.

use super::super::{Card, Parse, row};
use crate::model::ElementKind;
use crate::model::control::{Actuator, ControlLaw};
use std::fmt::Write;

/// The deck half of `PID` and `CONTROL`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["PID", "CONTROL"],
    rows: &[
        row(
            "PID",
            "PID controller: a torque on a HINGE element from its angle's error to a target a·f(t)",
        ),
        row("KP", "PID: proportional gain, N·m/rad (>= 0)"),
        row("KI", "PID: integral gain, N·m/(rad·s) (>= 0)"),
        row("KD", "PID: derivative gain, N·m·s/rad (>= 0)"),
        row(
            "TARGET",
            "PID: function number of the target angle f(t) (exact derivatives; AMPLITUDE a scales it)",
        ),
        row(
            "CONTROL",
            "controlled input: a torque on a HINGE (TORQUE) or a force on a node (FORCE) whose LAW is an expression of t and sensors",
        ),
        row(
            "TORQUE",
            "CONTROL: the input is a torque about the axis of the HINGE element that follows, N·m",
        ),
    ],
    parse: Parse::One(|b, c, id, ty| {
        if ty == "PID" {
            b.pid_card(c, id)
        } else {
            b.control_card(c, id)
        }
    }),
    write: |_, e, s| {
        let ElementKind::Control(c) = &e.kind else {
            return;
        };
        // Its nodes are its actuator's and sensors': the card names the actuator.
        let _ = match (c.actuator, &c.law) {
            (Actuator::HingeTorque(h), ControlLaw::Pid(_)) => write!(s, "{}", h.0),
            (Actuator::HingeTorque(h), _) => write!(s, "TORQUE {}", h.0),
            (Actuator::NodeForce(n, a), _) => {
                write!(s, "FORCE {} {}", n.0, ["X", "Y", "Z"][a.min(2)])
            }
        };
        match &c.law {
            ControlLaw::Pid(p) => {
                let _ = write!(
                    s,
                    " KP {:?} KI {:?} KD {:?} TARGET {} AMPLITUDE {:?}",
                    p.kp, p.ki, p.kd, p.target.0, p.amplitude
                );
            }
            ControlLaw::Expr(e) => {
                let _ = write!(s, " LAW {}", e.text);
            }
            _ => {}
        }
    },
};
