//! The figures' layout, read back from their SVG (whose lines, boxes and text are plain
//! elements): legends cross no curve, the trajectory's legend lies outside the clearance
//! circle, ideal curves are dashed and drawn over the clearance ones, tick labels never read
//! "-0".

use clearance_joint_app::figures::legend::segment_meets_rect;
use clearance_joint_app::figures::series::{BodySeries, CaseSeries};
use clearance_joint_app::figures::{Figure, FigureKind};

/// A polyline's stroke colour, stroke width and points.
type Polyline<'a> = (&'a String, &'a String, &'a Vec<(f64, f64)>);

/// An element of the SVG, in document order.
#[derive(Debug)]
enum Element {
    /// A polyline: stroke colour, stroke width, points.
    Line(String, String, Vec<(f64, f64)>),
    /// A legend box (the border rectangle): x0, y0, x1, y1.
    Legend((f64, f64, f64, f64)),
    /// A text's content.
    Text(String),
}

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    tag[start..].split('"').next()
}

fn number(tag: &str, name: &str) -> f64 {
    attr(tag, name).and_then(|v| v.parse().ok()).unwrap()
}

/// The polylines, legend boxes and texts of `svg`, in document order.
fn elements(svg: &str) -> Vec<Element> {
    let border = "#A0A0A0";
    let mut out = Vec::new();
    for chunk in svg.split('<') {
        if chunk.starts_with("polyline") {
            let points = attr(chunk, "points").unwrap_or("");
            let points = points
                .split_whitespace()
                .filter_map(|p| p.split_once(','))
                .map(|(x, y)| (x.parse().unwrap(), y.parse().unwrap()))
                .collect();
            let stroke = attr(chunk, "stroke").unwrap_or("").to_string();
            let width = attr(chunk, "stroke-width").unwrap_or("").to_string();
            out.push(Element::Line(stroke, width, points));
        } else if chunk.starts_with("rect") && attr(chunk, "stroke") == Some(border) {
            let (x, y) = (number(chunk, "x"), number(chunk, "y"));
            let (w, h) = (number(chunk, "width"), number(chunk, "height"));
            out.push(Element::Legend((x, y, x + w, y + h)));
        } else if chunk.starts_with("text") {
            let text = chunk.split_once('>').map_or("", |(_, t)| t);
            out.push(Element::Text(text.to_string()));
        }
    }
    out
}

/// A case whose curves fill every corner of their panels (oscillations over the whole
/// range), so no legend fits in a corner without headroom.
fn busy_case(label: &str, c: f64, phase: f64) -> CaseSeries {
    let n = 600;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
    let wave =
        |a: f64, w: f64| -> Vec<f64> { t.iter().map(|x| a * (w * x + phase).sin()).collect() };
    let (u, v): (Vec<f64>, Vec<f64>) = t
        .iter()
        .map(|x| (c * (7.0 * x).cos(), c * (11.0 * x).sin()))
        .unzip();
    CaseSeries {
        label: label.into(),
        hinge: "hinge".into(),
        clearance_mm: c,
        t_s: t.clone(),
        bodies: vec![BodySeries {
            name: "panel".into(),
            angle_deg: wave(10.0, 20.0),
            rate_deg_s: wave(200.0, 20.0),
            angle_ideal_deg: wave(9.0, 20.0),
            rate_ideal_deg_s: wave(180.0, 20.0),
        }],
        force_n: wave(50.0, 60.0).iter().map(|f| f.abs()).collect(),
        force_ideal_n: wave(1.0, 30.0).iter().map(|f| 1.5 + f).collect(),
        contact: vec![1.0; n],
        ecc_u_mm: u,
        ecc_v_mm: v,
        peaks: Vec::new(),
    }
}

fn svg_of(kind: FigureKind, cases: &[CaseSeries]) -> String {
    Figure {
        kind,
        title: "layout test",
        cases,
    }
    .svg()
    .unwrap()
}

/// Checks every legend box of `svg` against every polyline drawn before it (the curves of its
/// panel and of the earlier ones; its own marks come after it). Returns the number of boxes.
fn assert_legends_cross_no_curve(svg: &str, what: &str) -> usize {
    let mut lines: Vec<&Vec<(f64, f64)>> = Vec::new();
    let mut boxes = 0;
    let elements = elements(svg);
    for e in &elements {
        match e {
            Element::Line(_, _, points) => lines.push(points),
            Element::Legend(r) => {
                boxes += 1;
                for points in &lines {
                    let hit = points
                        .windows(2)
                        .find(|s| segment_meets_rect(s[0], s[1], *r));
                    assert!(
                        hit.is_none(),
                        "{what}: legend {r:?} covers the curve at {hit:?}"
                    );
                }
            }
            Element::Text(_) => {}
        }
    }
    boxes
}

#[test]
fn legends_cross_no_curve_even_when_every_corner_is_busy() {
    for cases in [
        vec![busy_case("c = 0.50 mm", 0.5, 0.0)],
        vec![
            busy_case("c = 0.10 mm", 0.1, 0.0),
            busy_case("c = 0.25 mm", 0.25, 0.7),
            busy_case("c = 0.50 mm", 0.5, 1.4),
        ],
    ] {
        for kind in FigureKind::ALL {
            let svg = svg_of(kind, &cases);
            let boxes = assert_legends_cross_no_curve(&svg, kind.stem());
            let want = match kind {
                FigureKind::AnglesRates => 2,
                FigureKind::Force => 2 * cases.len(),
                FigureKind::Trajectory => cases.len(),
            };
            assert_eq!(boxes, want, "{:?}: legend boxes", kind);
        }
    }
}

#[test]
fn the_trajectory_legend_lies_outside_the_clearance_circle() {
    let cases = [busy_case("c = 0.50 mm", 0.5, 0.0)];
    let svg = svg_of(FigureKind::Trajectory, &cases);
    let elements = elements(&svg);
    // The clearance circle: the black line of two pixels with hundreds of points.
    let circle = elements
        .iter()
        .find_map(|e| match e {
            Element::Line(s, w, p) if s == "#000000" && w == "2" && p.len() > 100 => Some(p),
            _ => None,
        })
        .expect("a clearance circle");
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for &(x, y) in circle {
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    let legend = elements
        .iter()
        .find_map(|e| match e {
            Element::Legend(r) => Some(*r),
            _ => None,
        })
        .expect("a legend");
    // Outside the circle's bounding square: wholly beside or below it.
    assert!(
        legend.1 > y1 || legend.3 < y0 || legend.0 > x1 || legend.2 < x0,
        "legend {legend:?} meets the circle's square {:?}",
        (x0, y0, x1, y1)
    );
    // Below the x axis description, inside the figure.
    let (w, h) = Figure {
        kind: FigureKind::Trajectory,
        title: "",
        cases: &cases,
    }
    .size();
    assert!(legend.1 > y1 && legend.2 <= f64::from(w) && legend.3 <= f64::from(h));
    for label in ["clearance circle |e| = c", "journal centre", "start"] {
        assert!(svg.contains(label), "no `{label}`");
    }
}

#[test]
fn the_ideal_curve_is_dashed_and_drawn_over_the_clearance_one() {
    let cases = [busy_case("clearance joint (c = 0.50 mm)", 0.5, 0.0)];
    let svg = svg_of(FigureKind::AnglesRates, &cases);
    let elements = elements(&svg);
    let lines: Vec<Polyline<'_>> = elements
        .iter()
        .filter_map(|e| match e {
            Element::Line(s, w, p) => Some((s, w, p)),
            _ => None,
        })
        .collect();
    // The clearance curve: one long polyline in the case's colour.
    let clearance = lines
        .iter()
        .position(|(s, _, p)| *s == "#0072B2" && p.len() > 100)
        .expect("a clearance curve");
    // The ideal curve: black dashes of two points each, many of them, after the clearance
    // curve of the first panel.
    let dashes: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].0 == "#000000" && lines[i].1 == "2" && lines[i].2.len() == 2)
        .collect();
    assert!(dashes.len() > 50, "{} dashes", dashes.len());
    assert!(
        dashes[0] > clearance,
        "the ideal curve is drawn before the clearance one"
    );
    for label in [
        "ideal joint (dashed)",
        "clearance joint (c = 0.50 mm)",
        "panel angle (deg)",
        "panel angular rate (deg/s)",
    ] {
        assert!(svg.contains(label), "no `{label}`");
    }
}

#[test]
fn no_tick_label_reads_negative_zero() {
    let cases = [busy_case("c = 0.50 mm", 0.5, 0.0)];
    for kind in FigureKind::ALL {
        let svg = svg_of(kind, &cases);
        for e in elements(&svg) {
            if let Element::Text(t) = e {
                let negative_zero = t.starts_with('-') && t[1..].parse::<f64>() == Ok(0.0);
                assert!(!negative_zero, "{kind:?}: tick label `{t}`");
            }
        }
    }
}
