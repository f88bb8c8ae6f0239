//! Matrix Market files (NIST's exchange format, <https://math.nist.gov/MatrixMarket/formats.html>):
//! the `coordinate real symmetric` (and `general`, checked symmetric) matrices that
//! Abaqus's matrix generation, Ansys, Code_Aster, CalculiX and SciPy's `mmwrite` write, and
//! that `mecano-rs export` writes. Hand-written (about 200 lines): the format is a banner,
//! comments, a size line and one `i j value` line per entry, and the one crate that reads
//! it (`matrix-market-rs`, `sprs`'s reader) reports neither the line nor the column of a
//! mistake, which the project's standard for bad input asks for.

use nalgebra::DMatrix;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Largest Matrix Market file read, bytes (a 100,000-dof solid's stiffness is ~100 MB).
pub const MAX_BYTES: u64 = 4 << 30;

/// A symmetric sparse matrix: its size and its entries on and below the diagonal
/// (0-based `(row, column, value)`, `row ≥ column`, duplicates summed).
#[derive(Debug, Clone, PartialEq)]
pub struct SymMatrix {
    /// Rows (= columns).
    pub n: usize,
    /// Entries of the lower triangle.
    pub entries: Vec<(usize, usize, f64)>,
}

impl SymMatrix {
    /// The dense matrix (both triangles).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(self.n, self.n);
        for &(i, j, v) in &self.entries {
            a[(i, j)] += v;
            if i != j {
                a[(j, i)] += v;
            }
        }
        a
    }

    /// The lower triangle of a dense symmetric matrix (entries of magnitude at most
    /// `drop · max|a|` left out; 0 keeps every non-zero).
    pub fn from_dense(a: &DMatrix<f64>, drop: f64) -> Self {
        let max = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut entries = Vec::new();
        for j in 0..a.ncols() {
            for i in j..a.nrows() {
                let v = a[(i, j)];
                if v != 0.0 && v.abs() > drop * max {
                    entries.push((i, j, v));
                }
            }
        }
        SymMatrix {
            n: a.nrows(),
            entries,
        }
    }

    /// The file's text: banner, a comment, size line, entries 1-based, values in the
    /// shortest form that reads back to the same `f64` (ryu).
    pub fn to_text(&self, comment: &str) -> String {
        let mut s = String::with_capacity(32 * self.entries.len() + 128);
        s.push_str("%%MatrixMarket matrix coordinate real symmetric\n");
        for line in comment.lines() {
            let _ = writeln!(s, "% {line}");
        }
        let _ = writeln!(s, "{} {} {}", self.n, self.n, self.entries.len());
        let mut buf = ryu::Buffer::new();
        for &(i, j, v) in &self.entries {
            let _ = writeln!(s, "{} {} {}", i + 1, j + 1, buf.format(v));
        }
        s
    }
}

/// What is wrong with a Matrix Market file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MtxErrorKind {
    /// The file cannot be read.
    #[error("cannot read: {0}")]
    Io(String),
    /// The first line is not a Matrix Market banner of a real coordinate matrix.
    #[error(
        "expected the banner `%%MatrixMarket matrix coordinate real symmetric` (or `general`), found `{0}`"
    )]
    Banner(String),
    /// A kind of matrix this reader does not take (array, complex, pattern, skew…).
    #[error("{0} matrices are not read: write the matrix as `coordinate real symmetric`")]
    Unsupported(String),
    /// The size line is missing or wrong.
    #[error("expected the size line `rows columns entries`, found `{0}`")]
    SizeLine(String),
    /// The matrix is not square.
    #[error("the matrix is {0} × {1}: a stiffness or mass matrix is square")]
    NotSquare(usize, usize),
    /// A field that should be a number.
    #[error("expected {what}, found `{found}`")]
    Field {
        /// What was expected.
        what: &'static str,
        /// What the file holds.
        found: String,
    },
    /// An index outside the matrix.
    #[error("index {index} outside 1..={n}")]
    Index {
        /// The index read.
        index: u64,
        /// The size.
        n: usize,
    },
    /// A value that is not finite.
    #[error("value `{0}` is not finite")]
    NotFinite(String),
    /// More fields on an entry line than `i j value`.
    #[error("unexpected `{0}` after `i j value`")]
    Trailing(String),
    /// Fewer entries than the size line announced.
    #[error("truncated: the size line announces {announced} entries, the file holds {found}")]
    Truncated {
        /// Entries announced.
        announced: usize,
        /// Entries found.
        found: usize,
    },
    /// More entries than the size line announced.
    #[error("more entries than the {0} the size line announces")]
    TooMany(usize),
    /// A `general` matrix whose entry `(i, j)` differs from `(j, i)`.
    #[error("not symmetric: entry ({i}, {j}) = {a} but ({j}, {i}) = {b}")]
    NotSymmetric {
        /// Row (1-based).
        i: usize,
        /// Column (1-based).
        j: usize,
        /// `A_ij`.
        a: f64,
        /// `A_ji`.
        b: f64,
    },
    /// A matrix of another size than the model's degrees of freedom.
    #[error("the matrix has {found} rows but the map of degrees of freedom lists {expected}")]
    WrongSize {
        /// The size expected.
        expected: usize,
        /// The size read.
        found: usize,
    },
}

/// A Matrix Market error, located: file, 1-based line and column (0 = the whole file).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}:{col}: {kind}", file.display())]
pub struct MtxError {
    /// The file.
    pub file: PathBuf,
    /// Line, 1-based (0: the file as a whole).
    pub line: usize,
    /// Column in characters, 1-based.
    pub col: usize,
    /// What is wrong.
    pub kind: MtxErrorKind,
}

/// Reads a bounded text file (at most `max` bytes) as UTF-8.
pub fn read_bounded_text(path: &Path, max: u64) -> Result<String, String> {
    use std::io::Read;
    let f = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let meta = f.metadata().map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file".into());
    }
    let mut bytes = Vec::new();
    f.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > max {
        return Err(format!("larger than {max} bytes"));
    }
    String::from_utf8(bytes).map_err(|_| "not UTF-8 text".into())
}

/// Reads the Matrix Market file `path`.
pub fn read(path: &Path) -> Result<SymMatrix, MtxError> {
    let text = read_bounded_text(path, MAX_BYTES).map_err(|e| MtxError {
        file: path.to_path_buf(),
        line: 0,
        col: 0,
        kind: MtxErrorKind::Io(e),
    })?;
    parse(&text).map_err(|(line, col, kind)| MtxError {
        file: path.to_path_buf(),
        line,
        col,
        kind,
    })
}

/// An error of a text: (line, column, kind).
pub type Located = (usize, usize, MtxErrorKind);

/// Column (1-based, in characters) of `field` within `line` (a sub-slice of it).
fn col_of(line: &str, field: &str) -> usize {
    let off = field.as_ptr() as usize - line.as_ptr() as usize;
    line[..off].chars().count() + 1
}

/// A coordinate file's entries: rows, columns, whether `general`, and each entry's
/// 0-based `(row, column, value, line)` in the file's order.
type Entries = (usize, usize, bool, Vec<(usize, usize, f64, usize)>);

/// Reads the banner, size line and entries of a coordinate text; `square`: a matrix of
/// another shape is refused at its size line.
fn entries(text: &str, square: bool) -> Result<Entries, Located> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (_, banner) = lines
        .next()
        .ok_or((1, 1, MtxErrorKind::Banner(String::new())))?;
    let words: Vec<String> = banner
        .split_whitespace()
        .map(|w| w.to_ascii_lowercase())
        .collect();
    if words.len() != 5 || words[0] != "%%matrixmarket" || words[1] != "matrix" {
        return Err((
            1,
            1,
            MtxErrorKind::Banner(banner.chars().take(80).collect()),
        ));
    }
    if words[2] != "coordinate" {
        return Err((1, 1, MtxErrorKind::Unsupported(words[2].clone())));
    }
    if words[3] != "real" && words[3] != "integer" {
        return Err((1, 1, MtxErrorKind::Unsupported(words[3].clone())));
    }
    let general = match words[4].as_str() {
        "symmetric" => false,
        "general" => true,
        other => return Err((1, 1, MtxErrorKind::Unsupported(other.to_string()))),
    };
    let mut lines = lines.filter(|(_, l)| !l.trim_start().starts_with('%') && !l.trim().is_empty());
    let (ln, size) = lines.next().ok_or((
        text.lines().count() + 1,
        1,
        MtxErrorKind::SizeLine("end of file".into()),
    ))?;
    let f: Vec<&str> = size.split_whitespace().collect();
    let nums: Vec<Option<usize>> = f.iter().map(|x| x.parse().ok()).collect();
    let (rows, cols, nnz) = match nums.as_slice() {
        [Some(r), Some(c), Some(z)] => (*r, *c, *z),
        _ => {
            return Err((
                ln,
                1,
                MtxErrorKind::SizeLine(size.chars().take(80).collect()),
            ));
        }
    };
    if rows != cols && (square || !general) {
        return Err((ln, 1, MtxErrorKind::NotSquare(rows, cols)));
    }
    let mut out = Vec::with_capacity(nnz.min(1 << 26));
    for (ln, line) in lines {
        if out.len() == nnz {
            let first = line.split_whitespace().next().unwrap_or(line);
            return Err((ln, col_of(line, first), MtxErrorKind::TooMany(nnz)));
        }
        let mut it = line.split_whitespace();
        let index = |w: Option<&str>, what: &'static str, n: usize| -> Result<usize, Located> {
            let w = w.ok_or((
                ln,
                line.chars().count() + 1,
                MtxErrorKind::Field {
                    what,
                    found: "end of line".into(),
                },
            ))?;
            let v: u64 = w.parse().map_err(|_| {
                (
                    ln,
                    col_of(line, w),
                    MtxErrorKind::Field {
                        what,
                        found: w.chars().take(40).collect(),
                    },
                )
            })?;
            if v == 0 || v > n as u64 {
                return Err((ln, col_of(line, w), MtxErrorKind::Index { index: v, n }));
            }
            Ok(v as usize - 1)
        };
        let i = index(it.next(), "a row index", rows)?;
        let j = index(it.next(), "a column index", cols)?;
        let w = it.next().ok_or((
            ln,
            line.chars().count() + 1,
            MtxErrorKind::Field {
                what: "a value",
                found: "end of line".into(),
            },
        ))?;
        let v: f64 = w.parse().map_err(|_| {
            (
                ln,
                col_of(line, w),
                MtxErrorKind::Field {
                    what: "a value",
                    found: w.chars().take(40).collect(),
                },
            )
        })?;
        if !v.is_finite() {
            return Err((ln, col_of(line, w), MtxErrorKind::NotFinite(w.into())));
        }
        if let Some(t) = it.next() {
            return Err((
                ln,
                col_of(line, t),
                MtxErrorKind::Trailing(t.chars().take(40).collect()),
            ));
        }
        out.push((i, j, v, ln));
    }
    if out.len() < nnz {
        return Err((
            text.lines().count().max(1),
            1,
            MtxErrorKind::Truncated {
                announced: nnz,
                found: out.len(),
            },
        ));
    }
    Ok((rows, cols, general, out))
}

/// Parses a `coordinate real general` text of any shape (the reduced set's coupling
/// matrix, `super::reduced`) into a dense matrix, duplicates summed; errors as (line,
/// column, kind).
pub fn parse_general(text: &str) -> Result<DMatrix<f64>, Located> {
    let (rows, cols, general, e) = entries(text, false)?;
    let mut a = DMatrix::zeros(rows, cols);
    for (i, j, v, _) in e {
        a[(i, j)] += v;
        if !general && i != j {
            a[(j, i)] += v;
        }
    }
    Ok(a)
}

/// The `coordinate real general` text of a dense matrix of any shape (its non-zero
/// entries, values in ryu's shortest form that reads back to the same `f64`).
pub fn general_text(a: &DMatrix<f64>, comment: &str) -> String {
    let nz = a.iter().filter(|v| **v != 0.0).count();
    let mut s = String::with_capacity(32 * nz + 128);
    s.push_str("%%MatrixMarket matrix coordinate real general\n");
    for line in comment.lines() {
        let _ = writeln!(s, "% {line}");
    }
    let _ = writeln!(s, "{} {} {nz}", a.nrows(), a.ncols());
    let mut buf = ryu::Buffer::new();
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            let v = a[(i, j)];
            if v != 0.0 {
                let _ = writeln!(s, "{} {} {}", i + 1, j + 1, buf.format(v));
            }
        }
    }
    s
}

/// Parses a Matrix Market text; errors as (line, column, kind).
pub fn parse(text: &str) -> Result<SymMatrix, Located> {
    let (n, _, general, all) = entries(text, true)?;
    let mut entries = Vec::with_capacity(all.len());
    let mut upper = Vec::new();
    for (i, j, v, ln) in all {
        if i >= j {
            entries.push((i, j, v));
        } else if general {
            upper.push((j, i, v, ln));
        } else {
            // A symmetric file that lists its upper triangle: the same matrix.
            entries.push((j, i, v));
        }
    }
    let mut lower = sum_duplicates(entries);
    if general {
        let up = sum_duplicates(upper.iter().map(|&(i, j, v, _)| (i, j, v)).collect());
        let line_of: std::collections::HashMap<(usize, usize), usize> =
            upper.iter().map(|&(i, j, _, l)| ((i, j), l)).collect();
        // Every off-diagonal entry of the lower triangle must be matched above, to
        // round-off of the larger (a matrix assembled in floating point).
        let mut a = lower.iter().filter(|e| e.0 != e.1).peekable();
        let mut b = up.iter().peekable();
        let tol = |x: f64, y: f64| (x - y).abs() <= 1e-12 * x.abs().max(y.abs());
        loop {
            match (a.peek(), b.peek()) {
                (None, None) => break,
                (Some(x), Some(y)) if (x.0, x.1) == (y.0, y.1) => {
                    if !tol(x.2, y.2) {
                        let l = line_of.get(&(y.0, y.1)).copied().unwrap_or(0);
                        return Err(asym(l, y.0, y.1, y.2, x.2));
                    }
                    a.next();
                    b.next();
                }
                (Some(x), y) if y.is_none_or(|y| (x.1, x.0) < (y.1, y.0)) => {
                    return Err(asym(0, x.1, x.0, 0.0, x.2));
                }
                (_, Some(y)) => {
                    let l = line_of.get(&(y.0, y.1)).copied().unwrap_or(0);
                    return Err(asym(l, y.1, y.0, y.2, 0.0));
                }
                _ => break,
            }
        }
        lower.shrink_to_fit();
    }
    Ok(SymMatrix { n, entries: lower })
}

fn asym(line: usize, i: usize, j: usize, a: f64, b: f64) -> Located {
    (
        line,
        1,
        MtxErrorKind::NotSymmetric {
            i: i.min(j) + 1,
            j: i.max(j) + 1,
            a,
            b,
        },
    )
}

/// Sorted by (column, row), duplicates summed.
fn sum_duplicates(mut e: Vec<(usize, usize, f64)>) -> Vec<(usize, usize, f64)> {
    e.sort_by_key(|&(i, j, _)| (j, i));
    let mut out: Vec<(usize, usize, f64)> = Vec::with_capacity(e.len());
    for (i, j, v) in e {
        match out.last_mut() {
            Some(l) if l.0 == i && l.1 == j => l.2 += v,
            _ => out.push((i, j, v)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "%%MatrixMarket matrix coordinate real symmetric\n% a comment\n3 3 4\n1 1 2.0\n2 1 -1\n2 2 2\n3 3 1e3\n";

    #[test]
    fn reads_and_writes_back() {
        let a = parse(GOOD).expect("reads");
        assert_eq!(a.n, 3);
        let d = a.to_dense();
        assert_eq!(d[(0, 1)], -1.0);
        assert_eq!(d[(1, 0)], -1.0);
        assert_eq!(d[(2, 2)], 1e3);
        let again = parse(&a.to_text("written")).expect("reads its own");
        assert_eq!(again, a);
    }

    #[test]
    fn general_symmetric_is_accepted_and_asymmetric_refused() {
        let g =
            "%%MatrixMarket matrix coordinate real general\n2 2 4\n1 1 1\n1 2 3\n2 1 3\n2 2 1\n";
        assert_eq!(parse(g).expect("symmetric").to_dense()[(0, 1)], 3.0);
        let bad = g.replace("2 1 3", "2 1 4");
        let (line, _, k) = parse(&bad).expect_err("asymmetric");
        assert!(
            matches!(k, MtxErrorKind::NotSymmetric { i: 1, j: 2, .. }),
            "{k}"
        );
        assert_eq!(line, 4);
    }

    #[test]
    fn mistakes_are_located() {
        let cases: [(&str, usize, usize); 7] = [
            ("%%MatrixMarket matrix array real general\n2 2\n", 1, 1),
            ("hello\n", 1, 1),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n3 2 1\n",
                2,
                1,
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1\n2 x 1\n",
                4,
                3,
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1\n3 1 1\n",
                4,
                1,
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1\n",
                3,
                1,
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 1 nan\n",
                3,
                5,
            ),
        ];
        for (text, line, col) in cases {
            let (l, c, k) = parse(text).expect_err(text);
            assert_eq!((l, c), (line, col), "{text}: {k}");
        }
        let (_, _, k) =
            parse("%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 1 1\n2 2 1\n")
                .expect_err("too many");
        assert_eq!(k, MtxErrorKind::TooMany(1));
    }
}
