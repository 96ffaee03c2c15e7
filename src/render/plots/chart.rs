//! One line chart, the shared part of every plot: its series, axes with units, drawn with
//! `plotters` to PNG and SVG, and the CSV of the points it shows written beside them.

use crate::render::plots::PlotError;
use crate::scene::atomic_file::write_atomically;
use crate::scene::batch::csv::record;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Plot width and height, pixels.
pub const PLOT_SIZE: (u32, u32) = (800, 500);

// The bundled DejaVu Sans (the frames' font): plotters is built without system fonts, so a
// machine without any draws the same text.
use crate::render::text::FONT_FILE;

/// The font family plotters is asked for; registered once from [`FONT_FILE`].
const FAMILY: &str = "sans-serif";

fn register_font() -> Result<(), String> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT_FILE).is_ok()
    });
    ok.then_some(())
        .ok_or_else(|| "the bundled font does not parse".to_string())
}

/// One named line of points.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Its name in the legend and the CSV's `series` column.
    pub name: String,
    /// The points (x, y), in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Per point, what it is (`step 3`), written to the CSV's `label` column.
    pub labels: Vec<String>,
}

impl Series {
    /// An empty series called `name`.
    pub fn new(name: impl Into<String>) -> Self {
        Series {
            name: name.into(),
            points: Vec::new(),
            labels: Vec::new(),
        }
    }

    /// Add the point (`x`, `y`) described by `label`.
    pub fn push(&mut self, x: f64, y: f64, label: impl Into<String>) {
        self.points.push((x, y));
        self.labels.push(label.into());
    }
}

/// A line chart: title, axes (their labels carry the units) and series.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// The file stem under `plots/` (`load_displacement`).
    pub name: String,
    /// The caption above the chart.
    pub title: String,
    /// The x axis label, with its unit.
    pub x_label: String,
    /// The y axis label, with its unit.
    pub y_label: String,
    /// The CSV's x and y column names (`max_displacement_m`).
    pub columns: (String, String),
    /// A logarithmic y axis (values ≤ 0 are left out of the drawing and the CSV).
    pub log_y: bool,
    /// Show the series' names in a legend.
    pub legend: bool,
    /// Draw every series in one colour (many series of one kind: the residuals of each step).
    pub one_colour: bool,
    /// Whole numbers on the x and y axes (steps, counts): ticks only there.
    pub integer: (bool, bool),
    /// The lines.
    pub series: Vec<Series>,
}

/// Colours of successive series (colour-blind-safe, Okabe & Ito).
const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// Above this many points a series is drawn as a line without a marker per point.
const MARKERS_UP_TO: usize = 200;

/// The files [`Chart::write`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct WrittenPlot {
    /// `plots/<name>.png`.
    pub png: PathBuf,
    /// `plots/<name>.svg`.
    pub svg: PathBuf,
    /// `plots/<name>.csv`: the points drawn.
    pub csv: PathBuf,
}

impl Chart {
    /// Whether the point (`x`, `y`) is drawn: finite, and positive on a log axis.
    fn keeps(&self, x: f64, y: f64) -> bool {
        x.is_finite() && y.is_finite() && !(self.log_y && y <= 0.0)
    }

    /// The series as drawn: the points [`Chart::keeps`], on a log axis as log10 of y.
    fn drawn(&self) -> Vec<Series> {
        self.series
            .iter()
            .map(|s| {
                let mut d = Series::new(s.name.clone());
                for (&(x, y), label) in s.points.iter().zip(&s.labels) {
                    if self.keeps(x, y) {
                        d.push(x, if self.log_y { y.log10() } else { y }, label.clone());
                    }
                }
                d
            })
            .collect()
    }

    /// The CSV of the points drawn: `series,<x column>,<y column>,label`, one row per point,
    /// the numbers in Rust's shortest round-trip form.
    pub fn csv(&self) -> String {
        let mut text = record(&["series", &self.columns.0, &self.columns.1, "label"]);
        for s in &self.series {
            for (&(x, y), label) in s.points.iter().zip(&s.labels) {
                if self.keeps(x, y) {
                    text.push_str(&record(&[
                        s.name.clone(),
                        format!("{x:?}"),
                        format!("{y:?}"),
                        label.clone(),
                    ]));
                }
            }
        }
        text
    }

    /// Write `dir/<name>.png`, `.svg` and `.csv`, each atomically.
    pub fn write(&self, dir: &Path) -> Result<WrittenPlot, PlotError> {
        let written = WrittenPlot {
            png: dir.join(format!("{}.png", self.name)),
            svg: dir.join(format!("{}.svg", self.name)),
            csv: dir.join(format!("{}.csv", self.name)),
        };
        let draw_err = |path: &Path| {
            let path = path.to_path_buf();
            move |message| PlotError::Draw { path, message }
        };
        let (w, h) = PLOT_SIZE;
        let mut rgb = vec![0u8; (w * h * 3) as usize];
        self.draw(BitMapBackend::with_buffer(&mut rgb, PLOT_SIZE).into_drawing_area())
            .map_err(draw_err(&written.png))?;
        let png = png_of(&rgb, w, h).map_err(draw_err(&written.png))?;
        let mut svg = String::new();
        self.draw(SVGBackend::with_string(&mut svg, PLOT_SIZE).into_drawing_area())
            .map_err(draw_err(&written.svg))?;
        for (path, bytes) in [
            (&written.png, png),
            (&written.svg, svg.into_bytes()),
            (&written.csv, self.csv().into_bytes()),
        ] {
            write_atomically(path, &bytes).map_err(|source| PlotError::Write {
                path: path.clone(),
                source,
            })?;
        }
        Ok(written)
    }

    /// Draw the chart on `root` (a bitmap or an SVG).
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
        register_font()?;
        let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(e)?;
        let drawn = self.drawn();
        let (xs, ys) = extents(&drawn, self.log_y);
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, (FAMILY, 22))
            .margin(18)
            .x_label_area_size(52)
            .y_label_area_size(86)
            .build_cartesian_2d(xs.0..xs.1, ys.0..ys.1)
            .map_err(e)?;
        let log_y = self.log_y;
        let (x_whole, y_whole) = self.integer;
        let (x_big, y_big) = (xs.0.abs().max(xs.1.abs()), ys.0.abs().max(ys.1.abs()));
        let y_tick = move |v: &f64| {
            if log_y {
                power_of_ten(*v)
            } else {
                axis_tick(*v, y_big, y_whole)
            }
        };
        let x_tick = move |v: &f64| axis_tick(*v, x_big, x_whole);
        // On a whole-number axis, about one label per unit (up to 10) lands them on integers.
        let labels = |whole: bool, r: (f64, f64)| {
            if whole {
                ((r.1 - r.0).floor() as usize + 1).clamp(2, 10)
            } else {
                10
            }
        };
        chart
            .configure_mesh()
            .x_labels(labels(x_whole, xs))
            .y_labels(labels(y_whole, ys))
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&x_tick)
            .y_label_formatter(&y_tick)
            .label_style((FAMILY, 14))
            .axis_desc_style((FAMILY, 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(e)?;
        for (k, s) in drawn.iter().enumerate() {
            let colour = if self.one_colour {
                PALETTE[0]
            } else {
                PALETTE[k % PALETTE.len()]
            };
            let line = ShapeStyle::from(&colour).stroke_width(2);
            let drawn_line = chart
                .draw_series(LineSeries::new(s.points.iter().copied(), line))
                .map_err(e)?;
            if self.legend {
                drawn_line
                    .label(s.name.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], line));
            }
            if s.points.len() <= MARKERS_UP_TO {
                chart
                    .draw_series(s.points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                    .map_err(e)?;
            }
        }
        if self.legend {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .label_font((FAMILY, 14))
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(160, 160, 160))
                .draw()
                .map_err(e)?;
        }
        root.present().map_err(e)?;
        Ok(())
    }
}

/// The x and y ranges that hold every point of `series`, with a margin; a log axis is widened
/// to whole decades so its ticks fall on powers of ten.
fn extents(series: &[Series], log_y: bool) -> ((f64, f64), (f64, f64)) {
    let points = series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in points {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return ((0.0, 1.0), (0.0, 1.0));
    }
    let widen = |a: f64, b: f64| {
        let span = b - a;
        if span > 0.0 {
            let pad = 0.05 * span;
            (a - pad, b + pad)
        } else {
            let pad = if a == 0.0 { 1.0 } else { 0.1 * a.abs() };
            (a - pad, b + pad)
        }
    };
    let ys = if log_y {
        let (a, b) = (y0.floor(), y1.ceil());
        (a, if b > a { b } else { a + 1.0 })
    } else {
        widen(y0, y1)
    };
    (widen(x0, x1), ys)
}

/// The label of tick `v` on an axis reaching `biggest` in magnitude: in exponent form when the
/// axis is below 1e-2 or from 1e5 (so one axis uses one form); none between whole numbers on
/// a `whole` axis.
fn axis_tick(v: f64, biggest: f64, whole: bool) -> String {
    if whole && (v - v.round()).abs() > 1e-9 {
        return String::new();
    }
    // A tick a round-off away from zero (the axis' ticks are multiples of a step, summed) is 0.
    if v.abs() <= 1e-9 * biggest {
        return "0".to_string();
    }
    if v != 0.0 && !(1e-2..1e5).contains(&biggest) {
        return exponent(v);
    }
    tick(v)
}

/// `v` in exponent form with up to 3 significant digits: `1.5e-5`.
fn exponent(v: f64) -> String {
    let s = format!("{v:.2e}");
    match s.split_once('e') {
        Some((m, e)) => {
            let m = if m.contains('.') {
                m.trim_end_matches('0').trim_end_matches('.')
            } else {
                m
            };
            format!("{m}e{e}")
        }
        None => s,
    }
}

/// A tick label: up to 4 significant digits, in exponent form below 1e-3 and from 1e5.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || a < 1e-12 {
        "0".to_string()
    } else if !(1e-3..1e5).contains(&a) {
        exponent(v)
    } else {
        let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let s = format!("{v:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    }
}

/// The label of log10 value `v` on a log axis: `1e-6` at whole decades, else the value.
fn power_of_ten(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("1e{}", v.round() as i64)
    } else {
        tick(10f64.powf(v))
    }
}

/// The PNG of an RGB buffer `w` × `h`.
fn png_of(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>, String> {
    let mut pixmap = tiny_skia::Pixmap::new(w, h).ok_or_else(|| format!("no {w} x {h} picture"))?;
    for (px, c) in pixmap
        .data_mut()
        .chunks_exact_mut(4)
        .zip(rgb.chunks_exact(3))
    {
        px.copy_from_slice(&[c[0], c[1], c[2], 255]);
    }
    pixmap.encode_png().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tick_a_round_off_from_zero_reads_0() {
        assert_eq!(axis_tick(-6.78e-21, 3.5e-4, false), "0");
        assert_eq!(axis_tick(5e-5, 3.5e-4, false), "5e-5");
        assert_eq!(axis_tick(1e-13, 1e-12, false), "1e-13");
    }

    #[test]
    fn ticks_are_short_and_exact_enough() {
        assert_eq!(tick(0.0), "0");
        assert_eq!(tick(0.5), "0.5");
        assert_eq!(tick(12.5), "12.5");
        assert_eq!(tick(1500.0), "1500");
        assert_eq!(tick(1.5e-5), "1.5e-5");
        assert_eq!(tick(-2.0e6), "-2e6");
        assert_eq!(power_of_ten(-6.0), "1e-6");
        // One form per axis: an axis up to 1.1 mm labels 2e-4 and 1e-3 alike.
        assert_eq!(axis_tick(1e-3, 1.1e-3, false), "1e-3");
        assert_eq!(axis_tick(0.5, 1.0, true), "");
        assert_eq!(axis_tick(3.0, 4.0, true), "3");
    }

    #[test]
    fn the_csv_has_one_row_per_point_drawn_and_a_log_axis_leaves_out_zeros() {
        let mut s = Series::new("a, b");
        s.push(1.0, 1e-3, "step 1");
        s.push(2.0, 0.0, "step 2");
        s.push(3.0, 1e-9, "step 3");
        let chart = Chart {
            name: "r".into(),
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            columns: ("x".into(), "y".into()),
            log_y: true,
            legend: false,
            one_colour: true,
            integer: (false, false),
            series: vec![s],
        };
        let csv = chart.csv();
        assert_eq!(
            csv,
            "series,x,y,label\n\"a, b\",1.0,0.001,step 1\n\"a, b\",3.0,1e-9,step 3\n"
        );
        assert_eq!(extents(&chart.drawn(), true).1, (-9.0, -3.0));
    }

    #[test]
    fn a_chart_draws_to_png_and_svg_with_its_axis_labels() {
        let mut s = Series::new("line");
        s.push(0.0, 0.0, "step 0");
        s.push(1.0, 2.0, "step 1");
        let chart = Chart {
            name: "c".into(),
            title: "title".into(),
            x_label: "displacement (m)".into(),
            y_label: "load factor (-)".into(),
            columns: ("x".into(), "y".into()),
            log_y: false,
            legend: true,
            one_colour: false,
            integer: (false, false),
            series: vec![s],
        };
        let dir = tempfile::tempdir().unwrap();
        let w = chart.write(dir.path()).unwrap();
        let png = std::fs::read(&w.png).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        let svg = std::fs::read_to_string(&w.svg).unwrap();
        assert!(svg.contains("displacement (m)") && svg.contains("load factor (-)"));
        // Something other than the white background was drawn (the line and the text).
        let pixmap = tiny_skia::Pixmap::decode_png(&png).unwrap();
        let dark = pixmap
            .pixels()
            .iter()
            .filter(|p| p.red() < 100 && p.green() < 100)
            .count();
        assert!(dark > 500, "{dark} dark pixels");
    }
}
