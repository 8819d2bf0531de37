//! `--plot`: position and velocity over time per axis, as a PNG.
//!
//! One panel per axis: position in blue, velocity in orange, each scaled
//! to its own range; grey lines mark zero. The ranges are written into the
//! PNG's text chunks and printed by `tmclsim run`.

use std::path::Path;
use tmclsim_firmware::Module;

pub struct Samples {
    time: Vec<f64>,
    /// Per axis: (position, speed) per sample.
    axes: Vec<Vec<(f64, f64)>>,
}

const WIDTH: usize = 1000;
const PANEL: usize = 300;
const MARGIN: usize = 10;

impl Samples {
    pub fn new(axes: usize) -> Samples {
        Samples { time: Vec::new(), axes: vec![Vec::new(); axes] }
    }

    pub fn take(&mut self, m: &Module) {
        self.time.push(m.now_ns() as f64 * 1e-9);
        for (a, series) in self.axes.iter_mut().enumerate() {
            series.push((m.actual_position(a) as f64, m.actual_speed(a) as f64));
        }
    }

    pub fn write_png(&self, path: &Path) -> Result<(), String> {
        let height = PANEL * self.axes.len().max(1);
        let mut img = vec![255u8; WIDTH * height * 3];
        let t_end = self.time.last().copied().unwrap_or(1.0).max(1e-9);
        let mut texts = vec![("Title".to_string(), "tmclsim run: position (blue) and velocity (orange) per axis".to_string())];
        for (a, series) in self.axes.iter().enumerate() {
            let top = a * PANEL;
            let frame = (MARGIN, top + MARGIN, WIDTH - MARGIN, top + PANEL - MARGIN);
            rect(&mut img, frame, [120, 120, 120]);
            for (k, color, name) in [(0usize, [31u8, 119, 180], "position"), (1, [255, 127, 14], "velocity")] {
                let values: Vec<f64> = series.iter().map(|s| if k == 0 { s.0 } else { s.1 }).collect();
                let (lo, hi) = range(&values);
                texts.push((format!("axis {a} {name}"), format!("{lo} to {hi}")));
                let y_of = |v: f64| frame.3 as f64 - (v - lo) / (hi - lo) * (frame.3 - frame.1) as f64;
                if lo < 0.0 && hi > 0.0 {
                    hline(&mut img, frame.0, frame.2, y_of(0.0) as usize, [200, 200, 200]);
                }
                let x_of = |t: f64| frame.0 as f64 + t / t_end * (frame.2 - frame.0) as f64;
                let mut prev: Option<(f64, f64)> = None;
                for (t, v) in self.time.iter().zip(&values) {
                    let p = (x_of(*t), y_of(*v));
                    if let Some(q) = prev {
                        line(&mut img, q, p, color);
                    }
                    prev = Some(p);
                }
            }
        }
        let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut enc = png::Encoder::new(std::io::BufWriter::new(file), WIDTH as u32, height as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        for (k, v) in &texts {
            enc.add_text_chunk(k.clone(), v.clone()).map_err(|e| e.to_string())?;
        }
        let mut writer = enc.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&img).map_err(|e| e.to_string())?;
        for (k, v) in texts.iter().skip(1) {
            println!("  {k}: {v}");
        }
        Ok(())
    }
}

fn range(values: &[f64]) -> (f64, f64) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    if hi - lo < 1e-9 { (lo - 1.0, hi + 1.0) } else { (lo, hi) }
}

fn put(img: &mut [u8], x: usize, y: usize, c: [u8; 3]) {
    if x < WIDTH {
        let i = (y * WIDTH + x) * 3;
        if i + 2 < img.len() {
            img[i..i + 3].copy_from_slice(&c);
        }
    }
}

fn hline(img: &mut [u8], x0: usize, x1: usize, y: usize, c: [u8; 3]) {
    for x in x0..=x1 {
        put(img, x, y, c);
    }
}

fn rect(img: &mut [u8], (x0, y0, x1, y1): (usize, usize, usize, usize), c: [u8; 3]) {
    hline(img, x0, x1, y0, c);
    hline(img, x0, x1, y1, c);
    for y in y0..=y1 {
        put(img, x0, y, c);
        put(img, x1, y, c);
    }
}

fn line(img: &mut [u8], (x0, y0): (f64, f64), (x1, y1): (f64, f64), c: [u8; 3]) {
    let steps = ((x1 - x0).abs().max((y1 - y0).abs()).ceil() as usize).max(1);
    for i in 0..=steps {
        let f = i as f64 / steps as f64;
        let (x, y) = (x0 + (x1 - x0) * f, y0 + (y1 - y0) * f);
        if x >= 0.0 && y >= 0.0 {
            put(img, x as usize, y as usize, c);
            put(img, x as usize, y as usize + 1, c);
        }
    }
}
