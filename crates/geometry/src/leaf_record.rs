//! One BVH leaf slot as 48 bytes: its three vectors (a triangle's vertices, or an instance's
//! world box) with the slot's id in their fourth lanes, which `Vec3A` pads and never uses.
//! A leaf test then reads one record instead of the vertices and a separate id array: one
//! cache miss and one page where there were two (docs/geometry.md, "Where an incoherent
//! ray's time goes").

use glam::{Vec3A, Vec4};

/// An id that fits the three spare 32-bit lanes of a [`LeafRecord`].
pub(crate) trait SlotId: Copy {
    fn to_lanes(self) -> [u32; 3];
    fn from_lanes(lanes: [u32; 3]) -> Self;
}

impl SlotId for u32 {
    #[inline(always)]
    fn to_lanes(self) -> [u32; 3] {
        [self, 0, 0]
    }

    #[inline(always)]
    fn from_lanes(lanes: [u32; 3]) -> Self {
        lanes[0]
    }
}

/// A leaf slot: three rows of x, y, z and one 32-bit lane of the id.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(crate) struct LeafRecord {
    rows: [Vec4; 3],
}

impl LeafRecord {
    pub fn new<Id: SlotId>(vectors: &[Vec3A; 3], id: Id) -> Self {
        let lanes = id.to_lanes();
        Self {
            rows: std::array::from_fn(|k| vectors[k].extend(f32::from_bits(lanes[k]))),
        }
    }

    /// The three vectors, their fourth lanes zero (an id's bits read as a float could be a
    /// subnormal, which slows arithmetic on some CPUs).
    #[inline(always)]
    pub fn vectors(&self) -> [Vec3A; 3] {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{__m128, _mm_and_ps, _mm_castsi128_ps, _mm_set_epi32};
            // SAFETY: SSE2 is part of x86-64.
            let xyz = unsafe { _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1)) };
            self.rows.map(|row| {
                // SAFETY: as above.
                Vec3A::from(unsafe { _mm_and_ps(__m128::from(row), xyz) })
            })
        }
        #[cfg(not(target_arch = "x86_64"))]
        self.rows.map(|row| Vec3A::new(row.x, row.y, row.z))
    }

    #[inline(always)]
    pub fn id<Id: SlotId>(&self) -> Id {
        Id::from_lanes(self.rows.map(|row| row.w.to_bits()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Vertices and ids come back bit for bit, the id's lanes whatever their bits
    /// (subnormal, NaN, infinite), and the vectors' fourth lanes are zero.
    #[test]
    fn a_record_returns_its_vectors_and_id() {
        let vectors = [
            Vec3A::new(1.5, -0.0, 3.25e-30),
            Vec3A::new(f32::MAX, f32::MIN_POSITIVE, -7.0),
            Vec3A::new(0.1, 0.2, 0.3),
        ];
        for id in [0u32, 1, 12_345, 0x7fc0_0001, 0x7f80_0000, u32::MAX] {
            let record = LeafRecord::new(&vectors, id);
            let back = record.vectors();
            for k in 0..3 {
                assert_eq!(
                    back[k].to_array().map(f32::to_bits),
                    vectors[k].to_array().map(f32::to_bits)
                );
                #[cfg(target_arch = "x86_64")]
                {
                    let lanes: [u32; 4] =
                        unsafe { std::mem::transmute(std::arch::x86_64::__m128::from(back[k])) };
                    assert_eq!(lanes[3], 0, "the fourth lane is cleared");
                }
            }
            assert_eq!(record.id::<u32>(), id);
        }
        assert_eq!(std::mem::size_of::<LeafRecord>(), 48);
    }
}
