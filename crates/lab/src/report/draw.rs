//! Drawing a figure: a header, a grid of panels, the legend on the right outside every
//! panel.

use plotters::coord::Shift;
use plotters::coord::combinators::WithKeyPoints;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axes::LogAxis;
use super::figures::{Figure, PlotPoint, pareto_front};
use super::point_labels::draw_point_labels;
use super::style::{DISTINCT_STYLES, Style, draw_marker, series_style};

pub(super) const FONT: &str = "sans-serif";
/// A panel's size: a lone panel gets more room than one of a grid.
pub(super) fn panel_size(panels: usize) -> (u32, u32) {
    if panels <= 1 { (620, 430) } else { (430, 330) }
}

pub(super) const TITLE_FONT: f64 = 24.0;
pub(super) const SUBTITLE_FONT: f64 = 17.0;
pub(super) const HEADER_H: u32 = 64;
pub(super) const LEGEND_ROW: i32 = 22;
pub(super) const LEGEND_TOP: i32 = 34;

/// plotters writes `font-size` as the style size / 1.24; estimates below need pixels.
pub(super) fn font_px(size: f64) -> f64 {
    size / 1.24
}

/// A generous width estimate for sans-serif text (browsers do the real layout).
pub(super) fn text_width(text: &str, size: f64) -> f64 {
    text.chars().count() as f64 * font_px(size) * 0.62
}

/// The panel keys in order: each setting's values in the order the run met them, the
/// last setting varying fastest (so rows and columns line up with settings).
pub(super) fn panel_keys(points: &[PlotPoint]) -> Vec<Vec<String>> {
    let width = points.first().map_or(0, |p| p.panel.len());
    let mut seen: Vec<Vec<String>> = vec![Vec::new(); width];
    for p in points {
        for (i, value) in p.panel.iter().enumerate() {
            if !seen[i].contains(value) {
                seen[i].push(value.clone());
            }
        }
    }
    let rank = |key: &Vec<String>| -> Vec<usize> {
        key.iter()
            .enumerate()
            .map(|(i, v)| seen[i].iter().position(|s| s == v).unwrap_or(0))
            .collect()
    };
    let mut keys: Vec<Vec<String>> = Vec::new();
    for p in points {
        if !keys.contains(&p.panel) {
            keys.push(p.panel.clone());
        }
    }
    keys.sort_by_key(|k| rank(k));
    keys
}

/// Where the panels go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PanelGrid {
    pub(super) rows: usize,
    pub(super) cols: usize,
    /// Panels fill columns first: a column per value of the first setting (a scene),
    /// the other settings (light counts) going down. Tall rather than wide, so a browser
    /// shows the chart without scrolling sideways.
    pub(super) column_major: bool,
}

impl PanelGrid {
    pub(super) fn new(panels: &[Vec<String>]) -> Self {
        let n = panels.len().max(1);
        let mut firsts: Vec<&String> = panels.iter().filter_map(|k| k.first()).collect();
        firsts.dedup();
        let settings = panels.first().map_or(0, |k| k.len());
        // Panel keys come sorted, so equal first values are adjacent: `firsts` counts
        // runs, equal to the distinct values exactly when every value has one block.
        let columns = firsts.len();
        if settings >= 2 && (2..=4).contains(&columns) && n.is_multiple_of(columns) {
            return Self {
                rows: n / columns,
                cols: columns,
                column_major: true,
            };
        }
        let cols = ((n as f64).sqrt().ceil() as usize).clamp(1, 3);
        Self {
            rows: n.div_ceil(cols),
            cols,
            column_major: false,
        }
    }

    /// The row-major cell of the `k`th panel.
    pub(super) fn cell(&self, k: usize) -> usize {
        if self.column_major {
            (k % self.rows) * self.cols + k / self.rows
        } else {
            k
        }
    }
}

/// A legend line: a series, the Pareto front, or a note.
pub(super) enum LegendEntry {
    Series(String, Style),
    Pareto,
    Note(String),
}

impl LegendEntry {
    pub(super) fn text(&self) -> &str {
        match self {
            LegendEntry::Series(text, _) | LegendEntry::Note(text) => text,
            LegendEntry::Pareto => "Pareto front",
        }
    }
}

pub(super) fn legend_entries(figure: &Figure) -> Vec<LegendEntry> {
    let mut entries: Vec<LegendEntry> = figure
        .series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let text = if figure.numbered {
                format!("({}) {s}", i + 1)
            } else {
                s.clone()
            };
            LegendEntry::Series(text, series_style(i))
        })
        .collect();
    if figure.pareto {
        entries.push(LegendEntry::Pareto);
        entries.push(LegendEntry::Note(
            "(nothing else is both faster and more accurate)".into(),
        ));
    }
    if let Some(note) = figure.label_note {
        entries.push(LegendEntry::Note(note.into()));
    }
    entries
}

pub(super) const LEGEND_FONT: f64 = 16.0;

pub(super) fn legend_width(entries: &[LegendEntry]) -> u32 {
    let widest = entries
        .iter()
        .map(|e| text_width(e.text(), LEGEND_FONT))
        .fold(0.0, f64::max);
    (widest + 56.0).ceil() as u32
}

/// Draws `figure` as SVG source (written to a file by the reports, put in the page by
/// its measure panel); returns it with its legend (series and style).
pub(super) fn draw_figure(figure: &Figure) -> anyhow::Result<(String, Vec<(String, Style)>)> {
    if figure.series.len() > DISTINCT_STYLES {
        log::warn!(
            "{}: {} series, more than the {DISTINCT_STYLES} distinct styles: some look alike",
            figure.file,
            figure.series.len()
        );
    }
    let panels = panel_keys(&figure.points);
    let legend = legend_entries(figure);
    let grid = PanelGrid::new(&panels);
    let legend_w = legend_width(&legend);
    let legend_h = LEGEND_TOP as u32 + legend.len() as u32 * LEGEND_ROW as u32 + 16;
    let (panel_w, panel_h) = panel_size(panels.len());
    let plots_w = grid.cols as u32 * panel_w;
    let plots_h = grid.rows as u32 * panel_h;
    let header_w = text_width(&figure.title, TITLE_FONT * 1.1)
        .max(text_width(&figure.subtitle, SUBTITLE_FONT))
        + 32.0;
    let size = (
        (plots_w + legend_w).max(header_w.ceil() as u32),
        HEADER_H + plots_h.max(legend_h),
    );
    let mut svg = String::new();
    // The drawing areas borrow the string until they are dropped at the block's end.
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        let (header, body) = root.split_vertically(HEADER_H);
        draw_header(&header, figure)?;
        let (plots, legend_area) = body.split_horizontally(plots_w);
        if figure.points.is_empty() {
            plots.draw(&Text::new(figure.empty_note, (20, 20), (FONT, 18)))?;
        } else {
            let x_axis = LogAxis::new(figure.points.iter().map(|p| p.x), &figure.x_names);
            let y_axis = LogAxis::new(figure.points.iter().map(|p| p.y), &[]);
            let plots = plots.shrink((0, 0), (plots_w, plots_h));
            let areas = plots.split_evenly((grid.rows, grid.cols));
            for (k, panel) in panels.iter().enumerate() {
                draw_panel(&areas[grid.cell(k)], figure, panel, &x_axis, &y_axis)?;
            }
        }
        draw_legend(&legend_area, &legend)?;
        root.present()?;
    }
    let legend = legend
        .into_iter()
        .filter_map(|e| match e {
            LegendEntry::Series(text, style) => Some((text, style)),
            _ => None,
        })
        .collect();
    Ok((svg, legend))
}

pub(super) fn draw_header(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    figure: &Figure,
) -> anyhow::Result<()> {
    let title = FontDesc::new(FontFamily::SansSerif, TITLE_FONT, FontStyle::Bold);
    area.draw(&Text::new(figure.title.clone(), (16, 10), title))?;
    area.draw(&Text::new(
        figure.subtitle.clone(),
        (16, 38),
        (FONT, SUBTITLE_FONT)
            .into_font()
            .color(&RGBColor(80, 80, 80)),
    ))?;
    Ok(())
}

pub(super) fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    entries: &[LegendEntry],
) -> anyhow::Result<()> {
    let text_style =
        TextStyle::from((FONT, LEGEND_FONT).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (i, entry) in entries.iter().enumerate() {
        let y = LEGEND_TOP + i as i32 * LEGEND_ROW;
        match entry {
            LegendEntry::Series(_, style) => {
                area.draw(&PathElement::new(
                    vec![(8, y), (36, y)],
                    style.colour.stroke_width(2),
                ))?;
                draw_marker(area, (22, y), *style)?;
            }
            LegendEntry::Pareto => {
                area.draw(&PathElement::new(vec![(8, y), (36, y)], pareto_style()))?;
            }
            LegendEntry::Note(_) => {}
        }
        area.draw(&Text::new(
            entry.text().to_string(),
            (44, y),
            text_style.clone(),
        ))?;
    }
    Ok(())
}

pub(super) fn pareto_style() -> ShapeStyle {
    BLACK.mix(0.12).stroke_width(10)
}

/// The darker shade of a series colour that point labels are written in (light hues
/// such as olive or cyan are hard to read as text).
pub(super) fn label_colour(colour: RGBColor) -> RGBColor {
    let dark = |c: u8| (c as f64 * 0.65) as u8;
    RGBColor(dark(colour.0), dark(colour.1), dark(colour.2))
}

pub(super) type PanelChart<'a> = ChartContext<
    'a,
    SVGBackend<'a>,
    Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>,
>;

pub(super) fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    figure: &Figure,
    panel: &[String],
    x_axis: &LogAxis,
    y_axis: &LogAxis,
) -> anyhow::Result<()> {
    let points: Vec<&PlotPoint> = figure.points.iter().filter(|p| p.panel == panel).collect();
    let mut builder = ChartBuilder::on(area);
    if !panel.is_empty() {
        builder.caption(panel.join(", "), (FONT, 18));
    }
    let mut chart = builder
        .margin(10)
        .margin_right(18)
        .x_label_area_size(48)
        .y_label_area_size(62)
        .build_cartesian_2d(x_axis.spec(), y_axis.spec())?;
    let x_label = |v: &f64| x_axis.label(*v);
    let y_label = |v: &f64| y_axis.label(*v);
    chart
        .configure_mesh()
        .x_desc(figure.x_desc.as_str())
        .y_desc(figure.y_desc.as_str())
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 15))
        .bold_line_style(BLACK.mix(0.2))
        .light_line_style(BLACK.mix(0.06))
        .draw()?;
    if figure.pareto {
        draw_pareto(&mut chart, &points)?;
    }
    draw_series_lines(&mut chart, figure, &points)?;
    for p in &points {
        draw_marker(chart.plotting_area(), (p.x, p.y), style_of(figure, p))?;
    }
    draw_point_labels(&chart, figure, &points)?;
    Ok(())
}

pub(super) fn style_of(figure: &Figure, p: &PlotPoint) -> Style {
    series_style(
        figure
            .series
            .iter()
            .position(|s| *s == p.series)
            .unwrap_or(0),
    )
}

/// The Pareto front as a wide translucent band under the points, with a disc under each
/// point on it (a front of one point is a disc alone).
pub(super) fn draw_pareto(chart: &mut PanelChart<'_>, points: &[&PlotPoint]) -> anyhow::Result<()> {
    let xy: Vec<(f64, f64)> = points.iter().map(|p| (p.x, p.y)).collect();
    let front = pareto_front(&xy);
    chart.draw_series(LineSeries::new(front.clone(), pareto_style()))?;
    chart.draw_series(
        front
            .iter()
            .map(|p| Circle::new(*p, 9, BLACK.mix(0.12).filled())),
    )?;
    Ok(())
}

/// Joins each series' points in their order (light count, radius, grid).
pub(super) fn draw_series_lines(
    chart: &mut PanelChart<'_>,
    figure: &Figure,
    points: &[&PlotPoint],
) -> anyhow::Result<()> {
    for series in &figure.series {
        let mut line: Vec<&&PlotPoint> = points.iter().filter(|p| p.series == *series).collect();
        if line.len() < 2 {
            continue;
        }
        line.sort_by(|a, b| a.order.total_cmp(&b.order));
        let style = style_of(figure, line[0]);
        let xy: Vec<(f64, f64)> = if figure.series_fronts {
            pareto_front(&line.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>())
        } else {
            line.iter().map(|p| (p.x, p.y)).collect()
        };
        chart.draw_series(LineSeries::new(xy, style.colour.mix(0.75).stroke_width(2)))?;
    }
    Ok(())
}
