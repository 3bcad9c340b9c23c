//! Series styles: a colour and a marker that no other series of the chart shares.

use plotters::prelude::*;

/// Markers, varied together with the colour so series also differ in grey print and for
/// colour-blind readers, and so that series beyond the palette still look different.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
}

pub(super) const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::TriangleUp,
    Marker::Diamond,
    Marker::TriangleDown,
];

/// Tableau 10: ten hues that stay apart from one another on white.
pub(super) const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// How many series a chart can draw before a colour and marker pair repeats.
pub(super) const DISTINCT_STYLES: usize = PALETTE.len() * MARKERS.len();

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Style {
    pub(super) colour: RGBColor,
    pub(super) marker: Marker,
}

/// Series `i`'s style: colours in palette order; each pass over the palette shifts the
/// markers by one, so colour `c` comes back only with a marker it had not had yet.
pub(super) fn series_style(i: usize) -> Style {
    let round = i / PALETTE.len();
    Style {
        colour: PALETTE[i % PALETTE.len()],
        marker: MARKERS[(i + round) % MARKERS.len()],
    }
}

pub(super) const MARKER_SIZE: i32 = 5;

pub(super) fn marker_outline(marker: Marker, r: i32) -> Vec<(i32, i32)> {
    match marker {
        Marker::Circle | Marker::Square => vec![(-r, -r), (r, -r), (r, r), (-r, r)],
        Marker::TriangleUp => vec![(0, -r - 1), (r + 1, r), (-r - 1, r)],
        Marker::Diamond => vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
        Marker::TriangleDown => vec![(0, r + 1), (r + 1, -r), (-r - 1, -r)],
    }
}

/// A hollow marker with a light fill: overlapping points of different series (equal
/// times are common) stay visible through each other.
pub(super) fn draw_marker<CT>(
    area: &DrawingArea<SVGBackend<'_>, CT>,
    at: CT::From,
    style: Style,
) -> anyhow::Result<()>
where
    CT: CoordTranslate,
    CT::From: Clone,
{
    let fill = style.colour.mix(0.2).filled();
    let stroke = style.colour.stroke_width(2);
    if style.marker == Marker::Circle {
        area.draw(&(EmptyElement::at(at.clone()) + Circle::new((0, 0), MARKER_SIZE, fill)))?;
        area.draw(&(EmptyElement::at(at) + Circle::new((0, 0), MARKER_SIZE, stroke)))?;
        return Ok(());
    }
    let outline = marker_outline(style.marker, MARKER_SIZE);
    let mut closed = outline.clone();
    closed.push(outline[0]);
    area.draw(&(EmptyElement::at(at.clone()) + Polygon::new(outline, fill)))?;
    area.draw(&(EmptyElement::at(at) + PathElement::new(closed, stroke)))?;
    Ok(())
}
