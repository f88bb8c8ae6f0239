//! `plot modes`: the shapes of a modal analysis in two planes and its frequencies, from the
//! directory `mecano-rs modes` wrote (`modes.csv`, `modes_shapes.csv`).
//!
//! Each shape is drawn through the output nodes in their deck order (a deck meant for the
//! figure writes them all along its beams: `OUTPUT NODES ALL`) at the positions of the
//! state linearised about (`x, y, z` of `modes_shapes.csv`) moved by `a` times the shape
//! (`ux, uy, uz`, largest translation +1), `a` = [`AMPLITUDE`] of the nodes' extent; the
//! state itself in grey. The last panel gives every mode's natural frequency against its
//! number; the legend names each drawn mode with its frequency as `modes.csv` has it.

use super::draw::*;
use super::*;

/// Drawn amplitude of a shape, as a fraction of the extent of the output nodes.
pub const AMPLITUDE: f64 = 0.15;

/// `mecano-rs plot modes MODES_DIR -o fig.svg`
#[derive(Args, Debug, Clone)]
pub struct ModesArgs {
    /// The directory `mecano-rs modes` wrote.
    #[arg(value_name = "MODES_DIR")]
    pub dir: PathBuf,
    /// Modes to draw (numbers of modes.csv), comma separated; default the first four.
    #[arg(long, value_delimiter = ',', value_name = "K")]
    pub modes: Vec<usize>,
    /// The two planes, comma separated (first letter: horizontal axis).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "xy,xz",
        value_name = "PLANES"
    )]
    pub planes: Vec<String>,
    /// Output file: `.svg` or `.png`.
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    pub out: PathBuf,
    /// Figure size in pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "1350x480")]
    pub size: (u32, u32),
}

/// One row of modes.csv: number, kind, natural frequency (Hz).
fn read_modes(dir: &Path) -> Result<Vec<(usize, String, f64)>, PlotError> {
    let file = dir.join("modes.csv");
    let text =
        crate::safe_file::read_text(&file, crate::safe_file::MAX_TEXT_BYTES).map_err(|_| {
            PlotError::NoFile {
                file: file.clone(),
                hint: "run mecano-rs modes DECK -o DIR first".into(),
            }
        })?;
    let bad = |msg: &str| PlotError::Read {
        file: file.clone(),
        msg: msg.to_string(),
    };
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or(bad("empty"))?.split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|c| *c == name)
            .ok_or(bad(&format!("no column {name}")))
    };
    let (cm, ck, cf) = (col("mode")?, col("kind")?, col("natural_hz")?);
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let get = |i: usize| f.get(i).copied().ok_or(bad("short row"));
            Ok((
                get(cm)?.parse().map_err(|_| bad("bad mode number"))?,
                get(ck)?.to_string(),
                get(cf)?.parse().map_err(|_| bad("bad frequency"))?,
            ))
        })
        .collect()
}

/// The label of mode `k` of frequency `f` Hz in the legend.
pub fn label(k: usize, f: f64) -> String {
    format!("mode {k}: {f:.6e} Hz")
}

fn plane_axes(p: &str) -> Result<(usize, usize, String), PlotError> {
    let p = p.trim().to_ascii_lowercase();
    let axes: Vec<usize> = p.chars().filter_map(|c| "xyz".find(c)).collect();
    if axes.len() != 2 || p.len() != 2 || axes[0] == axes[1] {
        return Err(PlotError::Usage(format!(
            "--planes: {p:?} is not a plane (use xy, xz, yz, yx, zx or zy)"
        )));
    }
    Ok((axes[0], axes[1], p.to_uppercase()))
}

/// `plot modes`: returns the written file.
pub fn modes(a: &ModesArgs) -> Result<PathBuf, PlotError> {
    let fmt = format_of(&a.out, &["svg", "png"])?;
    if !a.dir.is_dir() {
        return Err(PlotError::NoDir(a.dir.clone()));
    }
    if a.planes.len() != 2 {
        return Err(PlotError::Usage("--planes: give two planes".into()));
    }
    let planes = a
        .planes
        .iter()
        .map(|p| plane_axes(p))
        .collect::<Result<Vec<_>, _>>()?;
    let list = read_modes(&a.dir)?;
    let wanted: Vec<usize> = if a.modes.is_empty() {
        list.iter().map(|m| m.0).take(4).collect()
    } else {
        a.modes.clone()
    };
    let shapes = Table::read(&a.dir.join("modes_shapes.csv"))?;
    let idx = |n: &str| shapes.index(n);
    let (cm, cu, cx) = (
        idx("mode")?,
        [idx("ux")?, idx("uy")?, idx("uz")?],
        [idx("x")?, idx("y")?, idx("z")?],
    );
    let rows_of = |k: usize| -> Vec<&Vec<f64>> {
        shapes.rows.iter().filter(|r| r[cm] as usize == k).collect()
    };
    let first = rows_of(list.first().map_or(1, |m| m.0));
    let extent = (0..3)
        .map(|c| {
            let (lo, hi) = first
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), r| {
                    (l.min(r[cx[c]]), h.max(r[cx[c]]))
                });
            hi - lo
        })
        .fold(0.0f64, f64::max);
    let amp = AMPLITUDE * if extent > 0.0 { extent } else { 1.0 };
    let mut panels: Vec<Vec<Series>> = vec![Vec::new(), Vec::new()];
    for (pi, (h, v, _)) in planes.iter().enumerate() {
        panels[pi].push(Series {
            label: "state".into(),
            color: RGBColor(170, 170, 170),
            points: first.iter().map(|r| (r[cx[*h]], r[cx[*v]])).collect(),
        });
    }
    for (i, &k) in wanted.iter().enumerate() {
        let Some(m) = list.iter().find(|m| m.0 == k) else {
            return Err(PlotError::Usage(format!(
                "--modes: mode {k} is not in {}",
                a.dir.join("modes.csv").display()
            )));
        };
        let rows = rows_of(k);
        for (pi, (h, v, _)) in planes.iter().enumerate() {
            panels[pi].push(Series {
                label: label(k, m.2),
                color: COLORS[i % COLORS.len()],
                points: rows
                    .iter()
                    .map(|r| (r[cx[*h]] + amp * r[cu[*h]], r[cx[*v]] + amp * r[cu[*v]]))
                    .collect(),
            });
        }
    }
    let freqs = vec![Series {
        label: "natural frequency".into(),
        color: COLORS[0],
        points: list.iter().map(|m| (m.0 as f64, m.2)).collect(),
    }];
    let title = format!("Modes — {}", a.dir.display());
    prepare_out(&a.out)?;
    ensure_font();
    let out = a.out.as_path();
    with_backend!(fmt, out, a.size, |root| {
        (|| -> Result<(), String> {
            let area = root
                .titled(&title, ("sans-serif", 20))
                .map_err(|e| e.to_string())?;
            let cells = area.split_evenly((1, 3));
            for (pi, (h, v, name)) in planes.iter().enumerate() {
                let axis = |c: usize| format!("{} (m)", ["X", "Y", "Z"][c]);
                panel(
                    &cells[pi],
                    &format!("{name} plane (shapes × {amp:.3} m)"),
                    &axis(*h),
                    &axis(*v),
                    &panels[pi],
                    pi == 0,
                )?;
            }
            panel(
                &cells[2],
                "Frequencies",
                "mode",
                "natural frequency (Hz)",
                &freqs,
                false,
            )
        })()
    });
    Ok(a.out.clone())
}
