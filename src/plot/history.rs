//! `plot history`: columns of node histories against time, runs overlaid.

use super::draw::*;
use super::table::axis_label;
use super::*;

/// `plot history`: returns the written file.
pub fn history(a: &HistoryArgs) -> Result<PathBuf, PlotError> {
    let c = &a.common;
    let fmt = format_of(&c.out, &["svg", "png"])?;
    let labels = labels_for(&a.runs, &c.labels)?;
    let columns: Vec<String> = a
        .columns
        .iter()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    if columns.is_empty() {
        return Err(PlotError::Usage("--columns: no column given".into()));
    }
    // panels[(node, column)] = one series per run
    let mut panels: Vec<(String, String, Vec<Series>)> = Vec::new();
    let mut tables: Vec<BTreeMap<u32, Table>> = Vec::new();
    for run in &a.runs {
        let mut m = BTreeMap::new();
        for &n in &a.nodes {
            m.insert(n, read_node(run, n)?);
        }
        tables.push(m);
    }
    for &n in &a.nodes {
        for col in &columns {
            let mut ss = Vec::new();
            for (ri, label) in labels.iter().enumerate() {
                let table = &tables[ri][&n];
                let t = table.column("t")?;
                let y = table.column(col)?;
                ss.push(Series {
                    label: label.clone(),
                    color: COLORS[ri % COLORS.len()],
                    points: (0..t.len())
                        .filter(|&i| in_window(t[i], c.from, c.to))
                        .map(|i| (t[i], y[i]))
                        .collect(),
                });
            }
            panels.push((format!("node {n}"), axis_label(col), ss));
        }
    }
    let title = c.title.clone().unwrap_or_else(|| {
        format!(
            "Time histories — {}",
            if labels.len() > 1 {
                labels.join(" vs ")
            } else {
                labels[0].clone()
            }
        )
    });
    let size = c.size.unwrap_or((900, 300 * panels.len() as u32 + 40));
    prepare_out(&c.out)?;
    ensure_font();
    let out = c.out.as_path();
    with_backend!(fmt, out, size, |root| {
        (|| -> Result<(), String> {
            let area = root
                .titled(&title, ("sans-serif", 20))
                .map_err(|e| e.to_string())?;
            let areas = area.split_evenly((panels.len(), 1));
            for (i, ((cap, ydesc, ss), p)) in panels.iter().zip(&areas).enumerate() {
                panel(p, cap, "t: time (s)", ydesc, ss, i == 0)?;
            }
            Ok(())
        })()
    });
    Ok(c.out.clone())
}
