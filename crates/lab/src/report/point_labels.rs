//! Point labels placed where they cover no marker and no other label.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::draw::{FONT, PanelChart, font_px, label_colour, style_of, text_width};
use super::figures::{Figure, PlotPoint};
use super::style::MARKER_SIZE;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rect {
    pub(super) x0: f64,
    pub(super) y0: f64,
    pub(super) x1: f64,
    pub(super) y1: f64,
}

impl Rect {
    pub(super) fn overlap(&self, other: &Rect) -> f64 {
        let w = self.x1.min(other.x1) - self.x0.max(other.x0);
        let h = self.y1.min(other.y1) - self.y0.max(other.y0);
        if w > 0.0 && h > 0.0 { w * h } else { 0.0 }
    }

    pub(super) fn inside(&self, bounds: &Rect) -> bool {
        self.x0 >= bounds.x0 && self.x1 <= bounds.x1 && self.y0 >= bounds.y0 && self.y1 <= bounds.y1
    }
}

pub(super) const LABEL_FONT: f64 = 14.0;

/// A place for a label around a point: the text anchor's offset from the point and how
/// the text hangs from it.
pub(super) struct Spot {
    pub(super) dx: i32,
    pub(super) dy: i32,
    pub(super) h: HPos,
    pub(super) v: VPos,
}

/// Right, left, above, below, the diagonals, then the same farther out.
pub(super) fn label_spots() -> Vec<Spot> {
    let mut spots = Vec::new();
    for d in [MARKER_SIZE + 4, MARKER_SIZE + 16] {
        spots.extend([
            Spot {
                dx: d,
                dy: 0,
                h: HPos::Left,
                v: VPos::Center,
            },
            Spot {
                dx: -d,
                dy: 0,
                h: HPos::Right,
                v: VPos::Center,
            },
            Spot {
                dx: 0,
                dy: -d,
                h: HPos::Center,
                v: VPos::Bottom,
            },
            Spot {
                dx: 0,
                dy: d,
                h: HPos::Center,
                v: VPos::Top,
            },
            Spot {
                dx: d - 2,
                dy: -(d - 2),
                h: HPos::Left,
                v: VPos::Bottom,
            },
            Spot {
                dx: d - 2,
                dy: d - 2,
                h: HPos::Left,
                v: VPos::Top,
            },
            Spot {
                dx: -(d - 2),
                dy: -(d - 2),
                h: HPos::Right,
                v: VPos::Bottom,
            },
            Spot {
                dx: -(d - 2),
                dy: d - 2,
                h: HPos::Right,
                v: VPos::Top,
            },
        ]);
    }
    spots
}

/// The box a label's text covers at a spot around `at` (pixels).
pub(super) fn label_box(at: (i32, i32), spot: &Spot, w: f64, h: f64) -> Rect {
    let x = (at.0 + spot.dx) as f64;
    let y = (at.1 + spot.dy) as f64;
    let x0 = match spot.h {
        HPos::Left => x,
        HPos::Center => x - w / 2.0,
        HPos::Right => x - w,
    };
    let y0 = match spot.v {
        VPos::Top => y,
        VPos::Center => y - h / 2.0,
        VPos::Bottom => y - h,
    };
    Rect {
        x0,
        y0,
        x1: x0 + w,
        y1: y0 + h,
    }
}

/// The first spot whose box stays inside `bounds` and overlaps nothing `taken`; else the
/// one that overlaps least (a label is never dropped).
pub(super) fn place_label(
    at: (i32, i32),
    w: f64,
    h: f64,
    taken: &[Rect],
    bounds: &Rect,
) -> (Spot, Rect) {
    let mut best: Option<(f64, Spot, Rect)> = None;
    for spot in label_spots() {
        let rect = label_box(at, &spot, w, h);
        let mut cost: f64 = taken.iter().map(|t| t.overlap(&rect)).sum();
        if !rect.inside(bounds) {
            cost += 1e6;
        }
        if cost == 0.0 {
            return (spot, rect);
        }
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, spot, rect));
        }
    }
    let (_, spot, rect) = best.expect("label_spots is not empty");
    (spot, rect)
}

pub(super) fn draw_point_labels(
    chart: &PanelChart<'_>,
    figure: &Figure,
    points: &[&PlotPoint],
) -> anyhow::Result<()> {
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let bounds = Rect {
        x0: xs.start as f64,
        y0: ys.start as f64,
        x1: xs.end as f64,
        y1: ys.end as f64,
    };
    let pixel = |p: &PlotPoint| chart.backend_coord(&(p.x, p.y));
    let m = MARKER_SIZE as f64 + 1.0;
    let mut taken: Vec<Rect> = points
        .iter()
        .map(|p| {
            let (x, y) = pixel(p);
            Rect {
                x0: x as f64 - m,
                y0: y as f64 - m,
                x1: x as f64 + m,
                y1: y as f64 + m,
            }
        })
        .collect();
    let h = font_px(LABEL_FONT) * 1.15;
    for p in points {
        let Some(text) = &p.label else { continue };
        let (spot, rect) = place_label(pixel(p), text_width(text, LABEL_FONT), h, &taken, &bounds);
        taken.push(rect);
        let colour = label_colour(style_of(figure, p).colour);
        let style = TextStyle::from((FONT, LABEL_FONT).into_font())
            .color(&colour)
            .pos(Pos::new(spot.h, spot.v));
        chart.plotting_area().draw(
            &(EmptyElement::at((p.x, p.y)) + Text::new(text.clone(), (spot.dx, spot.dy), style)),
        )?;
    }
    Ok(())
}
