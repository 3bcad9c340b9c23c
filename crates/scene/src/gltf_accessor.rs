//! Reading glTF accessors, every component type the specification and
//! `KHR_mesh_quantization` allow, into the loader's `f32` vectors and `u32` indices.
//!
//! One reader for every case, written here rather than the `gltf` crate's (which reads only
//! the core types, returns nothing for an accessor without a buffer view, and panics on
//! short data): elements are read from their buffer view with its stride, normalized
//! integers become [-1, 1] or [0, 1] by the specification's rules (`max(c / 127, -1)` for a
//! signed byte), an accessor without a buffer view is zeros, and sparse values replace
//! what they name. Every read is checked against the bytes there are, before reading.

use std::collections::HashMap;

use gltf::accessor::{DataType, Dimensions};

/// The bytes of each buffer view: a slice of its buffer, or the decoded stream of a
/// compressed view (`EXT_meshopt_compression`).
#[derive(Debug, Default)]
pub(crate) struct ViewData {
    pub buffers: Vec<Vec<u8>>,
    /// Decoded compressed views, by view index.
    pub decoded: HashMap<usize, Vec<u8>>,
}

impl ViewData {
    /// The bytes of a buffer view, checked against its buffer.
    pub fn bytes(&self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        if let Some(decoded) = self.decoded.get(&view.index()) {
            return Ok(decoded);
        }
        let data = self
            .buffers
            .get(view.buffer().index())
            .map(Vec::as_slice)
            .unwrap_or_default();
        match view.offset().checked_add(view.length()) {
            Some(end) if end <= data.len() => Ok(&data[view.offset()..end]),
            _ => Err(format!(
                "buffer view {} (offset {}, length {}) ends past buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                data.len()
            )),
        }
    }
}

/// Why an accessor could not be read.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ReadError {
    /// Its elements (or sparse data) lie past the bytes there are.
    OutOfRange { accessor: usize, message: String },
    /// Its storage or shape is not what glTF allows where it is used.
    Invalid(String),
}

impl From<String> for ReadError {
    fn from(message: String) -> Self {
        ReadError::Invalid(message)
    }
}

/// Most elements read from an accessor without a buffer view (zeros, plus sparse
/// values): such an accessor's size is not bounded by any data, so a (hostile) count of
/// billions would otherwise allocate gigabytes.
pub(crate) const MAX_ELEMENTS_WITHOUT_VIEW: usize = 1 << 24;

/// The glTF name of a component type, for messages.
fn type_name(data_type: DataType, normalized: bool) -> String {
    let name = match data_type {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    };
    if normalized {
        format!("normalized {name}")
    } else {
        name.to_string()
    }
}

/// How glTF (with `KHR_mesh_quantization`) lets a vertex attribute be stored. `None`:
/// the attribute is not one manylights reads, anything goes.
fn attribute_allows(semantic: &str, data_type: DataType, normalized: bool) -> Option<bool> {
    use DataType::*;
    let quantized_position = matches!(data_type, I8 | U8 | I16 | U16);
    let allowed = match semantic {
        "POSITION" => data_type == F32 || quantized_position,
        "NORMAL" | "TANGENT" => data_type == F32 || (matches!(data_type, I8 | I16) && normalized),
        s if s.starts_with("TEXCOORD_") => data_type == F32 || quantized_position,
        _ => return None,
    };
    Some(allowed)
}

/// The shape each read attribute must have.
fn attribute_dimensions(semantic: &str) -> Option<Dimensions> {
    match semantic {
        "POSITION" | "NORMAL" => Some(Dimensions::Vec3),
        "TANGENT" => Some(Dimensions::Vec4),
        s if s.starts_with("TEXCOORD_") => Some(Dimensions::Vec2),
        _ => None,
    }
}

/// Checks that a vertex attribute's storage is one glTF allows for it. Messages name the
/// accessor.
pub(crate) fn check_attribute(semantic: &str, accessor: &gltf::Accessor) -> Result<(), String> {
    let (data_type, normalized) = (accessor.data_type(), accessor.normalized());
    let Some(allowed) = attribute_allows(semantic, data_type, normalized) else {
        return Ok(());
    };
    let dimensions = accessor.dimensions();
    let shape_ok = attribute_dimensions(semantic) == Some(dimensions);
    if !allowed || !shape_ok {
        return Err(format!(
            "{semantic} accessor {} has {} {dimensions:?} elements, which glTF (with KHR_mesh_quantization) does not allow there",
            accessor.index(),
            type_name(data_type, normalized),
        ));
    }
    Ok(())
}

/// Reads a float attribute of `N` components (its storage checked by
/// [`check_attribute`] or the caller).
pub(crate) fn read_vectors<const N: usize>(
    views: &ViewData,
    accessor: &gltf::Accessor,
) -> Result<Vec<[f32; N]>, ReadError> {
    if accessor.dimensions().multiplicity() != N {
        return Err(ReadError::Invalid(format!(
            "accessor {} has {:?} elements where {N} components are read",
            accessor.index(),
            accessor.dimensions()
        )));
    }
    let (data_type, normalized) = (accessor.data_type(), accessor.normalized());
    let convert = move |bytes: &[u8]| -> f32 { component_as_f32(bytes, data_type, normalized) };
    read_elements(views, accessor, |bytes| {
        let size = data_type.size();
        std::array::from_fn(|c| convert(&bytes[c * size..(c + 1) * size]))
    })
}

/// Reads an index accessor (scalar UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT).
pub(crate) fn read_indices(
    views: &ViewData,
    accessor: &gltf::Accessor,
) -> Result<Vec<u32>, ReadError> {
    let data_type = accessor.data_type();
    if accessor.dimensions() != Dimensions::Scalar
        || !matches!(data_type, DataType::U8 | DataType::U16 | DataType::U32)
        || accessor.normalized()
    {
        return Err(ReadError::Invalid(format!(
            "index accessor {} has {} {:?} elements; glTF indices are scalar UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
            accessor.index(),
            type_name(data_type, accessor.normalized()),
            accessor.dimensions()
        )));
    }
    read_elements(views, accessor, |bytes| match bytes.len() {
        1 => bytes[0] as u32,
        2 => u16::from_le_bytes([bytes[0], bytes[1]]) as u32,
        _ => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    })
}

/// One component as a float, by the specification's dequantization rules.
fn component_as_f32(bytes: &[u8], data_type: DataType, normalized: bool) -> f32 {
    match data_type {
        DataType::F32 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
        DataType::I8 => {
            let c = bytes[0] as i8 as f32;
            if normalized { (c / 127.0).max(-1.0) } else { c }
        }
        DataType::U8 => {
            let c = bytes[0] as f32;
            if normalized { c / 255.0 } else { c }
        }
        DataType::I16 => {
            let c = i16::from_le_bytes([bytes[0], bytes[1]]) as f32;
            if normalized {
                (c / 32767.0).max(-1.0)
            } else {
                c
            }
        }
        DataType::U16 => {
            let c = u16::from_le_bytes([bytes[0], bytes[1]]) as f32;
            if normalized { c / 65535.0 } else { c }
        }
        DataType::U32 => {
            let c = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
            if normalized {
                (c as f64 / u32::MAX as f64) as f32
            } else {
                c as f32
            }
        }
    }
}

/// Reads every element of an accessor with `element` (given the element's bytes): from
/// its buffer view, or zeros without one, then the sparse substitution.
fn read_elements<T: Copy>(
    views: &ViewData,
    accessor: &gltf::Accessor,
    element: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, ReadError> {
    if accessor.count() == 0 {
        return Err(ReadError::Invalid(format!(
            "accessor {} has no elements (glTF requires count >= 1)",
            accessor.index()
        )));
    }
    let mut out = dense_elements(views, accessor, &element)?;
    if let Some(sparse) = accessor.sparse() {
        substitute_sparse(views, accessor, &sparse, &mut out, &element)?;
    }
    Ok(out)
}

fn out_of_range(accessor: &gltf::Accessor) -> impl Fn(String) -> ReadError {
    let accessor = accessor.index();
    move |message| ReadError::OutOfRange { accessor, message }
}

/// The elements before sparse substitution: from the buffer view (checked against its
/// bytes, strides included), or zeros when there is none.
fn dense_elements<T: Copy>(
    views: &ViewData,
    accessor: &gltf::Accessor,
    element: &impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, ReadError> {
    let (count, size) = (accessor.count(), accessor.size());
    let Some(view) = accessor.view() else {
        if count > MAX_ELEMENTS_WITHOUT_VIEW {
            return Err(ReadError::Invalid(format!(
                "accessor {} has {count} elements and no buffer view; manylights reads at most {MAX_ELEMENTS_WITHOUT_VIEW} zero elements",
                accessor.index()
            )));
        }
        return Ok(vec![element(&vec![0u8; size]); count]);
    };
    let out_of_range = out_of_range(accessor);
    let bytes = views.bytes(&view).map_err(&out_of_range)?;
    let stride = view.stride().unwrap_or(size).max(size);
    let needed = stride
        .checked_mul(count - 1)
        .and_then(|n| n.checked_add(size))
        .and_then(|n| n.checked_add(accessor.offset()));
    if !matches!(needed, Some(needed) if needed <= bytes.len()) {
        return Err(out_of_range(format!(
            "{count} elements of {size} bytes (stride {stride}, offset {}) need more than the {} bytes of buffer view {}",
            accessor.offset(),
            bytes.len(),
            view.index()
        )));
    }
    let bytes = &bytes[accessor.offset()..];
    Ok((0..count)
        .map(|i| element(&bytes[i * stride..i * stride + size]))
        .collect())
}

/// Replaces the elements a sparse accessor names with its values, every index and value
/// checked against its bytes and the element count.
fn substitute_sparse<T: Copy>(
    views: &ViewData,
    accessor: &gltf::Accessor,
    sparse: &gltf::accessor::sparse::Sparse,
    out: &mut [T],
    element: &impl Fn(&[u8]) -> T,
) -> Result<(), ReadError> {
    let (count, size) = (accessor.count(), accessor.size());
    let out_of_range = out_of_range(accessor);
    let sparse_count = sparse.count();
    if sparse_count > count {
        return Err(out_of_range(format!(
            "{sparse_count} sparse values for {count} elements"
        )));
    }
    let index_size = match sparse.indices().index_type() {
        gltf::accessor::sparse::IndexType::U8 => 1,
        gltf::accessor::sparse::IndexType::U16 => 2,
        gltf::accessor::sparse::IndexType::U32 => 4,
    };
    let sparse_bytes = |view: gltf::buffer::View, offset: usize, item: usize| {
        let bytes = views.bytes(&view).map_err(&out_of_range)?;
        let needed = item
            .checked_mul(sparse_count)
            .and_then(|n| n.checked_add(offset));
        match needed {
            Some(needed) if needed <= bytes.len() => Ok(&bytes[offset..needed]),
            _ => Err(out_of_range(format!(
                "sparse data needs more than the {} bytes of buffer view {}",
                bytes.len(),
                view.index()
            ))),
        }
    };
    let indices = sparse_bytes(
        sparse.indices().view(),
        sparse.indices().offset(),
        index_size,
    )?;
    let values = sparse_bytes(sparse.values().view(), sparse.values().offset(), size)?;
    for i in 0..sparse_count {
        let chunk = &indices[i * index_size..(i + 1) * index_size];
        let target = match index_size {
            1 => chunk[0] as usize,
            2 => u16::from_le_bytes([chunk[0], chunk[1]]) as usize,
            _ => u32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]) as usize,
        };
        let slot = out
            .get_mut(target)
            .ok_or_else(|| out_of_range(format!("sparse index {target} >= count {count}")))?;
        *slot = element(&values[i * size..(i + 1) * size]);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_integers_follow_the_specification() {
        assert_eq!(component_as_f32(&[127], DataType::I8, true), 1.0);
        assert_eq!(component_as_f32(&[0x81], DataType::I8, true), -1.0);
        // -128 clamps to -1 (max(c / 127, -1)).
        assert_eq!(component_as_f32(&[0x80], DataType::I8, true), -1.0);
        assert_eq!(component_as_f32(&[0x80], DataType::I8, false), -128.0);
        assert_eq!(component_as_f32(&[255], DataType::U8, true), 1.0);
        assert_eq!(component_as_f32(&[0x00, 0x80], DataType::I16, true), -1.0);
        assert_eq!(component_as_f32(&[0xff, 0x7f], DataType::I16, true), 1.0);
        assert_eq!(component_as_f32(&[0xff, 0xff], DataType::U16, true), 1.0);
        assert_eq!(
            component_as_f32(&[0x34, 0x12], DataType::U16, false),
            4660.0
        );
        assert_eq!(
            component_as_f32(&1.5f32.to_le_bytes(), DataType::F32, false),
            1.5
        );
    }

    #[test]
    fn quantized_storage_follows_khr_mesh_quantization() {
        use DataType::*;
        assert_eq!(attribute_allows("POSITION", I16, false), Some(true));
        assert_eq!(attribute_allows("POSITION", U32, false), Some(false));
        assert_eq!(attribute_allows("NORMAL", I8, true), Some(true));
        assert_eq!(attribute_allows("NORMAL", I8, false), Some(false));
        assert_eq!(attribute_allows("NORMAL", U8, true), Some(false));
        assert_eq!(attribute_allows("TEXCOORD_1", U16, false), Some(true));
        assert_eq!(attribute_allows("COLOR_0", U32, false), None);
    }
}
