//! What every figure of `plot` shares: colours, the bundled font, the backend chosen by
//! the file's extension, padded ranges, tick labels and the line-chart panel.

use super::*;

pub(super) const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

pub(crate) use crate::figure::{Format, ensure_font};

pub(super) fn format_of(out: &Path, allowed: &[&str]) -> Result<Format, PlotError> {
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !allowed.contains(&ext.as_str()) {
        return Err(PlotError::Usage(format!(
            "{}: the output file must end in {}",
            out.display(),
            allowed
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(" or ")
        )));
    }
    Ok(if ext == "svg" {
        Format::Svg
    } else {
        Format::Png
    })
}

pub(super) fn prepare_out(out: &Path) -> Result<(), PlotError> {
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| PlotError::Draw {
            file: out.to_path_buf(),
            msg: e.to_string(),
        })?;
    }
    Ok(())
}

/// Draws on an SVG or PNG backend chosen by the file's extension ([`crate::figure`]).
macro_rules! with_backend {
    ($fmt:expr, $out:expr, $size:expr, |$root:ident| $body:expr) => {{
        crate::figure::draw_to!($fmt, $out, $size, |$root| $body).map_err(|msg| {
            PlotError::Draw {
                file: $out.to_path_buf(),
                msg,
            }
        })?;
    }};
}

/// A series: a label, a colour and points.
pub(super) struct Series {
    pub(super) label: String,
    pub(super) color: RGBColor,
    pub(super) points: Vec<(f64, f64)>,
}

/// A padded range covering `values` (never empty, never degenerate).
pub(super) fn range_of(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    let min_span = 1e-12_f64.max(1e-9 * lo.abs().max(hi.abs()));
    if span < min_span {
        let mid = 0.5 * (lo + hi);
        return (mid - min_span, mid + min_span);
    }
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// Tick labels: plain for ordinary magnitudes, scientific otherwise.
pub(super) fn tick(v: &f64, range: (f64, f64)) -> String {
    let m = range.0.abs().max(range.1.abs());
    if *v == 0.0 {
        "0".into()
    } else if !(1e-2..1e4).contains(&m) {
        format!("{v:.2e}")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.into() }
    }
}

/// One panel: a line chart of the series with labelled axes and a legend.
pub(super) fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    xdesc: &str,
    ydesc: &str,
    series: &[Series],
    legend: bool,
) -> Result<(), String> {
    let xr = range_of(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let yr = range_of(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(|e| e.to_string())?;
    let fx = move |v: &f64| tick(v, xr);
    let fy = move |v: &f64| tick(v, yr);
    chart
        .configure_mesh()
        .x_desc(xdesc)
        .y_desc(ydesc)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .axis_desc_style(("sans-serif", 15))
        .label_style(("sans-serif", 12))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(|e| e.to_string())?;
    for s in series {
        let color = s.color;
        chart
            .draw_series(LineSeries::new(
                s.points.iter().copied(),
                color.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?
            .label(s.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    if legend && !series.is_empty() {
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}
