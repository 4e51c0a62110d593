//! SVG line charts for documentation/index.html: panels stacked over one time axis, drawn from
//! a simulation at pack time, so the FMU's page shows what the packed model computes.

use std::fmt::Write;

/// One panel: its axis label and curves (label, values in the label's unit).
pub struct Panel {
    pub axis: String,
    pub curves: Vec<(String, Vec<f64>)>,
}

const WIDTH: f64 = 760.0;
const PANEL_HEIGHT: f64 = 170.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 150.0;
const GAP: f64 = 28.0;
const COLORS: [&str; 4] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"];
/// Points per curve at most: each bucket keeps its minimum and maximum, so an oscillation
/// faster than the bucket still shows its envelope.
const BUCKETS: usize = 600;

/// Ticks at 1, 2 or 5 times a power of ten covering [lo, hi], with their labels (as many
/// decimals as the step has).
fn ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let raw = (hi - lo) / 5.0;
    let e = raw.log10().floor();
    let p = 10f64.powf(e);
    let step = [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * p).find(|s| *s >= raw).unwrap_or(10.0 * p);
    let decimals = (-e).max(0.0) as usize;
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    let label = |v: f64| format!("{:.decimals$}", if v.abs() < 1e-9 * step { 0.0 } else { v });
    (first..=last).map(|k| k as f64 * step).map(|v| (v, label(v))).collect()
}

/// The value range of a panel, padded by 5 %; a flat curve gets a unit-wide band.
fn range(curves: &[(String, Vec<f64>)]) -> (f64, f64) {
    let all = curves.iter().flat_map(|c| c.1.iter().copied()).filter(|y| y.is_finite());
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.5 * lo.abs().max(1.0) };
    (lo - pad, hi + pad)
}

/// Indices of `y` to draw: all, or per bucket the first minimum and maximum in time order.
fn decimate(y: &[f64]) -> Vec<usize> {
    if y.len() <= 2 * BUCKETS {
        return (0..y.len()).collect();
    }
    let size = y.len().div_ceil(BUCKETS);
    let mut keep = Vec::with_capacity(2 * BUCKETS + 1);
    for start in (0..y.len()).step_by(size) {
        let bucket = start..(start + size).min(y.len());
        let min = bucket.clone().min_by(|&a, &b| y[a].total_cmp(&y[b])).unwrap_or(start);
        let max = bucket.max_by(|&a, &b| y[a].total_cmp(&y[b])).unwrap_or(start);
        keep.extend(if min < max { [min, max] } else { [max, min] });
    }
    keep.dedup();
    keep
}

/// An SVG chart of the panels over time `t` [s], with a title.
pub fn chart(title: &str, t: &[f64], panels: &[Panel]) -> String {
    let height = 30.0 + panels.len() as f64 * (PANEL_HEIGHT + GAP) + 20.0;
    let plot_w = WIDTH - LEFT - RIGHT;
    let (t0, t1) = (t.first().copied().unwrap_or(0.0), t.last().copied().unwrap_or(1.0).max(1e-9));
    let x = |tt: f64| LEFT + (tt - t0) / (t1 - t0) * plot_w;
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {WIDTH} {height}\" width=\"{WIDTH}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <text x=\"{}\" y=\"18\" text-anchor=\"middle\" font-size=\"14\">{}</text>\n",
        WIDTH / 2.0,
        escape(title)
    );
    for (k, panel) in panels.iter().enumerate() {
        let top = 30.0 + k as f64 * (PANEL_HEIGHT + GAP);
        let (lo, hi) = range(&panel.curves);
        let y = |v: f64| top + PANEL_HEIGHT - (v - lo) / (hi - lo) * PANEL_HEIGHT;
        let _ = writeln!(
            s,
            "<rect x=\"{LEFT}\" y=\"{top}\" width=\"{plot_w}\" height=\"{PANEL_HEIGHT}\" fill=\"none\" stroke=\"#444\"/>"
        );
        for (v, text) in ticks(lo, hi) {
            let _ = writeln!(
                s,
                "<line x1=\"{LEFT}\" x2=\"{}\" y1=\"{yy:.1}\" y2=\"{yy:.1}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
                LEFT + plot_w,
                LEFT - 4.0,
                y(v) + 4.0,
                text,
                yy = y(v)
            );
        }
        let _ = writeln!(
            s,
            "<text transform=\"translate(16 {:.1}) rotate(-90)\" text-anchor=\"middle\">{}</text>",
            top + PANEL_HEIGHT / 2.0,
            escape(&panel.axis)
        );
        for (c, (label, values)) in panel.curves.iter().enumerate() {
            let color = COLORS[c % COLORS.len()];
            let points: Vec<String> = decimate(values)
                .into_iter()
                .filter(|&i| values[i].is_finite())
                .map(|i| format!("{:.1},{:.1}", x(t[i]), y(values[i])))
                .collect();
            let (lx, ly) = (LEFT + plot_w + 10.0, top + 12.0 + 18.0 * c as f64);
            let _ = writeln!(
                s,
                "<polyline fill=\"none\" stroke=\"{color}\" stroke-width=\"1.2\" points=\"{}\"/>\n\
                 <line x1=\"{lx}\" x2=\"{}\" y1=\"{ly}\" y2=\"{ly}\" stroke=\"{color}\" stroke-width=\"2\"/><text x=\"{}\" y=\"{}\">{}</text>",
                points.join(" "),
                lx + 18.0,
                lx + 24.0,
                ly + 4.0,
                escape(label),
            );
        }
    }
    let bottom = 30.0 + panels.len() as f64 * (PANEL_HEIGHT + GAP) - GAP;
    for (v, text) in ticks(t0, t1) {
        let _ = writeln!(s, "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{text}</text>", x(v), bottom + 14.0,);
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">time [s]</text>\n</svg>",
        LEFT + plot_w / 2.0,
        bottom + 30.0
    );
    s
}

/// Text for SVG and HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside() {
        let labels = |lo, hi| ticks(lo, hi).into_iter().map(|t| t.1).collect::<Vec<_>>();
        assert_eq!(labels(0.0, 10.0), ["0", "2", "4", "6", "8", "10"]);
        assert_eq!(labels(-0.3, 0.7), ["-0.2", "0.0", "0.2", "0.4", "0.6"]);
        // 3 x 0.05 is 0.15000000000000002 in binary: the label is 0.15.
        assert_eq!(labels(0.0, 0.25), ["0.00", "0.05", "0.10", "0.15", "0.20", "0.25"]);
    }

    #[test]
    fn decimation_keeps_every_extreme() {
        // A 5 kHz sine over 1 s sampled at 100 kHz (its peaks on samples): far more points than
        // buckets, yet each bucket keeps a crest and a trough (each holds several periods).
        let y: Vec<f64> = (0..100_000).map(|i| (i as f64 * std::f64::consts::PI / 10.0).sin()).collect();
        let keep = decimate(&y);
        assert!(keep.len() <= 2 * BUCKETS + 1 && keep.windows(2).all(|w| w[0] < w[1]));
        assert!(keep.iter().all(|&i| y[i].abs() > 0.999));
        assert_eq!(keep.iter().filter(|&&i| y[i] > 0.0).count(), keep.len() / 2);
    }
}
