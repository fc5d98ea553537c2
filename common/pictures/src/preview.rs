//! Raster pictures (PNG) of grasp scenes and scans: a small software rasteriser (filled
//! triangles, z-buffer, Lambert shading from a fixed light, orthographic views), and figures
//! of 1D and 2D scans with axes ([`heatmap_figure`], [`line_figure`]), written with the
//! pure-Rust `png` crate. Titles and labels use the 8 x 8 bitmap font of `font8x8` (ASCII),
//! so no font files are needed.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use graspopt_sim::{ContactPoint, TriangleMesh};
use nalgebra::{Point3, Vector3};

use crate::chart::colour;
use crate::error::PicturesError;

mod figure;

pub use figure::{Axis, HeatmapFigure, LINE_COLOUR, LineFigure, heatmap_figure, line_figure};

/// Background of scene pictures.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];
/// Colour of contact dots (flat, never shaded, so it can be found in the picture).
pub const CONTACT_COLOUR: [u8; 3] = [230, 20, 20];
/// Colour of contact-normal segments.
pub const NORMAL_COLOUR: [u8; 3] = [20, 160, 40];
/// Colour of the line between the two views.
const SEPARATOR: [u8; 3] = [200, 200, 200];
/// Colour of heatmap cells whose value is not finite.
pub const MISSING_COLOUR: [u8; 3] = [128, 128, 128];
/// Gap between a heatmap and its colour bar, and the bar's width (pixels).
pub const BAR_GAP: u32 = 4;
/// Width of a heatmap's colour bar (pixels).
pub const BAR_WIDTH: u32 = 12;

/// Colour of titles and labels.
pub const TEXT_COLOUR: [u8; 3] = [20, 20, 20];

/// Width in pixels of `text` drawn at `scale` (8 x 8 font pixels per character, each a
/// `scale` x `scale` square).
pub fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * 8 * scale
}

/// Draws `text` with its top left corner at `(x, y)`, each font pixel a `scale` x `scale`
/// square; characters outside ASCII show as `?`, and what falls outside the picture is cut.
pub fn draw_text(img: &mut Image, (x, y): (i64, i64), text: &str, scale: u32, c: [u8; 3]) {
    let s = i64::from(scale.max(1));
    for (k, ch) in text.chars().enumerate() {
        let glyph = font8x8::legacy::BASIC_LEGACY[if ch.is_ascii() {
            ch as usize
        } else {
            '?' as usize
        }];
        let left = x + k as i64 * 8 * s;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                let (px, py) = (left + col * s, y + row as i64 * s);
                for dy in 0..s {
                    for dx in 0..s {
                        img.set(px + dx, py + dy, c);
                    }
                }
            }
        }
    }
}

/// [`draw_text`] centred on the column `centre`.
pub fn draw_text_centred(img: &mut Image, centre: i64, y: i64, text: &str, scale: u32) {
    let x = centre - i64::from(text_width(text, scale)) / 2;
    draw_text(img, (x, y), text, scale, TEXT_COLOUR);
}

/// An RGB picture, rows from the top, `pixels[y * width + x]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[u8; 3]>,
}

impl Image {
    /// A `width` x `height` picture filled with `fill`.
    pub fn new(width: u32, height: u32, fill: [u8; 3]) -> Self {
        Self {
            width,
            height,
            pixels: vec![fill; width as usize * height as usize],
        }
    }

    /// The pixel at column `x`, row `y` (from the top), `None` outside.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn get(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        (x < self.width && y < self.height)
            .then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// Sets a pixel; coordinates outside the picture are ignored.
    pub fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && x < i64::from(self.width) && y < i64::from(self.height) {
            self.pixels[y as usize * self.width as usize + x as usize] = c;
        }
    }

    /// Copies `other` with its top left corner at `(x, y)` (what falls outside is cut).
    pub fn blit(&mut self, other: &Image, (x, y): (i64, i64)) {
        for row in 0..other.height {
            for col in 0..other.width {
                let c = other.pixels[row as usize * other.width as usize + col as usize];
                self.set(x + i64::from(col), y + i64::from(row), c);
            }
        }
    }

    /// Writes the picture as an 8-bit RGB PNG. Errors name the path.
    pub fn save_png(&self, path: &Path) -> Result<(), PicturesError> {
        let write = || -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
            if !(self.width > 0 && self.height > 0) {
                return Err(Box::new(PicturesError::Empty {
                    width: self.width,
                    height: self.height,
                }));
            }
            let file = File::create(path)?;
            let mut encoder = png::Encoder::new(BufWriter::new(file), self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header()?;
            let data: Vec<u8> = self.pixels.iter().flatten().copied().collect();
            writer.write_image_data(&data)?;
            writer.finish()?;
            Ok(())
        };
        write().map_err(|source| PicturesError::WritePng {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// An orthographic camera: `right` and `up` span the picture plane, `forward` points into
/// the scene (larger depth is farther).
#[derive(Clone, Copy, Debug)]
struct Camera {
    right: Vector3<f64>,
    up: Vector3<f64>,
    forward: Vector3<f64>,
}

impl Camera {
    /// Looking along `forward`, with `up_hint` as close to up as possible.
    fn looking(forward: Vector3<f64>, up_hint: Vector3<f64>) -> Self {
        let forward = forward.normalize();
        let right = forward.cross(&up_hint).normalize();
        let up = right.cross(&forward);
        Self { right, up, forward }
    }
}

/// The two views of [`render_grasp`]. The default reference pose approaches along world `+x`
/// with world `+z` up, so: left, looking along the approach axis (from behind and a little
/// above and to the side of the hand, so the fingers around the object show); right, from the
/// side (along `+y`, a little from above), approach axis left to right.
fn cameras() -> [Camera; 2] {
    [
        Camera::looking(Vector3::new(1.0, 0.3, -0.8), Vector3::z()),
        Camera::looking(Vector3::new(0.0, 1.0, -0.3), Vector3::z()),
    ]
}

/// One view placed in the picture: the camera and the fit of the scene to a pixel rectangle.
#[derive(Clone, Copy, Debug)]
struct Viewport {
    camera: Camera,
    /// Left pixel column of the view.
    x0: f64,
    width: f64,
    height: f64,
    /// Scene point (in camera coordinates) at the centre of the view.
    centre: (f64, f64),
    /// Pixels per metre.
    scale: f64,
}

impl Viewport {
    /// Pixel column, row (from the top) and depth of a world point.
    fn project(&self, p: &Point3<f64>) -> (f64, f64, f64) {
        let v = p.coords;
        let (u, w) = (v.dot(&self.camera.right), v.dot(&self.camera.up));
        (
            self.x0 + self.width / 2.0 + (u - self.centre.0) * self.scale,
            self.height / 2.0 - (w - self.centre.1) * self.scale,
            v.dot(&self.camera.forward),
        )
    }
}

/// Both views, each fitted (same scale in both directions, a margin around) to the bounding
/// box of the scene's finite points as that camera sees it.
fn viewports(
    meshes: &[(&TriangleMesh, [u8; 3])],
    contacts: &[ContactPoint],
    width: u32,
    height: u32,
) -> [Viewport; 2] {
    let half = f64::from(width / 2);
    let points: Vec<Point3<f64>> = meshes
        .iter()
        .flat_map(|(m, _)| m.vertices.iter().copied())
        .chain(contacts.iter().map(|c| c.position))
        .filter(|p| p.coords.iter().all(|x| x.is_finite()))
        .collect();
    let cams = cameras();
    [0usize, 1].map(|i| {
        let camera = cams[i];
        let mut lo = (f64::INFINITY, f64::INFINITY);
        let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in &points {
            let (u, w) = (p.coords.dot(&camera.right), p.coords.dot(&camera.up));
            lo = (lo.0.min(u), lo.1.min(w));
            hi = (hi.0.max(u), hi.1.max(w));
        }
        let (centre, extent) = if points.is_empty() {
            ((0.0, 0.0), (1.0, 1.0))
        } else {
            (
                ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0),
                ((hi.0 - lo.0).max(1e-9), (hi.1 - lo.1).max(1e-9)),
            )
        };
        let usable = 0.9;
        let scale = (usable * half / extent.0).min(usable * f64::from(height) / extent.1);
        Viewport {
            camera,
            x0: i as f64 * half,
            width: half,
            height: f64::from(height),
            centre,
            scale,
        }
    })
}

/// A picture of a grasp from two viewpoints side by side (see the cameras above): the meshes
/// as filled, shaded triangles in their colours, the contacts' normals as short segments
/// drawn outward from the surface (normals point into the object), and the contacts as dots,
/// both drawn over everything so none is hidden.
pub fn render_grasp(
    meshes: &[(&TriangleMesh, [u8; 3])],
    contacts: &[ContactPoint],
    width: u32,
    height: u32,
) -> Image {
    let mut img = Image::new(width, height, BACKGROUND);
    let views = viewports(meshes, contacts, width, height);
    let mut depth = vec![f64::INFINITY; img.pixels.len()];
    // Light from the viewer's upper left, in camera coordinates.
    let light = Vector3::new(-0.4, 0.5, -0.77).normalize();
    let segment = views[0].width.min(views[0].height) * 0.08;
    for view in &views {
        let (x_lo, x_hi) = (view.x0 as i64, (view.x0 + view.width) as i64);
        for (mesh, c) in meshes {
            for t in &mesh.triangles {
                let Some(corners) = t
                    .iter()
                    .map(|&i| mesh.vertices.get(i as usize).copied())
                    .collect::<Option<Vec<_>>>()
                else {
                    continue;
                };
                let n = (corners[1] - corners[0]).cross(&(corners[2] - corners[0]));
                let Some(n) = n.try_normalize(1e-300) else {
                    continue;
                };
                let cam_n = Vector3::new(
                    n.dot(&view.camera.right),
                    n.dot(&view.camera.up),
                    n.dot(&view.camera.forward),
                );
                let shade = 0.35 + 0.65 * cam_n.dot(&light).abs();
                let colour = c.map(|k| (f64::from(k) * shade).round().clamp(0.0, 255.0) as u8);
                let p = [
                    view.project(&corners[0]),
                    view.project(&corners[1]),
                    view.project(&corners[2]),
                ];
                fill_triangle(&mut img, &mut depth, p, colour, (x_lo, x_hi));
            }
        }
        for c in contacts {
            let (x, y, _) = view.project(&c.position);
            let n = c.normal;
            let dir = (
                -n.dot(&view.camera.right) * segment,
                n.dot(&view.camera.up) * segment,
            );
            if !(x.is_finite() && y.is_finite() && dir.0.is_finite() && dir.1.is_finite()) {
                continue;
            }
            draw_line(
                &mut img,
                (x, y),
                (x + dir.0, y + dir.1),
                NORMAL_COLOUR,
                (x_lo, x_hi),
            );
        }
        for c in contacts {
            let (x, y, _) = view.project(&c.position);
            if x.is_finite() && y.is_finite() {
                draw_dot(&mut img, (x, y), 3.0, CONTACT_COLOUR, (x_lo, x_hi));
            }
        }
    }
    let mid = i64::from(width / 2);
    for y in 0..i64::from(height) {
        img.set(mid, y, SEPARATOR);
    }
    img
}

/// Height of the strip above a preview's views, for its title and the views' labels.
pub const PREVIEW_HEADER: u32 = 60;
/// What each view of [`render_grasp`] shows, as labelled in previews.
pub const VIEW_LABELS: [&str; 2] = ["along the approach axis", "from the side"];

/// A grasp picture (`width` x `height`): `title` at the top, the two views of
/// [`render_grasp`] below it, each labelled (see [`VIEW_LABELS`]).
pub fn render(
    meshes: &[(&TriangleMesh, [u8; 3])],
    contacts: &[ContactPoint],
    (width, height): (u32, u32),
    title: &str,
) -> Image {
    let header = PREVIEW_HEADER.min(height);
    let scene = render_grasp(meshes, contacts, width, height - header);
    let mut img = Image::new(width, height, BACKGROUND);
    img.blit(&scene, (0, i64::from(header)));
    // Large text where it fits, small where it does not.
    let scale = |text: &str, room: u32| if text_width(text, 2) <= room { 2 } else { 1 };
    let mid = i64::from(width / 2);
    draw_text_centred(&mut img, mid, 8, title, scale(title, width));
    for (i, label) in VIEW_LABELS.iter().enumerate() {
        let centre = i64::from(width / 4) * (2 * i as i64 + 1);
        draw_text_centred(&mut img, centre, 36, label, scale(label, width / 2));
    }
    for y in 32..i64::from(height) {
        img.set(mid, y, SEPARATOR);
    }
    img
}

/// Fills a projected triangle (pixel x, pixel y, depth per corner) where it is nearer than
/// the depth buffer, within the columns `cols` (half-open).
fn fill_triangle(
    img: &mut Image,
    depth: &mut [f64],
    p: [(f64, f64, f64); 3],
    c: [u8; 3],
    cols: (i64, i64),
) {
    if p.iter()
        .any(|q| !(q.0.is_finite() && q.1.is_finite() && q.2.is_finite()))
    {
        return;
    }
    let edge = |a: (f64, f64, f64), b: (f64, f64, f64), x: f64, y: f64| {
        (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0)
    };
    let area = edge(p[0], p[1], p[2].0, p[2].1);
    if area.abs() < 1e-12 {
        return;
    }
    let min_x = p.iter().map(|q| q.0).fold(f64::INFINITY, f64::min).floor() as i64;
    let max_x = p
        .iter()
        .map(|q| q.0)
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as i64;
    let min_y = p.iter().map(|q| q.1).fold(f64::INFINITY, f64::min).floor() as i64;
    let max_y = p
        .iter()
        .map(|q| q.1)
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as i64;
    let (x_from, x_to) = (min_x.max(cols.0), max_x.min(cols.1 - 1));
    let (y_from, y_to) = (min_y.max(0), max_y.min(i64::from(img.height) - 1));
    for y in y_from..=y_to {
        for x in x_from..=x_to {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let w0 = edge(p[1], p[2], px, py) / area;
            let w1 = edge(p[2], p[0], px, py) / area;
            let w2 = edge(p[0], p[1], px, py) / area;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let z = w0 * p[0].2 + w1 * p[1].2 + w2 * p[2].2;
            let k = y as usize * img.width as usize + x as usize;
            if z < depth[k] {
                depth[k] = z;
                img.pixels[k] = c;
            }
        }
    }
}

/// A segment about 2 pixels wide, within the columns `cols`.
fn draw_line(img: &mut Image, a: (f64, f64), b: (f64, f64), c: [u8; 3], cols: (i64, i64)) {
    let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).clamp(1, 10_000);
    for s in 0..=steps {
        let f = s as f64 / steps as f64;
        let (x, y) = (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
        for (dx, dy) in [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5)] {
            let (px, py) = ((x + dx).floor() as i64, (y + dy).floor() as i64);
            if px >= cols.0 && px < cols.1 {
                img.set(px, py, c);
            }
        }
    }
}

/// A filled disc of `radius` pixels centred at `centre`, within the columns `cols`.
fn draw_dot(img: &mut Image, centre: (f64, f64), radius: f64, c: [u8; 3], cols: (i64, i64)) {
    let r = radius.ceil() as i64 + 1;
    let (cx, cy) = (centre.0.floor() as i64, centre.1.floor() as i64);
    for y in cy - r..=cy + r {
        for x in cx - r..=cx + r {
            let (dx, dy) = (x as f64 + 0.5 - centre.0, y as f64 + 0.5 - centre.1);
            if dx * dx + dy * dy <= radius * radius && x >= cols.0 && x < cols.1 {
                img.set(x, y, c);
            }
        }
    }
}

/// A heatmap of `z[i][j]` (`i` horizontal, left to right; `j` vertical, bottom to top), one
/// `cell` x `cell` square per value, coloured by [`colour`] over the range of the finite
/// values (non-finite cells grey), with a colour bar (bottom: minimum, top: maximum) of
/// [`BAR_WIDTH`] pixels after a gap of [`BAR_GAP`] at the right. Size: `(nx * cell + BAR_GAP +
/// BAR_WIDTH) x (ny * cell)`, `ny` the longest column (at least one cell each way).
pub fn heatmap_png(z: &[Vec<f64>], cell: u32) -> Image {
    let cell = cell.max(1);
    let nx = z.len().max(1) as u32;
    let ny = z.iter().map(Vec::len).max().unwrap_or(0).max(1) as u32;
    let (w, h) = (nx * cell + BAR_GAP + BAR_WIDTH, ny * cell);
    let mut img = Image::new(w, h, BACKGROUND);
    let (lo, hi) = z
        .iter()
        .flatten()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let to_rgb = |(r, g, b): (u8, u8, u8)| [r, g, b];
    for (i, column) in z.iter().enumerate() {
        for (j, &v) in column.iter().enumerate() {
            let c = if !v.is_finite() {
                MISSING_COLOUR
            } else if hi > lo {
                to_rgb(colour((v - lo) / (hi - lo)))
            } else {
                to_rgb(colour(0.5))
            };
            let (x0, y0) = (i as u32 * cell, h - (j as u32 + 1) * cell);
            for y in y0..y0 + cell {
                for x in x0..x0 + cell {
                    img.set(i64::from(x), i64::from(y), c);
                }
            }
        }
    }
    let bx = nx * cell + BAR_GAP;
    for y in 0..h {
        let t = if h > 1 {
            f64::from(h - 1 - y) / f64::from(h - 1)
        } else {
            0.5
        };
        let c = to_rgb(colour(t));
        for x in bx..w {
            img.set(i64::from(x), i64::from(y), c);
        }
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(centre: Point3<f64>, half: f64) -> TriangleMesh {
        let v: Vec<Point3<f64>> = (0..8)
            .map(|k| {
                let s = |b: usize| if k & b != 0 { half } else { -half };
                centre + Vector3::new(s(1), s(2), s(4))
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriangleMesh::new(v, t)
    }

    fn distinct(img: &Image, cols: std::ops::Range<u32>) -> usize {
        let mut seen = std::collections::HashSet::new();
        for y in 0..img.height {
            for x in cols.clone() {
                seen.insert(img.get(x, y).unwrap());
            }
        }
        seen.len()
    }

    #[test]
    fn grasp_picture_shows_object_and_contact_dots_in_both_views() {
        let object = cube(Point3::origin(), 0.04);
        let finger = cube(Point3::new(-0.03, 0.0, 0.06), 0.01);
        let contacts = [ContactPoint {
            position: Point3::new(-0.04, 0.0, 0.0),
            normal: Vector3::x(),
            weight: 1.0,
        }];
        let meshes = [(&object, [90, 140, 220]), (&finger, [230, 150, 60])];
        let img = render_grasp(&meshes, &contacts, 400, 200);
        assert_eq!(
            (img.width, img.height, img.pixels.len()),
            (400, 200, 80_000)
        );
        for view in viewports(&meshes, &contacts, 400, 200) {
            let (x, y, _) = view.project(&contacts[0].position);
            assert!((view.x0..view.x0 + view.width).contains(&x) && (0.0..200.0).contains(&y));
            assert_eq!(img.get(x as u32, y as u32), Some(CONTACT_COLOUR));
            // The object's centre shows in its (shaded) blue.
            let (x, y, _) = view.project(&Point3::new(0.01, 0.005, -0.01));
            let [r, g, b] = img.get(x as u32, y as u32).unwrap();
            assert!(b > g && g > r && b > 60, "{:?}", [r, g, b]);
        }
        // Shading: several tones per view, and the background shows.
        assert!(distinct(&img, 0..200) >= 4);
        assert!(distinct(&img, 200..400) >= 4);
        assert!(img.pixels.contains(&NORMAL_COLOUR));
        assert!(img.pixels.contains(&BACKGROUND));
    }

    #[test]
    fn nearer_triangles_hide_farther_ones() {
        // Two cubes in a row along the first camera's line of sight: the near one wins.
        let cam = cameras()[0];
        let near = cube(Point3::origin() - cam.forward * 0.2, 0.01);
        let far = cube(Point3::origin() + cam.forward * 0.2, 0.03);
        let meshes = [(&far, [0, 0, 250]), (&near, [250, 0, 0])];
        let img = render_grasp(&meshes, &[], 300, 150);
        let view = viewports(&meshes, &[], 300, 150)[0];
        let (x, y, _) = view.project(&Point3::origin());
        let [r, _, b] = img.get(x as u32, y as u32).unwrap();
        assert!(r > 0 && b == 0);
    }

    #[test]
    fn empty_and_degenerate_scenes_do_not_panic() {
        let img = render_grasp(&[], &[], 10, 5);
        assert_eq!(img.pixels.len(), 50);
        let bad = TriangleMesh::new(
            vec![
                Point3::new(f64::NAN, 0.0, 0.0),
                Point3::origin(),
                Point3::origin(),
            ],
            vec![[0, 1, 2], [0, 1, 7]],
        );
        let contacts = [ContactPoint {
            position: Point3::new(f64::INFINITY, 0.0, 0.0),
            normal: Vector3::x(),
            weight: 1.0,
        }];
        let img = render_grasp(&[(&bad, [1, 2, 3])], &contacts, 1, 1);
        assert_eq!(img.pixels.len(), 1);
        let img = render_grasp(&[(&bad, [1, 2, 3])], &contacts, 0, 0);
        assert!(img.pixels.is_empty());
        let dir = std::env::temp_dir().join(format!("graspopt-render-{}", std::process::id()));
        let err = img.save_png(&dir.join("x.png")).unwrap_err();
        assert!(format!("{err:#}").contains("x.png"));
    }

    #[test]
    fn heatmap_cells_follow_the_colour_map() {
        // 3 columns (i) x 2 rows (j): minimum at i = 0, j = 0 (bottom left), maximum at
        // i = 2, j = 1 (top right), a missing value at i = 1, j = 1.
        let z = vec![vec![-1.0, 0.0], vec![0.5, f64::NAN], vec![1.0, 3.0]];
        let img = heatmap_png(&z, 5);
        assert_eq!((img.width, img.height), (15 + BAR_GAP + BAR_WIDTH, 10));
        let rgb = |t: f64| {
            let (r, g, b) = colour(t);
            [r, g, b]
        };
        assert_eq!(img.get(0, 9), Some(rgb(0.0)));
        assert_eq!(img.get(4, 5), Some(rgb(0.0)));
        assert_eq!(img.get(14, 0), Some(rgb(1.0)));
        assert_eq!(img.get(10, 4), Some(rgb(1.0)));
        assert_eq!(img.get(7, 2), Some(MISSING_COLOUR));
        assert_eq!(img.get(0, 0), Some(rgb(0.25)));
        // Colour bar: top is the maximum, bottom the minimum; the gap is background.
        assert_eq!(img.get(img.width - 1, 0), Some(rgb(1.0)));
        assert_eq!(img.get(img.width - 1, 9), Some(rgb(0.0)));
        assert_eq!(img.get(15, 3), Some(BACKGROUND));
        // Flat and empty maps are well defined.
        assert_eq!(heatmap_png(&[vec![2.0; 3]], 2).get(0, 0), Some(rgb(0.5)));
        let empty = heatmap_png(&[], 0);
        assert_eq!((empty.width, empty.height), (1 + BAR_GAP + BAR_WIDTH, 1));
    }

    #[test]
    fn png_round_trips() {
        let dir = std::env::temp_dir().join(format!("graspopt-render-rt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("map.png");
        let img = heatmap_png(&[vec![0.0, 1.0], vec![2.0, 3.0]], 3);
        img.save_png(&path).unwrap();
        let file = std::io::BufReader::new(File::open(&path).unwrap());
        let mut reader = png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (img.width, img.height));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let pixels: Vec<[u8; 3]> = buf[..info.buffer_size()]
            .chunks(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        assert_eq!(pixels, img.pixels);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
