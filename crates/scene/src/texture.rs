//! Texture decoding with bounded memory, and the fallback used when a texture cannot be
//! decoded (the scene still loads; a warning names the texture).

use crate::model::{ColorSpace, LoadWarning, Texture};

/// Largest texture side accepted, in texels. 16384 is the `max_texture_dimension_2d` of
/// most desktop GPUs; larger images could not be uploaded anyway.
pub const MAX_TEXTURE_DIMENSION: u32 = 16384;

/// Largest allocation the image decoder may make for one texture (a 16384^2 RGBA8 image).
const MAX_DECODE_BYTES: u64 = 16384 * 16384 * 4;

/// Decodes PNG or JPEG bytes to RGBA8. On failure returns the fallback texture and
/// records a warning.
pub(crate) fn decode_or_fallback(
    bytes: &[u8],
    source: String,
    color_space: ColorSpace,
    scene_file: &str,
    warnings: &mut Vec<LoadWarning>,
) -> Texture {
    match decode(bytes) {
        Ok(image) => Texture {
            source,
            width: image.width(),
            height: image.height(),
            color_space,
            rgba8: image.into_raw(),
        },
        Err(problem) => {
            warnings.push(LoadWarning {
                file: scene_file.to_string(),
                message: format!(
                    "texture '{source}' cannot be decoded ({problem}); using a fallback texture"
                ),
            });
            fallback(source, color_space)
        }
    }
}

fn decode(bytes: &[u8]) -> Result<image::RgbaImage, String> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_DIMENSION);
    limits.max_image_height = Some(MAX_TEXTURE_DIMENSION);
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    reader.limits(limits);
    let image = reader.decode().map_err(|e| e.to_string())?;
    Ok(image.into_rgba8())
}

/// A 2x2 texture that stands in for one that failed to decode: a magenta/black checker
/// for colour (visibly wrong, as intended), a flat +Z normal for normal maps.
pub fn fallback(source: String, color_space: ColorSpace) -> Texture {
    let rgba8 = match color_space {
        ColorSpace::Srgb => [
            [255, 0, 255, 255],
            [0, 0, 0, 255],
            [0, 0, 0, 255],
            [255, 0, 255, 255],
        ],
        ColorSpace::Linear => [[128, 128, 255, 255]; 4],
    }
    .concat();
    Texture {
        source,
        width: 2,
        height: 2,
        color_space,
        rgba8,
    }
}
