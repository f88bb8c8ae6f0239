//! An already reduced superelement (issue 38 §3): the files of a `FILES` directory that
//! hold a reduced body instead of an FE model — what the floating frame evaluates
//! ([`Body`]), as text another tool can write (`mecano-rs export DECK --reduced ID`
//! writes them; docs/superelements.md, "Already reduced input"). With `n` elastic
//! coordinates (6 per interface node other than the frame node, then the modes):
//!
//! - `M0.mtx`: `𝕄₀`, `(6 + n)²`, Matrix Market `coordinate real symmetric` — the mass
//!   matrix over `[V; Ω; q]`: mass, first moment, rotary inertia about the frame node,
//!   the rigid–elastic couplings, `ΦᵀMΦ`;
//! - `G.mtx`: `[G_1 … G_n]`, `(6 + n) × 3n`, `coordinate real general`, `G_k = A₀ᵀ M A₁ₖ`
//!   (the change of inertia with coordinate `k`, `super::invariants`);
//! - `H.mtx`: `[A₁ₖᵀ M A₁ₗ]`, `3n × 3n`, symmetric;
//! - `Kr.mtx`: `ΦᵀKΦ`, `n × n`, symmetric;
//! - `body.csv`: `mass,cx,cy,cz` and one row: the mass (kg, `𝕄₀`'s first entry) and the
//!   first moment `c₀ = A_VᵀMs` about the frame node (kg·m, frame axes at rest);
//! - `interface.csv`: `node,x,y,z`: the interface nodes' FE numbers in `INTERFACE`'s order
//!   (the frame node first) and their places in the FE model's frame (m; only the
//!   differences to the frame node's are read);
//! - `modes.csv`: `mode,omega2`: the kept fixed-interface modes' `ω²` (rad²/s²).
//!
//! The invariants are what cannot be derived from reduced `K` and `M` alone: the inertia's
//! changes with deformation (`G`, `H`) need the mode shapes at the mass. Values in the
//! shortest form that reads back to the same `f64` (ryu): a set written by mecano-rs reads
//! back bit for bit.

use super::fe::{self, read_csv, read_text};
use super::invariants::Body;
use super::mtx::{self, MtxError, MtxErrorKind, SymMatrix};
use crate::model::SuperelementData;
use nalgebra::{Cholesky, DMatrix, Vector3};
use std::path::Path;

/// The files of a reduced set.
pub const FILES: [&str; 7] = [
    "M0.mtx",
    "G.mtx",
    "H.mtx",
    "Kr.mtx",
    "body.csv",
    "interface.csv",
    "modes.csv",
];

/// Largest CSV of a set, bytes.
const MAX_CSV: u64 = 1 << 26;

/// Whether `dir` holds a reduced set (its `M0.mtx`) rather than an FE model.
pub fn is_set(dir: &Path) -> bool {
    std::fs::symlink_metadata(dir.join(FILES[0])).is_ok()
}

/// What is wrong with a reduced set.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReducedError {
    /// A file that cannot be read or parsed, located.
    #[error(transparent)]
    File(#[from] MtxError),
    /// A file of another size than the set's.
    #[error("{file}: {found}, but {expected}")]
    Size {
        /// The file.
        file: String,
        /// What it holds.
        found: String,
        /// What the set or the deck makes it.
        expected: String,
    },
    /// The set and the deck disagree, or the set is not a body.
    #[error("{0}")]
    Invalid(String),
}

fn located(path: &Path, line: usize, col: usize, what: &'static str, found: &str) -> MtxError {
    MtxError {
        file: path.to_path_buf(),
        line,
        col,
        kind: MtxErrorKind::Field {
            what,
            found: found.chars().take(40).collect(),
        },
    }
}

fn sym(dir: &Path, name: &str) -> Result<DMatrix<f64>, MtxError> {
    Ok(mtx::read(&dir.join(name))?.to_dense())
}

/// Reads the reduced set of `dir` for the superelement of data `d` whose interface nodes
/// are at `places` (the deck's), and checks it: every file well formed (located), the sizes
/// those of the deck's `INTERFACE` and `MODES`, the interface the deck's and at its places
/// (to [`super::PLACE_TOL`] of the largest interface distance), the mass positive and
/// `𝕄₀` positive definite, no `RBE2`/`RBE3` (they are made before a reduction).
pub fn read(
    dir: &Path,
    d: &SuperelementData,
    places: &[Vector3<f64>],
) -> Result<Body, ReducedError> {
    if let Some(r) = d.rbe.first() {
        return Err(ReducedError::Invalid(format!(
            "{} holds a reduced set: its interfaces were made before the reduction, so the deck's RBE2/RBE3 {} cannot be",
            dir.display(),
            r.node
        )));
    }
    let p = |i: usize| dir.join(FILES[i]);
    let n = d.elastic_coordinates();
    let nb = d.interface.len() - 1;
    let size = |i: usize, found: (usize, usize), want: (usize, usize)| {
        if found == want {
            return Ok(());
        }
        Err(ReducedError::Size {
            file: p(i).display().to_string(),
            found: format!("{} × {}", found.0, found.1),
            expected: format!(
                "the deck's INTERFACE ({} nodes) and MODES {} make n = 6·{nb} + {} = {n} elastic coordinates, so {} × {}",
                nb + 1,
                d.modes,
                d.modes,
                want.0,
                want.1
            ),
        })
    };
    // The interface first: a set of another body is said as such.
    let text = read_text(&p(5), MAX_CSV)?;
    let rows = read_csv(
        &p(5),
        &text,
        &["node", "x", "y", "z"],
        "the header `node,x,y,z`",
        "an FE node number and three finite coordinates",
        |s| s.parse::<f64>().ok().filter(|v| v.is_finite()),
    )?;
    let listed: Vec<f64> = rows.iter().map(|(_, f)| f[0]).collect();
    let deck: Vec<f64> = d.interface.iter().map(|&a| f64::from(a)).collect();
    if listed != deck {
        return Err(ReducedError::Invalid(format!(
            "{} lists the interface FE nodes {}, the deck's INTERFACE {} (the same nodes in the same order, the frame node first)",
            p(5).display(),
            listed
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            d.interface
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let x: Vec<Vector3<f64>> = rows
        .iter()
        .map(|(_, f)| Vector3::new(f[1], f[2], f[3]))
        .collect();
    let s_iface: Vec<Vector3<f64>> = x[1..].iter().map(|xi| xi - x[0]).collect();
    let reach = s_iface.iter().fold(0.0f64, |m, s| m.max(s.norm()));
    for (i, s) in s_iface.iter().enumerate() {
        let deck_rel = places[i + 1] - places[0];
        if (deck_rel - s).norm() > super::PLACE_TOL * reach {
            return Err(ReducedError::Invalid(format!(
                "interface FE node {} is at {:?} from the frame node in the deck but at {:?} in {}",
                d.interface[i + 1],
                deck_rel.as_slice(),
                s.as_slice(),
                p(5).display()
            )));
        }
    }
    let k = sym(dir, FILES[3])?;
    size(3, k.shape(), (n, n))?;
    let m0 = sym(dir, FILES[0])?;
    size(0, m0.shape(), (6 + n, 6 + n))?;
    let gtext = read_text(&p(1), mtx::MAX_BYTES)?;
    let g = mtx::parse_general(&gtext).map_err(|(line, col, kind)| MtxError {
        file: p(1),
        line,
        col,
        kind,
    })?;
    size(1, g.shape(), (6 + n, 3 * n))?;
    let h = sym(dir, FILES[2])?;
    size(2, h.shape(), (3 * n, 3 * n))?;
    // body.csv: one row, the mass positive and 𝕄₀'s.
    let text = read_text(&p(4), MAX_CSV)?;
    let rows = read_csv(
        &p(4),
        &text,
        &["mass", "cx", "cy", "cz"],
        "the header `mass,cx,cy,cz`",
        "four finite numbers",
        |s| s.parse::<f64>().ok().filter(|v| v.is_finite()),
    )?;
    let [(ln, f)] = rows.as_slice() else {
        return Err(located(
            &p(4),
            2,
            1,
            "one row `mass,cx,cy,cz`",
            &format!("{} rows", rows.len()),
        )
        .into());
    };
    let mass = f[0];
    if mass <= 0.0 {
        return Err(located(&p(4), *ln, 1, "a mass > 0 kg", &mass.to_string()).into());
    }
    if (mass - m0[(0, 0)]).abs() > 1e-12 * mass {
        return Err(ReducedError::Invalid(format!(
            "{}:{ln}:1: the mass {mass} kg is not M0.mtx's first entry {} (the mass of 𝕄₀'s translations)",
            p(4).display(),
            m0[(0, 0)]
        )));
    }
    let c0 = Vector3::new(f[1], f[2], f[3]);
    // modes.csv: MODES rows, numbered, ω² > 0.
    let text = read_text(&p(6), MAX_CSV)?;
    let rows = read_csv(
        &p(6),
        &text,
        &["mode", "omega2"],
        "the header `mode,omega2`",
        "a mode number and its ω² > 0, rad²/s²",
        |s| s.parse::<f64>().ok().filter(|v| v.is_finite()),
    )?;
    let mut omega2 = Vec::with_capacity(rows.len());
    for (ln, f) in &rows {
        if f[0] != (omega2.len() + 1) as f64 {
            return Err(located(
                &p(6),
                *ln,
                1,
                "the modes numbered 1, 2, 3, … in order",
                &f[0].to_string(),
            )
            .into());
        }
        if f[1] <= 0.0 {
            return Err(located(&p(6), *ln, 2, "an ω² > 0, rad²/s²", &f[1].to_string()).into());
        }
        omega2.push(f[1]);
    }
    if omega2.len() != d.modes as usize {
        return Err(ReducedError::Size {
            file: p(6).display().to_string(),
            found: format!("{} modes", omega2.len()),
            expected: format!("the deck's MODES is {}", d.modes),
        });
    }
    if Cholesky::new(m0.clone()).is_none() {
        return Err(ReducedError::Invalid(format!(
            "{}: 𝕄₀ is not positive definite (a body's kinetic energy is positive for every motion)",
            p(0).display()
        )));
    }
    Ok(Body {
        n,
        m0,
        g,
        h,
        mass,
        c0,
        k,
        s_iface,
        omega2,
    })
}

/// The texts of the reduced set of `body` (files in [`FILES`]' order), its interface nodes
/// `interface` (FE numbers, frame node first; `interface.csv` places the frame node at the
/// origin, so that the places read back are the body's own bits); `about` a comment.
pub fn texts(body: &Body, interface: &[u32], about: &str) -> [String; 7] {
    let s = |a: &DMatrix<f64>, what: &str| {
        SymMatrix::from_dense(a, 0.0).to_text(&format!("{what}. {about}"))
    };
    let mut buf = ryu::Buffer::new();
    let mut f = |v: f64| buf.format(v).to_string();
    let body_csv = format!(
        "mass,cx,cy,cz\n{},{},{},{}\n",
        f(body.mass),
        f(body.c0.x),
        f(body.c0.y),
        f(body.c0.z)
    );
    let places: Vec<(u32, Vector3<f64>)> = interface
        .iter()
        .enumerate()
        .map(|(i, &a)| {
            (
                a,
                if i == 0 {
                    Vector3::zeros()
                } else {
                    body.s_iface[i - 1]
                },
            )
        })
        .collect();
    let mut modes = String::from("mode,omega2\n");
    for (i, w) in body.omega2.iter().enumerate() {
        modes.push_str(&format!("{},{}\n", i + 1, f(*w)));
    }
    [
        s(
            &body.m0,
            "M0: the floating frame's mass matrix over [V; Omega; q]",
        ),
        mtx::general_text(
            &body.g,
            &format!("G = [G_1 ... G_n], G_k = A0' M A1k. {about}"),
        ),
        s(&body.h, "H = [A1k' M A1l]"),
        s(&body.k, "Kr = Phi' K Phi, the reduced stiffness"),
        body_csv,
        fe::nodes_text(&places),
        modes,
    ]
}
