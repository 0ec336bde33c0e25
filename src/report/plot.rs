//! Plots as PNG: spectra as log-scale heat maps with a colour bar, profiles
//! and curves as line plots (plotters on an RGB buffer, encoded with
//! `image`; text in the vendored DejaVu Sans).

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use plotters::style::{FontStyle, register_font};

use super::png::save_png;
use crate::Error;
use crate::io::WriteError;
use crate::spectrum::Spectrum;

static FONT: Once = Once::new();

/// Registers the vendored font under plotters' "sans-serif" family, once.
fn ensure_font() {
    FONT.call_once(|| {
        register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../../assets/fonts/DejaVuSans.ttf"),
        )
        .unwrap_or_else(|_| panic!("the vendored DejaVu Sans is a valid TrueType font"));
    });
}

fn draw_error(e: impl std::fmt::Display) -> std::io::Error {
    std::io::Error::other(format!("drawing failed: {e}"))
}

/// One curve of a line plot.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// (x, y) points in order.
    pub points: Vec<(f64, f64)>,
    /// Dashed reference line rather than data.
    pub reference: bool,
    /// A vertical interval (low, high) per point, drawn as an error bar
    /// with caps; empty for none. A low end at or below zero on a log axis
    /// runs to the bottom of the plot.
    pub error_bars: Vec<(f64, f64)>,
}

/// A line plot with labelled axes, optionally log-log.
#[derive(Debug, Clone)]
pub struct LinePlot {
    /// Title over the plot.
    pub title: String,
    /// Horizontal axis label.
    pub x_label: String,
    /// Vertical axis label.
    pub y_label: String,
    /// Both axes logarithmic.
    pub log_log: bool,
    /// The curves.
    pub series: Vec<Series>,
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Writes `plot` as a 800×560 PNG at `path`, atomically.
///
/// # Errors
/// [`Error::Write`] naming `path` (also for drawing failures).
pub fn line_plot_png(plot: &LinePlot, path: &Path) -> Result<(), Error> {
    ensure_font();
    let (w, h) = (800u32, 560u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let drawn = draw_lines(plot, &mut buf, (w, h));
    drawn.map_err(|cause| {
        Error::Write(WriteError {
            path: path.to_path_buf(),
            cause,
        })
    })?;
    let img = image::RgbImage::from_raw(w, h, buf).expect("buffer matches size");
    save_png(&img, path)
}

fn draw_lines(plot: &LinePlot, buf: &mut [u8], size: (u32, u32)) -> std::io::Result<()> {
    let finite = |v: f64| v.is_finite() && (!plot.log_log || v > 0.0);
    let pts: Vec<(f64, f64)> = plot
        .series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|&(x, y)| finite(x) && finite(y))
        .collect();
    if pts.is_empty() {
        return Err(std::io::Error::other("nothing to plot: no finite points"));
    }
    let (mut x0, mut x1) = min_max(pts.iter().map(|p| p.0));
    let (mut y0, mut y1) = min_max(pts.iter().map(|p| p.1));
    if plot.log_log {
        (x0, x1, y0, y1) = (x0 / 1.2, x1 * 1.2, y0 / 2.0, y1 * 2.0);
    } else {
        let (px, py) = ((x1 - x0).max(1e-300) * 0.03, (y1 - y0).max(1e-300) * 0.05);
        (x0, x1, y0, y1) = (x0 - px, x1 + px, (y0 - py).min(0.0), y1 + py);
    }
    let root = BitMapBackend::with_buffer(buf, size).into_drawing_area();
    root.fill(&WHITE).map_err(draw_error)?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&plot.title, ("sans-serif", title_size(&root, &plot.title)))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80);
    macro_rules! finish {
        ($chart:expr) => {{
            let mut chart = $chart;
            // Log axes label only their key points (log_axis_ticks): N as
            // a number, values as m·10^e.
            let axis_number = |v: &f64| {
                if plot.log_log {
                    // A tick m·10^e computed as such: its log10 can fall
                    // a rounding below e.
                    let e = (v.abs().log10() + 1e-9).floor();
                    let m = (v / 10f64.powf(e)).round();
                    if m == 1.0 {
                        format!("1e{e}")
                    } else {
                        format!("{m}e{e}")
                    }
                } else {
                    format!("{}", (v * 1e6).round() / 1e6)
                }
            };
            let x_number = |v: &f64| {
                if !plot.log_log {
                    return axis_number(v);
                }
                if *v >= 10.0 {
                    format!("{}", v.round())
                } else {
                    format!("{}", (v * 1e4).round() / 1e4)
                }
            };
            chart
                .configure_mesh()
                .x_labels(10)
                .y_labels(10)
                .x_label_formatter(&x_number)
                .y_label_formatter(&axis_number)
                .x_desc(plot.x_label.as_str())
                .y_desc(plot.y_label.as_str())
                .label_style(("sans-serif", 15))
                .axis_desc_style(("sans-serif", 17))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(draw_error)?;
            for (i, s) in plot.series.iter().enumerate() {
                let colour = PALETTE[i % PALETTE.len()];
                let data: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|&(x, y)| finite(x) && finite(y))
                    .collect();
                let style = ShapeStyle::from(&colour).stroke_width(if s.reference { 1 } else { 2 });
                let anno = if s.reference {
                    chart
                        .draw_series(DashedLineSeries::new(data, 6, 4, style))
                        .map_err(draw_error)?
                } else {
                    // Error bars first, under the markers; a low end that a
                    // log axis cannot show runs to its bottom.
                    let bars = data.iter().zip(&s.error_bars).map(|(&(x, y), &(lo, hi))| {
                        let lo = if finite(lo) { lo } else { y0 };
                        ErrorBar::new_vertical(x, lo.max(y0), y, hi.min(y1), style, 8)
                    });
                    chart.draw_series(bars).map_err(draw_error)?;
                    // Markers on the data, so measured points stand out from
                    // a reference line running through them.
                    chart
                        .draw_series(data.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                        .map_err(draw_error)?;
                    chart
                        .draw_series(LineSeries::new(data, style))
                        .map_err(draw_error)?
                };
                // The key drawn as the series is: a dashed reference line as
                // two dashes, data as a solid line.
                let (gap, width) = if s.reference { (6, 1) } else { (0, 2) };
                anno.label(s.label.as_str()).legend(move |(x, y)| {
                    let key = colour.stroke_width(width);
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (12 - gap / 2, 0)], key)
                        + PathElement::new(vec![(12 + gap / 2, 0), (24, 0)], key)
                });
            }
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 15))
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(160, 160, 160))
                .position(legend_corner(plot, (x0, x1), (y0, y1)))
                .draw()
                .map_err(draw_error)?;
        }};
    }
    if plot.log_log {
        // Own key points: plotters' log axis repeats a decade's first
        // value from the decade below (two "1000" labels) and bunches its
        // light lines there.
        let (x_bold, x_light) = log_axis_ticks(x0, x1, false);
        let (y_bold, y_light) = log_axis_ticks(y0, y1, true);
        let x_axis = (x0..x1)
            .log_scale()
            .with_key_points(x_bold)
            .with_light_points(x_light);
        let y_axis = (y0..y1)
            .log_scale()
            .with_key_points(y_bold)
            .with_light_points(y_light);
        finish!(
            builder
                .build_cartesian_2d(x_axis, y_axis)
                .map_err(draw_error)?
        );
    } else {
        finish!(
            builder
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(draw_error)?
        );
    }
    root.present().map_err(draw_error)
}

/// The corner of the plot area whose legend-sized box (40% of the width,
/// 30% of the height) covers the fewest samples of the curves, each
/// segment sampled at 16 points in plot coordinates (log for a log-log
/// plot); the upper right on ties.
fn legend_corner(plot: &LinePlot, x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    let scale = |v: f64, (lo, hi): (f64, f64)| {
        if plot.log_log {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    };
    let mut samples = Vec::new();
    for s in &plot.series {
        let p: Vec<(f64, f64)> = s
            .points
            .iter()
            .map(|&(a, b)| (scale(a, x), scale(b, y)))
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .collect();
        samples.extend(p.iter().copied());
        for w in p.windows(2) {
            samples.extend((1..16).map(|i| {
                let t = f64::from(i) / 16.0;
                (
                    w[0].0 + t * (w[1].0 - w[0].0),
                    w[0].1 + t * (w[1].1 - w[0].1),
                )
            }));
        }
    }
    let covered = |right: bool, upper: bool| {
        samples
            .iter()
            .filter(|&&(a, b)| {
                (if right { a >= 0.6 } else { a <= 0.4 })
                    && (if upper { b >= 0.7 } else { b <= 0.3 })
            })
            .count()
    };
    [
        (SeriesLabelPosition::UpperRight, covered(true, true)),
        (SeriesLabelPosition::UpperLeft, covered(false, true)),
        (SeriesLabelPosition::LowerLeft, covered(false, false)),
        (SeriesLabelPosition::LowerRight, covered(true, false)),
    ]
    .into_iter()
    .min_by_key(|&(_, c)| c)
    .map_or(SeriesLabelPosition::UpperRight, |(p, _)| p)
}

/// Labelled and light grid values of a log axis over [lo, hi]: labels at
/// decades (`decades_first`, a value axis) or at 1, 2, 5 times them (an N
/// axis), falling back to finer mantissas until two labels show, and to
/// decades when 1, 2, 5 would crowd past 12; light lines at the other
/// integer mantissas.
fn log_axis_ticks(lo: f64, hi: f64, decades_first: bool) -> (Vec<f64>, Vec<f64>) {
    const ALL: [f64; 9] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
    let choices: &[&[f64]] = if decades_first {
        &[&[1.0], &[1.0, 2.0, 5.0], &ALL]
    } else {
        &[&[1.0, 2.0, 5.0], &ALL]
    };
    let mut bold = choices
        .iter()
        .map(|m| log_ticks(lo, hi, m))
        .find(|t| t.len() >= 2)
        .unwrap_or_else(|| log_ticks(lo, hi, &ALL));
    if bold.len() > 12 {
        bold = log_ticks(lo, hi, &[1.0]);
    }
    let light = log_ticks(lo, hi, &ALL)
        .into_iter()
        .filter(|v| !bold.contains(v))
        .collect();
    (bold, light)
}

/// The values m·10^e (m from `mantissas`) within [lo, hi], 0 < lo < hi,
/// each computed from its exponent (no drift from repeated products).
fn log_ticks(lo: f64, hi: f64, mantissas: &[f64]) -> Vec<f64> {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let mut ticks: Vec<f64> = (first..=last)
        .flat_map(|e| mantissas.iter().map(move |m| m * 10f64.powi(e)))
        .filter(|v| (lo..=hi).contains(v))
        .collect();
    ticks.sort_by(f64::total_cmp);
    ticks
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// A grid of values drawn as a heat map with a labelled colour bar.
#[derive(Debug, Clone)]
pub struct HeatMap<'a> {
    /// Title over the picture.
    pub title: String,
    /// Values row by row, the first row at the top; NaN draws grey.
    pub values: &'a [f64],
    /// Cells per row.
    pub width: usize,
    /// The axes' value ranges (left to right, bottom to top; a falling
    /// y range numbers rows from the top, as image coordinates do), in
    /// whole units (pixels, frequencies): only whole ticks are labelled.
    pub x_range: (f64, f64),
    /// See `x_range`.
    pub y_range: (f64, f64),
    /// Horizontal axis label.
    pub x_label: String,
    /// Vertical axis label.
    pub y_label: String,
    /// Colour-bar label.
    pub bar_label: String,
    /// Values mapped to the colour map's ends (clamped beyond).
    pub colour_range: (f64, f64),
}

/// Writes a 2D power spectrum as a heat map centred at DC, log10 power in
/// the viridis colour map with a labelled colour bar (a 760×609 PNG: square
/// cells).
///
/// The colour range spans the powers at k ≠ 0: from the largest down at
/// most four decades; DC (power N, off any useful scale) is drawn grey,
/// the colour of no value, so it does not read as low-frequency power.
///
/// # Errors
/// [`Error::Write`] naming `path`; a spectrum that is not 2D is refused the
/// same way.
pub fn spectrum_png(spectrum: &Spectrum, title: &str, path: &Path) -> Result<(), Error> {
    power_png(spectrum, title, ["kx", "ky"], "log10 power (N·P_S)", path)
}

/// As [`spectrum_png`] with the two frequency axes named `axes` (e.g.
/// `["kx", "ku"]` for an XU projection) and the colour bar `bar_label` (the
/// power of a sample set or of an integrand).
///
/// # Errors
/// As [`spectrum_png`].
pub fn power_png(
    spectrum: &Spectrum,
    title: &str,
    axes: [&str; 2],
    bar_label: &str,
    path: &Path,
) -> Result<(), Error> {
    if spectrum.freqs.dim != 2 {
        return Err(Error::Write(WriteError {
            path: path.to_path_buf(),
            cause: std::io::Error::other("a spectrum picture needs a 2D spectrum (use --dims)"),
        }));
    }
    let zero = spectrum.freqs.zero_index();
    let (lo, hi) = power_colour_range(
        spectrum
            .power
            .iter()
            .enumerate()
            .filter(|&(i, &p)| i != zero && p > 0.0)
            .map(|(_, &p)| p.log10()),
    );
    let side = spectrum.freqs.side();
    // Rows from the top: k_y from +h down to −h.
    let values: Vec<f64> = (0..side)
        .rev()
        .flat_map(|row| (0..side).map(move |col| row * side + col))
        .map(|idx| match spectrum.power[idx] {
            _ if idx == zero => f64::NAN,
            p if p <= 0.0 => lo,
            p => p.log10(),
        })
        .collect();
    let h = spectrum.freqs.half as f64;
    heatmap_png(
        &HeatMap {
            title: title.into(),
            values: &values,
            width: side,
            x_range: (-h - 0.5, h + 0.5),
            y_range: (-h - 0.5, h + 0.5),
            x_label: axes[0].into(),
            y_label: axes[1].into(),
            bar_label: bar_label.into(),
            colour_range: (lo, hi),
        },
        path,
    )
}

/// The colour range of a power picture from the log10 powers at k ≠ 0:
/// from the largest down at most four decades. A single value (an
/// integrand with one frequency pair, e.g. a cosine) tops a one-decade
/// range, so it reads as the peak it is and zeros (drawn at the bottom) as
/// nothing; no positive power gives (−1, 1).
fn power_colour_range(logs: impl Iterator<Item = f64>) -> (f64, f64) {
    match min_max(logs) {
        (lo, hi) if hi > lo => (lo.max(hi - 4.0), hi),
        (_, hi) if hi.is_finite() => (hi - 1.0, hi),
        _ => (-1.0, 1.0),
    }
}

/// Writes `map` as a PNG (viridis, colour bar on the right), atomically,
/// with square cells: 760×609 for a square grid, shorter for a wide one,
/// narrower for a tall one (see [`frame_for_square_cells`]).
///
/// # Errors
/// [`Error::Write`] naming `path` (also for an empty or ragged grid and for
/// drawing failures).
pub fn heatmap_png(map: &HeatMap, path: &Path) -> Result<(), Error> {
    let fail = |cause| {
        Error::Write(WriteError {
            path: path.to_path_buf(),
            cause,
        })
    };
    if map.width == 0 || map.values.is_empty() || map.values.len() % map.width != 0 {
        return Err(fail(std::io::Error::other(format!(
            "a heat map of {} values cannot have rows of {}",
            map.values.len(),
            map.width
        ))));
    }
    ensure_font();
    let (lo, hi) = colour_span(map.colour_range);
    let (cols, rows) = (map.width, map.values.len() / map.width);
    let (w, h) = frame_for_square_cells(map, cols as f64 / rows as f64).map_err(fail)?;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let (heat, bar) = draw_heatmap_frame(map, &mut buf, (w, h)).map_err(fail)?;
    let colour = |v: f64| {
        if v.is_nan() {
            RGBColor(128, 128, 128)
        } else {
            ViridisRGB::get_color_normalized(v.clamp(lo, hi), lo, hi)
        }
    };
    let mut put = |x: i32, y: i32, c: RGBColor| {
        let o = ((y as u32 * w + x as u32) * 3) as usize;
        buf[o..o + 3].copy_from_slice(&[c.0, c.1, c.2]);
    };
    let (hx, hy) = heat;
    for py in hy.clone() {
        let fy = (py - hy.start) as f64 / (hy.end - hy.start) as f64;
        let row = ((fy * rows as f64) as usize).min(rows - 1);
        for px in hx.clone() {
            let fx = (px - hx.start) as f64 / (hx.end - hx.start) as f64;
            let col = ((fx * cols as f64) as usize).min(cols - 1);
            put(px, py, colour(map.values[row * cols + col]));
        }
    }
    let (bx, by) = bar;
    for py in by.clone() {
        let v = hi - (py - by.start) as f64 / (by.end - by.start - 1).max(1) as f64 * (hi - lo);
        for px in bx.clone() {
            put(px, py, colour(v));
        }
    }
    let img = image::RgbImage::from_raw(w, h, buf).expect("buffer matches size");
    save_png(&img, path)
}

type PixelRange = (std::ops::Range<i32>, std::ops::Range<i32>);

/// The picture's width and height that make a `cols`/`rows` grid of
/// aspect `aspect` draw with square cells (a rendered image of 2:1, a 16:9
/// frame), instead of stretched into the default 760×640 frame: a wide grid
/// shortens the picture, a tall one narrows it. The frame's margins, labels
/// and colour bar are measured, not assumed (a narrower picture may shrink
/// its title, which moves the plot), so the fit is repeated until the plot
/// is within a pixel of the aspect. Aspects beyond 1:4 and 4:1 are clamped
/// there (the colour bar keeps room for its ticks), so only such extreme
/// grids get oblong cells.
fn frame_for_square_cells(map: &HeatMap, aspect: f64) -> std::io::Result<(u32, u32)> {
    let aspect = aspect.clamp(0.25, 4.0);
    let (mut w, mut h) = (760u32, 640u32);
    for _ in 0..4 {
        let mut probe = vec![255u8; (w * h * 3) as usize];
        let ((px, py), _) = draw_heatmap_frame(map, &mut probe, (w, h))?;
        let (pw, ph) = (f64::from(px.end - px.start), f64::from(py.end - py.start));
        let (too_tall, too_wide) = (ph - pw / aspect, pw - ph * aspect);
        if too_tall.abs() < 1.0 && too_wide.abs() < 1.0 {
            break;
        }
        if aspect >= pw / ph {
            h = (f64::from(h) - too_tall).round() as u32;
        } else {
            w = (f64::from(w) - too_wide).round() as u32;
        }
    }
    Ok((w, h))
}

/// A colour range that spans something: an empty one (a constant field:
/// every pixel's shear 0) gets v ± 1 instead of a bar whose ticks all read
/// the same. A range given is otherwise kept, however narrow.
fn colour_span((lo, hi): (f64, f64)) -> (f64, f64) {
    if hi > lo {
        (lo, hi)
    } else if lo.is_finite() {
        (lo - 1.0, lo + 1.0)
    } else {
        (-1.0, 1.0)
    }
}

/// A tick label: whole numbers without a decimal point, others to the
/// fourth significant digit, and no "-0".
fn tick_number(v: f64) -> String {
    let v = if v == 0.0 { 0.0 } else { v };
    if v.fract() == 0.0 && v.abs() < 1e9 {
        format!("{v:.0}")
    } else {
        let text = format!("{:.4}", v);
        let text = text.trim_end_matches('0').trim_end_matches('.').to_string();
        if text == "-0" { "0".into() } else { text }
    }
}

/// The largest title size up to 22 px whose text fits the picture's width
/// (a long title, such as a scene figure's, was clipped at both ends).
fn title_size<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
) -> f64 {
    let room = area.dim_in_pixel().0.saturating_sub(24);
    let mut size = 22.0;
    while size > 11.0 {
        match area.estimate_text_size(title, &("sans-serif", size).into_text_style(area)) {
            Ok((w, _)) if w > room => size -= 1.0,
            _ => break,
        }
    }
    size
}

/// Draws axes, labels and colour-bar ticks; returns the pixel ranges of the
/// heat map and the colour bar, which the caller fills.
fn draw_heatmap_frame(
    map: &HeatMap,
    buf: &mut [u8],
    size: (u32, u32),
) -> std::io::Result<(PixelRange, PixelRange)> {
    let root = BitMapBackend::with_buffer(buf, size).into_drawing_area();
    root.fill(&WHITE).map_err(draw_error)?;
    let root = root
        .titled(&map.title, ("sans-serif", title_size(&root, &map.title)))
        .map_err(draw_error)?;
    let (left, right) = root.split_horizontally(size.0 - 150);
    let (x0, x1) = map.x_range;
    let (y0, y1) = map.y_range;
    let mut heat = ChartBuilder::on(&left)
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(72)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(draw_error)?;
    // The axes count pixels or frequencies: whole numbers only, and no more
    // labels than whole numbers in the range (an image one pixel high was
    // labelled 0.1, 0.2, …).
    let whole = |v: &f64| {
        if (v - v.round()).abs() < 1e-9 {
            tick_number(v.round())
        } else {
            String::new()
        }
    };
    let labels = |a: f64, b: f64| ((a - b).abs().floor() as usize + 1).clamp(2, 10);
    heat.configure_mesh()
        .disable_mesh()
        .x_labels(labels(x0, x1))
        .y_labels(labels(y0, y1))
        .x_label_formatter(&whole)
        .y_label_formatter(&whole)
        .x_desc(map.x_label.as_str())
        .y_desc(map.y_label.as_str())
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()
        .map_err(draw_error)?;
    let (lo, hi) = colour_span(map.colour_range);
    let mut bar = ChartBuilder::on(&right)
        .margin_top(12)
        .margin_bottom(56)
        .margin_right(12)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(draw_error)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_formatter(&|v| tick_number(*v))
        .y_desc(map.bar_label.as_str())
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(draw_error)?;
    let ranges = (
        heat.plotting_area().get_pixel_range(),
        bar.plotting_area().get_pixel_range(),
    );
    root.present().map_err(draw_error)?;
    Ok(ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plot area a heat map of `cols` × `rows` cells is drawn into, in
    /// pixels, measured from the drawn frame.
    fn plot_area(cols: usize, rows: usize) -> (f64, f64) {
        let values = vec![0.0; cols * rows];
        let map = HeatMap {
            title: "a title as long as a render's: variance over 16 renders".into(),
            values: &values,
            width: cols,
            x_range: (0.0, cols as f64),
            y_range: (rows as f64, 0.0),
            x_label: "pixel x".into(),
            y_label: "pixel y".into(),
            bar_label: "log10 variance".into(),
            colour_range: (0.0, 1.0),
        };
        ensure_font();
        let (w, h) = frame_for_square_cells(&map, cols as f64 / rows as f64).unwrap();
        let mut buf = vec![255u8; (w * h * 3) as usize];
        let ((px, py), _) = draw_heatmap_frame(&map, &mut buf, (w, h)).unwrap();
        (f64::from(px.end - px.start), f64::from(py.end - py.start))
    }

    #[test]
    fn heat_map_cells_are_square_at_any_aspect() {
        // The plot area of the default 760×640 frame is 0.94:1; a 2:1 render
        // was stretched into it. One pixel of slack on each side.
        for (cols, rows) in [(256, 256), (192, 96), (640, 360), (64, 160), (100, 400)] {
            let (pw, ph) = plot_area(cols, rows);
            let want = cols as f64 / rows as f64;
            assert!(
                (pw - ph * want).abs() <= 1.0 + want && (ph - pw / want).abs() <= 1.0 + 1.0 / want,
                "{cols}×{rows}: plot area {pw}×{ph} has aspect {}, not {want}",
                pw / ph
            );
        }
        // Beyond 4:1 the aspect is clamped (the colour bar needs height).
        let (pw, ph) = plot_area(1000, 10);
        assert!((pw / ph - 4.0).abs() < 0.05, "1000×10: {pw}×{ph}");
    }

    #[test]
    fn power_colour_range_ends_at_the_largest_power() {
        // cos:kx=3,ky=5 has P_f = 1/4 at ±k and 0 elsewhere: the range ends
        // at log10(1/4) (it was centred there, drawing the peak mid-scale).
        let peak = 0.25f64.log10();
        assert_eq!(
            power_colour_range([peak, peak].into_iter()),
            (peak - 1.0, peak)
        );
        // Six decades: the lowest two are clipped.
        assert_eq!(
            power_colour_range([-7.0, -3.0, -1.0].into_iter()),
            (-5.0, -1.0)
        );
        assert_eq!(power_colour_range(std::iter::empty()), (-1.0, 1.0));
    }

    #[test]
    fn tick_labels_are_tidy() {
        assert_eq!(tick_number(250.0), "250");
        assert_eq!(tick_number(-0.0), "0");
        assert_eq!(tick_number(-0.00001), "0");
        assert_eq!(tick_number(-2.5), "-2.5");
        assert_eq!(tick_number(0.125), "0.125");
        assert_eq!(colour_span((0.0, 0.0)), (-1.0, 1.0));
        assert_eq!(colour_span((-3.0, -2.0)), (-3.0, -2.0));
        // A narrow range given is kept (--variance-range -3,-2.998).
        assert_eq!(colour_span((-3.0, -2.998)), (-3.0, -2.998));
    }

    #[test]
    fn log_ticks_are_distinct_and_exact() {
        // Plotters' own key points gave 1000 twice over 53…4915.
        let (bold, light) = log_axis_ticks(53.3, 4915.2, false);
        assert_eq!(bold, vec![100.0, 200.0, 500.0, 1000.0, 2000.0]);
        assert_eq!(light.iter().filter(|&&v| v == 1000.0).count(), 0);
        assert!(light.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(light.first(), Some(&60.0));
        // A value axis labels decades; within one decade it falls back.
        assert_eq!(log_axis_ticks(2e-9, 3e-3, true).0.len(), 6);
        assert_eq!(log_axis_ticks(1.5e-5, 9e-5, true).0, vec![2e-5, 5e-5]);
        // Many decades: decades only, not 1, 2, 5 of each.
        assert_eq!(log_axis_ticks(1.0, 1e9, false).0.len(), 10);
    }

    fn falling(error_bars: Vec<(f64, f64)>) -> LinePlot {
        LinePlot {
            title: "t".into(),
            x_label: "N".into(),
            y_label: "variance".into(),
            log_log: true,
            series: vec![Series {
                label: "data".into(),
                points: vec![
                    (64.0, 1e-3),
                    (256.0, 2.5e-4),
                    (1024.0, 6e-5),
                    (4096.0, 1.5e-5),
                ],
                reference: false,
                error_bars,
            }],
        }
    }

    #[test]
    fn the_legend_avoids_the_curve() {
        // A falling curve fills the upper left and lower right.
        let p = falling(Vec::new());
        let position = legend_corner(&p, (50.0, 5000.0), (7e-6, 2e-3));
        assert!(
            matches!(
                position,
                SeriesLabelPosition::UpperRight | SeriesLabelPosition::LowerLeft
            ),
            "{position:?}"
        );
        let rising = LinePlot {
            log_log: false,
            series: vec![Series {
                points: vec![(0.0, 0.0), (1.0, 1.0)],
                ..p.series[0].clone()
            }],
            ..p
        };
        let position = legend_corner(&rising, (0.0, 1.0), (0.0, 1.0));
        assert!(
            matches!(
                position,
                SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerRight
            ),
            "{position:?}"
        );
    }

    #[test]
    fn error_bars_are_drawn() {
        ensure_font();
        let draw = |plot: &LinePlot| {
            let mut buf = vec![255u8; 800 * 560 * 3];
            draw_lines(plot, &mut buf, (800, 560)).unwrap();
            buf
        };
        let plain = draw(&falling(Vec::new()));
        let bars = vec![(5e-4, 2e-3), (1e-4, 5e-4), (3e-5, 1.2e-4), (-1e-5, 3e-5)];
        let barred = draw(&falling(bars));
        let changed = plain.iter().zip(&barred).filter(|(a, b)| a != b).count();
        // Four bars of tens of pixels each, and caps.
        assert!(changed > 4 * 3 * 30, "{changed} bytes changed");
    }
}
