//! `plot trajectory`: node paths in the XY, XZ and YZ planes.

use super::draw::*;
use super::*;

/// `plot trajectory`: returns the written file.
pub fn trajectory(a: &TrajectoryArgs) -> Result<PathBuf, PlotError> {
    let c = &a.common;
    let fmt = format_of(&c.out, &["svg", "png"])?;
    let labels = labels_for(&a.runs, &c.labels)?;
    let mut planes = Vec::new();
    for p in &a.planes {
        let p = p.trim().to_ascii_lowercase();
        let axes: Vec<char> = p.chars().collect();
        if axes.len() != 2 || axes[0] == axes[1] || !axes.iter().all(|c| "xyz".contains(*c)) {
            return Err(PlotError::Usage(format!(
                "--planes: {p:?} is not a plane (use xy, xz, yz, yx, zx or zy)"
            )));
        }
        planes.push((axes[0].to_string(), axes[1].to_string()));
    }
    // series[plane] = lines over runs × nodes
    let mut series: Vec<Vec<Series>> = planes.iter().map(|_| Vec::new()).collect();
    let mut k = 0;
    for (run, label) in a.runs.iter().zip(&labels) {
        for &n in &a.nodes {
            let table = read_node(run, n)?;
            let t = table.column("t")?;
            for (pi, (h, v)) in planes.iter().enumerate() {
                let xs = table.column(h)?;
                let ys = table.column(v)?;
                let points = (0..t.len())
                    .filter(|&i| in_window(t[i], c.from, c.to))
                    .map(|i| (xs[i], ys[i]))
                    .collect();
                let name = if a.runs.len() > 1 {
                    format!("{label}, node {n}")
                } else {
                    format!("node {n}")
                };
                series[pi].push(Series {
                    label: name,
                    color: COLORS[k % COLORS.len()],
                    points,
                });
            }
            k += 1;
        }
    }
    let title = c.title.clone().unwrap_or_else(|| {
        let nodes: Vec<String> = a.nodes.iter().map(|n| n.to_string()).collect();
        format!(
            "Trajectories of nodes {} — {}",
            nodes.join(", "),
            labels.join(" vs ")
        )
    });
    let size = c.size.unwrap_or((450 * planes.len() as u32, 480));
    prepare_out(&c.out)?;
    ensure_font();
    let out = c.out.as_path();
    with_backend!(fmt, out, size, |root| {
        (|| -> Result<(), String> {
            let area = root
                .titled(&title, ("sans-serif", 20))
                .map_err(|e| e.to_string())?;
            let panels = area.split_evenly((1, planes.len()));
            for (pi, ((h, v), p)) in planes.iter().zip(&panels).enumerate() {
                let cap = format!("{}{} plane", h.to_uppercase(), v.to_uppercase());
                panel(
                    p,
                    &cap,
                    &format!("{} (m)", h.to_uppercase()),
                    &format!("{} (m)", v.to_uppercase()),
                    &series[pi],
                    pi == 0,
                )?;
            }
            Ok(())
        })()
    });
    Ok(c.out.clone())
}
