//! Each setting's numbers over the cameras drawn for it (`draw:COUNT` views): a setting
//! judged on a few chosen cameras can be tuned to them, so accuracy targets are stated over
//! drawn ones, as the mean, the spread and the worst.

use super::image_metrics::mean;
use super::matrix::BenchConfig;
use super::results::BenchResult;

/// A number's mean, standard deviation and worst (largest) over cameras.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    pub mean: f64,
    pub spread: f64,
    pub worst: f64,
}

impl Spread {
    /// Over `values`; `None` for none.
    pub fn of(values: &[f64]) -> Option<Self> {
        if values.is_empty() {
            return None;
        }
        let centre = mean(values);
        let deviations: Vec<f64> = values.iter().map(|v| (v - centre).powi(2)).collect();
        let variance = mean(&deviations);
        Some(Self {
            mean: centre,
            spread: variance.sqrt(),
            worst: values.iter().copied().fold(f64::MIN, f64::max),
        })
    }
}

/// One setting over the cameras drawn for it.
#[derive(Debug, Clone, PartialEq)]
pub struct OverDrawnCameras {
    /// The setting: its configuration without the view.
    pub config: BenchConfig,
    /// The drawn cameras it ran on without an error.
    pub cameras: usize,
    pub gpu_ms: Option<Spread>,
    /// The mean relative error at the f64 samples.
    pub mean_error: Option<Spread>,
    pub flip: Option<Spread>,
    pub seams: Option<Spread>,
    pub blotch: Option<Spread>,
}

/// Every setting that ran on drawn cameras, in the order of its first result.
pub fn over_drawn_cameras<'a>(
    results: impl IntoIterator<Item = &'a BenchResult>,
) -> Vec<OverDrawnCameras> {
    let mut groups: Vec<(BenchConfig, Vec<&BenchResult>)> = Vec::new();
    for result in results {
        let drawn = (result.config.view.as_deref()).is_some_and(|view| view.starts_with("drawn:"));
        if !drawn || result.error.is_some() {
            continue;
        }
        let setting = BenchConfig {
            view: None,
            ..result.config.clone()
        };
        match groups.iter_mut().find(|(config, _)| *config == setting) {
            Some((_, members)) => members.push(result),
            None => groups.push((setting, vec![result])),
        }
    }
    groups
        .into_iter()
        .map(|(config, members)| {
            let over = |value: fn(&BenchResult) -> Option<f64>| {
                Spread::of(&members.iter().filter_map(|r| value(r)).collect::<Vec<_>>())
            };
            OverDrawnCameras {
                config,
                cameras: members.len(),
                gpu_ms: over(|r| r.gpu_total_median_ms),
                mean_error: over(|r| Some(r.accuracy.f64_mean_relative)),
                flip: over(|r| r.accuracy.flip_at_reference_exposure),
                seams: over(|r| r.accuracy.seam_ratio),
                blotch: over(|r| r.accuracy.blotch),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spread_is_the_mean_the_deviation_and_the_worst() {
        assert_eq!(Spread::of(&[]), None);
        let spread = Spread::of(&[1.0, 3.0]).unwrap();
        assert_eq!(
            spread,
            Spread {
                mean: 2.0,
                spread: 1.0,
                worst: 3.0
            }
        );
    }
}
