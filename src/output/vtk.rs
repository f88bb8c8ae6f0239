//! ParaView output (`OUTPUT … VTK`): a `.pvd` collection of ASCII XML `.vtu` files.
//!
//! In the output directory: `model.pvd` (the time series, open it in ParaView) and
//! `vtk/frame_<k>.vtu`, one unstructured grid per written state (every `EVERY`-th step,
//! like the CSV histories). Points are the nodes at their current positions (deck order);
//! cells are the beams and the segments of rigid bodies (chains of their nodes) as
//! `VTK_LINE` (type 3), with the element number as cell data `element`. Point data (global
//! frame, SI units): `displacement` (m), `rotation` (rotation vector, log of the nodal
//! rotation, rad), `velocity` (m/s), `angular_velocity` (rad/s). After the nodes come the
//! meshes elements draw ([`crate::elements::Element::mesh`]): a superelement's FE nodes,
//! recovered from its frame and elastic coordinates, joined by the lines of its `K`'s graph,
//! their cells numbered by the superelement.
//!
//! `model.pvd` is rewritten every [`PVD_EVERY`] frames and at the end, so a run that stops
//! early leaves a readable series. No NaN or infinity is written: such a value stops the run
//! like a CSV row would.

use crate::model::{ElementKind, Model};
use crate::rotation;
use crate::solver::{Observer, Snapshot, Stats, System};
use std::fmt::Write as _;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// The cell type of a two-node line in VTK.
pub const VTK_LINE: u8 = 3;
/// The `.pvd` is rewritten every this many frames (and at the end).
pub const PVD_EVERY: usize = 50;
/// Name of the collection file in the output directory.
pub const PVD_NAME: &str = "model.pvd";

/// What a [`VtkWriter`] needs to go on after a restart: the frames written so far.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VtkState {
    frames: Vec<(f64, String)>,
    last_step: Option<u64>,
}

/// Streams the deformed model to a ParaView series.
pub struct VtkWriter {
    dir: PathBuf,
    sampling: super::Sampling,
    /// Line cells: (element number, dense node index 1, dense node index 2).
    cells: Vec<(u32, usize, usize)>,
    /// (time, file relative to the output directory) of each frame.
    frames: Vec<(f64, String)>,
    last_step: Option<u64>,
}

impl VtkWriter {
    /// Creates `dir/vtk/` and an empty `dir/model.pvd`.
    pub fn create(dir: &Path, model: &Model, sys: &System) -> io::Result<Self> {
        let w = Self::create_in(dir, model, sys)?;
        w.write_pvd()?;
        Ok(w)
    }

    fn create_in(dir: &Path, model: &Model, _sys: &System) -> io::Result<Self> {
        fs::create_dir_all(dir)?;
        crate::safe_file::real_dir(&dir.join("vtk"))?;
        let cells = line_cells(model);
        let w = VtkWriter {
            dir: dir.to_path_buf(),
            sampling: super::Sampling::of(model),
            cells,
            frames: Vec::new(),
            last_step: None,
        };
        Ok(w)
    }

    /// Number of line cells per frame.
    pub fn n_cells(&self) -> usize {
        self.cells.len()
    }

    fn write_frame(&mut self, snap: &Snapshot) -> io::Result<()> {
        let integ = snap.integ;
        let n = integ.nodes.len();
        let mut pts = Vec::with_capacity(n);
        let mut disp = Vec::with_capacity(n);
        let mut rot = Vec::with_capacity(n);
        let mut vel = Vec::with_capacity(n);
        let mut omega = Vec::with_capacity(n);
        for (i, s) in integ.nodes.iter().enumerate() {
            pts.push(s.x);
            disp.push(s.x - integ.sys.x0[i]);
            rot.push(rotation::log(&s.r));
            vel.push(s.v);
            omega.push(s.r * s.w);
        }
        // Meshes elements draw beyond the nodes (a superelement's FE mesh), appended.
        let mut cells = std::borrow::Cow::Borrowed(&self.cells);
        for el in &integ.sys.elements {
            if let Some(m) = el.mesh(&integ.nodes) {
                let off = pts.len();
                pts.extend(m.points);
                disp.extend(m.displacement);
                rot.extend(m.rotation);
                vel.extend(m.velocity);
                omega.extend(m.angular_velocity);
                let id = el.id().0;
                cells
                    .to_mut()
                    .extend(m.lines.iter().map(|&(a, b)| (id, off + a, off + b)));
            }
        }
        let s = frame_xml(&cells, [&pts, &disp, &rot, &vel, &omega])?;
        let rel = format!("vtk/frame_{:06}.vtu", self.frames.len());
        crate::safe_file::write(&self.dir.join(&rel), s.as_bytes())?;
        self.frames.push((integ.t, rel));
        self.last_step = Some(snap.step);
        if self.frames.len().is_multiple_of(PVD_EVERY) {
            self.write_pvd()?;
        }
        Ok(())
    }

    fn write_pvd(&self) -> io::Result<()> {
        write_collection(&self.dir.join(PVD_NAME), &self.frames)
    }

    /// The state a restart needs: the frames written so far (the `.pvd` is rewritten
    /// with them now). Frames written after it are written again by the restart.
    pub fn save_state(&self) -> io::Result<VtkState> {
        self.write_pvd()?;
        Ok(VtkState {
            frames: self.frames.clone(),
            last_step: self.last_step,
        })
    }

    /// Goes on from a [`VtkWriter::save_state`] in `dir` (the series is cut back to it).
    pub fn resume(dir: &Path, model: &Model, sys: &System, state: &VtkState) -> io::Result<Self> {
        let mut w = Self::create_in(dir, model, sys)?;
        w.frames = state.frames.clone();
        w.last_step = state.last_step;
        w.write_pvd()?;
        Ok(w)
    }

    /// Writes the final state if `EVERY` skipped it (not for an interrupted run, which a
    /// restart goes on from), and the complete `.pvd`.
    pub fn finish(
        &mut self,
        integ: &crate::solver::Integrator,
        interrupted: bool,
    ) -> io::Result<()> {
        if self.last_step != Some(integ.stats.steps) && !interrupted {
            self.write_frame(&Snapshot {
                integ,
                step: integ.stats.steps,
                h: 0.0,
            })?;
        }
        self.write_pvd()
    }
}

impl Observer for VtkWriter {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        if self.sampling.takes(snap) {
            self.write_frame(snap)?;
        }
        Ok(())
    }

    /// Positions and rotations only.
    fn reads_reactions(&self, _snap: &Snapshot) -> bool {
        false
    }
}

/// The line cells of a model: (element number, dense node 1, dense node 2) for each
/// segment of its beams and rigid bodies.
pub fn line_cells(model: &Model) -> Vec<(u32, usize, usize)> {
    let mut cells = Vec::new();
    for el in model.elements.values() {
        if matches!(el.kind, ElementKind::Beam { .. } | ElementKind::Rigid) {
            let idx: Vec<usize> = el
                .nodes
                .iter()
                .filter_map(|n| model.nodes.get_index_of(n))
                .collect();
            for w in idx.windows(2) {
                cells.push((el.id.0, w[0], w[1]));
            }
        }
    }
    cells
}

/// One `.vtu` frame's text: points `all[0]` and point data `displacement`, `rotation`,
/// `velocity`, `angular_velocity` (`all[1..]`), the line `cells`. Refuses a non-finite value.
pub fn frame_xml(
    cells: &[(u32, usize, usize)],
    all: [&[nalgebra::Vector3<f64>]; 5],
) -> io::Result<String> {
    let [pts, disp, rot, vel, omega] = all;
    if all
        .iter()
        .any(|a| a.iter().any(|v| !v.iter().all(|c| c.is_finite())))
    {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            "refusing to write a non-finite value (VTK frame)",
        ));
    }
    let vecs = |s: &mut String, name: Option<&str>, v: &[nalgebra::Vector3<f64>]| {
        match name {
            Some(nm) => {
                let _ = writeln!(
                    s,
                    "        <DataArray type=\"Float64\" Name=\"{nm}\" NumberOfComponents=\"3\" format=\"ascii\">"
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
                );
            }
        }
        for p in v {
            let _ = writeln!(s, "          {:e} {:e} {:e}", p.x, p.y, p.z);
        }
        s.push_str("        </DataArray>\n");
    };
    let n = pts.len();
    let mut s = String::with_capacity(4096 + 200 * n);
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">",
        cells.len()
    );
    s.push_str("      <PointData Vectors=\"displacement\">\n");
    vecs(&mut s, Some("displacement"), disp);
    vecs(&mut s, Some("rotation"), rot);
    vecs(&mut s, Some("velocity"), vel);
    vecs(&mut s, Some("angular_velocity"), omega);
    s.push_str("      </PointData>\n      <CellData Scalars=\"element\">\n        <DataArray type=\"Int32\" Name=\"element\" format=\"ascii\">\n         ");
    for c in cells {
        let _ = write!(s, " {}", c.0);
    }
    s.push_str("\n        </DataArray>\n      </CellData>\n      <Points>\n");
    vecs(&mut s, None, pts);
    s.push_str("      </Points>\n      <Cells>\n        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n         ");
    for c in cells {
        let _ = write!(s, " {} {}", c.1, c.2);
    }
    s.push_str("\n        </DataArray>\n        <DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n         ");
    for k in 0..cells.len() {
        let _ = write!(s, " {}", 2 * (k + 1));
    }
    s.push_str("\n        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n         ");
    for _ in cells {
        let _ = write!(s, " {VTK_LINE}");
    }
    s.push_str(
        "\n        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n",
    );
    Ok(s)
}

/// Writes a `.pvd` collection of `frames` (time, file relative to the collection's
/// directory) atomically (a temporary file renamed).
pub fn write_collection(path: &Path, frames: &[(f64, String)]) -> io::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, f) in frames {
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{f}\"/>"
        );
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    let tmp = path.with_extension("pvd.tmp");
    crate::safe_file::write_atomic(&tmp, path, s.as_bytes())
}

/// Forwards every state and progress report to several observers, in order (the first
/// error stops the run).
pub struct Fanout<'a>(pub Vec<&'a mut dyn Observer>);

impl Observer for Fanout<'_> {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        for o in &mut self.0 {
            o.state(snap)?;
        }
        Ok(())
    }

    fn progress(&mut self, t: f64, end: f64, stats: &Stats) {
        for o in &mut self.0 {
            o.progress(t, end, stats);
        }
    }

    fn reads_reactions(&self, snap: &Snapshot) -> bool {
        self.0.iter().any(|o| o.reads_reactions(snap))
    }

    fn pause(
        &mut self,
        integ: &crate::solver::Integrator,
        ctl: &crate::solver::LoopState,
    ) -> io::Result<crate::solver::Pause> {
        let mut out = crate::solver::Pause::Continue;
        for o in &mut self.0 {
            if o.pause(integ, ctl)? == crate::solver::Pause::Stop {
                out = crate::solver::Pause::Stop;
            }
        }
        Ok(out)
    }
}
