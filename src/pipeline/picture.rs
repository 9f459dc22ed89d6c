//! Pictures of a tessellation: an SVG drawing (and, from it, a PNG) of the welded surface
//! meshes and the curves of [`super::mesh`].
//!
//! The view is an orthographic projection: isometric (looking along -(1, 1, 1), z up) when
//! anything leaves the plane z = 0, else the XY plane seen from above. Triangles are filled
//! far to near (painter's order) with one colour per entity, shaded by the angle between
//! the triangle's normal and the view direction (two-sided Lambert); face outlines (open
//! boundaries and silhouettes) and curves are drawn over the faces they lie on and under
//! the faces in front of them. Coordinates
//! are mapped to pixels by the program, not by an SVG `viewBox`, so line widths are the
//! same in every renderer. A frame, a scale bar in the document's unit, a title and one
//! label per entity, at a point of it that no face hides, complete the picture; entities
//! hidden everywhere get no label, and a caption says how many.

use std::fmt::Write as _;

use crate::nurbs::Point3;
use crate::nurbs::vector::dot;

use super::mesh::{CurveLine, FaceMesh, triangle_normal};

/// Picture width in pixels.
const WIDTH: f64 = 800.0;
/// Margin around the drawing, in pixels (room for the scale bar and labels).
const MARGIN: f64 = 48.0;

/// One colour per entity, cycling (Tableau 10, a palette that stays distinct for the
/// colour-blind in its first entries).
const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// An orthographic camera: screen right, screen up and the direction toward the viewer.
struct View {
    right: Point3,
    up: Point3,
    toward: Point3,
    name: &'static str,
}

impl View {
    fn project(&self, p: Point3) -> (f64, f64, f64) {
        (dot(p, self.right), dot(p, self.up), dot(p, self.toward))
    }
}

/// Isometric when any point leaves z = 0, else the XY plane from above.
fn choose_view(faces: &[FaceMesh], curves: &[CurveLine]) -> View {
    let flat = faces
        .iter()
        .flat_map(|f| &f.positions)
        .chain(curves.iter().flat_map(|c| &c.points))
        .all(|p| p[2] == 0.0);
    if flat {
        View {
            right: [1.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            toward: [0.0, 0.0, 1.0],
            name: "top view (XY)",
        }
    } else {
        let s2 = std::f64::consts::FRAC_1_SQRT_2;
        let s6 = 1.0 / 6f64.sqrt();
        let s3 = 1.0 / 3f64.sqrt();
        View {
            right: [-s2, s2, 0.0],
            up: [-s6, -s6, 2.0 * s6],
            toward: [s3, s3, s3],
            name: "isometric view",
        }
    }
}

/// The colour of face outlines and silhouettes.
const OUTLINE: &str = "#303030";

/// The edges of a welded face mesh that outline it seen from `toward`: edges of one
/// triangle only (the face's open boundary) and edges whose two triangles face opposite
/// ways (the silhouette).
fn outline_edges(f: &FaceMesh, toward: Point3) -> Vec<[Point3; 2]> {
    use std::collections::HashMap;
    let mut edges: HashMap<(u32, u32), Vec<f64>> = HashMap::new();
    for t in &f.triangles {
        let [a, b, c] = t.map(|v| f.positions[v as usize]);
        let facing = dot(triangle_normal(a, b, c), toward);
        for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            edges.entry((p.min(q), p.max(q))).or_default().push(facing);
        }
    }
    let mut out: Vec<[Point3; 2]> = edges
        .into_iter()
        .filter(|(_, facing)| match facing.as_slice() {
            [_] => true,
            [x, y] => (*x > 0.0) != (*y > 0.0),
            _ => false,
        })
        .map(|((p, q), _)| [f.positions[p as usize], f.positions[q as usize]])
        .collect();
    // Hash order is arbitrary: sort for a reproducible picture.
    out.sort_by(|a, b| {
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    out
}

/// A length of 1, 2 or 5 times a power of ten, near `target`.
fn nice_length(target: f64) -> f64 {
    if !(target.is_finite() && target > 0.0) {
        return 1.0;
    }
    let power = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * power)
        .find(|&l| l <= target)
        .unwrap_or(power)
}

/// A triangle on screen: pixel x, y and depth toward the viewer of each corner.
type ScreenTriangle = [(f64, f64, f64); 3];

/// Screen-space triangles bucketed on a grid, to find the triangles that cover a point.
struct Coverage {
    triangles: Vec<ScreenTriangle>,
    cells: Vec<Vec<usize>>,
    cell: f64,
    columns: usize,
}

impl Coverage {
    const COLUMNS: usize = 64;

    fn new(triangles: Vec<ScreenTriangle>, height: f64) -> Self {
        let columns = Self::COLUMNS;
        let cell = WIDTH / columns as f64;
        let rows = (height / cell).ceil().max(1.0) as usize;
        let mut cells = vec![Vec::new(); columns * rows];
        let index = |x: f64, limit: usize| ((x / cell).floor().max(0.0) as usize).min(limit - 1);
        for (k, t) in triangles.iter().enumerate() {
            let (x0, x1) = (
                t[0].0.min(t[1].0).min(t[2].0),
                t[0].0.max(t[1].0).max(t[2].0),
            );
            let (y0, y1) = (
                t[0].1.min(t[1].1).min(t[2].1),
                t[0].1.max(t[1].1).max(t[2].1),
            );
            for row in index(y0, rows)..=index(y1, rows) {
                for col in index(x0, columns)..=index(x1, columns) {
                    cells[row * columns + col].push(k);
                }
            }
        }
        Coverage {
            triangles,
            cells,
            cell,
            columns,
        }
    }

    /// Whether a triangle covers the point and lies in front of it by more than `slack`.
    fn hides(&self, (x, y, d): (f64, f64, f64), slack: f64) -> bool {
        let rows = self.cells.len() / self.columns;
        let col = ((x / self.cell).floor().max(0.0) as usize).min(self.columns - 1);
        let row = ((y / self.cell).floor().max(0.0) as usize).min(rows.max(1) - 1);
        self.cells[row * self.columns + col].iter().any(|&k| {
            let [a, b, c] = self.triangles[k];
            // Barycentric coordinates of (x, y) in the screen triangle.
            let det = (b.1 - c.1) * (a.0 - c.0) + (c.0 - b.0) * (a.1 - c.1);
            if det == 0.0 {
                return false;
            }
            let l1 = ((b.1 - c.1) * (x - c.0) + (c.0 - b.0) * (y - c.1)) / det;
            let l2 = ((c.1 - a.1) * (x - c.0) + (a.0 - c.0) * (y - c.1)) / det;
            let l3 = 1.0 - l1 - l2;
            let inside = l1 >= 0.0 && l2 >= 0.0 && l3 >= 0.0;
            inside && l1 * a.2 + l2 * b.2 + l3 * c.2 > d + slack
        })
    }
}

/// Of some screen points, the one nearest their mean (so a label sits inside the visible
/// part of its entity, even a ring-shaped one); `None` for no points.
fn visible_middle(points: impl Iterator<Item = (f64, f64, f64)>) -> Option<(f64, f64)> {
    let points: Vec<(f64, f64)> = points.map(|(x, y, _)| (x, y)).collect();
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(sx, sy), &(x, y)| (sx + x / n, sy + y / n));
    points.into_iter().min_by(|a, b| {
        (a.0 - mx)
            .hypot(a.1 - my)
            .total_cmp(&(b.0 - mx).hypot(b.1 - my))
    })
}

/// XML text escaping for labels.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Bytes of SVG text a triangle takes at least: its `<polygon>` element with every number
/// at its shortest (`0.00`, `rgb(0,0,0)`) is 129 bytes.
pub const SVG_TRIANGLE_BYTES: usize = 120;

/// The SVG picture of the meshes and curves; `unit` names the length unit of the scale bar.
/// `None` as soon as the text passes `max_bytes` (checked after each triangle and line, so
/// a picture over the limit is never held whole).
pub fn svg(
    faces: &[FaceMesh],
    curves: &[CurveLine],
    unit: &str,
    max_bytes: usize,
) -> Option<String> {
    let view = choose_view(faces, curves);
    // Screen bounds of everything drawn.
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in faces
        .iter()
        .flat_map(|f| &f.positions)
        .chain(curves.iter().flat_map(|c| &c.points))
    {
        let (x, y, _) = view.project(*p);
        lo = [lo[0].min(x), lo[1].min(y)];
        hi = [hi[0].max(x), hi[1].max(y)];
    }
    if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
        lo = [0.0; 2];
        hi = [1.0; 2];
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    let scale = (WIDTH - 2.0 * MARGIN) / span; // pixels per model unit
    let height = ((hi[1] - lo[1]) * scale + 2.0 * MARGIN)
        .ceil()
        .max(2.0 * MARGIN + 1.0);
    let px = |p: Point3| -> (f64, f64, f64) {
        let (x, y, d) = view.project(p);
        (
            MARGIN + (x - lo[0]) * scale,
            height - MARGIN - (y - lo[1]) * scale,
            d,
        )
    };
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{height}\" \
         viewBox=\"0 0 {WIDTH} {height}\" font-family=\"DejaVu Sans, Arial, sans-serif\" \
         font-size=\"12\">"
    );
    let _ = writeln!(
        s,
        "<rect x=\"0\" y=\"0\" width=\"{WIDTH}\" height=\"{height}\" fill=\"white\"/>"
    );
    // Triangles far to near (painter's order), then the curve segments that no triangle
    // hides: a segment is hidden when a triangle covering its midpoint on screen lies in
    // front of it by more than a hundredth of the picture's size (an edge lies on its own
    // faces, whose flat triangles may stand off the exact surface by the chord tolerance).
    let mut triangles: Vec<(ScreenTriangle, [u8; 3], f64)> = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        for t in &f.triangles {
            let [a, b, c] = t.map(|v| f.positions[v as usize]);
            let light = 0.35 + 0.65 * dot(triangle_normal(a, b, c), view.toward).abs();
            triangles.push(([px(a), px(b), px(c)], color, light));
        }
    }
    let depth = |t: &ScreenTriangle| (t[0].2 + t[1].2 + t[2].2) / 3.0;
    triangles.sort_by(|a, b| depth(&a.0).total_cmp(&depth(&b.0)));
    for (t, color, light) in &triangles {
        let [r, g, b] = color.map(|c| (f64::from(c) * light).round());
        // A 1 px stroke of the fill colour closes the anti-aliasing seams.
        let _ = writeln!(
            s,
            "<polygon points=\"{:.2},{:.2} {:.2},{:.2} {:.2},{:.2}\" \
             fill=\"rgb({r},{g},{b})\" stroke=\"rgb({r},{g},{b})\" \
             stroke-width=\"1\" stroke-linejoin=\"round\"/>",
            t[0].0, t[0].1, t[1].0, t[1].1, t[2].0, t[2].1
        );
        if s.len() > max_bytes {
            return None;
        }
    }
    let cover = Coverage::new(triangles.into_iter().map(|(t, _, _)| t).collect(), height);
    let slack = 1e-2 * span;
    // Whether the text passed `max_bytes` (the lines after that are not written).
    let mut over = false;
    let mut line = |p: (f64, f64, f64), q: (f64, f64, f64), stroke: &str, width: f64| {
        let mid = ((p.0 + q.0) / 2.0, (p.1 + q.1) / 2.0, (p.2 + q.2) / 2.0);
        over = over || s.len() > max_bytes;
        if !over && !cover.hides(mid, slack) {
            let _ = writeln!(
                s,
                "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" \
                 stroke=\"{stroke}\" stroke-width=\"{width}\" stroke-linecap=\"round\"/>",
                p.0, p.1, q.0, q.1
            );
        }
    };
    // Outlines of the faces: their open boundaries and their silhouettes (edges between a
    // triangle that faces the viewer and one that faces away).
    for f in faces {
        for [a, b] in outline_edges(f, view.toward) {
            line(px(a), px(b), OUTLINE, 1.25);
        }
    }
    for (k, c) in curves.iter().enumerate() {
        let [r, g, b] = PALETTE[(faces.len() + k) % PALETTE.len()];
        let stroke = format!("rgb({r},{g},{b})");
        for w in c.points.windows(2) {
            line(px(w[0]), px(w[1]), &stroke, 2.0);
        }
    }
    if over || s.len() > max_bytes {
        return None;
    }
    // Labels: each entity's id at a visible point of it (a triangle centroid of a face, a
    // point or chord midpoint of a curve that no triangle hides), the one nearest the
    // middle of its visible points; an entity hidden everywhere gets no label, and the
    // caption says how many. A label that would sit on an earlier one moves down a line.
    let spot = |candidates: &mut dyn Iterator<Item = (f64, f64, f64)>| {
        visible_middle(candidates.filter(|&q| !cover.hides(q, slack)))
    };
    let faces_at = faces.iter().map(|f| {
        let mut centroids = f.triangles.iter().map(|t| {
            let [a, b, c] = t.map(|v| px(f.positions[v as usize]));
            (
                (a.0 + b.0 + c.0) / 3.0,
                (a.1 + b.1 + c.1) / 3.0,
                (a.2 + b.2 + c.2) / 3.0,
            )
        });
        (f.entity.as_str(), spot(&mut centroids))
    });
    let curves_at = curves.iter().map(|c| {
        let mut points = c.points.iter().map(|&p| px(p)).chain(
            c.points
                .windows(2)
                .map(|w| px(std::array::from_fn(|k| 0.5 * (w[0][k] + w[1][k])))),
        );
        (c.entity.as_str(), spot(&mut points))
    });
    let mut placed: Vec<(f64, f64)> = Vec::new();
    let mut hidden = 0usize;
    for (id, at) in faces_at.chain(curves_at) {
        let Some((x, mut y)) = at else {
            hidden += 1;
            continue;
        };
        while placed
            .iter()
            .any(|&(px, py)| (px - x).abs() < 40.0 && (py - y).abs() < 13.0)
        {
            y += 14.0;
        }
        placed.push((x, y));
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"black\" stroke=\"white\" stroke-width=\"3\" \
             paint-order=\"stroke\">{}</text>",
            x + 3.0,
            y - 3.0,
            escape(id)
        );
    }
    if hidden > 0 {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#222\" text-anchor=\"end\">{hidden} \
             hidden entit{} not labelled</text>",
            WIDTH - MARGIN / 2.0,
            height - MARGIN / 4.0 - 3.0,
            if hidden == 1 { "y" } else { "ies" }
        );
    }
    // Frame, title and scale bar.
    let _ = writeln!(
        s,
        "<rect x=\"{m}\" y=\"{m}\" width=\"{w:.1}\" height=\"{h:.1}\" fill=\"none\" \
         stroke=\"#444\" stroke-width=\"1\"/>",
        m = MARGIN / 2.0,
        w = WIDTH - MARGIN,
        h = height - MARGIN
    );
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#222\">nurbsx: {} surface(s), {} curve(s), {}</text>",
        MARGIN / 2.0,
        MARGIN / 2.0 - 6.0,
        faces.len(),
        curves.len(),
        view.name
    );
    let bar = nice_length(span / 5.0);
    let (x0, y0) = (MARGIN, height - MARGIN / 4.0 - 4.0);
    let x1 = x0 + bar * scale;
    let _ = writeln!(
        s,
        "<path d=\"M{x0:.1},{:.1} V{y0:.1} H{x1:.1} V{:.1}\" fill=\"none\" stroke=\"black\" \
         stroke-width=\"1.5\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" fill=\"black\">{bar} {}</text>",
        y0 - 5.0,
        y0 - 5.0,
        x1 + 6.0,
        y0 + 1.0,
        escape(unit)
    );
    s.push_str("</svg>\n");
    Some(s)
}

/// Rasterises an SVG picture of [`svg`] to PNG with resvg (the text in the system's fonts;
/// without fonts the labels are left out of the PNG, the geometry is drawn all the same).
pub fn png(svg: &str) -> Result<Vec<u8>, super::PipelineError> {
    use resvg::{tiny_skia, usvg};
    let failed = |what: String| {
        super::PipelineError::new(
            super::ErrorKind::Geometry,
            "picture.png",
            what,
            Default::default(),
        )
    };
    let mut options = usvg::Options::default();
    options.fontdb_mut().load_system_fonts();
    let tree = usvg::Tree::from_str(svg, &options)
        .map_err(|e| failed(format!("cannot read the SVG picture: {e}")))?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| failed(format!("cannot allocate a {size:?} picture")))?;
    resvg::render(
        &tree,
        tiny_skia::Transform::identity(),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|e| failed(format!("cannot encode the PNG: {e}")))
}
