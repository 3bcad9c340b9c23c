//! Log axes: range and ticks.

use std::ops::Range;

use plotters::coord::combinators::{BindKeyPoints, WithKeyPoints};
use plotters::prelude::*;

use super::figures::trim_zeros;

/// The most labelled ticks on an axis of a panel before labels crowd.
pub(super) const MAX_TICKS: usize = 10;

/// The data range widened a little on a log scale so the extreme points and their
/// labels sit inside the plot.
pub(super) fn padded_log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| *v > 0.0 && v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.1..10.0;
    }
    let span = (hi / lo).log10();
    let pad = 10f64.powf((span * 0.1).max(0.06));
    (lo / pad)..(hi * pad)
}

/// The values `m * 10^e` within lo..=hi for the mantissas `m`.
pub(super) fn mantissa_ticks(lo: f64, hi: f64, mantissas: &[f64]) -> Vec<f64> {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let mut ticks = Vec::new();
    for e in first..=last {
        for m in mantissas {
            let v = m * 10f64.powi(e);
            if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                ticks.push(v);
            }
        }
    }
    ticks
}

/// Labelled ticks for a log axis over lo..hi: 1-2-5 per decade when that gives at least
/// 3 and at most `max` ticks; decades (thinned to `max`) when 1-2-5 would crowd; every
/// integer mantissa when the range is too short for 1-2-5; evenly spaced round values
/// when even that gives fewer than 3 (a range within one step such as 0.86..0.88).
pub(super) fn log_ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    let one_two_five = mantissa_ticks(lo, hi, &[1.0, 2.0, 5.0]);
    if one_two_five.len() > max {
        let decades = mantissa_ticks(lo, hi, &[1.0]);
        let every = decades.len().div_ceil(max.max(1));
        return decades.into_iter().step_by(every).collect();
    }
    if one_two_five.len() >= 3 {
        return one_two_five;
    }
    let integers = mantissa_ticks(lo, hi, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    if integers.len() >= 3 {
        return integers;
    }
    linear_ticks(lo, hi)
}

/// Round values evenly spaced over lo..=hi, about four steps of 1, 2 or 5 x 10^k.
pub(super) fn linear_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if hi <= lo {
        return vec![lo];
    }
    let rough = (hi - lo) / 4.0;
    let power = 10f64.powf(rough.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|s| *s >= rough)
        .unwrap_or(10.0 * power);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

/// Unlabelled grid lines at every integer mantissa, so the log scale reads as one.
pub(super) fn minor_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let ticks = mantissa_ticks(lo, hi, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    if ticks.len() > 100 { Vec::new() } else { ticks }
}

/// A tick value written compactly: `0.15`, `2`, `500`, `20k`, `1.5M`, `1e-5`.
pub(super) fn tick_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    for (scale, suffix) in [(1e9, "G"), (1e6, "M"), (1e3, "k")] {
        if v.abs() >= scale {
            return format!("{}{suffix}", significant(v / scale));
        }
    }
    if v.abs() >= 1e-3 {
        return significant(v);
    }
    let text = format!("{v:.2e}");
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    format!("{}e{exponent}", trim_zeros(mantissa.to_string()))
}

/// Up to 4 significant digits, trailing zeros dropped.
pub(super) fn significant(v: f64) -> String {
    let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 9) as usize;
    trim_zeros(format!("{v:.decimals$}"))
}

/// A log axis shared by every panel of a chart (shared so panels compare at a glance).
pub(super) struct LogAxis {
    pub(super) range: Range<f64>,
    pub(super) ticks: Vec<f64>,
    pub(super) minor: Vec<f64>,
    pub(super) names: Vec<(f64, String)>,
}

impl LogAxis {
    pub(super) fn new(values: impl Iterator<Item = f64>, names: &[(f64, String)]) -> Self {
        let range = padded_log_range(values);
        let (ticks, minor) = if names.is_empty() {
            (
                log_ticks(range.start, range.end, MAX_TICKS),
                minor_ticks(range.start, range.end),
            )
        } else {
            (names.iter().map(|(v, _)| *v).collect(), Vec::new())
        };
        Self {
            range,
            ticks,
            minor,
            names: names.to_vec(),
        }
    }

    pub(super) fn spec(&self) -> WithKeyPoints<LogCoord<f64>> {
        self.range
            .clone()
            .log_scale()
            .with_key_points(self.ticks.clone())
            .with_light_points(self.minor.clone())
    }

    pub(super) fn label(&self, v: f64) -> String {
        self.names
            .iter()
            .find(|(x, _)| (x - v).abs() <= 1e-9 * x.abs())
            .map(|(_, name)| name.clone())
            .unwrap_or_else(|| tick_label(v))
    }
}
