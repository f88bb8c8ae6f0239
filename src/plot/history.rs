//! `plot history`: columns of node and element histories against time, runs overlaid.

use super::draw::*;
use super::table::{axis_label, read_element};
use super::*;

/// `plot history`: returns the written file.
pub fn history(a: &HistoryArgs) -> Result<PathBuf, PlotError> {
    let c = &a.common;
    let fmt = format_of(&c.out, &["svg", "png"])?;
    let labels = labels_for(&a.runs, &c.labels)?;
    let list = |cols: &[String]| -> Vec<String> {
        cols.iter()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect()
    };
    let columns = list(&a.columns);
    let element_columns = if a.element_columns.is_empty() {
        columns.clone()
    } else {
        list(&a.element_columns)
    };
    if !a.nodes.is_empty() && columns.is_empty() {
        return Err(PlotError::Usage("--columns: no column given".into()));
    }
    if !a.elements.is_empty() && element_columns.is_empty() {
        return Err(PlotError::Usage(
            "--element-columns (or --columns): no column given".into(),
        ));
    }
    // What is drawn: (caption, one table per run, its columns), nodes then elements.
    let mut sources: Vec<(String, Vec<Table>, &[String])> = Vec::new();
    for &n in &a.nodes {
        let tables = a
            .runs
            .iter()
            .map(|r| read_node(r, n))
            .collect::<Result<_, _>>()?;
        sources.push((format!("node {n}"), tables, &columns));
    }
    for &e in &a.elements {
        let tables = a
            .runs
            .iter()
            .map(|r| read_element(r, e))
            .collect::<Result<_, _>>()?;
        sources.push((format!("element {e}"), tables, &element_columns));
    }
    // panels[(source, column)] = one series per run
    let mut panels: Vec<(String, String, Vec<Series>)> = Vec::new();
    for (caption, tables, cols) in &sources {
        for col in cols.iter() {
            let mut ss = Vec::new();
            for (ri, label) in labels.iter().enumerate() {
                let table = &tables[ri];
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
            panels.push((caption.clone(), axis_label(col), ss));
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
