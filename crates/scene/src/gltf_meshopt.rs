//! `EXT_meshopt_compression` (and `KHR_meshopt_compression`): buffer views compressed with
//! meshoptimizer's vertex and index codecs, as gltfpack writes them. Decoded with the
//! `meshopt` crate (bindings to meshoptimizer itself, whose decoders are documented as
//! safe on untrusted input), then checked here: sizes are validated before anything is
//! allocated, and a decoder error is an error naming the view.

use crate::gltf_json::{MeshoptFilter, MeshoptMode, MeshoptView};

/// Largest ratio of decoded to compressed bytes accepted. meshoptimizer's codecs spend at
/// least two bits per 16 bytes of vertex data (64:1) and a few bits per triangle, so real
/// streams stay far below it; the limit keeps a forged `count` from allocating gigabytes
/// out of a few bytes.
const MAX_EXPANSION: usize = 1024;

/// Decodes one compressed view from its buffer's bytes.
pub(crate) fn decode(index: usize, view: &MeshoptView, buffer: &[u8]) -> Result<Vec<u8>, String> {
    let fail = |message: String| format!("meshopt-compressed buffer view {index}: {message}");
    let encoded = view
        .byte_offset
        .checked_add(view.byte_length)
        .filter(|&end| end <= buffer.len())
        .map(|end| &buffer[view.byte_offset..end])
        .ok_or_else(|| {
            fail(format!(
                "bytes {}..+{} lie outside buffer {} ({} bytes)",
                view.byte_offset,
                view.byte_length,
                view.buffer,
                buffer.len()
            ))
        })?;
    let decoded_size = view
        .count
        .checked_mul(view.byte_stride)
        .filter(|&size| size <= encoded.len().saturating_mul(MAX_EXPANSION).max(1 << 16))
        .ok_or_else(|| {
            fail(format!(
                "{} elements of {} bytes from {} compressed bytes is more than meshoptimizer's codecs can hold",
                view.count,
                view.byte_stride,
                encoded.len()
            ))
        })?;
    let stride_ok = match view.mode {
        MeshoptMode::Attributes => {
            view.byte_stride.is_multiple_of(4) && (4..=256).contains(&view.byte_stride)
        }
        MeshoptMode::Triangles | MeshoptMode::Indices => matches!(view.byte_stride, 2 | 4),
    };
    if !stride_ok {
        return Err(fail(format!(
            "byteStride {} is not allowed in {:?} mode",
            view.byte_stride, view.mode
        )));
    }
    if view.mode == MeshoptMode::Triangles && !view.count.is_multiple_of(3) {
        return Err(fail(format!(
            "TRIANGLES mode needs a multiple of 3 indices, got {}",
            view.count
        )));
    }
    if view.mode != MeshoptMode::Attributes && view.filter != MeshoptFilter::None {
        return Err(fail(format!(
            "filter {:?} applies to ATTRIBUTES only",
            view.filter
        )));
    }
    let codec_error = |e: meshopt::Error| fail(format!("cannot decode: {e}"));
    let mut bytes = match view.mode {
        MeshoptMode::Attributes => {
            decode_vertices(encoded, view.count, view.byte_stride).map_err(codec_error)?
        }
        MeshoptMode::Triangles | MeshoptMode::Indices => {
            decode_index_stream(encoded, view).map_err(codec_error)?
        }
    };
    debug_assert_eq!(bytes.len(), decoded_size);
    apply_filter(&mut bytes, view).map_err(fail)?;
    Ok(bytes)
}

/// One decoded vertex, `N` bytes (the codec works on whole vertices; `Default` for arrays
/// stops at 32 elements, hence the wrapper).
#[derive(Clone, Copy)]
struct Vertex<const N: usize>([u8; N]);

impl<const N: usize> Default for Vertex<N> {
    fn default() -> Self {
        Vertex([0; N])
    }
}

fn decode_fixed<const N: usize>(encoded: &[u8], count: usize) -> meshopt::Result<Vec<u8>> {
    let vertices: Vec<Vertex<N>> = meshopt::decode_vertex_buffer(encoded, count)?;
    Ok(vertices.iter().flat_map(|vertex| vertex.0).collect())
}

/// Dispatches a run-time stride (a multiple of 4 up to 256, checked by the caller) to the
/// codec's compile-time vertex size.
fn decode_vertices(encoded: &[u8], count: usize, stride: usize) -> meshopt::Result<Vec<u8>> {
    macro_rules! strides {
        ($($n:literal)*) => {
            match stride {
                $($n => decode_fixed::<$n>(encoded, count),)*
                _ => unreachable!("stride {stride} checked by the caller"),
            }
        };
    }
    strides!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104
        108 112 116 120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188
        192 196 200 204 208 212 216 220 224 228 232 236 240 244 248 252 256)
}

fn decode_index_stream(encoded: &[u8], view: &MeshoptView) -> meshopt::Result<Vec<u8>> {
    let triangles = view.mode == MeshoptMode::Triangles;
    Ok(if view.byte_stride == 2 {
        let indices: Vec<u16> = if triangles {
            meshopt::decode_index_buffer(encoded, view.count)?
        } else {
            meshopt::decode_index_sequence(encoded, view.count)?
        };
        indices.iter().flat_map(|i| i.to_le_bytes()).collect()
    } else {
        let indices: Vec<u32> = if triangles {
            meshopt::decode_index_buffer(encoded, view.count)?
        } else {
            meshopt::decode_index_sequence(encoded, view.count)?
        };
        indices.iter().flat_map(|i| i.to_le_bytes()).collect()
    })
}

/// Undoes the view's filter in place (the decoded bytes are little-endian, as glTF's).
fn apply_filter(bytes: &mut [u8], view: &MeshoptView) -> Result<(), String> {
    let stride = view.byte_stride;
    match (view.filter, stride) {
        (MeshoptFilter::None, _) => {}
        (MeshoptFilter::Octahedral | MeshoptFilter::Color, 4) => {
            let mut items: Vec<[i8; 4]> = bytes
                .chunks_exact(4)
                .map(|c| [c[0] as i8, c[1] as i8, c[2] as i8, c[3] as i8])
                .collect();
            if view.filter == MeshoptFilter::Octahedral {
                meshopt::decode_filter_oct(&mut items);
            } else {
                meshopt::decode_filter_color(&mut items);
            }
            for (chunk, item) in bytes.chunks_exact_mut(4).zip(items) {
                chunk.copy_from_slice(&item.map(|c| c as u8));
            }
        }
        (MeshoptFilter::Octahedral | MeshoptFilter::Color | MeshoptFilter::Quaternion, 8) => {
            let mut items: Vec<[i16; 4]> = bytes
                .chunks_exact(8)
                .map(|c| std::array::from_fn(|k| i16::from_le_bytes([c[2 * k], c[2 * k + 1]])))
                .collect();
            match view.filter {
                MeshoptFilter::Octahedral => meshopt::decode_filter_oct(&mut items),
                MeshoptFilter::Color => meshopt::decode_filter_color(&mut items),
                _ => meshopt::decode_filter_quat(&mut items),
            }
            for (chunk, item) in bytes.chunks_exact_mut(8).zip(items) {
                for (k, component) in item.iter().enumerate() {
                    chunk[2 * k..2 * k + 2].copy_from_slice(&component.to_le_bytes());
                }
            }
        }
        (MeshoptFilter::Exponential, _) if stride.is_multiple_of(4) => {
            // Each 32-bit component decodes on its own.
            let mut items: Vec<[u32; 1]> = bytes
                .chunks_exact(4)
                .map(|c| [u32::from_le_bytes([c[0], c[1], c[2], c[3]])])
                .collect();
            meshopt::decode_filter_exp(&mut items);
            for (chunk, item) in bytes.chunks_exact_mut(4).zip(items) {
                chunk.copy_from_slice(&item[0].to_le_bytes());
            }
        }
        (filter, stride) => {
            return Err(format!(
                "filter {filter:?} does not apply to byteStride {stride}"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(
        mode: MeshoptMode,
        filter: MeshoptFilter,
        stride: usize,
        count: usize,
        len: usize,
    ) -> MeshoptView {
        MeshoptView {
            buffer: 0,
            byte_offset: 0,
            byte_length: len,
            byte_stride: stride,
            count,
            mode,
            filter,
        }
    }

    #[test]
    fn vertex_and_index_streams_round_trip() {
        let vertices: Vec<[u16; 6]> = (0..100u16).map(|i| [i, i * 3, 7, i ^ 5, 0, 9]).collect();
        let encoded = meshopt::encode_vertex_buffer(&vertices).unwrap();
        let decoded = decode(
            3,
            &view(
                MeshoptMode::Attributes,
                MeshoptFilter::None,
                12,
                100,
                encoded.len(),
            ),
            &encoded,
        )
        .unwrap();
        let expected: Vec<u8> = vertices
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        assert_eq!(decoded, expected);

        let indices: Vec<u32> = vec![0, 1, 2, 2, 1, 3, 3, 1, 4];
        let encoded = meshopt::encode_index_buffer(&indices, 5).unwrap();
        let decoded = decode(
            0,
            &view(
                MeshoptMode::Triangles,
                MeshoptFilter::None,
                2,
                9,
                encoded.len(),
            ),
            &encoded,
        )
        .unwrap();
        let expected: Vec<u8> = indices
            .iter()
            .flat_map(|&i| (i as u16).to_le_bytes())
            .collect();
        assert_eq!(decoded, expected);
    }

    #[test]
    fn forged_sizes_are_errors_not_allocations() {
        let error = decode(
            7,
            &view(
                MeshoptMode::Attributes,
                MeshoptFilter::None,
                256,
                usize::MAX / 2,
                4,
            ),
            &[0xa0, 0, 0, 0],
        )
        .unwrap_err();
        assert!(error.contains("buffer view 7"), "{error}");
        let error = decode(
            7,
            &view(MeshoptMode::Attributes, MeshoptFilter::None, 6, 1, 4),
            &[0xa0, 0, 0, 0],
        )
        .unwrap_err();
        assert!(error.contains("byteStride 6"), "{error}");
        // Garbage is a decoder error, not a panic.
        let error = decode(
            7,
            &view(MeshoptMode::Attributes, MeshoptFilter::None, 4, 16, 8),
            &[1, 2, 3, 4, 5, 6, 7, 8],
        )
        .unwrap_err();
        assert!(error.contains("cannot decode"), "{error}");
    }
}
