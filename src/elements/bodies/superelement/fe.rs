//! A finite-element model as the files a superelement reads (and `mecano-rs export`
//! writes) in one directory: `K.mtx` and `M.mtx` (Matrix Market, [`super::mtx`]),
//! `nodes.csv` (`node,x,y,z`: the FE nodes' coordinates, m, in the deck's global frame) and
//! `dofs.csv` (`dof,node,component`: row `dof` (1-based) of the matrices is component 1–6
//! — `ux uy uz rx ry rz` — of FE node `node`).

use super::mtx::{self, MtxError, MtxErrorKind, SymMatrix};
use indexmap::IndexMap;
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// The names of the four files, in the directory the deck names.
pub const FILES: [&str; 4] = ["K.mtx", "M.mtx", "nodes.csv", "dofs.csv"];

/// Largest CSV file read, bytes.
const MAX_CSV: u64 = 1 << 30;

/// A finite-element model read from its files.
#[derive(Debug, Clone)]
pub struct FeModel {
    /// Stiffness (lower triangle).
    pub k: SymMatrix,
    /// Mass (lower triangle).
    pub m: SymMatrix,
    /// Coordinates of the FE nodes, by FE node number.
    pub nodes: IndexMap<u32, Vector3<f64>>,
    /// Row `i` of the matrices is component `dofs[i].1` (0–5) of FE node `dofs[i].0`.
    pub dofs: Vec<(u32, u8)>,
}

impl FeModel {
    /// Row of component `c` (0–5) of FE node `node`, if the matrices have it.
    pub fn dof_of(&self, node: u32, c: u8) -> Option<usize> {
        self.dofs.iter().position(|&(n, k)| n == node && k == c)
    }
}

/// A CSV mistake, located.
fn csv_err(file: &Path, line: usize, col: usize, what: &'static str, found: &str) -> MtxError {
    MtxError {
        file: file.to_path_buf(),
        line,
        col,
        kind: MtxErrorKind::Field {
            what,
            found: found.chars().take(40).collect(),
        },
    }
}

/// Reads a file of the set whole (at most `max` bytes), its error located at the file.
pub fn read_text(path: &Path, max: u64) -> Result<String, MtxError> {
    mtx::read_bounded_text(path, max).map_err(|e| MtxError {
        file: path.to_path_buf(),
        line: 0,
        col: 0,
        kind: MtxErrorKind::Io(e),
    })
}

/// Reads the rows of a CSV text (the file `path`) of `header`'s columns (the header line
/// itself checked, `expected` its description), each field parsed by `parse`; returns (line number, fields).
pub fn read_csv<T>(
    path: &Path,
    text: &str,
    header: &[&str],
    expected: &'static str,
    what: &'static str,
    parse: impl Fn(&str) -> Option<T>,
) -> Result<Vec<(usize, Vec<T>)>, MtxError> {
    let mut rows = Vec::new();
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    match lines.next() {
        Some((_, h)) if h.split(',').map(str::trim).collect::<Vec<_>>().as_slice() == header => {}
        Some((_, h)) => return Err(csv_err(path, 1, 1, expected, h)),
        None => return Err(csv_err(path, 1, 1, expected, "end of file")),
    }
    for (ln, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let mut fields = Vec::with_capacity(header.len());
        let mut col = 1;
        for f in line.split(',') {
            let v = parse(f.trim()).ok_or_else(|| csv_err(path, ln, col, what, f.trim()))?;
            fields.push(v);
            col += f.chars().count() + 1;
        }
        if fields.len() != header.len() {
            return Err(csv_err(path, ln, 1, what, line));
        }
        rows.push((ln, fields));
    }
    Ok(rows)
}

/// Reads the four files of `dir` and checks that they agree: the matrices' size is the
/// map's, every dof's node has coordinates, no dof is listed twice.
pub fn read(dir: &Path) -> Result<FeModel, MtxError> {
    parse(dir, &read_texts(dir)?)
}

/// The texts of the four files of `dir`, in [`FILES`]' order (read in the order the
/// model is checked: `nodes.csv`, `dofs.csv`, `K.mtx`, `M.mtx`).
pub fn read_texts(dir: &Path) -> Result<[String; 4], MtxError> {
    let nodes = read_text(&dir.join(FILES[2]), MAX_CSV)?;
    let dofs = read_text(&dir.join(FILES[3]), MAX_CSV)?;
    let k = read_text(&dir.join(FILES[0]), mtx::MAX_BYTES)?;
    let m = read_text(&dir.join(FILES[1]), mtx::MAX_BYTES)?;
    Ok([k, m, nodes, dofs])
}

/// The FE model of the texts of `dir`'s four files ([`read_texts`]), checked as [`read`].
pub fn parse(dir: &Path, texts: &[String; 4]) -> Result<FeModel, MtxError> {
    let p = |name: &str| -> PathBuf { dir.join(name) };
    let node_rows = read_csv(
        &p(FILES[2]),
        &texts[2],
        &["node", "x", "y", "z"],
        "the header `node,x,y,z`",
        "a node number and three finite coordinates",
        |s| s.parse::<f64>().ok().filter(|v| v.is_finite()),
    )?;
    let mut nodes = IndexMap::new();
    for (ln, f) in node_rows {
        let n = f[0];
        if n < 1.0 || n.fract() != 0.0 || n > f64::from(u32::MAX) {
            return Err(csv_err(
                &p(FILES[2]),
                ln,
                1,
                "a node number ≥ 1",
                &n.to_string(),
            ));
        }
        if nodes
            .insert(n as u32, Vector3::new(f[1], f[2], f[3]))
            .is_some()
        {
            return Err(csv_err(
                &p(FILES[2]),
                ln,
                1,
                "a node not listed before",
                &n.to_string(),
            ));
        }
    }
    let dof_rows = read_csv(
        &p(FILES[3]),
        &texts[3],
        &["dof", "node", "component"],
        "the header `dof,node,component`",
        "three positive integers",
        |s| s.parse::<u64>().ok(),
    )?;
    let mut dofs = Vec::with_capacity(dof_rows.len());
    let mut seen = std::collections::HashSet::new();
    for (ln, f) in dof_rows {
        let dpath = p(FILES[3]);
        if f[0] != dofs.len() as u64 + 1 {
            return Err(csv_err(
                &dpath,
                ln,
                1,
                "the dofs numbered 1, 2, 3, … in order",
                &f[0].to_string(),
            ));
        }
        let node = u32::try_from(f[1]).ok().filter(|n| nodes.contains_key(n));
        let Some(node) = node else {
            return Err(csv_err(
                &dpath,
                ln,
                2,
                "a node of nodes.csv",
                &f[1].to_string(),
            ));
        };
        if !(1..=6).contains(&f[2]) {
            return Err(csv_err(
                &dpath,
                ln,
                3,
                "a component 1 to 6 (ux uy uz rx ry rz)",
                &f[2].to_string(),
            ));
        }
        let c = (f[2] - 1) as u8;
        if !seen.insert((node, c)) {
            return Err(csv_err(
                &dpath,
                ln,
                2,
                "a (node, component) not listed before",
                &format!("{node},{}", f[2]),
            ));
        }
        dofs.push((node, c));
    }
    let sized = |m: SymMatrix, name: &str| -> Result<SymMatrix, MtxError> {
        if m.n != dofs.len() {
            return Err(MtxError {
                file: p(name),
                line: 0,
                col: 0,
                kind: MtxErrorKind::WrongSize {
                    expected: dofs.len(),
                    found: m.n,
                },
            });
        }
        Ok(m)
    };
    let matrix = |i: usize| {
        mtx::parse(&texts[i]).map_err(|(line, col, kind)| MtxError {
            file: p(FILES[i]),
            line,
            col,
            kind,
        })
    };
    let k = sized(matrix(0)?, FILES[0])?;
    let m = sized(matrix(1)?, FILES[1])?;
    Ok(FeModel { k, m, nodes, dofs })
}

/// The text of `nodes.csv`.
pub fn nodes_text(nodes: &[(u32, Vector3<f64>)]) -> String {
    let mut b = ryu::Buffer::new();
    let mut s = String::from("node,x,y,z\n");
    for (n, x) in nodes {
        s.push_str(&n.to_string());
        for c in x.iter() {
            s.push(',');
            s.push_str(b.format(*c));
        }
        s.push('\n');
    }
    s
}

/// The text of `dofs.csv` (`dofs[i]` = (node, component 0–5)).
pub fn dofs_text(dofs: &[(u32, u8)]) -> String {
    let mut s = String::from("dof,node,component\n");
    for (i, (n, c)) in dofs.iter().enumerate() {
        s.push_str(&format!("{},{n},{}\n", i + 1, c + 1));
    }
    s
}
