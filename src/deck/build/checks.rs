//! Model-level checks that the elements would otherwise make when they are built, made
//! here where the card's spans are known so that each error points at its field (issue 28
//! §5): a joint or CAME on one node twice, CAME profiles that cannot touch, SPLINE points
//! that coincide. The elements keep their own checks as a second line.

use super::*;
use crate::model::Profile;

/// A joint, RIGID or CAME that names one node twice: located at the second mention.
pub(super) fn same_node(keyword: &'static str, element: u32, nodes: &[(u32, Span)]) -> R<()> {
    for (i, (n, span)) in nodes.iter().enumerate() {
        if nodes[..i].iter().any(|(m, _)| m == n) {
            return Err(DeckError::new(
                K::NodeToItself {
                    keyword,
                    element,
                    node: *n,
                },
                *span,
            ));
        }
    }
    Ok(())
}

/// The profile pairs a CAME supports (as `elements::came::Came::new` decides): a POINT or
/// a CIRCLE on one side, and not two POINTs. Located at the FOLLOWER keyword.
pub(super) fn came_profiles(element: u32, cam: &Profile, fol: &Profile, at: Span) -> R<()> {
    let roller = |p: &Profile| matches!(p, Profile::Point | Profile::Circle { .. });
    let reason = match (cam, fol) {
        (Profile::Point, Profile::Point) => {
            "a POINT cam and a POINT follower never touch: give one of them as a LINE, CIRCLE or SPLINE"
        }
        (c, f) if !roller(c) && !roller(f) => {
            "CAME needs a POINT or a CIRCLE on one side (curve against curve is not supported): make the follower a POINT or a CIRCLE (roller)"
        }
        _ => return Ok(()),
    };
    Err(DeckError::new(K::CameProfiles { element, reason }, at))
}

/// SPLINE points as `elements::profile::Spline::new` needs them: no two consecutive
/// points equal (nor the last and the first of a CLOSED one, unless the last repeats the
/// first to close the curve). Located at the repeated point.
pub(super) fn spline_points(points: &[[f64; 2]], spans: &[Span], closed: bool) -> R<()> {
    let mut n = points.len();
    if closed && n > 1 && points[0] == points[n - 1] {
        n -= 1; // the closing repetition
    }
    let pairs = (1..n).map(|i| (i - 1, i));
    let wrap = (closed && n > 1).then_some((n - 1, 0));
    for (a, b) in pairs.chain(wrap) {
        if points[a] == points[b] {
            let (index, previous) = if b == 0 { (a + 1, 1) } else { (b + 1, a + 1) };
            let span = if b == 0 { spans[a] } else { spans[b] };
            return Err(DeckError::new(
                K::SplinePointsCoincide { index, previous },
                span,
            ));
        }
    }
    if n < 2 || (closed && n < 3) {
        let at = spans.get(n).or(spans.last()).copied().unwrap_or_default();
        return Err(DeckError::new(
            K::SplinePointsCoincide {
                index: n + 1,
                previous: 1,
            },
            at,
        ));
    }
    Ok(())
}
