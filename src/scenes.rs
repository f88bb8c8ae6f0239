//! Decks built in code: the seed scene at any mesh size, for benchmarks, tests and studies.

use std::fmt::Write;

/// Settings of [`pendulum_deck`] besides the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PendulumSettings {
    /// Young's modulus of both bars, N/m² (`2.1e11`: `decks/pendulum.dat`, flexible1).
    pub young: f64,
    /// Time step, s.
    pub step: f64,
    /// End time, s.
    pub end: f64,
    /// HHT α.
    pub alpha: f64,
    /// Write the histories of the paper's nodes and elements (`false`: `OUTPUT NODES NONE
    /// ELEMENTS NONE`).
    pub output: bool,
}

impl Default for PendulumSettings {
    /// The settings of `decks/pendulum.dat`.
    fn default() -> Self {
        PendulumSettings {
            young: 2.1e11,
            step: 1e-4,
            end: 2.0,
            alpha: -0.1,
            output: true,
        }
    }
}

/// The deck of `decks/pendulum.dat`'s scene (the spatial double pendulum striking the floor)
/// with `elements_per_bar` beam elements in each bar (`decks/pendulum.dat` has 10).
///
/// Bar 1 runs along X from the hinge at the origin (ground node 1, axis Z) to (1, 0, 0); bar 2
/// from there along `d = (cos 30°, 0, sin 30°)`, joined to bar 1 by a universal joint (axis 1
/// Z on bar 1, axis 2 Y on bar 2); 1 kg point masses at both tips; gravity along −Y; a
/// triangular torque pulse `−1000 N·m × f(t)` about Z at node 2; a `CAME` contact of bar 2's
/// tip with the floor `y = −1.8` (`k = 1e7 N/m`, `c = 1e3 N·s/m`, the paper's unclipped law
/// eq. (17): `CLIP OFF`). With `n` elements per
/// bar: nodes `2 … n+2` (bar 1, tip `n+2`), `n+3 … 2n+3` (bar 2, tip `2n+3`), floor node
/// `2n+4`; elements: hinge 1, beams `2 … n+1`, ujoint `n+2`, beams `n+3 … 2n+2`, contact
/// `2n+3`, masses `2n+4`, `2n+5`. For `n = 10` and the default settings this is
/// `decks/pendulum.dat` up to comments.
pub fn pendulum_deck(elements_per_bar: usize, s: &PendulumSettings) -> String {
    let n = elements_per_bar.max(1);
    let (tip1, first2, tip2, floor) = (n + 2, n + 3, 2 * n + 3, 2 * n + 4);
    let (uj, contact, m1, m2) = (n + 2, 2 * n + 3, 2 * n + 4, 2 * n + 5);
    let mut d = String::new();
    let w = &mut d;
    head(w, &format!("{n} elements per bar"), s);
    let _ = writeln!(w, "NODES\n  1   0 0 0  FIX ALL");
    let _ = writeln!(w, "  2 TO {tip1} LINE  0 0 0   1 0 0");
    let _ = writeln!(
        w,
        "  {first2} TO {tip2} LINE  1 0 0   {TIP2_X:?} 0 {TIP2_Z:?}"
    );
    let _ = writeln!(w, "  {floor}  0 -1.8 0  FIX ALL\n");
    let _ = writeln!(w, "FUNCTIONS\n  1 TABLE  0 0  0.01 1  0.02 0\n");
    let _ = writeln!(w, "ELEMENTS\n  1  HINGE 1 2  AXIS 0 0 1");
    // `a TO b` generations need b > a: a single element is a plain card.
    let range = |a: usize, b: usize| {
        if b > a {
            format!("{a} TO {b}")
        } else {
            a.to_string()
        }
    };
    let _ = writeln!(w, "  {} BEAM 2 3  MAT 1 SEC 1", range(2, n + 1));
    let _ = writeln!(w, "  {uj} UJOINT {tip1} {first2}  AXIS1 0 0 1  AXIS2 0 1 0");
    let _ = writeln!(
        w,
        "  {} BEAM {first2} {}  MAT 1 SEC 1",
        range(n + 3, 2 * n + 2),
        first2 + 1
    );
    tail(w, [tip1, tip2, floor], [uj, contact, m1, m2], s);
    d
}

/// Bar 2's tip: (1, 0, 0) + (cos 30°, 0, sin 30°), as written in decks/pendulum.dat.
const TIP2_X: f64 = 1.8660254037844386;
const TIP2_Z: f64 = 0.5;

/// TITLE, MATERIALS and SECTIONS of the seed scene (`what`: its mesh, in the title).
fn head(w: &mut String, what: &str, s: &PendulumSettings) {
    let _ = writeln!(
        w,
        "TITLE double pendulum striking the floor - {what} (E = {:e})\n",
        s.young
    );
    let _ = writeln!(w, "MATERIALS\n  1  E {:e}  NU 0.3  RHO 7800\n", s.young);
    let _ = writeln!(
        w,
        "SECTIONS\n  1  A 9e-4  I2 8.3e-8  I3 8.3e-8  J 4.15e-8  K 0.8333333333333334\n"
    );
}

/// The seed scene's contact (the paper's eq. (17) as written: `CLIP OFF`), tip masses,
/// loads, analysis, output and END, with the nodes `[tip 1, tip 2, floor]` and the
/// elements `[universal joint, contact, mass 1, mass 2]` of the deck's numbering.
fn tail(w: &mut String, nodes: [usize; 3], elements: [usize; 4], s: &PendulumSettings) {
    let [tip1, tip2, floor] = nodes;
    let [uj, contact, m1, m2] = elements;
    let _ = writeln!(
        w,
        "  {contact} CAME {floor} {tip2}  CAM LINE  FOLLOWER POINT  K 1e7  C 1e3  CLIP OFF"
    );
    let _ = writeln!(w, "  {m1} MASS {tip1} M 1\n  {m2} MASS {tip2} M 1\n");
    let _ = writeln!(
        w,
        "LOADS\n  GRAVITY 0 -9.81 0\n  MOMENT 2  0 0 -1000  FUNCTION 1\n"
    );
    let _ = writeln!(
        w,
        "ANALYSIS DYNAMIC ALPHA {:?} STEP {:e} END {:?}\n",
        s.alpha, s.step, s.end
    );
    if s.output {
        let _ = writeln!(
            w,
            "OUTPUT NODES 2 {tip1} {tip2} ELEMENTS 1 {uj} {contact} EVERY 10"
        );
    } else {
        let _ = writeln!(w, "OUTPUT NODES NONE ELEMENTS NONE");
    }
    let _ = writeln!(w, "END");
}

/// The seed scene with each bar ONE BEAM card of `ORDER order` divided in `divide` elements
/// (`order · divide + 1` nodes per bar), with the numbers of `decks/pendulum.dat`: user
/// nodes 1, 2, 12 (bar 1's tip), 13, 23 (bar 2's tip), 24 (floor); elements hinge 1, bar 1
/// (2), ujoint 12, bar 2 (13), contact 23, masses 24 and 25. The generated nodes are
/// numbered from 25 on. `(10, 1)` is `decks/pendulum.dat`'s mesh with other numbers.
pub fn pendulum_order_deck(divide: u32, order: u32, s: &PendulumSettings) -> String {
    let mut d = String::new();
    let w = &mut d;
    head(w, &format!("{divide} elements of order {order} per bar"), s);
    let _ = writeln!(
        w,
        "NODES\n  1   0 0 0  FIX ALL\n  2   0 0 0\n  12  1 0 0\n  13  1 0 0"
    );
    let _ = writeln!(
        w,
        "  23  {TIP2_X:?} 0 {TIP2_Z:?}\n  24  0 -1.8 0  FIX ALL\n"
    );
    let _ = writeln!(w, "FUNCTIONS\n  1 TABLE  0 0  0.01 1  0.02 0\n");
    let _ = writeln!(w, "ELEMENTS\n  1  HINGE 1 2  AXIS 0 0 1");
    let _ = writeln!(
        w,
        "  2  BEAM 2 12  MAT 1 SEC 1 DIVIDE {divide} ORDER {order}"
    );
    let _ = writeln!(w, "  12 UJOINT 12 13  AXIS1 0 0 1  AXIS2 0 1 0");
    let _ = writeln!(
        w,
        "  13 BEAM 13 23  MAT 1 SEC 1 DIVIDE {divide} ORDER {order}"
    );
    tail(w, [12, 23, 24], [12, 23, 24, 25], s);
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ten_elements_per_bar_is_the_seed_deck() {
        let mut ours = crate::deck::parse_deck(
            &pendulum_deck(10, &PendulumSettings::default()),
            "generated",
        )
        .expect("the generated deck parses");
        let seed = crate::deck::load_deck(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/decks/pendulum.dat"
        )))
        .expect("seed deck");
        // Same model up to the title and the source spans: same canonical deck.
        ours.title = seed.title.clone();
        assert_eq!(
            crate::deck::write_deck(&ours),
            crate::deck::write_deck(&seed)
        );
        for n in [1, 3, 80] {
            let m = crate::deck::parse_deck(
                &pendulum_deck(
                    n,
                    &PendulumSettings {
                        output: false,
                        ..Default::default()
                    },
                ),
                "generated",
            )
            .expect("parses");
            assert_eq!(m.nodes.len(), 2 * n + 4);
            assert_eq!(m.elements.len(), 2 * n + 5);
        }
        // Ten two-node beams per bar as one card each: the same model as the seed's up to
        // the numbering of the interior nodes (same positions, same counts).
        let m = crate::deck::parse_deck(
            &pendulum_order_deck(10, 1, &PendulumSettings::default()),
            "generated",
        )
        .expect("parses");
        assert_eq!(m.nodes.len(), seed.nodes.len());
        for (d, p) in [(1, 8), (2, 4), (3, 5)] {
            let m = crate::deck::parse_deck(
                &pendulum_order_deck(d, p, &PendulumSettings::default()),
                "generated",
            )
            .expect("parses");
            assert_eq!(m.nodes.len() as u32, 4 + 2 * d * p);
        }
    }
}
