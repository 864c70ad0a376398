//! Bounds-checked glTF accessor reading (dense and sparse) into `f32` or `u32` values.
//!
//! The `gltf` crate's own readers assume a consistent file (they can panic on a zero count,
//! a wrong component type or a stride smaller than an element), so the loader reads bytes
//! itself: every range is checked against the buffer data actually loaded before anything
//! is allocated, which bounds every allocation by the file's real size.

use ::gltf::accessor::{sparse::IndexType, DataType, Dimensions};
use ::gltf::buffer::View;
use ::gltf::Accessor;
use std::borrow::Cow;

/// Elements an accessor without a buffer view (all zeros, possibly sparse) may have: it
/// costs no file bytes, so it needs its own cap.
pub(crate) const MAX_ZERO_ELEMENTS: usize = 1 << 24;

fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// One component as `f32`, applying glTF's normalisation rules when `normalized`.
fn component_f32(b: &[u8], t: DataType, normalized: bool) -> f32 {
    match t {
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        DataType::U8 if normalized => b[0] as f32 / 255.0,
        DataType::U8 => b[0] as f32,
        DataType::I8 if normalized => (b[0] as i8 as f32 / 127.0).max(-1.0),
        DataType::I8 => b[0] as i8 as f32,
        DataType::U16 if normalized => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
        DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f32,
        DataType::I16 if normalized => {
            (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0)
        }
        DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f32,
        DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
    }
}

fn component_u32(b: &[u8], t: DataType) -> u32 {
    match t {
        DataType::U8 | DataType::I8 => b[0] as u32,
        DataType::U16 | DataType::I16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        DataType::U32 | DataType::F32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

/// The bytes of a buffer view, checked against the loaded buffer.
pub(crate) fn view_bytes<'b>(
    view: &View,
    buffers: &'b [Cow<'_, [u8]>],
) -> Result<&'b [u8], String> {
    let b = view.buffer().index();
    let data = buffers
        .get(b)
        .ok_or_else(|| format!("bufferView {} uses missing buffer {b}", view.index()))?;
    let start = view.offset();
    view.offset()
        .checked_add(view.length())
        .and_then(|end| data.get(start..end))
        .ok_or_else(|| {
            format!(
                "bufferView {} (offset {start}, length {}) lies outside buffer {b} ({} bytes)",
                view.index(),
                view.length(),
                data.len()
            )
        })
}

/// Checks that `count` elements of `elem` bytes at `offset` with `stride` fit in `bytes`,
/// and returns the stride used.
fn check_fit(
    what: &str,
    bytes: &[u8],
    offset: usize,
    stride: Option<usize>,
    elem: usize,
    count: usize,
) -> Result<usize, String> {
    let stride = stride.unwrap_or(elem);
    if stride < elem {
        return Err(format!(
            "{what}: byteStride {stride} is smaller than an element ({elem} bytes)"
        ));
    }
    if count == 0 {
        return Ok(stride);
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(offset))
        .and_then(|x| x.checked_add(elem));
    match end {
        Some(end) if end <= bytes.len() => Ok(stride),
        _ => Err(format!(
            "{what}: {count} elements at offset {offset} (stride {stride}) do not fit in its \
             {}-byte bufferView",
            bytes.len()
        )),
    }
}

/// Reads any scalar/vector accessor, converting components with `conv`; returns the flat
/// values and the component count.
fn read<T: Copy + Default>(
    acc: &Accessor,
    buffers: &[Cow<[u8]>],
    conv: impl Fn(&[u8]) -> T,
) -> Result<(Vec<T>, usize), String> {
    let what = format!("accessor {}", acc.index());
    let n = match acc.dimensions() {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        d => return Err(format!("{what}: unexpected type {d:?}")),
    };
    let csize = component_size(acc.data_type());
    let elem = csize * n;
    let count = acc.count();
    let mut out: Vec<T> = match acc.view() {
        Some(view) => {
            let bytes = view_bytes(&view, buffers)?;
            let stride = check_fit(&what, bytes, acc.offset(), view.stride(), elem, count)?;
            let mut out = Vec::with_capacity(count * n);
            for i in 0..count {
                let e = &bytes[acc.offset() + i * stride..][..elem];
                out.extend(e.chunks_exact(csize).map(&conv));
            }
            out
        }
        None if count > MAX_ZERO_ELEMENTS => {
            return Err(format!(
                "{what}: {count} elements without a bufferView (limit {MAX_ZERO_ELEMENTS})"
            ))
        }
        None => vec![T::default(); count * n],
    };
    if let Some(sparse) = acc.sparse() {
        let k = sparse.count();
        let idx = sparse.indices();
        let isize_ = idx.index_type().size();
        let ibytes = view_bytes(&idx.view(), buffers)?;
        check_fit(&what, ibytes, idx.offset(), None, isize_, k)?;
        let vals = sparse.values();
        let vbytes = view_bytes(&vals.view(), buffers)?;
        check_fit(&what, vbytes, vals.offset(), None, elem, k)?;
        for j in 0..k {
            let ib = &ibytes[idx.offset() + j * isize_..];
            let target = match idx.index_type() {
                IndexType::U8 => ib[0] as usize,
                IndexType::U16 => u16::from_le_bytes([ib[0], ib[1]]) as usize,
                IndexType::U32 => u32::from_le_bytes([ib[0], ib[1], ib[2], ib[3]]) as usize,
            };
            if target >= count {
                return Err(format!(
                    "{what}: sparse index {target} out of range for {count} elements"
                ));
            }
            let e = &vbytes[vals.offset() + j * elem..][..elem];
            for (c, v) in e.chunks_exact(csize).enumerate() {
                out[target * n + c] = conv(v);
            }
        }
    }
    Ok((out, n))
}

/// Reads a float attribute whose type must be one of `dims` (component counts).
pub(crate) fn read_f32(
    acc: &Accessor,
    buffers: &[Cow<[u8]>],
    dims: &[usize],
) -> Result<(Vec<f32>, usize), String> {
    let (t, norm) = (acc.data_type(), acc.normalized());
    let (v, n) = read(acc, buffers, |b| component_f32(b, t, norm))?;
    if !dims.contains(&n) {
        return Err(format!(
            "accessor {} has {n} components, expected {dims:?}",
            acc.index()
        ));
    }
    Ok((v, n))
}

/// Reads an index accessor (scalar, unsigned byte / short / int).
pub(crate) fn read_indices(acc: &Accessor, buffers: &[Cow<[u8]>]) -> Result<Vec<u32>, String> {
    let t = acc.data_type();
    if !matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
        || acc.dimensions() != Dimensions::Scalar
    {
        return Err(format!(
            "index accessor {} is {:?} {:?}; expected unsigned scalar",
            acc.index(),
            acc.dimensions(),
            t
        ));
    }
    Ok(read(acc, buffers, |b| component_u32(b, t))?.0)
}
