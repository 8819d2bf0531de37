//! `tmclsim run --plot FILE.png|FILE.svg` and `--samples FILE.csv`: the
//! motion of a run sampled at a fixed step of virtual time.
//!
//! The plot has one panel per quantity and axis, all on one time axis:
//! position (with the target), velocity, and — where they change within
//! the window — the load reading (AP 206), the motor current and the
//! digital outputs. Axes carry their units, every panel a legend.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::io::Write;
use std::path::Path;
use tmclsim_firmware::Module;

/// The motion of a run, one row per sample.
pub struct Samples {
    time: Vec<f64>,
    axes: Vec<AxisSeries>,
    outputs: Vec<u32>,
    /// How many digital outputs the module has (bits of `outputs`).
    output_count: u32,
}

#[derive(Default)]
struct AxisSeries {
    position: Vec<f64>,
    target: Vec<f64>,
    speed: Vec<f64>,
    load: Vec<f64>,
    current: Vec<f64>,
}

const WIDTH: u32 = 1200;
const PANEL_HEIGHT: u32 = 230;
/// The strip right of each panel that holds its legend.
const LEGEND_WIDTH: u32 = 190;
/// Points drawn per line at most; denser series are drawn as their
/// minimum and maximum per slice of time, so that no extreme is lost.
const MAX_POINTS: usize = 4000;

const BLUE: RGBColor = RGBColor(31, 119, 180);
const ORANGE: RGBColor = RGBColor(255, 127, 14);
const GREEN: RGBColor = RGBColor(44, 160, 44);
const RED: RGBColor = RGBColor(214, 39, 40);
const PURPLE: RGBColor = RGBColor(148, 103, 189);
const PALETTE: [RGBColor; 8] = [BLUE, ORANGE, GREEN, RED, PURPLE, RGBColor(140, 86, 75), RGBColor(227, 119, 194), RGBColor(127, 127, 127)];

/// One line of a panel: its legend, colour and points (time, value).
type Line = (String, RGBColor, Vec<(f64, f64)>);

/// One panel: a title, the y axis's label and its lines.
struct Panel {
    title: String,
    y_label: String,
    lines: Vec<Line>,
}

impl Samples {
    pub fn new(axes: usize, output_count: u32) -> Samples {
        Samples { time: Vec::new(), axes: (0..axes).map(|_| AxisSeries::default()).collect(), outputs: Vec::new(), output_count }
    }

    /// Takes one sample of the module as it is now.
    pub fn take(&mut self, m: &Module) {
        self.time.push(m.now_ns() as f64 * 1e-9);
        for (a, s) in self.axes.iter_mut().enumerate() {
            let axis = m.axis(a);
            s.position.push(f64::from(m.actual_position(a)));
            s.target.push(f64::from(axis.target_word));
            s.speed.push(f64::from(m.actual_speed(a)));
            s.load.push(f64::from(axis.driver.load_value));
            s.current.push(f64::from(m.motor_current(a)));
        }
        self.outputs.push(m.outputs());
    }

    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Writes the samples as CSV: time, then per axis position, target,
    /// speed, load and current, then the outputs as a bit field.
    pub fn write_csv(&self, path: &Path) -> Result<(), String> {
        let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut w = std::io::BufWriter::new(file);
        let mut header = "time_s".to_string();
        for a in 0..self.axes.len() {
            header.push_str(&format!(",position_{a},target_{a},speed_{a},load_{a},current_{a}"));
        }
        header.push_str(",outputs");
        let io = |e: std::io::Error| format!("{}: {e}", path.display());
        writeln!(w, "{header}").map_err(io)?;
        for (i, t) in self.time.iter().enumerate() {
            let mut line = format!("{t:.6}");
            for s in &self.axes {
                line.push_str(&format!(",{},{},{},{},{}", s.position[i], s.target[i], s.speed[i], s.load[i], s.current[i]));
            }
            line.push_str(&format!(",{}", self.outputs[i]));
            writeln!(w, "{line}").map_err(io)?;
        }
        w.flush().map_err(io)
    }

    /// Draws the samples between `from` and `to` (seconds; `None`: the
    /// whole run) into a PNG or SVG file, by the file's extension.
    pub fn write_plot(&self, path: &Path, from: Option<f64>, to: Option<f64>) -> Result<(), String> {
        let t0 = from.unwrap_or(0.0);
        let t1 = to.unwrap_or_else(|| self.time.last().copied().unwrap_or(0.0));
        if t1 <= t0 {
            return Err(format!("the plot's window {t0} s … {t1} s is empty"));
        }
        let window: Vec<usize> = (0..self.time.len()).filter(|&i| (t0..=t1).contains(&self.time[i])).collect();
        if window.is_empty() {
            return Err(format!("no samples between {t0} s and {t1} s"));
        }
        let panels = self.panels(&window);
        let height = PANEL_HEIGHT * panels.len() as u32;
        // A font of our own: the plot looks the same on every machine.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
        let result = match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png") => draw(BitMapBackend::new(path, (WIDTH, height)).into_drawing_area(), &panels, t0, t1),
            Some("svg") => draw(SVGBackend::new(path, (WIDTH, height)).into_drawing_area(), &panels, t0, t1),
            _ => return Err(format!("{}: the plot is written as .png or .svg", path.display())),
        };
        result.map_err(|e| format!("{}: {e}", path.display()))
    }

    fn panels(&self, window: &[usize]) -> Vec<Panel> {
        let series = |values: &[f64]| -> Vec<(f64, f64)> { decimate(window.iter().map(|&i| (self.time[i], values[i])).collect()) };
        let changes = |values: &[f64]| window.iter().any(|&i| values[i] != values[window[0]]);
        let mut panels = Vec::new();
        for (a, s) in self.axes.iter().enumerate() {
            panels.push(Panel {
                title: format!("axis {a}: position"),
                y_label: "µsteps".into(),
                lines: vec![
                    ("actual position (AP 1)".into(), BLUE, series(&s.position)),
                    ("target position (AP 0)".into(), GREEN, series(&s.target)),
                ],
            });
            panels.push(Panel {
                title: format!("axis {a}: velocity"),
                y_label: "internal units".into(),
                lines: vec![("actual speed (AP 3)".into(), ORANGE, series(&s.speed))],
            });
            if changes(&s.load) {
                panels.push(Panel {
                    title: format!("axis {a}: load"),
                    y_label: "reading".into(),
                    lines: vec![("load value (AP 206)".into(), RED, series(&s.load))],
                });
            }
            if changes(&s.current) {
                panels.push(Panel {
                    title: format!("axis {a}: motor current"),
                    y_label: "0…255 = 0…100 %".into(),
                    lines: vec![("current in effect".into(), PURPLE, series(&s.current))],
                });
            }
        }
        let changed_outputs: Vec<u32> = (0..self.output_count.min(32))
            .filter(|&n| window.iter().any(|&i| (self.outputs[i] ^ self.outputs[window[0]]) >> n & 1 == 1))
            .collect();
        if !changed_outputs.is_empty() {
            // Each output as a step trace of its own, stacked: n + level.
            let lines = changed_outputs
                .iter()
                .enumerate()
                .map(|(k, &n)| {
                    let levels: Vec<f64> = self.outputs.iter().map(|o| k as f64 * 1.5 + f64::from(o >> n & 1)).collect();
                    (format!("OUT{n}"), PALETTE[k % PALETTE.len()], series(&levels))
                })
                .collect();
            panels.push(Panel { title: "digital outputs".into(), y_label: "low / high".into(), lines });
        }
        panels
    }
}

/// At most [`MAX_POINTS`] points: per slice of time, the first, the
/// minimum and the maximum (in time order) and the last sample.
fn decimate(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    if points.len() <= MAX_POINTS {
        return points;
    }
    let per = points.len().div_ceil(MAX_POINTS / 4);
    let mut out = Vec::with_capacity(MAX_POINTS);
    for chunk in points.chunks(per) {
        let lo = chunk.iter().enumerate().min_by(|a, b| a.1.1.total_cmp(&b.1.1)).map_or(0, |(i, _)| i);
        let hi = chunk.iter().enumerate().max_by(|a, b| a.1.1.total_cmp(&b.1.1)).map_or(0, |(i, _)| i);
        let mut keep = [0, lo.min(hi), lo.max(hi), chunk.len() - 1];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for i in keep {
            if i != last {
                out.push(chunk[i]);
                last = i;
            }
        }
    }
    out
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, panels: &[Panel], t0: f64, t1: f64) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    for (panel, area) in panels.iter().zip(root.split_evenly((panels.len(), 1))) {
        // The legend has a strip of its own, right of the plot: it never
        // covers a curve.
        let (area, legend) = area.split_horizontally(area.dim_in_pixel().0.saturating_sub(LEGEND_WIDTH));
        let (lo, hi) = range(panel.lines.iter().flat_map(|(_, _, p)| p.iter().map(|q| q.1)));
        let mut chart = ChartBuilder::on(&area)
            .caption(&panel.title, ("sans-serif", 16))
            .margin(8)
            .margin_right(16)
            .x_label_area_size(34)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc(panel.y_label.as_str())
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 13))
            .light_line_style(RGBColor(235, 235, 235))
            .x_label_formatter(&|t| format!("{t}"))
            .y_label_formatter(&|v| if (hi - lo) >= 10.0 { format!("{v:.0}") } else { format!("{v:.2}") })
            .draw()
            .map_err(e)?;
        for (_, color, points) in &panel.lines {
            chart.draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(2))).map_err(e)?;
        }
        draw_legend(&legend, &panel.lines).map_err(e)?;
    }
    root.present().map_err(e)
}

/// A panel's legend, top down in its strip: a short line of each curve's
/// colour, then its name.
fn draw_legend<DB: DrawingBackend>(strip: &DrawingArea<DB, Shift>, lines: &[Line]) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for (k, (name, color, _)) in lines.iter().enumerate() {
        let y = 36 + 20 * k as i32;
        strip.draw(&PathElement::new(vec![(0, y), (18, y)], color.stroke_width(2)))?;
        strip.draw(&Text::new(name.as_str(), (24, y - 7), ("sans-serif", 12)))?;
    }
    Ok(())
}

/// The y range of a panel, with a margin; a flat line gets ±1.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    if hi - lo < 1e-9 {
        return (lo - 1.0, hi + 1.0);
    }
    let pad = (hi - lo) * 0.05;
    (lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::decimate;

    #[test]
    fn decimation_keeps_every_extreme() {
        let points: Vec<(f64, f64)> =
            (0..100_000).map(|i| (f64::from(i), f64::from((i * 7919) % 1000) - f64::from(i32::from(i == 54_321)) * 5000.0)).collect();
        let d = decimate(points.clone());
        assert!(d.len() <= super::MAX_POINTS, "{}", d.len());
        assert!(d.contains(&(54_321.0, -5000.0 + f64::from(54_321 * 7919 % 1000))), "the single dip survives");
        assert!(d.windows(2).all(|w| w[0].0 < w[1].0), "in time order");
        assert_eq!((d[0], *d.last().unwrap()), (points[0], *points.last().unwrap()));
        assert_eq!(decimate(points[..10].to_vec()), points[..10].to_vec(), "short series stay as they are");
    }
}
