//! `histories.nc`: every selected node's and element's history and the energy balance in
//! one NetCDF file (classic format with 64-bit offsets, "CDF-2"), for large selections
//! (`OUTPUT … FORMAT NETCDF`).
//!
//! Format: NetCDF Classic and 64-bit Offset Format, Unidata (the specification in the
//! NetCDF User's Guide, "File Format Specifications"); MBDyn writes its output in NetCDF
//! too. The file is written by this module (no C library, no crate: the classic format is
//! a header and big-endian arrays), and read by every NetCDF reader: `scipy.io.netcdf_file`
//! (pure Python), netCDF4, xarray, ncdump. Layout:
//!
//! | variable | dimensions | content |
//! | --- | --- | --- |
//! | `t` | (time) | the instants, s |
//! | `node_id` | (node) | the node numbers, in the order of `node` |
//! | `node` | (time, node, node_column) | the columns of `node_<N>.csv` after `t` (attribute `columns`) |
//! | `element_k_id` | (element_k) | the element numbers of group k (elements of one header) |
//! | `element_k` | (time, element_k, element_k_column) | the columns of `element_<N>.csv` after `t` |
//! | `energy` | (time, energy_column) | the columns of `energy.csv` after `t` |
//!
//! `time` is the record dimension: one record per written instant, appended in blocks of
//! whole records; the record count in the header (bytes 4..8) is rewritten after each
//! block, so a file cut by a failure holds whole records, all counted. A restart cuts the
//! file back to its checkpointed length and sets the count from it.

use std::io::{self, Read, Seek, SeekFrom, Write};
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

/// The file's name in an output directory.
pub const FILE_NAME: &str = "histories.nc";

/// NetCDF external types (classic format).
pub(crate) const NC_CHAR: u32 = 2;
pub(crate) const NC_INT: u32 = 4;
pub(crate) const NC_DOUBLE: u32 = 6;
pub(crate) const NC_DIMENSION: u32 = 0x0A;
pub(crate) const NC_VARIABLE: u32 = 0x0B;
pub(crate) const NC_ATTRIBUTE: u32 = 0x0C;

/// One group of entities written as one variable: its name (`node`, `element_1`, …), the
/// entity numbers and the column names after `t`.
pub(crate) struct Group {
    pub(crate) name: String,
    pub(crate) ids: Vec<u32>,
    pub(crate) columns: Vec<String>,
}

fn put_u32(b: &mut Vec<u8>, v: u32) {
    b.extend_from_slice(&v.to_be_bytes());
}

fn pad4(b: &mut Vec<u8>) {
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
}

fn put_name(b: &mut Vec<u8>, s: &str) {
    put_u32(b, s.len() as u32);
    b.extend_from_slice(s.as_bytes());
    pad4(b);
}

fn put_text_att(b: &mut Vec<u8>, name: &str, text: &str) {
    put_name(b, name);
    put_u32(b, NC_CHAR);
    put_u32(b, text.len() as u32);
    b.extend_from_slice(text.as_bytes());
    pad4(b);
}

/// A variable of the header: name, dimension ids, `columns` attribute, type, size of one
/// record (or of the whole variable), and whether it is a record variable.
struct VarDef {
    name: String,
    dims: Vec<u32>,
    columns: Option<String>,
    kind: u32,
    vsize: u64,
    record: bool,
}

/// The header of a file holding `groups` (nodes first, then element groups, then energy),
/// and the offset of its first record and the size of one record.
struct Layout {
    /// Header followed by the id arrays (everything before the first record).
    prefix: Vec<u8>,
    rec_begin: u64,
    rec_size: u64,
}

fn layout(title: &str, groups: &[Group]) -> Layout {
    // Dimensions: time (record), then per group (count, columns).
    let mut dims: Vec<(String, u64)> = vec![("time".into(), 0)];
    let mut vars: Vec<VarDef> = Vec::new();
    let mut data: Vec<Vec<u8>> = Vec::new();
    vars.push(VarDef {
        name: "t".into(),
        dims: vec![0],
        columns: None,
        kind: NC_DOUBLE,
        vsize: 8,
        record: true,
    });
    for g in groups {
        let id_dim = if g.name == "energy" {
            None
        } else {
            dims.push((g.name.clone(), g.ids.len() as u64));
            Some(dims.len() as u32 - 1)
        };
        dims.push((format!("{}_column", g.name), g.columns.len() as u64));
        let col_dim = dims.len() as u32 - 1;
        let n = g.ids.len().max(1) as u64;
        if let Some(d) = id_dim {
            let mut ids = Vec::with_capacity(4 * g.ids.len());
            for id in &g.ids {
                put_u32(&mut ids, *id);
            }
            vars.push(VarDef {
                name: format!("{}_id", g.name),
                dims: vec![d],
                columns: None,
                kind: NC_INT,
                vsize: ids.len() as u64,
                record: false,
            });
            data.push(ids);
        }
        let mut d = vec![0];
        d.extend(id_dim);
        d.push(col_dim);
        vars.push(VarDef {
            name: g.name.clone(),
            dims: d,
            columns: Some(g.columns.join(",")),
            kind: NC_DOUBLE,
            vsize: 8 * n * g.columns.len() as u64,
            record: true,
        });
    }
    let build = |begins: &[u64]| {
        let mut b = Vec::new();
        b.extend_from_slice(b"CDF\x02");
        put_u32(&mut b, 0); // numrecs, rewritten after each block
        put_u32(&mut b, NC_DIMENSION);
        put_u32(&mut b, dims.len() as u32);
        for (name, len) in &dims {
            put_name(&mut b, name);
            put_u32(&mut b, *len as u32);
        }
        put_u32(&mut b, NC_ATTRIBUTE);
        put_u32(&mut b, 2);
        put_text_att(&mut b, "title", title);
        put_text_att(&mut b, "source", "mecano-rs");
        put_u32(&mut b, NC_VARIABLE);
        put_u32(&mut b, vars.len() as u32);
        for (v, begin) in vars.iter().zip(begins) {
            put_name(&mut b, &v.name);
            put_u32(&mut b, v.dims.len() as u32);
            for d in &v.dims {
                put_u32(&mut b, *d);
            }
            match &v.columns {
                Some(c) => {
                    put_u32(&mut b, NC_ATTRIBUTE);
                    put_u32(&mut b, 1);
                    put_text_att(&mut b, "columns", c);
                }
                None => {
                    put_u32(&mut b, 0);
                    put_u32(&mut b, 0);
                }
            }
            put_u32(&mut b, v.kind);
            put_u32(&mut b, u32::try_from(v.vsize).unwrap_or(u32::MAX));
            b.extend_from_slice(&begin.to_be_bytes());
        }
        b
    };
    let header_len = build(&vec![0; vars.len()]).len() as u64;
    let mut begins = Vec::with_capacity(vars.len());
    let mut at = header_len;
    for v in vars.iter().filter(|v| !v.record) {
        begins.push((v.name.clone(), at));
        at += v.vsize.next_multiple_of(4);
    }
    let rec_begin = at;
    for v in vars.iter().filter(|v| v.record) {
        begins.push((v.name.clone(), at));
        at += v.vsize;
    }
    let ordered: Vec<u64> = vars
        .iter()
        .map(|v| begins.iter().find(|(n, _)| *n == v.name).map_or(0, |b| b.1))
        .collect();
    let mut prefix = build(&ordered);
    for d in data {
        prefix.extend_from_slice(&d);
        pad4(&mut prefix);
    }
    Layout {
        prefix,
        rec_begin,
        rec_size: at - rec_begin,
    }
}

/// The writer of `histories.nc`.
pub(crate) struct Columnar {
    path: PathBuf,
    layout: Layout,
    /// Records written to the file.
    numrecs: u64,
    /// The record being filled.
    record: Vec<u8>,
    /// Whole records not yet written.
    pending: Vec<u8>,
    block: usize,
}

impl Columnar {
    /// Creates (truncates) the file and writes its header and id arrays.
    pub(crate) fn create(dir: &Path, title: &str, groups: &[Group]) -> io::Result<Self> {
        let path = dir.join(FILE_NAME);
        let layout = layout(title, groups);
        let mut f = crate::safe_file::create(&path)?;
        f.write_all(&layout.prefix)?;
        Ok(Self::with(path, layout, 0))
    }

    fn with(path: PathBuf, layout: Layout, numrecs: u64) -> Self {
        let rec = layout.rec_size as usize;
        // Blocks of about 4 MB, at least one record; the buffers never grow.
        let block = (4usize << 20).max(rec);
        Columnar {
            path,
            numrecs,
            record: Vec::with_capacity(rec),
            pending: Vec::with_capacity(block + rec),
            block,
            layout,
        }
    }

    /// Reopens the file of a stopped run, cut back to `len` bytes (its checkpoint). Its
    /// header must be the one this selection writes.
    pub(crate) fn reopen(dir: &Path, title: &str, groups: &[Group], len: u64) -> io::Result<Self> {
        let path = dir.join(FILE_NAME);
        let layout = layout(title, groups);
        let bad = |why: String| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: {why}", path.display()),
            )
        };
        let mut f = crate::safe_file::read_write(&path)?;
        let actual = f.metadata()?.len();
        if actual < len || len < layout.rec_begin {
            return Err(bad(format!(
                "{actual} bytes, not the {len} its checkpoint recorded"
            )));
        }
        let mut head = vec![0u8; layout.prefix.len()];
        f.read_exact(&mut head)?;
        head[4..8].fill(0);
        if head != layout.prefix {
            return Err(bad("its header is not the one of the deck's OUTPUT".into()));
        }
        let body = len - layout.rec_begin;
        if !body.is_multiple_of(layout.rec_size) {
            return Err(bad(format!("{len} bytes is not a whole number of records")));
        }
        let numrecs = body / layout.rec_size;
        f.set_len(len)?;
        f.seek(SeekFrom::Start(4))?;
        f.write_all(&(numrecs as u32).to_be_bytes())?;
        Ok(Self::with(path, layout, numrecs))
    }

    /// Starts the record of time `t`.
    pub(crate) fn begin(&mut self, t: f64) {
        self.record.clear();
        self.record.extend_from_slice(&t.to_be_bytes());
    }

    /// Appends values (an entity's columns after `t`, in group order) to the record.
    pub(crate) fn put(&mut self, values: &[f64]) {
        for v in values {
            self.record.extend_from_slice(&v.to_be_bytes());
        }
    }

    /// Ends the record: it joins the block, written once the block is full.
    pub(crate) fn end(&mut self) -> io::Result<()> {
        debug_assert_eq!(self.record.len() as u64, self.layout.rec_size);
        self.pending.extend_from_slice(&self.record);
        if self.pending.len() >= self.block {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the whole records buffered, then their count in the header.
    pub(crate) fn flush(&mut self) -> io::Result<()> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let f = crate::safe_file::write_existing(&self.path)?;
        let at = self.layout.rec_begin + self.numrecs * self.layout.rec_size;
        f.write_all_at(&self.pending, at)?;
        self.numrecs += (self.pending.len() as u64) / self.layout.rec_size;
        self.pending.clear();
        f.write_all_at(&(self.numrecs as u32).to_be_bytes(), 4)
    }

    /// Writes the buffered records and waits until the file is on the disk.
    pub(crate) fn sync(&mut self) -> io::Result<()> {
        self.flush()?;
        crate::safe_file::write_existing(&self.path)?.sync_data()
    }

    /// Length of the file once the buffered records are written, bytes.
    pub(crate) fn len(&self) -> u64 {
        self.layout.rec_begin + self.numrecs * self.layout.rec_size + self.pending.len() as u64
    }
}
