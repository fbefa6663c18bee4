//! Mitsuba's `serialized` mesh format (Mitsuba 3 docs, "Serialized mesh loader"): per shape,
//! u16 0x041C, u16 version (3 or 4), then a zlib stream of: u32 flags, (v4) a NUL-terminated
//! name, u64 vertex and triangle counts, positions, optional normals (0x0001), uvs (0x0002)
//! and colours (0x0008), then u32 indices (u64 above 2³² vertices); floats are f32 (0x1000)
//! or f64 (0x2000). Several shapes: the file ends with their offsets (u64 in v4, u32 in v3)
//! and a u32 count. All little-endian.

use std::io::Read;

use glam::DVec3;

pub struct SerializedMesh {
    pub positions: Vec<DVec3>,
    pub normals: Option<Vec<DVec3>>,
    pub uvs: Option<Vec<f64>>,
    pub triangles: Vec<[usize; 3]>,
}

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_UVS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

/// Shape `shape_index` of the file's bytes; errors say what was expected.
pub fn read_serialized(bytes: &[u8], shape_index: usize) -> Result<SerializedMesh, String> {
    let u16_at = |o: usize| -> Result<u16, String> {
        bytes
            .get(o..o + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .ok_or_else(|| format!("truncated at byte {o}"))
    };
    let (magic, version) = (u16_at(0)?, u16_at(2)?);
    if magic != MAGIC || !(version == 3 || version == 4) {
        return Err(format!(
            "expected a Mitsuba serialized mesh (0x041C, version 3 or 4), found 0x{magic:04X} version {version}"
        ));
    }
    let offset = if shape_index == 0 {
        0
    } else {
        let n = bytes.len();
        let count = bytes
            .get(n.saturating_sub(4)..)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or("truncated shape dictionary")?;
        if shape_index >= count {
            return Err(format!(
                "shape_index {shape_index}: the file has {count} shapes"
            ));
        }
        let width = if version == 4 { 8 } else { 4 };
        let at = n
            .checked_sub(4 + width * (count - shape_index))
            .ok_or("truncated shape dictionary")?;
        let b = &bytes[at..at + width];
        if width == 8 {
            u64::from_le_bytes(b.try_into().map_err(|_| "bad offset")?) as usize
        } else {
            u32::from_le_bytes(b.try_into().map_err(|_| "bad offset")?) as usize
        }
    };
    if u16_at(offset)? != MAGIC {
        return Err(format!(
            "shape {shape_index} at byte {offset}: no 0x041C header"
        ));
    }
    let version = u16_at(offset + 2)?;
    let mut z = flate2::read::ZlibDecoder::new(&bytes[offset + 4..]);
    let mut read = |n: usize| -> Result<Vec<u8>, String> {
        let mut buf = vec![0u8; n];
        z.read_exact(&mut buf)
            .map_err(|e| format!("compressed data: {e}"))?;
        Ok(buf)
    };
    let flags = u32::from_le_bytes(read(4)?.try_into().expect("4 bytes"));
    if version == 4 {
        while read(1)?[0] != 0 {}
    }
    let vertices = u64::from_le_bytes(read(8)?.try_into().expect("8 bytes")) as usize;
    let triangles = u64::from_le_bytes(read(8)?.try_into().expect("8 bytes")) as usize;
    let double = flags & DOUBLE_PRECISION != 0;
    let mut floats = |n: usize| -> Result<Vec<f64>, String> {
        let size = if double { 8 } else { 4 };
        let raw = read(n.checked_mul(size).ok_or("vertex count too large")?)?;
        Ok(raw
            .chunks(size)
            .map(|c| {
                if double {
                    f64::from_le_bytes(c.try_into().expect("8 bytes"))
                } else {
                    f64::from(f32::from_le_bytes(c.try_into().expect("4 bytes")))
                }
            })
            .collect())
    };
    let vec3s = |xs: Vec<f64>| {
        xs.chunks(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect::<Vec<_>>()
    };
    let positions = vec3s(floats(vertices * 3)?);
    let normals = if flags & HAS_NORMALS != 0 {
        Some(vec3s(floats(vertices * 3)?))
    } else {
        None
    };
    let uvs = if flags & HAS_UVS != 0 {
        Some(floats(vertices * 2)?)
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        floats(vertices * 3)?;
    }
    let wide = vertices > u32::MAX as usize;
    let size = if wide { 8 } else { 4 };
    let raw = read(
        triangles
            .checked_mul(3 * size)
            .ok_or("triangle count too large")?,
    )?;
    let indices: Vec<usize> = raw
        .chunks(size)
        .map(|c| {
            if wide {
                u64::from_le_bytes(c.try_into().expect("8 bytes")) as usize
            } else {
                u32::from_le_bytes(c.try_into().expect("4 bytes")) as usize
            }
        })
        .collect();
    if let Some(bad) = indices.iter().find(|i| **i >= vertices) {
        return Err(format!(
            "index {bad} out of range (the mesh has {vertices} vertices)"
        ));
    }
    Ok(SerializedMesh {
        positions,
        normals,
        uvs,
        triangles: indices.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::io::Write;

    /// A version-4 file with one f32 triangle with uvs, written as Mitsuba writes it.
    pub fn one_triangle() -> Vec<u8> {
        let mut body = Vec::new();
        body.extend(&(HAS_UVS | 0x1000).to_le_bytes());
        body.extend(b"tri\0");
        body.extend(&3u64.to_le_bytes());
        body.extend(&1u64.to_le_bytes());
        for x in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.5] {
            body.extend(&x.to_le_bytes());
        }
        for x in [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0] {
            body.extend(&x.to_le_bytes());
        }
        for i in [0u32, 1, 2] {
            body.extend(&i.to_le_bytes());
        }
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&body).unwrap();
        let mut file = Vec::new();
        file.extend(&MAGIC.to_le_bytes());
        file.extend(&4u16.to_le_bytes());
        file.extend(z.finish().unwrap());
        file
    }

    #[test]
    fn reads_a_triangle_and_refuses_other_files() {
        let m = read_serialized(&one_triangle(), 0).unwrap();
        assert_eq!(m.positions[2], DVec3::new(0.0, 1.0, 0.5));
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert_eq!(m.uvs.unwrap().len(), 6);
        assert!(m.normals.is_none());
        let e = read_serialized(b"PLY\0\0\0", 0).err().unwrap();
        assert!(e.contains("expected a Mitsuba serialized mesh"), "{e}");
    }
}
