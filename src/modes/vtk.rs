//! The ParaView series of a modal analysis: one `.pvd` per mode, `vtk/mode_<k>.pvd`, whose
//! [`FRAMES`] frames go through one period of the mode, `vtk/mode_<k>_<j>.vtu` (the
//! writer of runs, [`crate::output::vtk`]: same cells, same point data).
//!
//! Frame `j` (phase `φ = 2πj/FRAMES`, time `j T/FRAMES` for a vibration, `j/FRAMES` for
//! a mode that does not oscillate) shows the state linearised about moved along the mode:
//! positions `x + a sin φ u`, rotations `R exp(a sin φ θ)` (the spin unknowns are
//! material), velocities `a ω cos φ u` and angular velocities `R a ω cos φ θ` (global),
//! displacement from the reference `x + a sin φ u − x₀`. The amplitude `a` makes the
//! mode's largest translation over the model `+`[`AMPLITUDE`]` × ` the model's size (or its
//! largest rotation +0.1 rad when it has no translation), so that frame `FRAMES/4`
//! (`sin φ = 1`) less frame 0 is the amplitude times `modes_shapes.csv`'s shape.

use super::{ModalAnalysis, Mode};
use crate::elements::NodeState;
use crate::model::Model;
use crate::output::vtk::{frame_xml, line_cells, write_collection};
use crate::rotation;
use crate::solver::system::{FIXED, System};
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::path::Path;

/// Frames per period.
pub const FRAMES: usize = 16;
/// Largest translation of a mode in its series, as a fraction of the model's size.
pub const AMPLITUDE: f64 = 0.05;
/// Largest rotation of a mode that has no translation, rad.
pub const ROTATION_AMPLITUDE: f64 = 0.1;

/// The amplitude of mode `m` in its series: (`a`, unit `"m"` or `"rad"`), with `a` divided
/// by the mode's signed largest translation (rotation) so that it scales the raw shape.
pub fn amplitude(sys: &System, m: &Mode) -> (f64, f64, &'static str) {
    let pick = |range: std::ops::Range<usize>| {
        sys.node_dofs
            .iter()
            .flat_map(|d| {
                range
                    .clone()
                    .map(|c| if d[c] == FIXED { 0.0 } else { m.shape[d[c]] })
            })
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(0.0)
    };
    match pick(0..3) {
        t if t != 0.0 => {
            let a = AMPLITUDE * sys.ref_length;
            (a / t, a, "m")
        }
        _ => match pick(3..6) {
            r if r != 0.0 => (ROTATION_AMPLITUDE / r, ROTATION_AMPLITUDE, "rad"),
            _ => (0.0, 0.0, "m"),
        },
    }
}

/// Writes `dir/vtk/mode_<k>.pvd` and its frames for every mode of `a` about the state
/// `nodes` of `sys`. Returns the `.pvd` files, relative to `dir`.
pub fn write_series(
    dir: &Path,
    model: &Model,
    sys: &System,
    nodes: &[NodeState],
    a: &ModalAnalysis,
) -> std::io::Result<Vec<String>> {
    std::fs::create_dir_all(dir)?;
    crate::safe_file::real_dir(&dir.join("vtk"))?;
    let cells = line_cells(model);
    let mut pvds = Vec::new();
    for (k, m) in a.modes.iter().enumerate() {
        let (scale, _, _) = amplitude(sys, m);
        let omega = 2.0 * PI * m.frequency_hz;
        let mut frames = Vec::with_capacity(FRAMES);
        for j in 0..FRAMES {
            let phase = 2.0 * PI * j as f64 / FRAMES as f64;
            let (sn, cs) = (scale * phase.sin(), scale * omega * phase.cos());
            let n = nodes.len();
            let (mut pts, mut disp, mut rot, mut vel, mut om) = (
                Vec::with_capacity(n),
                Vec::with_capacity(n),
                Vec::with_capacity(n),
                Vec::with_capacity(n),
                Vec::with_capacity(n),
            );
            for (i, s) in nodes.iter().enumerate() {
                let d = &sys.node_dofs[i];
                let comp = |c: usize| if d[c] == FIXED { 0.0 } else { m.shape[d[c]] };
                let u = Vector3::new(comp(0), comp(1), comp(2));
                let th = Vector3::new(comp(3), comp(4), comp(5));
                let x = s.x + u * sn;
                pts.push(x);
                disp.push(x - sys.x0[i]);
                rot.push(rotation::log(&(s.r * rotation::exp(&(th * sn)))));
                vel.push(u * cs);
                om.push(s.r * (th * cs));
            }
            let text = frame_xml(&cells, [&pts, &disp, &rot, &vel, &om])?;
            let rel = format!("vtk/mode_{:03}_{j:02}.vtu", k + 1);
            crate::safe_file::write(&dir.join(&rel), text.as_bytes())?;
            let t = match m.period() {
                Some(p) => p * j as f64 / FRAMES as f64,
                None => j as f64 / FRAMES as f64,
            };
            // The collection lists files relative to itself (in vtk/).
            frames.push((t, rel.trim_start_matches("vtk/").to_string()));
        }
        let pvd = format!("vtk/mode_{:03}.pvd", k + 1);
        write_collection(&dir.join(&pvd), &frames)?;
        pvds.push(pvd);
    }
    Ok(pvds)
}

/// `summary.json`'s `vtk` block: per mode its series and amplitude.
pub fn summary(sys: &System, a: &ModalAnalysis) -> serde_json::Value {
    let modes: Vec<serde_json::Value> = a
        .modes
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let (_, amp, unit) = amplitude(sys, m);
            serde_json::json!({
                "mode": k + 1,
                "series": format!("vtk/mode_{:03}.pvd", k + 1),
                "amplitude": amp,
                "unit": unit,
            })
        })
        .collect();
    serde_json::json!({
        "frames_per_period": FRAMES,
        "note": "frame FRAMES/4 less frame 0 = amplitude x the shape of modes_shapes.csv",
        "modes": modes,
    })
}
