//! Binary PLY payloads (little and big endian) decoded straight into the columns a triangle
//! mesh uses. `ply-rs` reads a binary payload one property at a time into a map per
//! element, cloning the property's name for each value: on a 10⁶-triangle mesh that was
//! ≈ 1.8 s of allocation and hashing. This reads the same layout the header declares (every
//! element in order, unused properties skipped) at close to the speed of a copy.

use ply_rs::ply::{Encoding, Header, PropertyType, ScalarType};

use crate::ply::{FaceIndices, MeshColumns, FACE_INDEX_PROPERTIES, VERTEX_PROPERTIES};

/// Byte order of a binary payload.
#[derive(Clone, Copy)]
enum ByteOrder {
    Little,
    Big,
}

/// What the decoder does with one declared property.
enum Use {
    /// A vertex property the mesh uses: stored in this slot of the vertex columns.
    Vertex(usize),
    /// The face element's index list.
    FaceCorners,
    /// Anything else: read over.
    Skip,
}

/// A cursor over the payload bytes that reads the PLY scalar types.
struct Payload<'a> {
    bytes: &'a [u8],
    at: usize,
    order: ByteOrder,
}

impl Payload<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let end = self.at.checked_add(N)?;
        let out: [u8; N] = self.bytes.get(self.at..end)?.try_into().ok()?;
        self.at = end;
        Some(out)
    }

    /// One scalar as f64 (exact for every PLY integer type); `None` at the end of the data.
    fn number(&mut self, kind: &ScalarType) -> Option<f64> {
        macro_rules! read {
            ($t:ty) => {{
                let b = self.take::<{ std::mem::size_of::<$t>() }>()?;
                match self.order {
                    ByteOrder::Little => <$t>::from_le_bytes(b) as f64,
                    ByteOrder::Big => <$t>::from_be_bytes(b) as f64,
                }
            }};
        }
        Some(match kind {
            ScalarType::Char => read!(i8),
            ScalarType::UChar => read!(u8),
            ScalarType::Short => read!(i16),
            ScalarType::UShort => read!(u16),
            ScalarType::Int => read!(i32),
            ScalarType::UInt => read!(u32),
            ScalarType::Float => read!(f32),
            ScalarType::Double => read!(f64),
        })
    }
}

fn scalar_bytes(kind: &ScalarType) -> usize {
    match kind {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

fn is_integer(kind: &ScalarType) -> bool {
    match kind {
        ScalarType::Char
        | ScalarType::UChar
        | ScalarType::Short
        | ScalarType::UShort
        | ScalarType::Int
        | ScalarType::UInt => true,
        ScalarType::Float | ScalarType::Double => false,
    }
}

/// Decodes a binary payload (`bytes`: everything after `end_header`) into the mesh columns.
/// Errors are sentences naming the element and its index.
pub(crate) fn decode_binary_payload(header: &Header, bytes: &[u8]) -> Result<MeshColumns, String> {
    let order = match header.encoding {
        Encoding::BinaryLittleEndian => ByteOrder::Little,
        Encoding::BinaryBigEndian => ByteOrder::Big,
        Encoding::Ascii => return Err("an ASCII payload is not binary".into()),
    };
    let mut payload = Payload {
        bytes,
        at: 0,
        order,
    };
    let mut columns = MeshColumns::default();
    for (name, element) in &header.elements {
        let is_vertex = name == "vertex";
        let is_face = name == "face";
        let face_list = if is_face {
            FACE_INDEX_PROPERTIES
                .iter()
                .find_map(|p| element.properties.get(*p).map(|d| (*p, &d.data_type)))
        } else {
            None
        };
        if is_face {
            columns.face_count = element.count;
            columns.faces = match face_list {
                None => FaceIndices::Missing,
                Some((_, PropertyType::List(_, item))) if is_integer(item) => {
                    FaceIndices::default_lists()
                }
                Some(_) => FaceIndices::NotIntegers,
            };
        }
        let mut vertex_slots: Vec<Option<Vec<f32>>> = Vec::new();
        let uses: Vec<(Use, &PropertyType)> = element
            .properties
            .iter()
            .map(|(prop, def)| {
                let use_ = if is_vertex {
                    match (&def.data_type, VERTEX_PROPERTIES.contains(&prop.as_str())) {
                        (PropertyType::Scalar(_), true) => {
                            vertex_slots.push(Some(Vec::new()));
                            columns.vertex_names.push(prop.clone());
                            Use::Vertex(vertex_slots.len() - 1)
                        }
                        (PropertyType::List(..), true) => {
                            vertex_slots.push(None);
                            columns.vertex_names.push(prop.clone());
                            Use::Skip
                        }
                        (_, false) => Use::Skip,
                    }
                } else if face_list.is_some_and(|(p, _)| p == prop.as_str())
                    && matches!(columns.faces, FaceIndices::Lists { .. })
                {
                    Use::FaceCorners
                } else {
                    Use::Skip
                };
                (use_, &def.data_type)
            })
            .collect();
        if uses.is_empty() {
            continue;
        }
        // The header's count is the file's word: reserve no more than the bytes left can hold.
        let min_element_bytes: usize = uses
            .iter()
            .map(|(_, t)| match t {
                PropertyType::Scalar(s) => scalar_bytes(s),
                PropertyType::List(count, _) => scalar_bytes(count),
            })
            .sum();
        let reserve = element
            .count
            .min((bytes.len() - payload.at) / min_element_bytes.max(1));
        for column in vertex_slots.iter_mut().flatten() {
            column.reserve_exact(reserve);
        }
        let mut face_starts: Vec<usize> = Vec::new();
        let mut face_corners: Vec<i64> = Vec::new();
        if is_face {
            face_starts.reserve_exact(reserve + 1);
            face_starts.push(0);
            face_corners.reserve(reserve * 3);
        }
        let truncated = |i: usize| {
            format!(
                "cannot parse PLY: the file ends in element '{name}' {i} of {} — the file ends \
                 before all elements the header declares were read (truncated file?)",
                element.count
            )
        };
        for i in 0..element.count {
            for (use_, kind) in &uses {
                match kind {
                    PropertyType::Scalar(s) => match use_ {
                        Use::Vertex(slot) => {
                            let value = payload.number(s).ok_or_else(|| truncated(i))?;
                            if let Some(column) = &mut vertex_slots[*slot] {
                                column.push(value as f32);
                            }
                        }
                        Use::FaceCorners | Use::Skip => {
                            payload.at = payload
                                .at
                                .checked_add(scalar_bytes(s))
                                .filter(|&end| end <= bytes.len())
                                .ok_or_else(|| truncated(i))?;
                        }
                    },
                    PropertyType::List(count_kind, item) => {
                        let count = payload.number(count_kind).ok_or_else(|| truncated(i))?;
                        if !is_integer(count_kind) || count < 0.0 {
                            return Err(format!(
                                "cannot parse PLY: element '{name}' {i} has a list of length \
                                 {count}; expected a non-negative integer length"
                            ));
                        }
                        let count = count as usize;
                        match use_ {
                            Use::FaceCorners => {
                                for _ in 0..count {
                                    let v = payload.number(item).ok_or_else(|| truncated(i))?;
                                    face_corners.push(v as i64);
                                }
                                face_starts.push(face_corners.len());
                            }
                            Use::Vertex(_) | Use::Skip => {
                                payload.at = count
                                    .checked_mul(scalar_bytes(item))
                                    .and_then(|n| payload.at.checked_add(n))
                                    .filter(|&end| end <= bytes.len())
                                    .ok_or_else(|| truncated(i))?;
                            }
                        }
                    }
                }
            }
        }
        if is_vertex {
            columns.vertex_count = element.count;
            columns.vertex_columns = vertex_slots;
        }
        if let FaceIndices::Lists { starts, corners } = &mut columns.faces {
            if is_face {
                *starts = face_starts;
                *corners = face_corners;
            }
        }
    }
    Ok(columns)
}
