//! Memory asked before it is taken (issue 35 §2): what a model will cost — its nodes and
//! elements, the unknowns of its system with their iteration matrix and LU factors, the
//! output buffers — estimated from counts before the nodes are generated (`a TO b`,
//! `DIVIDE n`, `--refine k`), and refused when it exceeds the memory available to the
//! process or the limit the user gave (`--max-memory`).
//!
//! **The estimate** ([`Footprint::bytes`]): the model's own entities at their in-memory
//! size (`size_of` of a node and of an element with their map slots), plus
//! [`UNKNOWN_BYTES`] per unknown — the measured cost of the iteration matrix, its LU
//! factors, the element-to-matrix maps and the integrator's vectors per unknown of a beam
//! chain, 1.46 kB at one million unknowns (docs/large.md, "Memory per unknown"; 1.5–2.2 kB
//! for smaller chains), the sparsest model there is: any other model costs at least this —
//! plus the writers' row buffers (16 MB) and a NetCDF block (4 MB). Six unknowns per free
//! node (the fixed ones carry none). A refusal therefore means the run could not fit, not
//! that it might not.
//!
//! **The limit** ([`limit`]): `--max-memory` when given ([`set_max_memory`]), else what the
//! system says the process may still take: `MemAvailable` of `/proc/meminfo`, lowered to the
//! room left under a cgroup's `memory.max` (a container, a Slurm job). Without either
//! (another system), no limit: the allocations themselves are fallible (`try_reserve`).

use std::sync::atomic::{AtomicU64, Ordering};

/// Bytes per unknown of the system (module docs; docs/large.md, measured at 1M unknowns).
pub const UNKNOWN_BYTES: u64 = 1460;
/// Bytes of the output's buffers: the writers' row budget (16 MB) and a NetCDF block (4 MB).
pub const BUFFER_BYTES: u64 = 20 << 20;
/// A map slot of an `IndexMap` entry beyond its key and value: the hash index (`usize`)
/// and the stored hash.
const SLOT_BYTES: u64 = 16;

/// The counts a model's memory is estimated from.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Footprint {
    /// Nodes.
    pub nodes: u64,
    /// Elements.
    pub elements: u64,
    /// Unknowns of the system (nodal degrees of freedom and multipliers).
    pub unknowns: u64,
}

impl Footprint {
    /// The estimate in bytes (module docs), saturating.
    pub fn bytes(&self) -> u64 {
        let node = std::mem::size_of::<super::Node>() as u64 + SLOT_BYTES;
        // An element: its record, its node list (two ids for most), its map slot.
        let element = std::mem::size_of::<super::Element>() as u64 + 8 + SLOT_BYTES;
        self.nodes
            .saturating_mul(node)
            .saturating_add(self.elements.saturating_mul(element))
            .saturating_add(self.unknowns.saturating_mul(UNKNOWN_BYTES))
            .saturating_add(BUFFER_BYTES)
    }
}

/// Where the limit comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Source {
    /// `--max-memory`.
    Option,
    /// The memory the system says is available.
    Available,
}

/// A model larger than the memory it may take.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{what} would take about {need} of memory ({nodes} nodes, {elements} elements, {unknowns} unknowns: {per} kB per unknown for the system, docs/large.md), more than the {limit} {origin}",
    need = human(*need),
    limit = human(*limit),
    per = UNKNOWN_BYTES as f64 / 1000.0,
    origin = match origin {
        Source::Option => "of --max-memory",
        Source::Available => "available (MemAvailable; --max-memory sets another limit)",
    },
)]
pub struct TooLarge {
    /// What was asked ("the model", "DIVIDE 1000000").
    pub what: String,
    /// The estimate, bytes.
    pub need: u64,
    /// The limit, bytes.
    pub limit: u64,
    /// Where the limit comes from.
    pub origin: Source,
    /// Nodes of the model asked for.
    pub nodes: u64,
    /// Elements.
    pub elements: u64,
    /// Unknowns.
    pub unknowns: u64,
}

/// A byte count in kB, MB, GB, TB (powers of 1000), three significant digits.
pub fn human(b: u64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut x = b as f64;
    let mut u = 0;
    while x >= 1000.0 && u + 1 < units.len() {
        x /= 1000.0;
        u += 1;
    }
    format!("{x:.3} {}", units[u])
}

/// `--max-memory`, bytes (0: not given).
static MAX_MEMORY: AtomicU64 = AtomicU64::new(0);

/// Sets the limit of this process (`--max-memory`); 0 goes back to the memory available.
pub fn set_max_memory(bytes: u64) {
    MAX_MEMORY.store(bytes, Ordering::SeqCst);
}

/// The limit in force and where it comes from; `None` when none is known.
pub fn limit() -> Option<(u64, Source)> {
    match MAX_MEMORY.load(Ordering::SeqCst) {
        0 => available().map(|b| (b, Source::Available)),
        b => Some((b, Source::Option)),
    }
}

/// The memory this process may still take: `MemAvailable`, lowered to the room under the
/// cgroup's `memory.max` (cgroup v2) when there is one.
pub fn available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let avail = meminfo.as_deref().and_then(|t| {
        t.lines()
            .find_map(|l| l.strip_prefix("MemAvailable:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            .map(|kb| kb.saturating_mul(1024))
    });
    let read = |p: &str| {
        std::fs::read_to_string(p)
            .ok()
            .and_then(|t| t.trim().parse::<u64>().ok())
    };
    let cgroup = match (
        read("/sys/fs/cgroup/memory.max"),
        read("/sys/fs/cgroup/memory.current"),
    ) {
        (Some(max), Some(cur)) => Some(max.saturating_sub(cur)),
        _ => None,
    };
    match (avail, cgroup) {
        (Some(a), Some(c)) => Some(a.min(c)),
        (a, c) => a.or(c),
    }
}

/// Checks `f` against the limit in force: `what` names the request in the refusal.
pub fn check(f: Footprint, what: &str) -> Result<(), TooLarge> {
    match limit() {
        Some((limit, origin)) => check_against(f, what, limit, origin),
        None => Ok(()),
    }
}

/// Checks `f` against `limit`.
pub fn check_against(f: Footprint, what: &str, limit: u64, origin: Source) -> Result<(), TooLarge> {
    let need = f.bytes();
    if need <= limit {
        return Ok(());
    }
    Err(TooLarge {
        what: what.to_string(),
        need,
        limit,
        origin,
        nodes: f.nodes,
        elements: f.elements,
        unknowns: f.unknowns,
    })
}

/// Reads `--max-memory`'s value: bytes, or with a suffix `k`, `M`, `G`, `T` (powers of
/// 1024, as `ulimit` and Slurm's `--mem`), e.g. `512M`, `2G`, `1.5G`.
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, mult) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let m: u64 = match c.to_ascii_uppercase() {
                'K' => 1 << 10,
                'M' => 1 << 20,
                'G' => 1 << 30,
                'T' => 1 << 40,
                _ => return Err(format!("`{t}`: the unit is k, M, G or T")),
            };
            (&t[..i], m)
        }
        _ => (t, 1),
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("`{t}` is not a size (e.g. 512M, 2G)"))?;
    let bytes = v * mult as f64;
    if !(1.0..1.8e19).contains(&bytes) {
        return Err(format!("`{t}`: a size from 1 byte to 16 EiB"));
    }
    Ok(bytes as u64)
}

impl super::Model {
    /// The model's [`Footprint`]: its nodes and elements, six unknowns per free node.
    pub fn footprint(&self) -> Footprint {
        let free: u64 = self
            .nodes
            .values()
            .map(|n| n.fixed.iter().filter(|f| !**f).count() as u64)
            .sum();
        Footprint {
            nodes: self.nodes.len() as u64,
            elements: self.elements.len() as u64,
            unknowns: free,
        }
    }

    /// The [`Footprint`] once the beams of `counts` are divided (each into `n` elements) and
    /// the interior nodes of their orders generated ([`Model::footprint_added`]).
    pub fn footprint_divided(&self, counts: &[(super::ElementId, u32)]) -> Footprint {
        self.footprint().plus(self.footprint_added(counts))
    }

    /// What dividing the beams of `counts` adds: `n − 1` free nodes and elements per beam
    /// divided into `n`, and `n (p − 1)` interior nodes for a beam of order `p` (divisions
    /// come first; the interior nodes are generated after them).
    pub fn footprint_added(&self, counts: &[(super::ElementId, u32)]) -> Footprint {
        let mut f = Footprint::default();
        for (beam, n) in counts {
            let n = u64::from((*n).max(1));
            let p = match self.elements.get(beam).map(|e| &e.kind) {
                Some(super::ElementKind::Beam { order, .. }) => u64::from((*order).max(1)),
                _ => 1,
            };
            let nodes = (n - 1).saturating_add(n.saturating_mul(p - 1));
            f.nodes = f.nodes.saturating_add(nodes);
            f.elements = f.elements.saturating_add(n - 1);
            f.unknowns = f.unknowns.saturating_add(nodes.saturating_mul(6));
        }
        f
    }
}

impl Footprint {
    /// The sum of two footprints (saturating).
    pub fn plus(self, o: Footprint) -> Footprint {
        Footprint {
            nodes: self.nodes.saturating_add(o.nodes),
            elements: self.elements.saturating_add(o.elements),
            unknowns: self.unknowns.saturating_add(o.unknowns),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_with_their_units() {
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("2g"), Ok(2 << 30));
        assert_eq!(parse_size("1.5G"), Ok(3 << 29));
        assert_eq!(parse_size("1000"), Ok(1000));
        for bad in ["", "G", "-1G", "0", "1X", "nan", "1e30"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    /// A million unknowns cost what docs/large.md measured, plus the model and the
    /// buffers; a limit below is a refusal that states the figure and the limit.
    #[test]
    fn the_estimate_is_refused_beyond_the_limit_with_its_figure() {
        let f = Footprint {
            nodes: 166_667,
            elements: 166_666,
            unknowns: 1_000_002,
        };
        let b = f.bytes();
        assert!(b > 1_460_000_000 && b < 1_460_000_000 + 200_000_000, "{b}");
        assert!(check_against(f, "the model", b, Source::Option).is_ok());
        let e = check_against(f, "the model", 1 << 30, Source::Option).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("1.074 GB") && m.contains("--max-memory"), "{m}");
        assert_eq!(
            Footprint {
                nodes: u64::MAX,
                ..f
            }
            .bytes(),
            u64::MAX
        );
    }
}
