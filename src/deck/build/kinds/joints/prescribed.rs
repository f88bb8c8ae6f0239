//! `PRESCRIBED <node> (X|Y|Z|ROTATION AXIS <x> <y> <z>) FUNCTION <f> [AMPLITUDE a]`: a
//! node's displacement or rotation driven in time. Its reader stays in `build/drives.rs`
//! beside the checks HINGE's `DRIVE` shares (a fixed or already driven freedom refused).

use super::super::v3;
use super::super::{Card, Parse, node_list, row};
use crate::model::{ElementKind, NodeMotion};
use std::fmt::Write;

/// The deck half of `PRESCRIBED`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["PRESCRIBED"],
    rows: &[
        row(
            "PRESCRIBED",
            "a node's displacement component (X, Y, Z) or rotation about a fixed axis prescribed as a·f(t)",
        ),
        row(
            "ROTATION",
            "PRESCRIBED: the node's rotation about a fixed global axis",
        ),
    ],
    parse: Parse::One(|b, c, _, _| {
        let (n, kind) = b.prescribed(c)?;
        Ok((vec![n], kind))
    }),
    write: |_, e, s| {
        s.push_str(&node_list(e));
        let ElementKind::Prescribed { motion, drive } = &e.kind else {
            return;
        };
        match motion {
            NodeMotion::Displacement(i) => {
                let _ = write!(s, " {}", ["X", "Y", "Z"][*i]);
            }
            NodeMotion::Rotation(a) => {
                let _ = write!(s, " ROTATION AXIS {}", v3(a));
            }
        }
        let _ = write!(
            s,
            " FUNCTION {} AMPLITUDE {:?}",
            drive.function.0, drive.amplitude
        );
    },
};
