//! A BVH over a triangle soup whose vertices are stored in BVH leaf order, so that a leaf test
//! reads 48 contiguous bytes instead of three indexed loads (the layout of obvhs'
//! `cornell_box_cwbvh` example). Each leaf slot also carries a caller-chosen id: the triangle
//! index for a mesh's own BVH ([`crate::mesh_bvh::MeshBvh`]); for the scene BVH of
//! [`crate::Geometry`], the original instance and triangle of a baked world-space triangle, or
//! an instance whose slot holds its world box instead of vertices (one 48-byte record,
//! leaf_record.rs). The closest-hit and any-hit traversals visit children nearest first and
//! prefetch the lines each node test selects (triangle_bvh_nearest.rs); a ray stream runs
//! the same steps for several rays interleaved (triangle_bvh_stream.rs). The nodes are
//! obvhs' compressed 8-wide nodes; obvhs' own `traverse!` loop is not used.

use std::marker::PhantomData;
use std::ops::ControlFlow;

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;

use crate::bvh_build::{build_bvh, padded_aabb, BuildQuality};
use crate::leaf_record::{LeafRecord, SlotId};
use crate::triangle::{TriangleHit, WatertightRay};

#[path = "triangle_bvh_nearest.rs"]
mod nearest;
#[path = "triangle_bvh_stream.rs"]
mod stream;

pub(crate) struct TriangleBvh<Id> {
    /// `None` for an empty soup.
    bvh: Option<CwBvh>,
    /// Vertices and id of each slot, in BVH leaf order.
    leaves: Vec<LeafRecord>,
    id: PhantomData<Id>,
}

impl<Id: SlotId> TriangleBvh<Id> {
    /// Build over `triangles`, where `ids[i]` names `triangles[i]`.
    pub fn build(triangles: &[[Vec3A; 3]], ids: &[Id], quality: BuildQuality) -> Self {
        Self::build_with_bounds(
            triangles,
            ids,
            |t, _| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])),
            quality,
        )
    }

    /// Build over primitives stored as three vectors each, with their bounds (min, max) given
    /// by `bounds(primitive, id)` (padded here).
    pub fn build_with_bounds(
        triangles: &[[Vec3A; 3]],
        ids: &[Id],
        bounds: impl Fn(&[Vec3A; 3], Id) -> (Vec3A, Vec3A),
        quality: BuildQuality,
    ) -> Self {
        debug_assert_eq!(triangles.len(), ids.len());
        let boxes: Vec<Aabb> = triangles
            .iter()
            .zip(ids)
            .map(|(t, &id)| {
                let (lo, hi) = bounds(t, id);
                padded_aabb(lo, hi)
            })
            .collect();
        let bvh = build_bvh(&boxes, quality);
        let leaves = match &bvh {
            Some(b) => b
                .primitive_indices
                .iter()
                .map(|&i| LeafRecord::new(&triangles[i as usize], ids[i as usize]))
                .collect(),
            None => Vec::new(),
        };
        Self {
            bvh,
            leaves,
            id: PhantomData,
        }
    }

    /// Closest hit with `t` in `(t_min, t_max)`: the watertight test's record and the id of
    /// the triangle; the node test is `WIDE`'s ([`node_entries_on`]).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub unsafe fn intersect_with<const WIDE: bool>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<(TriangleHit, Id)> {
        let mut best = TriangleBest::new(origin, direction, t_min);
        let test = |p: &[Vec3A; 3], id: Id, t_max: f32| best.test(p, id, t_max);
        // SAFETY: the caller's contract for `WIDE`.
        unsafe { self.traverse_with::<WIDE>(origin, direction, t_min, t_max, test) };
        best.hit
    }

    /// Closest-hit traversal of the ray over `(t_min, t_max)`: `test(primitive, id, t_max)`
    /// intersects one stored primitive and returns its `t` (which then bounds the rest of the
    /// traversal) or `f32::INFINITY` for a miss; the caller keeps the record of the best hit.
    /// For soups that store other leaves than triangles (the flattened scene's instances).
    /// Children are visited nearest first and culled once a hit lies nearer
    /// ([`Self::traverse_nearest_first`]); the node test is `WIDE`'s ([`node_entries_on`]).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub unsafe fn traverse_with<const WIDE: bool>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
        mut test: impl FnMut(&[Vec3A; 3], Id, f32) -> f32,
    ) {
        let Some(bvh) = self.bvh.as_ref() else {
            return;
        };
        let test = |p: &[Vec3A; 3], id: Id, t_max: f32| ControlFlow::Continue(test(p, id, t_max));
        // SAFETY: the caller's contract for `WIDE`.
        unsafe { self.traverse_nearest_first::<WIDE>(bvh, origin, direction, t_min, t_max, test) };
    }

    /// Any-hit traversal: whether `test(primitive, id, t_max)` accepts any primitive whose
    /// box the ray reaches in `(t_min, t_max)` (stops at the first). The closest-hit
    /// traversal's order ([`Self::traverse_nearest_first`]), which bench-bvh measured
    /// ~10 % faster than obvhs' `traverse!` on incoherent shadow rays (docs/geometry.md);
    /// the node test is `WIDE`'s ([`node_entries_on`]).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub unsafe fn any_with<const WIDE: bool>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
        mut test: impl FnMut(&[Vec3A; 3], Id, f32) -> bool,
    ) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let test = |p: &[Vec3A; 3], id: Id, t_max: f32| {
            if test(p, id, t_max) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(f32::INFINITY)
            }
        };
        // SAFETY: the caller's contract for `WIDE`.
        unsafe { self.traverse_nearest_first::<WIDE>(bvh, origin, direction, t_min, t_max, test) }
    }

    /// Whether any triangle lies in `(t_min, t_max)` (stops at the first hit); the node
    /// test is `WIDE`'s ([`node_entries_on`]).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub unsafe fn occluded_with<const WIDE: bool>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> bool {
        let wt = WatertightRay::new(origin, direction, t_min);
        let test =
            |[a, b, c]: &[Vec3A; 3], _: Id, t_max: f32| wt.intersect(*a, *b, *c, t_max).is_some();
        // SAFETY: the caller's contract for `WIDE`.
        unsafe { self.any_with::<WIDE>(origin, direction, t_min, t_max, test) }
    }
}

/// One ray's closest triangle so far: the leaf test of the closest-hit traversals, one ray
/// at a time ([`TriangleBvh::intersect_with`]) or in a stream.
struct TriangleBest<Id> {
    watertight: WatertightRay,
    hit: Option<(TriangleHit, Id)>,
}

impl<Id: Copy> TriangleBest<Id> {
    #[inline(always)]
    fn new(origin: Vec3A, direction: Vec3A, t_min: f32) -> Self {
        Self {
            watertight: WatertightRay::new(origin, direction, t_min),
            hit: None,
        }
    }

    /// The watertight test of the stored triangle `[a, b, c]`: its `t` below `t_max`, kept
    /// with `id` as the best, or ∞.
    #[inline(always)]
    fn test(&mut self, [a, b, c]: &[Vec3A; 3], id: Id, t_max: f32) -> f32 {
        match self.watertight.intersect(*a, *b, *c, t_max) {
            Some(h) => {
                self.hit = Some((h, id));
                h.t
            }
            None => f32::INFINITY,
        }
    }
}

/// Start loading the cache lines of an object's first and last byte: all of it for objects
/// of up to 64 bytes (a triangle is 48, an id 8), and of a node (80 bytes) unless it starts
/// in a line's last 16 bytes. Nothing on other architectures.
#[inline(always)]
fn prefetch_object<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let first = p as *const i8;
        // SAFETY: prefetching never faults, whatever the address.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(first);
            _mm_prefetch::<_MM_HINT_T0>(first.wrapping_add(size_of::<T>() - 1));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// The children of `node` that are not empty, one bit per slot (a slot's meta byte is 0
/// when empty).
#[inline(always)]
fn occupied_slots(node: &CwBvhNode) -> u32 {
    const LOW7: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    let meta8 = u64::from_le_bytes(node.child_meta);
    // The high bit of each byte set where the byte is not zero, then the eight high bits
    // gathered into one byte by a multiplication.
    let nonzero = (meta8 | ((meta8 & LOW7) + LOW7)) & !LOW7;
    ((nonzero >> 7).wrapping_mul(0x0102_0408_1020_4080) >> 56) as u32
}

/// [`node_entries_avx2`] where `WIDE`, else [`node_entries`]: the same slots and distances,
/// bit for bit.
///
/// # Safety
/// With `WIDE`, the CPU must run AVX2.
#[inline(always)]
unsafe fn node_entries_on<const WIDE: bool>(
    node: &CwBvhNode,
    ray: &obvhs::ray::Ray,
) -> (u32, [f32; 8]) {
    #[cfg(target_arch = "x86_64")]
    if WIDE {
        // SAFETY: the caller's contract.
        let (entered, t_entry) = unsafe { node_entries_avx2(node, ray) };
        return (entered & occupied_slots(node), t_entry);
    }
    let (entered, t_entry) = node_entries(node, ray);
    (entered & occupied_slots(node), t_entry)
}

/// [`node_entries`] for all eight slots at once in AVX2. The quantised bounds are widened
/// from bytes by two instructions per axis and side instead of 24 scalar conversions (the
/// costliest part of the 4-wide test, as obvhs' `intersect_ray_simd` notes); the slab
/// arithmetic, its operand order (min/max pass the second operand on NaN) and the bound by
/// `tmin` are [`node_entries`]', so the slots and distances are the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn node_entries_avx2(node: &CwBvhNode, ray: &obvhs::ray::Ray) -> (u32, [f32; 8]) {
    use std::arch::x86_64::*;
    let dir_inv = node.compute_extent() * ray.inv_direction;
    let origin = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    // Eight u8 bounds → eight f32 (exact).
    macro_rules! widen {
        ($bytes:expr) => {
            _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_cvtsi64_si128(i64::from_le_bytes(
                $bytes,
            ))))
        };
    }
    // (entry, exit) distances along one axis: near·inv + o, far·inv + o.
    macro_rules! slab {
        ($lo:expr, $hi:expr, $negative:expr, $inv:expr, $o:expr) => {{
            let (lo, hi) = (widen!($lo), widen!($hi));
            let (near, far) = if $negative { (hi, lo) } else { (lo, hi) };
            let (inv, o) = (_mm256_set1_ps($inv), _mm256_set1_ps($o));
            (
                _mm256_add_ps(_mm256_mul_ps(near, inv), o),
                _mm256_add_ps(_mm256_mul_ps(far, inv), o),
            )
        }};
    }
    let (tmin_x, tmax_x) = slab!(
        node.child_min_x,
        node.child_max_x,
        ray.direction.x < 0.0,
        dir_inv.x,
        origin.x
    );
    let (tmin_y, tmax_y) = slab!(
        node.child_min_y,
        node.child_max_y,
        ray.direction.y < 0.0,
        dir_inv.y,
        origin.y
    );
    let (tmin_z, tmax_z) = slab!(
        node.child_min_z,
        node.child_max_z,
        ray.direction.z < 0.0,
        dir_inv.z,
        origin.z
    );
    let tmin = _mm256_max_ps(
        _mm256_max_ps(tmin_x, _mm256_max_ps(tmin_y, tmin_z)),
        _mm256_set1_ps(ray.tmin),
    );
    let tmax = _mm256_min_ps(
        _mm256_min_ps(tmax_x, _mm256_min_ps(tmax_y, tmax_z)),
        _mm256_set1_ps(ray.tmax),
    );
    let entered = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(tmin, tmax)) as u32;
    let mut t_entry = [0.0f32; 8];
    // SAFETY: `t_entry` holds eight f32 (an unaligned store).
    unsafe { _mm256_storeu_ps(t_entry.as_mut_ptr(), tmin) };
    (entered, t_entry)
}

/// Which slots' boxes of `node` the ray enters within `[ray.tmin, ray.tmax]` (empty slots
/// included; bit i for slot i) and each slot's entry distance: obvhs'
/// `CwBvhNode::intersect_ray_simd` (the same slab arithmetic, lane order and NaN handling,
/// four children at a time in SSE through glam's `Vec4`), except that a child's entry
/// distance is bounded below by the ray's own `tmin` where obvhs clamps it to ≥ 10⁻⁴
/// whatever `tmin` is (`cwbvh::node::EPSILON`): a hit closer than 10⁻⁴ m to the origin (a
/// ray leaving a point 10 µm in front of a wall) was never reached.
#[inline(always)]
fn node_entries(node: &CwBvhNode, ray: &obvhs::ray::Ray) -> (u32, [f32; 8]) {
    use glam::Vec4;
    let dir_inv = node.compute_extent() * ray.inv_direction;
    let origin = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    let (rdx, rdy, rdz) = (
        ray.direction.x < 0.0,
        ray.direction.y < 0.0,
        ray.direction.z < 0.0,
    );
    let (t_lo, t_hi) = (Vec4::splat(ray.tmin), Vec4::splat(ray.tmax));
    let mut entered = 0u32;
    let mut t_entry = [0.0f32; 8];
    for i in 0..2 {
        let q = |v: &[u8; 8]| {
            Vec4::new(
                f32::from(v[i * 4]),
                f32::from(v[i * 4 + 1]),
                f32::from(v[i * 4 + 2]),
                f32::from(v[i * 4 + 3]),
            )
        };
        let slab = |lo: Vec4, hi: Vec4, negative: bool, inv: f32, o: f32| {
            let (near, far) = if negative { (hi, lo) } else { (lo, hi) };
            let (inv, o) = (Vec4::splat(inv), Vec4::splat(o));
            (near * inv + o, far * inv + o)
        };
        let (tmin_x, tmax_x) = slab(
            q(&node.child_min_x),
            q(&node.child_max_x),
            rdx,
            dir_inv.x,
            origin.x,
        );
        let (tmin_y, tmax_y) = slab(
            q(&node.child_min_y),
            q(&node.child_max_y),
            rdy,
            dir_inv.y,
            origin.y,
        );
        let (tmin_z, tmax_z) = slab(
            q(&node.child_min_z),
            q(&node.child_max_z),
            rdz,
            dir_inv.z,
            origin.z,
        );
        let tmin = tmin_x.max(tmin_y.max(tmin_z)).max(t_lo);
        let tmax = tmax_x.min(tmax_y.min(tmax_z)).min(t_hi);
        entered |= tmin.cmple(tmax).bitmask() << (i * 4);
        t_entry[i * 4..i * 4 + 4].copy_from_slice(&tmin.to_array());
    }
    (entered, t_entry)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh_build::bvh_ray;
    use rand::{Rng, SeedableRng};

    /// The AVX2 node test enters the 4-wide test's slots at the same entry distances, bit
    /// for bit, on every node of a real BVH, for rays from inside and outside, axis-parallel
    /// directions (infinite inverse clamped) and `tmin` above the quantisation's 10⁻⁴.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn the_avx2_node_test_gives_the_four_wide_entries() {
        if !prism_cpu::Simd::detected().avx2() {
            eprintln!("skipped: this CPU has no AVX2");
            return;
        }
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut point = |r: f32| {
            Vec3A::new(
                rng.gen_range(-r..r),
                rng.gen_range(-r..r),
                rng.gen_range(-r..r),
            )
        };
        let triangles: Vec<[Vec3A; 3]> = (0..4000)
            .map(|_| {
                let c = point(5.0);
                [c, c + point(0.3), c + point(0.3)]
            })
            .collect();
        let ids: Vec<u32> = (0..triangles.len() as u32).collect();
        let soup = TriangleBvh::build(&triangles, &ids, BuildQuality::default());
        let bvh = soup.bvh.as_ref().unwrap();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(8);
        let (mut compared, mut entered) = (0usize, 0usize);
        for k in 0..4000 {
            let origin = Vec3A::new(
                rng.gen_range(-8.0..8.0),
                rng.gen_range(-8.0..8.0),
                rng.gen_range(-8.0..8.0),
            );
            let mut direction = Vec3A::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            if k % 5 == 0 {
                direction.x = 0.0;
            }
            if k % 7 == 0 {
                direction.z = -0.0;
            }
            let direction = direction.normalize_or(Vec3A::Y);
            let t_min = [0.0, 1e-5, 0.5][k % 3];
            let t_max = [f32::INFINITY, 3.0][k % 2];
            let ray = bvh_ray(origin, direction, t_min, t_max);
            for node in &bvh.nodes {
                let occupied = occupied_slots(node);
                // SAFETY: checked above that the CPU has AVX2.
                let (wide_slots, wide_t) = unsafe { node_entries_avx2(node, &ray) };
                let (slots, t) = node_entries(node, &ray);
                assert_eq!(wide_slots & occupied, slots & occupied, "ray {k}");
                let mut each = slots & occupied;
                while each != 0 {
                    let slot = each.trailing_zeros() as usize;
                    each &= each - 1;
                    assert_eq!(wide_t[slot].to_bits(), t[slot].to_bits(), "ray {k}");
                }
                compared += 1;
                entered += usize::from(slots & occupied != 0);
            }
        }
        // The premise: enough node tests, and masks that enter children, not only misses.
        assert!(compared > 100_000, "{compared} node tests");
        assert!(
            entered > 1_000,
            "{entered} of {compared} node tests entered a child"
        );
    }
}
