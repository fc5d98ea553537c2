//! Small SVG charts for scans: a line plot (1D) and a heatmap with a colour bar (2D).
//! SVG needs no fonts on this machine: the viewer renders the text.

use std::fmt::Write;

const W: f64 = 640.0;
const H: f64 = 420.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 90.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 55.0;

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        (0.0, 1.0)
    } else if hi - lo < 1e-12 {
        (lo - 0.5, hi + 0.5)
    } else {
        (lo, hi)
    }
}

fn header(out: &mut String, title: &str) {
    let _ = write!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">
<rect width="{W}" height="{H}" fill="white"/>
<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>
"#,
        W / 2.0,
        escape(title)
    );
}

fn axes(out: &mut String, x: (f64, f64), y: (f64, f64), xlabel: &str, ylabel: &str, width: f64) {
    let (x0, y0, x1, y1) = (LEFT, H - BOTTOM, LEFT + width, TOP);
    let _ = writeln!(
        out,
        r#"<rect x="{x0}" y="{y1}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        x1 - x0,
        y0 - y1
    );
    for i in 0..=4 {
        let t = i as f64 / 4.0;
        let px = x0 + t * (x1 - x0);
        let py = y0 - t * (y0 - y1);
        let _ = writeln!(
            out,
            r#"<line x1="{px}" y1="{y0}" x2="{px}" y2="{}" stroke="black"/><text x="{px}" y="{}" text-anchor="middle">{:.3}</text>"#,
            y0 + 5.0,
            y0 + 18.0,
            x.0 + t * (x.1 - x.0)
        );
        let _ = writeln!(
            out,
            r#"<line x1="{}" y1="{py}" x2="{x0}" y2="{py}" stroke="black"/><text x="{}" y="{}" text-anchor="end">{:.3}</text>"#,
            x0 - 5.0,
            x0 - 8.0,
            py + 4.0,
            y.0 + t * (y.1 - y.0)
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text><text transform="translate(16 {}) rotate(-90)" text-anchor="middle">{}</text>"#,
        (x0 + x1) / 2.0,
        H - 12.0,
        escape(xlabel),
        (y0 + y1) / 2.0,
        escape(ylabel)
    );
}

/// A line plot of `ys` against `xs`, with a dashed zero line when 0 is in range.
pub fn line_plot(title: &str, xlabel: &str, ylabel: &str, xs: &[f64], ys: &[f64]) -> String {
    lines_plot(title, xlabel, ylabel, xs, &[("", ys.to_vec())])
}

/// Several named series against the same `xs`, with a legend when names are given.
pub fn lines_plot(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    xs: &[f64],
    series: &[(&str, Vec<f64>)],
) -> String {
    const COLOURS: [&str; 6] = [
        "rgb(31,119,180)",
        "rgb(214,39,40)",
        "rgb(44,160,44)",
        "rgb(148,103,189)",
        "rgb(255,127,14)",
        "rgb(23,190,207)",
    ];
    let mut out = String::new();
    header(&mut out, title);
    let width = W - LEFT - 30.0;
    let xr = range(xs.iter().copied());
    let yr = range(series.iter().flat_map(|(_, ys)| ys.iter().copied()));
    axes(&mut out, xr, yr, xlabel, ylabel, width);
    let px = |x: f64| LEFT + (x - xr.0) / (xr.1 - xr.0) * width;
    let py = |y: f64| (H - BOTTOM) - (y - yr.0) / (yr.1 - yr.0) * (H - BOTTOM - TOP);
    if yr.0 < 0.0 && yr.1 > 0.0 {
        let _ = writeln!(
            out,
            r#"<line x1="{LEFT}" y1="{0}" x2="{1}" y2="{0}" stroke="gray" stroke-dasharray="4 3"/>"#,
            py(0.0),
            LEFT + width
        );
    }
    for (k, (name, ys)) in series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let points: Vec<String> = xs
            .iter()
            .zip(ys)
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|(&x, &y)| format!("{:.2},{:.2}", px(x), py(y)))
            .collect();
        let _ = writeln!(
            out,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="2"/>"#,
            points.join(" ")
        );
        if !name.is_empty() {
            let y = TOP + 16.0 + 16.0 * k as f64;
            let _ = writeln!(
                out,
                r#"<line x1="{0}" y1="{y}" x2="{1}" y2="{y}" stroke="{colour}" stroke-width="2"/><text x="{2}" y="{3}">{4}</text>"#,
                LEFT + 10.0,
                LEFT + 30.0,
                LEFT + 36.0,
                y + 4.0,
                escape(name)
            );
        }
    }
    out.push_str("</svg>\n");
    out
}

/// A colour for `t` in [0, 1]: dark blue, through white-ish green, to yellow.
pub fn colour(t: f64) -> (u8, u8, u8) {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let stops = [
        (0.0, (48.0, 18.0, 59.0)),
        (0.25, (40.0, 110.0, 200.0)),
        (0.5, (30.0, 190.0, 160.0)),
        (0.75, (170.0, 220.0, 60.0)),
        (1.0, (250.0, 230.0, 40.0)),
    ];
    for w in stops.windows(2) {
        let ((t0, c0), (t1, c1)) = (w[0], w[1]);
        if t <= t1 {
            let f = (t - t0) / (t1 - t0);
            let mix = |a: f64, b: f64| (a + f * (b - a)).round() as u8;
            return (mix(c0.0, c1.0), mix(c0.1, c1.1), mix(c0.2, c1.2));
        }
    }
    (250, 230, 40)
}

/// A heatmap of `z[i][j]` over `xs[i]` (horizontal) and `ys[j]` (vertical).
pub fn heatmap(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    xs: &[f64],
    ys: &[f64],
    z: &[Vec<f64>],
) -> String {
    let mut out = String::new();
    header(&mut out, title);
    let width = W - LEFT - RIGHT;
    let xr = range(xs.iter().copied());
    let yr = range(ys.iter().copied());
    let zr = range(z.iter().flatten().copied());
    let (nx, ny) = (xs.len().max(1) as f64, ys.len().max(1) as f64);
    let cw = width / nx;
    let ch = (H - BOTTOM - TOP) / ny;
    for (i, column) in z.iter().enumerate() {
        for (j, &v) in column.iter().enumerate() {
            let (r, g, b) = colour((v - zr.0) / (zr.1 - zr.0));
            let _ = writeln!(
                out,
                r#"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="rgb({r},{g},{b})"/>"#,
                LEFT + i as f64 * cw,
                H - BOTTOM - (j as f64 + 1.0) * ch,
                cw + 0.3,
                ch + 0.3
            );
        }
    }
    axes(&mut out, xr, yr, xlabel, ylabel, width);
    // Colour bar.
    let bx = LEFT + width + 20.0;
    for k in 0..50 {
        let t = k as f64 / 49.0;
        let (r, g, b) = colour(t);
        let y = H - BOTTOM - (k as f64 + 1.0) * (H - BOTTOM - TOP) / 50.0;
        let _ = writeln!(
            out,
            r#"<rect x="{bx}" y="{y:.2}" width="14" height="{:.2}" fill="rgb({r},{g},{b})"/>"#,
            (H - BOTTOM - TOP) / 50.0 + 0.3
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}">{:.3}</text><text x="{}" y="{}">{:.3}</text>"#,
        bx,
        TOP - 6.0,
        zr.1,
        bx,
        H - BOTTOM + 16.0,
        zr.0
    );
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_span_the_map_and_clamp() {
        assert_eq!(colour(0.0), (48, 18, 59));
        assert_eq!(colour(1.0), (250, 230, 40));
        assert_eq!(colour(2.0), colour(1.0));
        assert_eq!(colour(f64::NAN), colour(0.0));
    }

    #[test]
    fn charts_are_well_formed() {
        let svg = line_plot("a < b", "x", "y", &[0.0, 1.0, 2.0], &[-1.0, 0.5, 1.0]);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("a &lt; b") && svg.contains("stroke-dasharray"));
        let map = heatmap(
            "m",
            "x",
            "y",
            &[0.0, 1.0],
            &[0.0, 1.0, 2.0],
            &[vec![0.0, 1.0, 2.0], vec![3.0, 4.0, 5.0]],
        );
        assert_eq!(map.matches("<rect").count(), 1 + 6 + 1 + 50);
    }
}
