//! How far the GPU reference is from the f64 samples it is held to: the largest relative
//! difference where it is exact, its standard error and the largest difference in
//! standard errors where it is estimated (the report's "Whole frames" table). The f64
//! reference decides where they disagree; these say by how much.

use super::reference::Reference;
use super::reference::{pixel, relative};
use super::results::ImageReference;

/// The GPU reference's largest relative difference from the f64 samples (`None` where the
/// image is naive's, estimated or absent).
pub(super) fn relative_difference(reference: &Reference) -> Option<f64> {
    let image = reference.image.as_ref()?;
    let gpu = matches!(
        reference.image_source,
        Some(ImageReference::GpuFullFrame | ImageReference::GpuFullFrameVisible)
    );
    (gpu && reference.image_standard_error.is_none()).then(|| {
        reference
            .samples
            .iter()
            .map(|(i, want)| relative(pixel(image, *i), *want))
            .fold(0.0, f64::max)
    })
}

/// The estimated GPU reference's mean relative standard error over the covered pixels
/// (brightest channel).
pub(super) fn mean_relative_standard_error(reference: &Reference) -> Option<f64> {
    let (image, errors) = (
        reference.image.as_ref()?,
        reference.image_standard_error.as_ref()?,
    );
    let relative: Vec<f64> = image
        .iter()
        .zip(errors)
        .filter(|(radiance, _)| radiance[0].max(radiance[1]).max(radiance[2]) > 0.0)
        .map(|(radiance, error)| {
            error.max_element() / f64::from(radiance[0].max(radiance[1]).max(radiance[2]))
        })
        .collect();
    (!relative.is_empty()).then(|| relative.iter().sum::<f64>() / relative.len() as f64)
}

/// The estimated GPU reference's largest difference from the f64 samples, per channel in
/// their combined standard errors (plus the f32 shading's 1e-5 of the value, where both
/// are exact).
pub(super) fn standard_errors_apart(reference: &Reference) -> Option<f64> {
    let (image, errors) = (
        reference.image.as_ref()?,
        reference.image_standard_error.as_ref()?,
    );
    let sigmas = reference
        .samples
        .iter()
        .zip(&reference.standard_errors)
        .flat_map(|((i, want), f64_error)| {
            let got = pixel(image, *i);
            (0..3).map(move |c| {
                let spread = (errors[*i][c].powi(2) + f64_error[c].powi(2)).sqrt();
                (got[c] - want[c]).abs() / (spread + 1e-5 * want[c].abs())
            })
        })
        .filter(|sigmas| sigmas.is_finite())
        .fold(0.0, f64::max);
    Some(sigmas)
}
