//! The one way a figure reaches a file (`plot`, `study`, `sweep`): the bundled font, the
//! backend chosen by the file's extension (`.svg`: plotters' SVG backend; anything else:
//! the bitmap backend, PNG), a white canvas, the figure's own drawing, and the file
//! written. Each figure draws on a `DrawingArea` of either backend, so the same code
//! gives both formats.

use plotters::prelude::FontStyle;
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

/// Registers the bundled font (DejaVu Sans, `assets/fonts/`) as plotters' "sans-serif",
/// once per process, so figures need no system font.
pub fn ensure_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
        // The font is compiled in and known to parse; a failure would only lose the text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, bytes);
    });
}

/// The format of a figure file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Vector (`.svg`).
    Svg,
    /// Bitmap (`.png`, encoded by the `image` crate from the extension).
    Png,
}

impl Format {
    /// `.svg` (any case) is SVG; every other extension goes to the bitmap backend.
    pub fn of(file: &Path) -> Format {
        let ext = file
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if ext.as_deref() == Some("svg") {
            Format::Svg
        } else {
            Format::Png
        }
    }
}

/// `draw_to!(format, file, size, |root| body)`: opens `file` on the backend of `format`
/// at `size` pixels, fills it white, evaluates `body` (a `Result<(), String>` drawing on
/// `root`, a `&DrawingArea` of that backend) and writes the file. The value is a
/// `Result<(), String>`.
macro_rules! draw_to {
    ($format:expr, $file:expr, $size:expr, |$root:ident| $body:expr) => {{
        $crate::figure::ensure_font();
        (|| -> Result<(), String> {
            use ::plotters::prelude::*;
            match $format {
                $crate::figure::Format::Svg => {
                    let area = SVGBackend::new($file, $size).into_drawing_area();
                    area.fill(&WHITE).map_err(|e| e.to_string())?;
                    let $root = &area;
                    $body?;
                    area.present().map_err(|e| e.to_string())
                }
                $crate::figure::Format::Png => {
                    let area = BitMapBackend::new($file, $size).into_drawing_area();
                    area.fill(&WHITE).map_err(|e| e.to_string())?;
                    let $root = &area;
                    $body?;
                    area.present().map_err(|e| e.to_string())
                }
            }
        })()
    }};
}
pub(crate) use draw_to;
