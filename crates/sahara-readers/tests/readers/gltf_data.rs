//! Small glTF files built in memory: float and index bytes, base64, and a
//! one-triangle buffer with its JSON. Shared with `sahara-formats`' tests,
//! which include this file by path.

/// Little-endian bytes of floats.
pub(crate) fn f32s(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Little-endian bytes of u16s, padded to a multiple of 4 bytes.
pub(crate) fn u16s(values: &[u16]) -> Vec<u8> {
    let mut out: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    out.resize(out.len().div_ceil(4) * 4, 0);
    out
}

/// Standard base64 with padding (written here so the loader's decoder is checked independently).
pub(crate) fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// One triangle: positions, normals, uvs, u16 indices; returns the buffer and the byte offsets.
pub(crate) fn triangle_buffer() -> Vec<u8> {
    let mut bin = f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]); // 0..36
    bin.extend(f32s(&[0., 0., 1., 0., 0., 1., 0., 0., 1.])); // 36..72
    bin.extend(f32s(&[0., 0., 1., 0., 0., 1.])); // 72..96
    bin.extend(u16s(&[0, 1, 2])); // 96..102 (+2 padding)
    bin
}

/// The JSON for [`triangle_buffer`] given the buffer's `uri` entry (or none for GLB) and extra top-level JSON.
pub(crate) fn triangle_json(buffer: &str, length: usize, extra: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "buffers": [{{ {buffer} "byteLength": {length}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 96}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 6}}
  ],
  "accessors": [
    {{"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3"}},
    {{"bufferView": 0, "byteOffset": 36, "componentType": 5126, "count": 3, "type": "VEC3"}},
    {{"bufferView": 0, "byteOffset": 72, "componentType": 5126, "count": 3, "type": "VEC2"}},
    {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}
  ],
  "meshes": [{{"name": "tri", "primitives": [{{
    "attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": 0}}]}}],
  {extra}
}}"#
    )
}
