//! Reading glTF accessors from loaded buffers, with every size and offset checked.
//!
//! The `gltf` crate's own reader trusts the file's offsets and counts; here
//! each accessor is checked against its buffer view and buffer before any
//! value is read, so a malformed file gives an error, never a panic. Sparse
//! accessors and accessors without a buffer view are not supported.

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::Accessor;

/// Reads a float accessor of `components` per element as a flat array:
/// `F32` as is; the integer forms `KHR_mesh_quantization` allows as the
/// glTF specification says: normalized `U8`/`U16`/`I8`/`I16` map to
/// `[0, 1]` (or `[-1, 1]`), unnormalized ones are their integer values.
pub(crate) fn read_floats(
    accessor: &Accessor,
    buffers: &[Vec<u8>],
    components: usize,
) -> Result<Vec<f32>, String> {
    check_dimensions(accessor, components)?;
    let data_type = accessor.data_type();
    let convert: fn(&[u8]) -> f32 = match (data_type, accessor.normalized()) {
        (DataType::F32, _) => |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U8, true) => |b| b[0] as f32 / 255.0,
        (DataType::U16, true) => |b| u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
        (DataType::I8, true) => |b| (b[0] as i8 as f32 / 127.0).max(-1.0),
        (DataType::I16, true) => |b| (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        (DataType::U8, false) => |b| b[0] as f32,
        (DataType::U16, false) => |b| u16::from_le_bytes([b[0], b[1]]) as f32,
        (DataType::I8, false) => |b| b[0] as i8 as f32,
        (DataType::I16, false) => |b| i16::from_le_bytes([b[0], b[1]]) as f32,
        (other, normalized) => {
            return Err(format!(
                "accessor {} has component type {other:?}{}; expected FLOAT, or BYTE/SHORT \
                 (normalized or not, KHR_mesh_quantization)",
                accessor.index(),
                if normalized { " (normalized)" } else { "" },
            ))
        }
    };
    let size = data_type.size();
    let mut out = Vec::new();
    for element in elements(accessor, buffers, size * components)? {
        out.extend(element.chunks_exact(size).map(convert));
    }
    Ok(out)
}

/// Reads a scalar index accessor (`U8`, `U16` or `U32`).
pub(crate) fn read_indices(accessor: &Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    check_dimensions(accessor, 1)?;
    let convert: fn(&[u8]) -> u32 = match accessor.data_type() {
        DataType::U8 => |b| b[0] as u32,
        DataType::U16 => |b| u16::from_le_bytes([b[0], b[1]]) as u32,
        DataType::U32 => |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        other => {
            return Err(format!(
                "index accessor {} has component type {other:?}; expected an unsigned integer",
                accessor.index()
            ))
        }
    };
    let size = accessor.data_type().size();
    Ok(elements(accessor, buffers, size)?.map(convert).collect())
}

/// Rejects an accessor whose element is not `components` wide.
fn check_dimensions(accessor: &Accessor, components: usize) -> Result<(), String> {
    let found = match accessor.dimensions() {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    };
    if found != components || matches!(accessor.dimensions(), Dimensions::Mat2) {
        return Err(format!(
            "accessor {} is {:?}; expected {}",
            accessor.index(),
            accessor.dimensions(),
            ["SCALAR", "VEC2", "VEC3", "VEC4"][components.clamp(1, 4) - 1]
        ));
    }
    Ok(())
}

/// The bytes of each element of `accessor`, after checking they lie inside its view and buffer.
fn elements<'b>(
    accessor: &Accessor,
    buffers: &'b [Vec<u8>],
    element_size: usize,
) -> Result<impl Iterator<Item = &'b [u8]>, String> {
    let index = accessor.index();
    if accessor.sparse().is_some() {
        return Err(format!(
            "accessor {index} is sparse, which is not supported"
        ));
    }
    let view = accessor.view().ok_or_else(|| {
        format!("accessor {index} has no buffer view (zero-filled accessors are not supported)")
    })?;
    let buffer = buffers.get(view.buffer().index()).ok_or_else(|| {
        format!(
            "accessor {index}: buffer {} not loaded",
            view.buffer().index()
        )
    })?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&end| end <= buffer.len())
        .ok_or_else(|| {
            format!(
                "buffer view {} (bytes {}..+{}) lies outside buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buffer.len()
            )
        })?;
    let view_bytes = &buffer[view.offset()..view_end];
    let stride = view.stride().unwrap_or(element_size);
    if stride < element_size {
        return Err(format!(
            "buffer view {} has stride {stride}, smaller than accessor {index}'s {element_size}-byte elements",
            view.index()
        ));
    }
    let count = accessor.count();
    let needed = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|b| b.checked_add(element_size))
            .and_then(|b| b.checked_add(accessor.offset())),
    };
    match needed {
        Some(end) if end <= view_bytes.len() => {}
        _ => {
            return Err(format!(
                "accessor {index} ({count} elements of {element_size} bytes, stride {stride}, offset {}) runs past the end of buffer view {} ({} bytes)",
                accessor.offset(),
                view.index(),
                view_bytes.len()
            ))
        }
    }
    let start = accessor.offset();
    Ok((0..count).map(move |i| {
        let at = start + i * stride;
        &view_bytes[at..at + element_size]
    }))
}
