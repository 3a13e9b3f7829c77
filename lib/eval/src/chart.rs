//! Charts of measured series as SVG (plotters): one point series per method, a title, a
//! subtitle, axis labels, a legend, and stamp lines (machine, scene, command) under the plot.

use std::path::Path;

use anyhow::{anyhow, Result};
use plotters::prelude::*;

/// One curve.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    /// (x, y) points, drawn in the given order.
    pub points: Vec<(f64, f64)>,
}

/// What the chart shows.
#[derive(Clone, Debug, Default)]
pub struct Chart {
    pub title: String,
    pub subtitle: String,
    pub x_label: String,
    pub y_label: String,
    /// A logarithmic x axis (compression ratios).
    pub x_log: bool,
    /// Lines printed under the plot: machine, scene, command.
    pub stamp: Vec<String>,
}

const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

fn bounds(series: &[Series], log: bool) -> ((f64, f64), (f64, f64)) {
    let pts = series
        .iter()
        .flat_map(|s| &s.points)
        .filter(|p| p.0.is_finite() && p.1.is_finite() && (!log || p.0 > 0.0));
    let (mut x0, mut x1, mut y0, mut y1) =
        (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        return ((1.0, 10.0), (0.0, 1.0));
    }
    let (x0, x1) = if log {
        (x0 / 1.25, x1 * 1.25)
    } else {
        let m = (x1 - x0).max(1e-9) * 0.05;
        (x0 - m, x1 + m)
    };
    let m = (y1 - y0).max(1e-6) * 0.08;
    ((x0, x1), (y0 - m, y1 + m))
}

/// Renders the chart as an SVG document.
pub fn svg(chart: &Chart, series: &[Series]) -> Result<String> {
    let mut out = String::new();
    {
        let height = 600 + 18 * chart.stamp.len() as u32;
        let root = SVGBackend::with_string(&mut out, (900, height)).into_drawing_area();
        let e = |e: &dyn std::fmt::Display| anyhow!("chart: {e}");
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let (plot, foot) = root.split_vertically(600);
        let (head, body) = plot.split_vertically(50);
        head.draw(&Text::new(chart.title.clone(), (20, 8), ("sans-serif", 22).into_font()))
            .map_err(|x| e(&x))?;
        head.draw(&Text::new(
            chart.subtitle.clone(),
            (20, 32),
            ("sans-serif", 13).into_font().color(&RGBColor(80, 80, 80)),
        ))
        .map_err(|x| e(&x))?;
        for (i, line) in chart.stamp.iter().enumerate() {
            foot.draw(&Text::new(
                line.clone(),
                (20, 2 + 18 * i as i32),
                ("monospace", 11).into_font().color(&RGBColor(60, 60, 60)),
            ))
            .map_err(|x| e(&x))?;
        }
        let ((x0, x1), (y0, y1)) = bounds(series, chart.x_log);
        let mut builder = ChartBuilder::on(&body);
        builder.margin(15).x_label_area_size(45).y_label_area_size(60);
        macro_rules! draw {
            ($ctx:expr) => {{
                let mut ctx = $ctx;
                ctx.configure_mesh()
                    .x_desc(chart.x_label.clone())
                    .y_desc(chart.y_label.clone())
                    .draw()
                    .map_err(|x| e(&x))?;
                for (i, s) in series.iter().enumerate() {
                    let c = PALETTE[i % PALETTE.len()];
                    let pts: Vec<(f64, f64)> = s
                        .points
                        .iter()
                        .copied()
                        .filter(|p| {
                            p.0.is_finite() && p.1.is_finite() && (!chart.x_log || p.0 > 0.0)
                        })
                        .collect();
                    ctx.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                        .map_err(|x| e(&x))?
                        .label(s.name.clone())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                        });
                    ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                        .map_err(|x| e(&x))?;
                }
                ctx.configure_series_labels()
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .position(SeriesLabelPosition::UpperRight)
                    .draw()
                    .map_err(|x| e(&x))?;
            }};
        }
        if chart.x_log {
            draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1).map_err(|x| e(&x))?);
        } else {
            draw!(builder.build_cartesian_2d(x0..x1, y0..y1).map_err(|x| e(&x))?);
        }
        root.present().map_err(|x| e(&x))?;
    }
    Ok(out)
}

/// Renders and writes the chart atomically.
pub fn write_svg(path: &Path, chart: &Chart, series: &[Series]) -> Result<()> {
    crate::report::write_atomic(path, svg(chart, series)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svg_names_every_series_and_the_stamp() {
        let chart = Chart {
            title: "T".into(),
            subtitle: "S".into(),
            x_label: "ratio".into(),
            y_label: "PSNR".into(),
            x_log: true,
            stamp: vec!["machine: m".into()],
        };
        let series = vec![
            Series { name: "alpha".into(), points: vec![(96.0, 30.0), (384.0, 25.0)] },
            Series { name: "beta".into(), points: vec![(100.0, 28.0), (400.0, 24.0)] },
        ];
        let s = svg(&chart, &series).unwrap();
        for want in ["<svg", "alpha", "beta", "machine: m", "ratio", "PSNR"] {
            assert!(s.contains(want), "{want}");
        }
    }
}
