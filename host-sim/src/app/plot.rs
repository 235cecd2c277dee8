//! SVG plots: line charts with optional limit lines and shaded bands.

use plotters::prelude::*;
use std::path::Path;

/// A named series of (x, y) points.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points.
    pub points: Vec<(f64, f64)>,
    /// Draw points instead of a line.
    pub markers: bool,
}

/// A horizontal line (a limit) or a shaded x-interval.
pub enum Mark {
    /// Horizontal line at y with a label.
    HLine(String, f64),
    /// Vertical line at x with a label.
    VLine(String, f64),
    /// Shaded band [x0, x1) with a label, in light red (true) or light green (false).
    Band(String, f64, f64, bool),
}

/// A line chart.
pub struct Chart<'a> {
    /// Title.
    pub title: &'a str,
    /// X-axis label.
    pub x_label: &'a str,
    /// Y-axis label.
    pub y_label: &'a str,
    /// Series.
    pub series: Vec<Series>,
    /// Marks.
    pub marks: Vec<Mark>,
}

const COLORS: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

fn bounds(chart: &Chart) -> (f64, f64, f64, f64) {
    let mut x0 = f64::INFINITY;
    let mut x1 = f64::NEG_INFINITY;
    let mut y0 = f64::INFINITY;
    let mut y1 = f64::NEG_INFINITY;
    for s in &chart.series {
        for &(x, y) in &s.points {
            if x.is_finite() && y.is_finite() {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    for m in &chart.marks {
        match *m {
            Mark::HLine(_, y) if y.is_finite() => {
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
            Mark::VLine(_, x) if x.is_finite() => {
                x0 = x0.min(x);
                x1 = x1.max(x);
            }
            _ => {}
        }
    }
    if !x0.is_finite() {
        (x0, x1) = (0.0, 1.0);
    }
    if !y0.is_finite() {
        (y0, y1) = (0.0, 1.0);
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    let pad = if y1 > y0 {
        0.05 * (y1 - y0)
    } else {
        0.5 * y0.abs().max(1e-12)
    };
    (x0, x1, y0 - pad, y1 + pad)
}

/// Writes `chart` as an SVG file.
pub fn write_svg(path: &Path, chart: &Chart) -> Result<(), String> {
    write_svg_with_legend(path, chart, None)
}

/// Writes `chart` as an SVG file with the legend at `legend` (plotters' default place when
/// `None`), for charts whose data fill that place.
pub fn write_svg_with_legend(
    path: &Path,
    chart: &Chart,
    legend: Option<SeriesLabelPosition>,
) -> Result<(), String> {
    let root = SVGBackend::new(path, (960, 540)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (x0, x1, y0, y1) = bounds(chart);
    let mut c = ChartBuilder::on(&root)
        .caption(chart.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    c.configure_mesh()
        .x_desc(chart.x_label)
        .y_desc(chart.y_label)
        .draw()
        .map_err(|e| e.to_string())?;
    for m in &chart.marks {
        if let Mark::Band(label, a, b, red) = m {
            let color = if *red {
                RGBColor(255, 200, 200)
            } else {
                RGBColor(205, 240, 205)
            };
            let b = if b.is_finite() { b.min(x1) } else { x1 };
            c.draw_series(std::iter::once(Rectangle::new(
                [(a.max(x0), y0), (b, y1)],
                color.filled(),
            )))
            .map_err(|e| e.to_string())?
            .label(label.as_str())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 15, y + 5)], color.filled()));
        }
    }
    for (i, s) in chart.series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let pts = s
            .points
            .iter()
            .copied()
            .filter(|(x, y)| x.is_finite() && y.is_finite());
        if s.markers {
            c.draw_series(pts.map(|p| Circle::new(p, 3, color.filled())))
                .map_err(|e| e.to_string())?
                .label(s.label.as_str())
                .legend(move |(x, y)| Circle::new((x + 7, y), 3, color.filled()));
        } else {
            c.draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(s.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 15, y)], color.stroke_width(2))
                });
        }
    }
    // Limits in red first, then other reference lines in green and grey.
    let line_colors = [RED, RGBColor(0, 150, 0), RGBColor(90, 90, 90)];
    let mut hlines = 0;
    for m in &chart.marks {
        match m {
            Mark::HLine(label, y) => {
                let color = line_colors[hlines % line_colors.len()];
                hlines += 1;
                c.draw_series(LineSeries::new([(x0, *y), (x1, *y)], color.stroke_width(2)))
                    .map_err(|e| e.to_string())?
                    .label(label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 15, y)], color.stroke_width(2))
                    });
            }
            Mark::VLine(label, x) => {
                c.draw_series(LineSeries::new([(*x, y0), (*x, y1)], BLACK.stroke_width(2)))
                    .map_err(|e| e.to_string())?
                    .label(label.as_str())
                    .legend(|(x, y)| {
                        PathElement::new([(x, y), (x + 15, y)], BLACK.stroke_width(2))
                    });
            }
            Mark::Band(..) => {}
        }
    }
    let mut labels = c.configure_series_labels();
    if let Some(at) = legend {
        labels.position(at);
    }
    labels
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_an_svg_with_its_labels() {
        let scratch_dir = tempfile::Builder::new()
            .prefix("plot-test-")
            .tempdir()
            .unwrap();
        let dir = scratch_dir.path();
        let path = dir.join("t.svg");
        write_svg(
            &path,
            &Chart {
                title: "speed",
                x_label: "t, s",
                y_label: "ω, rad/s",
                series: vec![Series {
                    label: "ω".into(),
                    points: (0..100)
                        .map(|i| (i as f64, (i as f64 / 10.0).sin()))
                        .collect(),
                    markers: false,
                }],
                marks: vec![
                    Mark::HLine("limit".into(), 0.5),
                    Mark::Band("gathering".into(), 10.0, 20.0, true),
                ],
            },
        )
        .unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("<svg") && svg.contains("limit") && svg.contains("gathering"));
    }
}
