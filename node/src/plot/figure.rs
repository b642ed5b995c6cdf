//! A figure of time-series panels drawn with `plotters` to PNG and SVG: each panel has a caption, a time
//! axis in seconds, a y axis with its unit, the run's series, reference series overlaid, an optional
//! marked level (e.g. the fill level) and a legend. Text uses the DejaVu Sans font built into the binary,
//! so no system font is needed.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One line of a panel.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub t: Vec<f64>,
    pub y: Vec<f64>,
    /// Measured or analytic data (drawn dashed, in a second colour) rather than the run's.
    pub reference: bool,
}

#[derive(Clone, Debug, Default)]
pub struct Panel {
    pub title: String,
    /// The y axis's quantity and unit, e.g. "elevation (m)".
    pub y_label: String,
    pub series: Vec<Series>,
    /// A level marked across the panel, with its legend text.
    pub level: Option<(f64, String)>,
    /// The x axis's quantity and unit (empty: time, "t (s)").
    pub x_label: String,
    /// Mark every point of the run's series (for a few points, e.g. one per particle spacing).
    pub markers: bool,
}

#[derive(Clone, Debug, Default)]
pub struct Figure {
    pub title: String,
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
}

const FONT: &str = "sans-serif";
const RUN: RGBColor = RGBColor(0, 114, 178);
/// The colours of a panel's run series, in order (the first is [`RUN`]; Okabe & Ito's palette).
const RUNS: [RGBColor; 6] = [
    RUN,
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(117, 112, 179),
    RGBColor(153, 153, 153),
];
const REFERENCES: [RGBColor; 3] = [
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
];
const LEVEL: RGBColor = RGBColor(90, 90, 90);

/// Makes the built-in font the one plotters draws "sans-serif" text with (once per process).
pub fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("the built-in DejaVu Sans font is a valid TrueType font"));
    });
}

/// Lower and upper bound of the finite values, padded by 5 % (a flat series gets a unit-wide range).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-3)
    };
    (lo - pad, hi + pad)
}

/// The runs of finite points of a series (a NaN, e.g. a dry probe, breaks the line).
fn segments(s: &Series) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for (&t, &y) in s.t.iter().zip(&s.y) {
        if y.is_finite() {
            out.last_mut().expect("one at least").push((t, y));
        } else if !out.last().expect("one at least").is_empty() {
            out.push(Vec::new());
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    // The time axis spans the data exactly.
    let (lo, hi) = p
        .series
        .iter()
        .flat_map(|s| s.t.iter().copied())
        .filter(|t| t.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
            (a.min(t), b.max(t))
        });
    let (t0, t1) = if hi > lo {
        (lo, hi)
    } else {
        range([lo, hi].into_iter())
    };
    let (y0, y1) = range(
        p.series
            .iter()
            .flat_map(|s| s.y.iter().copied())
            .chain(p.level.as_ref().map(|l| l.0)),
    );
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(75)
        .build_cartesian_2d(t0..t1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(if p.x_label.is_empty() {
            "t (s)"
        } else {
            p.x_label.as_str()
        })
        .y_desc(p.y_label.as_str())
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()
        .map_err(e)?;
    if let Some((level, text)) = &p.level {
        let style = LEVEL.stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new(
                [(t0, *level), (t1, *level)],
                6,
                4,
                style,
            ))
            .map_err(e)?
            .label(text.as_str())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
    }
    let (mut k_ref, mut k_run) = (0, 0);
    for s in &p.series {
        let colour = if s.reference {
            k_ref += 1;
            REFERENCES[(k_ref - 1) % REFERENCES.len()]
        } else {
            k_run += 1;
            RUNS[(k_run - 1) % RUNS.len()]
        };
        let style = colour.stroke_width(2);
        for (i, seg) in segments(s).into_iter().enumerate() {
            if p.markers && !s.reference && seg.len() > 1 {
                chart
                    .draw_series(seg.iter().map(|&xy| Circle::new(xy, 3, colour.filled())))
                    .map_err(e)?;
            }
            // A value between two gaps (NaN) has no line to be part of: a dot.
            let drawn = if seg.len() == 1 {
                chart.draw_series(std::iter::once(Circle::new(seg[0], 3, colour.filled())))
            } else if s.reference {
                chart.draw_series(DashedLineSeries::new(seg, 8, 3, style))
            } else {
                chart.draw_series(LineSeries::new(seg, style))
            }
            .map_err(e)?;
            if i == 0 {
                drawn
                    .label(s.label.as_str())
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
            }
        }
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)?;
    Ok(())
}

/// Draws the figure on `root`.
pub fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, f: &Figure) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    register_font();
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let body = root.titled(&f.title, (FONT, 22)).map_err(e)?;
    let cols = f.columns.max(1);
    let rows = f.panels.len().div_ceil(cols).max(1);
    for (area, p) in body.split_evenly((rows, cols)).iter().zip(&f.panels) {
        draw_panel(area, p)?;
    }
    root.present().map_err(e)
}

/// Writes the figure as `stem.png` and `stem.svg`, `size` pixels; returns both paths.
pub fn save(f: &Figure, stem: &Path, size: (u32, u32)) -> Result<Vec<PathBuf>, String> {
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    let ctx = |p: &Path| {
        let p = p.display().to_string();
        move |e: String| format!("{p}: {e}")
    };
    draw(BitMapBackend::new(&png, size).into_drawing_area(), f).map_err(ctx(&png))?;
    draw(SVGBackend::new(&svg, size).into_drawing_area(), f).map_err(ctx(&svg))?;
    Ok(vec![png, svg])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_breaks_a_series_into_segments() {
        let s = Series {
            label: "p".into(),
            t: vec![0.0, 1.0, 2.0, 3.0, 4.0],
            y: vec![1.0, f64::NAN, 2.0, 3.0, f64::NAN],
            reference: false,
        };
        assert_eq!(
            segments(&s),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
        assert_eq!(range([f64::NAN].into_iter()), (-1.0, 1.0));
        let (lo, hi) = range([0.0, 10.0, f64::NAN].into_iter());
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12);
    }
}
