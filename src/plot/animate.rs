//! `plot animate`: the whole model in elevation and plan as an animated GIF, with the
//! connectivity read from the run's deck.

use super::draw::*;
use super::*;

/// The deck named in `dir/summary.json`.
pub fn deck_of(dir: &Path) -> Result<PathBuf, PlotError> {
    let file = dir.join("summary.json");
    let text =
        crate::safe_file::read_text(&file, crate::safe_file::MAX_TEXT_BYTES).map_err(|_| {
            PlotError::NoFile {
                file: file.clone(),
                hint: "not a run's output directory? give the deck with --deck".into(),
            }
        })?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| PlotError::Read {
        file: file.clone(),
        msg: e.to_string(),
    })?;
    v.get("deck")
        .and_then(|d| d.as_str())
        .map(PathBuf::from)
        .ok_or_else(|| PlotError::Read {
            file,
            msg: "no \"deck\" entry: give the deck with --deck".into(),
        })
}

/// The `--refine` factor recorded in `dir/summary.json` (1 when absent).
pub fn refine_of(dir: &Path) -> u32 {
    crate::safe_file::read_text(&dir.join("summary.json"), crate::safe_file::MAX_TEXT_BYTES)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v.get("refine").and_then(|r| r.as_u64()))
        .and_then(|r| u32::try_from(r).ok())
        .unwrap_or(1)
}

/// The segments to draw for a model: pairs of node numbers (beams, rigid bodies as chains,
/// joints), and whether each is a joint.
pub fn connectivity(model: &Model) -> Vec<(u32, u32, bool)> {
    let mut segs = Vec::new();
    for el in model.elements.values() {
        let ids: Vec<u32> = el.nodes.iter().map(|n| n.0).collect();
        match &el.kind {
            ElementKind::Beam { .. } | ElementKind::Rigid => {
                for w in ids.windows(2) {
                    segs.push((w[0], w[1], false));
                }
            }
            ElementKind::Mass { .. } | ElementKind::Came(_) => {}
            _ => {
                if ids.len() == 2 {
                    segs.push((ids[0], ids[1], true));
                }
            }
        }
    }
    segs
}

/// `plot animate`: returns the written file.
pub fn animate(a: &AnimateArgs) -> Result<PathBuf, PlotError> {
    let ext = a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if ext != "gif" {
        return Err(PlotError::Usage(format!(
            "{}: the animation is written as a GIF: the output file must end in .gif",
            a.out.display()
        )));
    }
    if a.frames == 0 {
        return Err(PlotError::Usage("--frames must be at least 1".into()));
    }
    if !a.run.is_dir() {
        return Err(PlotError::NoDir(a.run.clone()));
    }
    let deck = match &a.deck {
        Some(d) => d.clone(),
        None => deck_of(&a.run)?,
    };
    if !deck.is_file() {
        return Err(PlotError::NoFile {
            file: deck,
            hint: "the deck of the run (from summary.json, relative to the directory the run was started in); give it with --deck".into(),
        });
    }
    // Prints the deck's diagnostics on failure.
    // The run's mesh: a run with --refine k records k in summary.json.
    let refine = refine_of(&a.run);
    let model = crate::app::load_refined(&deck, refine).map_err(|_| PlotError::Read {
        file: deck.clone(),
        msg: "the deck has errors (shown above)".into(),
    })?;
    let segs = connectivity(&model);
    let masses: Vec<u32> = model
        .elements
        .values()
        .filter(|e| matches!(e.kind, ElementKind::Mass { .. }))
        .map(|e| e.nodes[0].0)
        .collect();
    // Node histories: every drawn node needs one, except fully fixed nodes (drawn in place).
    let mut drawn: Vec<u32> = segs
        .iter()
        .flat_map(|s| [s.0, s.1])
        .chain(masses.iter().copied())
        .collect();
    drawn.sort_unstable();
    drawn.dedup();
    let mut tables: BTreeMap<u32, Table> = BTreeMap::new();
    let mut missing = Vec::new();
    for &n in &drawn {
        match read_node(&a.run, n) {
            Ok(t) => {
                tables.insert(n, t);
            }
            Err(PlotError::NoFile { .. }) => {
                let fixed = model
                    .nodes
                    .get(&crate::model::NodeId(n))
                    .is_some_and(|nd| nd.fixed[..3].iter().all(|&f| f));
                if !fixed {
                    missing.push(n);
                }
            }
            Err(e) => return Err(e),
        }
    }
    if !missing.is_empty() {
        return Err(PlotError::NoFile {
            file: a.run.join(format!("node_{}.csv", missing[0])),
            hint: format!(
                "the animation needs the history of every moving node; missing: {}; run the deck with OUTPUT NODES ALL",
                missing
                    .iter()
                    .map(|n| n.to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
        });
    }
    let Some(first) = tables.values().next() else {
        return Err(PlotError::Usage("no node history to animate".into()));
    };
    let t = first.column("t")?;
    let n_rows = tables.values().map(|t| t.rows.len()).min().unwrap_or(0);
    let rows: Vec<usize> = (0..n_rows)
        .filter(|&i| in_window(t[i], a.from, a.to))
        .collect();
    if rows.is_empty() {
        return Err(PlotError::Usage("no rows in the chosen time window".into()));
    }
    let (ix, iy, iz) = (first.index("x")?, first.index("y")?, first.index("z")?);
    let pos = |n: u32, row: usize| -> (f64, f64, f64) {
        match tables.get(&n) {
            Some(t) => (t.rows[row][ix], t.rows[row][iy], t.rows[row][iz]),
            None => {
                let p = model.nodes[&crate::model::NodeId(n)].position;
                (p.x, p.y, p.z)
            }
        }
    };
    // Fixed axis ranges over all frames, equal scales in both panels.
    let all = || {
        rows.iter()
            .flat_map(|&r| drawn.iter().map(move |&n| (n, r)))
    };
    let xr = range_of(all().map(|(n, r)| pos(n, r).0));
    let yr = range_of(all().map(|(n, r)| pos(n, r).1));
    let zr = range_of(all().map(|(n, r)| pos(n, r).2));
    let (w, h) = a.size;
    let pw = f64::from(w / 2 - 100);
    let ph = f64::from(h - 120);
    let equal = |hr: (f64, f64), vr: (f64, f64)| {
        let sx = (hr.1 - hr.0) / pw;
        let sy = (vr.1 - vr.0) / ph;
        let s = sx.max(sy);
        let grow = |r: (f64, f64), len: f64| {
            let mid = 0.5 * (r.0 + r.1);
            (mid - 0.5 * s * len, mid + 0.5 * s * len)
        };
        (grow(hr, pw), grow(vr, ph))
    };
    let (ex, ey) = equal(xr, yr);
    let (px, pz) = equal(xr, zr);
    let step = (rows.len() as f64 / a.frames as f64).max(1.0);
    let frames: Vec<usize> = (0..a.frames.min(rows.len()))
        .map(|k| rows[((k as f64 * step) as usize).min(rows.len() - 1)])
        .collect();
    prepare_out(&a.out)?;
    ensure_font();
    let draw_err = |msg: String| PlotError::Draw {
        file: a.out.clone(),
        msg,
    };
    let root = BitMapBackend::gif(&a.out, a.size, a.delay)
        .map_err(|e| draw_err(e.to_string()))?
        .into_drawing_area();
    let title = model.title.clone();
    for &row in &frames {
        (|| -> Result<(), String> {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let mut head = String::new();
            let _ = write!(head, "{title} — t = {:.3} s", t[row]);
            let area = root
                .titled(&head, ("sans-serif", 18))
                .map_err(|e| e.to_string())?;
            let halves = area.split_evenly((1, 2));
            for (k, p) in halves.iter().enumerate() {
                let (hr, vr, vdesc, cap) = if k == 0 {
                    (ex, ey, "Y (m)", "elevation (X–Y)")
                } else {
                    (px, pz, "Z (m)", "plan (X–Z)")
                };
                let proj = |n: u32| {
                    let q = pos(n, row);
                    if k == 0 { (q.0, q.1) } else { (q.0, q.2) }
                };
                let mut chart = ChartBuilder::on(p)
                    .caption(cap, ("sans-serif", 15))
                    .margin(10)
                    .x_label_area_size(40)
                    .y_label_area_size(55)
                    .build_cartesian_2d(hr.0..hr.1, vr.0..vr.1)
                    .map_err(|e| e.to_string())?;
                chart
                    .configure_mesh()
                    .x_desc("X (m)")
                    .y_desc(vdesc)
                    .axis_desc_style(("sans-serif", 13))
                    .label_style(("sans-serif", 11))
                    .light_line_style(WHITE.mix(0.0))
                    .draw()
                    .map_err(|e| e.to_string())?;
                chart
                    .draw_series(segs.iter().map(|&(n1, n2, joint)| {
                        let style = if joint {
                            RGBColor(120, 120, 120).stroke_width(1)
                        } else {
                            COLORS[0].stroke_width(3)
                        };
                        PathElement::new(vec![proj(n1), proj(n2)], style)
                    }))
                    .map_err(|e| e.to_string())?;
                chart
                    .draw_series(
                        masses
                            .iter()
                            .map(|&n| Circle::new(proj(n), 5, COLORS[1].filled())),
                    )
                    .map_err(|e| e.to_string())?;
            }
            root.present().map_err(|e| e.to_string())
        })()
        .map_err(draw_err)?;
    }
    Ok(a.out.clone())
}
