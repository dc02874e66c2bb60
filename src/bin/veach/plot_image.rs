//! Log-log line plots of error against time, for `veach plot-convergence` (no plotting
//! dependency: lines, grid and the 5×7 label font on an RGB image).

use crate::label::{draw_text, text_width};
use image::{Rgb, RgbImage};

pub struct Series {
    pub label: String,
    /// (x, y) points, both positive.
    pub points: Vec<(f64, f64)>,
}

const PALETTE: [[u8; 3]; 6] =
    [[31, 119, 180], [214, 39, 40], [44, 160, 44], [255, 127, 14], [148, 103, 189], [23, 190, 207]];
const W: u32 = 900;
const H: u32 = 560;
const LEFT: f64 = 100.0;
const RIGHT: f64 = 30.0;
const TOP: f64 = 30.0;
const BOTTOM: f64 = 70.0;

fn decade_label(e: i32) -> String {
    match e {
        -3..=0 => format!("{}", 10f64.powi(e)),
        1..=4 => format!("{}", 10i64.pow(e as u32)),
        _ => format!("1E{e}"),
    }
}

/// Draws every series on shared log-log axes spanning whole decades, with a dashed
/// 1/√x guide through the first point of the first series (Monte Carlo's convergence rate).
pub fn plot_loglog(series: &[Series], x_label: &str, y_label: &str) -> RgbImage {
    let mut img = RgbImage::from_pixel(W, H, Rgb([255, 255, 255]));
    let pts = || series.iter().flat_map(|s| s.points.iter()).filter(|(x, y)| *x > 0.0 && *y > 0.0);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts() {
        x0 = x0.min(x.log10());
        x1 = x1.max(x.log10());
        y0 = y0.min(y.log10());
        y1 = y1.max(y.log10());
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let (ex0, ex1) = (x0.floor() as i32, (x1.ceil() as i32).max(x0.floor() as i32 + 1));
    let (ey0, ey1) = (y0.floor() as i32, (y1.ceil() as i32).max(y0.floor() as i32 + 1));
    let (pw, ph) = (W as f64 - LEFT - RIGHT, H as f64 - TOP - BOTTOM);
    let to_px = |x: f64, y: f64| {
        let fx = (x.log10() - ex0 as f64) / (ex1 - ex0) as f64;
        let fy = (y.log10() - ey0 as f64) / (ey1 - ey0) as f64;
        (LEFT + fx * pw, TOP + (1.0 - fy) * ph)
    };
    let grid = Rgb([225, 225, 225]);
    let axis = [40, 40, 40];
    // Decade grid lines with labels, and minor lines at 2..9.
    for e in ex0..=ex1 {
        for m in 1..10 {
            let v = m as f64 * 10f64.powi(e);
            if e == ex1 && m > 1 {
                break;
            }
            let (px, _) = to_px(v, 1.0);
            let shade = if m == 1 { grid } else { Rgb([242, 242, 242]) };
            line(&mut img, (px, TOP), (px, TOP + ph), shade, 1.0, false);
        }
        let (px, _) = to_px(10f64.powi(e), 1.0);
        let label = decade_label(e);
        let tw = text_width(&label, 2) as f64;
        draw_text(&mut img, (px - tw / 2.0).max(0.0) as u32, (TOP + ph + 10.0) as u32, &label, 2, axis);
    }
    for e in ey0..=ey1 {
        for m in 1..10 {
            if e == ey1 && m > 1 {
                break;
            }
            let (_, py) = to_px(1.0, m as f64 * 10f64.powi(e));
            let shade = if m == 1 { grid } else { Rgb([242, 242, 242]) };
            line(&mut img, (LEFT, py), (LEFT + pw, py), shade, 1.0, false);
        }
        let (_, py) = to_px(1.0, 10f64.powi(e));
        let label = decade_label(e);
        let tw = text_width(&label, 2) as f64;
        draw_text(&mut img, (LEFT - 10.0 - tw).max(0.0) as u32, (py - 7.0).max(0.0) as u32, &label, 2, axis);
    }
    line(&mut img, (LEFT, TOP), (LEFT, TOP + ph), Rgb(axis), 1.5, false);
    line(&mut img, (LEFT, TOP + ph), (LEFT + pw, TOP + ph), Rgb(axis), 1.5, false);
    let tw = text_width(x_label, 2) as f64;
    draw_text(&mut img, (LEFT + pw / 2.0 - tw / 2.0) as u32, H - 28, x_label, 2, axis);
    draw_text(&mut img, 8, 8, y_label, 2, axis);

    // The 1/√x guide.
    if let Some(&(gx, gy)) = series.first().and_then(|s| s.points.first()) {
        let xe = 10f64.powi(ex1);
        let ye = gy * (gx / xe).sqrt();
        line(&mut img, to_px(gx, gy), to_px(xe, ye), Rgb([150, 150, 150]), 1.0, true);
    }
    for (k, s) in series.iter().enumerate() {
        let color = Rgb(PALETTE[k % PALETTE.len()]);
        let p: Vec<(f64, f64)> =
            s.points.iter().filter(|(x, y)| *x > 0.0 && *y > 0.0).map(|&(x, y)| to_px(x, y)).collect();
        for w in p.windows(2) {
            line(&mut img, w[0], w[1], color, 2.5, false);
        }
        for &(px, py) in &p {
            for dy in -3i32..=3 {
                for dx in -3i32..=3 {
                    put(&mut img, px as i32 + dx, py as i32 + dy, color);
                }
            }
        }
        // Legend, top right.
        let y = TOP as u32 + 12 + 22 * k as u32;
        // A long label starts at the plot's left edge rather than wrapping below zero.
        let lx = ((LEFT + pw) as u32).saturating_sub(20 + text_width(&s.label, 2) + 40).max(LEFT as u32);
        line(&mut img, (lx as f64, y as f64 + 7.0), (lx as f64 + 30.0, y as f64 + 7.0), color, 3.0, false);
        draw_text(&mut img, lx + 38, y, &s.label, 2, PALETTE[k % PALETTE.len()]);
    }
    let guide = "DASHED: 1/SQRT(X)";
    draw_text(&mut img, (LEFT + 12.0) as u32, (TOP + ph - 24.0) as u32, guide, 2, [150, 150, 150]);
    img
}

fn put(img: &mut RgbImage, x: i32, y: i32, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, c);
    }
}

/// A thick line by stepping along it one pixel at a time.
fn line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: Rgb<u8>, width: f64, dashed: bool) {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let steps = dx.abs().max(dy.abs()).ceil().max(1.0) as i32;
    let r = (width / 2.0).max(0.5);
    for i in 0..=steps {
        if dashed && (i / 8) % 2 == 1 {
            continue;
        }
        let t = i as f64 / steps as f64;
        let (x, y) = (a.0 + t * dx, a.1 + t * dy);
        let ri = r.ceil() as i32;
        for oy in -ri..=ri {
            for ox in -ri..=ri {
                if ((ox * ox + oy * oy) as f64) <= r * r + 0.25 {
                    put(img, x.round() as i32 + ox, y.round() as i32 + oy, c);
                }
            }
        }
    }
}
