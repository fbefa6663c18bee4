//! Scenes of few leaves traced without a BVH: every leaf is tested, eight at a time.
//!
//! For the Cornell box (24 baked triangles and 6 rectangles) the 8-wide compressed BVH costs
//! more than it saves: a callgrind profile put ≈ 60 % of a closest-hit query (≈ 850
//! instructions) in CWBVH node decoding and traversal bookkeeping, for ≈ 1.7 primitive
//! tests. Here the leaves are stored structure-of-arrays in batches of [`LANES`], and one
//! pass of straight-line, branch-free code tests a whole batch:
//!
//! - **Triangles** (baked world-space triangles of [`crate::Geometry`]) with the watertight
//!   test of [`WatertightRay::intersect`], written per lane with the *same* operations in the
//!   same order (the 3×3 shear product of glam's `Mat3A * Vec3A`, `element_sum`, `dot`), so
//!   each lane rounds exactly as the scalar test: the same `t`, `b1`, `b2` bits, and shared
//!   edges/vertices of closed meshes stay closed. A lane whose edge function is exactly 0
//!   (the paper's f64 fallback case, Woop et al. 2013 §3.1) is re-tested with the scalar
//!   test. Batches hold triangles of one instance where that fills them at least half, and
//!   the world boxes of eight batches are slab-tested at once, so a ray skips the triangles
//!   of a cuboid whose box it misses.
//! - **Rectangles** (instance leaves) with the exact object-space test of
//!   [`crate::Rectangle::intersect`]: each lane takes the ray to its rectangle's object space
//!   with the operations of glam's `Affine3A::transform_point3a`/`transform_vector3a`, so
//!   `t` is bit-identical to the instanced path. With more than [`LANES`] rectangles, the
//!   first batch holds the largest (walls, floors: always tested, they bound the ray early)
//!   and the others are grouped by the Morton code of their centres, each batch with a world
//!   box slab-tested eight batches at once like the triangles': in an open-plan office of
//!   126 rectangles (96 ceiling panels) a ray tests ≈ 2 batches instead of 16.
//! - Everything else (spheres, disks, meshes kept instanced) is left to the caller, which
//!   tests those leaves one by one after the batches.
//!
//! The kernels are `#[inline(always)]` loops over fixed-size lane arrays, compiled once at
//! the baseline width (SSE2 on x86-64: two 4-wide vectors per batch; whatever the target
//! offers elsewhere) and once inside a `#[target_feature(enable = "avx2")]` function, run
//! where the ISA the scene was built with allows AVX2 (`prism_cpu::active()` at build,
//! within `PRISM_SIMD` / `--simd`; one 8-wide vector). Results are bit-identical on both
//! paths: Rust never contracts `a * b + c` into an FMA, and lanes are independent (tested
//! for every ISA the machine has).
//!
//! Closest hit: the smallest `t` over all lanes; a tie between two leaves at exactly the
//! same `t` is broken by a fixed order (rectangles before triangles in a lane, then the
//! lower lane key), deterministic but not necessarily the BVH's traversal order. The
//! result differs from the BVH path only there, and where two hits lie within an ulp of
//! each other (the BVH tests later leaves against the shrunken `t_max` before its division,
//! which can reject one a hair closer).

use glam::Vec3A;

use crate::bvh_build::{bvh_ray, padded_aabb};
use crate::rectangle::Rectangle;
use crate::transform::Transform;
use crate::triangle::{TriangleHit, WatertightRay};

/// Leaves tested per batch: one AVX register of `f32`.
pub const LANES: usize = 8;

/// Storage of eight `f32` lanes (aligned for 8-wide loads).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct F8([f32; LANES]);

impl F8 {
    fn splat(x: f32) -> F8 {
        F8([x; LANES])
    }
}

/// Eight `f32` lanes in registers; a mask is a value of the same type whose lanes have all
/// bits set (true) or clear. Written with explicit intrinsics: the same kernels written as
/// loops over `[f32; 8]` were only partly vectorised by LLVM (scalar inserts and spills).
trait Lanes:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
{
    fn splat(x: f32) -> Self;
    fn load(x: &F8) -> Self;
    fn store(self) -> F8;
    fn lt(self, o: Self) -> Self;
    fn gt(self, o: Self) -> Self;
    fn le(self, o: Self) -> Self;
    fn eq(self, o: Self) -> Self;
    /// `!=` as Rust's (true when either lane is NaN).
    fn ne(self, o: Self) -> Self;
    /// `if self < o { self } else { o }` (minps).
    fn min(self, o: Self) -> Self;
    /// `if self > o { self } else { o }` (maxps).
    fn max(self, o: Self) -> Self;
    fn abs(self) -> Self;
    fn and(self, o: Self) -> Self;
    fn or(self, o: Self) -> Self;
    /// `self & !o`.
    fn and_not(self, o: Self) -> Self;
    /// Lane-wise `if self { a } else { b }` for a mask `self`.
    fn select(self, a: Self, b: Self) -> Self;
    /// Bit `l` set for each true lane of a mask.
    fn bits(self) -> u32;
}

/// The portable lanes (targets other than x86-64).
#[cfg(not(target_arch = "x86_64"))]
mod portable {
    use super::{Lanes, F8, LANES};

    #[derive(Clone, Copy)]
    pub struct Scalar8(pub [f32; LANES]);

    fn map(a: Scalar8, b: Scalar8, f: impl Fn(f32, f32) -> f32) -> Scalar8 {
        let mut r = [0.0; LANES];
        for l in 0..LANES {
            r[l] = f(a.0[l], b.0[l]);
        }
        Scalar8(r)
    }

    fn mask(c: bool) -> f32 {
        f32::from_bits(if c { u32::MAX } else { 0 })
    }

    fn bitwise(a: Scalar8, b: Scalar8, f: impl Fn(u32, u32) -> u32) -> Scalar8 {
        map(a, b, |x, y| f32::from_bits(f(x.to_bits(), y.to_bits())))
    }

    impl std::ops::Add for Scalar8 {
        type Output = Self;
        fn add(self, o: Self) -> Self {
            map(self, o, |a, b| a + b)
        }
    }
    impl std::ops::Sub for Scalar8 {
        type Output = Self;
        fn sub(self, o: Self) -> Self {
            map(self, o, |a, b| a - b)
        }
    }
    impl std::ops::Mul for Scalar8 {
        type Output = Self;
        fn mul(self, o: Self) -> Self {
            map(self, o, |a, b| a * b)
        }
    }
    impl std::ops::Div for Scalar8 {
        type Output = Self;
        fn div(self, o: Self) -> Self {
            map(self, o, |a, b| a / b)
        }
    }

    impl Lanes for Scalar8 {
        fn splat(x: f32) -> Self {
            Scalar8([x; LANES])
        }
        fn load(x: &F8) -> Self {
            Scalar8(x.0)
        }
        fn store(self) -> F8 {
            F8(self.0)
        }
        fn lt(self, o: Self) -> Self {
            map(self, o, |a, b| mask(a < b))
        }
        fn gt(self, o: Self) -> Self {
            map(self, o, |a, b| mask(a > b))
        }
        fn le(self, o: Self) -> Self {
            map(self, o, |a, b| mask(a <= b))
        }
        fn eq(self, o: Self) -> Self {
            map(self, o, |a, b| mask(a == b))
        }
        fn ne(self, o: Self) -> Self {
            map(self, o, |a, b| mask(a != b))
        }
        fn min(self, o: Self) -> Self {
            map(self, o, |a, b| if a < b { a } else { b })
        }
        fn max(self, o: Self) -> Self {
            map(self, o, |a, b| if a > b { a } else { b })
        }
        fn abs(self) -> Self {
            map(self, self, |a, _| f32::from_bits(a.to_bits() & 0x7fff_ffff))
        }
        fn and(self, o: Self) -> Self {
            bitwise(self, o, |a, b| a & b)
        }
        fn or(self, o: Self) -> Self {
            bitwise(self, o, |a, b| a | b)
        }
        fn and_not(self, o: Self) -> Self {
            bitwise(self, o, |a, b| a & !b)
        }
        fn select(self, a: Self, b: Self) -> Self {
            a.and(self).or(b.and_not(self))
        }
        fn bits(self) -> u32 {
            let mut b = 0;
            for l in 0..LANES {
                b |= (self.0[l].to_bits() >> 31) << l;
            }
            b
        }
    }
}

/// x86-64 lanes: two SSE2 registers (the baseline) or one AVX register.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Lanes, F8};
    use std::arch::x86_64::*;

    /// Eight lanes as two SSE2 registers (every x86-64 CPU).
    #[derive(Clone, Copy)]
    pub struct Sse8(__m128, __m128);

    /// Eight lanes in one AVX register. Only built inside functions compiled with
    /// `#[target_feature(enable = "avx2")]`, which are called only when the scene's
    /// `prism_cpu::Simd` allows AVX2 (so the CPU has it).
    #[derive(Clone, Copy)]
    pub struct Avx8(__m256);

    macro_rules! sse_binop {
        ($trait:ident, $method:ident, $intr:ident) => {
            impl std::ops::$trait for Sse8 {
                type Output = Self;
                #[inline(always)]
                fn $method(self, o: Self) -> Self {
                    // SAFETY: SSE2 is part of the x86-64 baseline.
                    unsafe { Sse8($intr(self.0, o.0), $intr(self.1, o.1)) }
                }
            }
        };
    }
    sse_binop!(Add, add, _mm_add_ps);
    sse_binop!(Sub, sub, _mm_sub_ps);
    sse_binop!(Mul, mul, _mm_mul_ps);
    sse_binop!(Div, div, _mm_div_ps);

    macro_rules! sse_fn {
        ($method:ident, $intr:ident) => {
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: SSE2 is part of the x86-64 baseline.
                unsafe { Sse8($intr(self.0, o.0), $intr(self.1, o.1)) }
            }
        };
    }

    impl Lanes for Sse8 {
        #[inline(always)]
        fn splat(x: f32) -> Self {
            // SAFETY: SSE2 is part of the x86-64 baseline.
            unsafe { Sse8(_mm_set1_ps(x), _mm_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(x: &F8) -> Self {
            // SAFETY: `F8` is 32-byte aligned and holds 8 f32s, so both 16-byte aligned
            // loads are in bounds.
            unsafe { Sse8(_mm_load_ps(x.0.as_ptr()), _mm_load_ps(x.0.as_ptr().add(4))) }
        }
        #[inline(always)]
        fn store(self) -> F8 {
            let mut r = F8([0.0; 8]);
            // SAFETY: as in `load`.
            unsafe {
                _mm_store_ps(r.0.as_mut_ptr(), self.0);
                _mm_store_ps(r.0.as_mut_ptr().add(4), self.1);
            }
            r
        }
        sse_fn!(lt, _mm_cmplt_ps);
        sse_fn!(gt, _mm_cmpgt_ps);
        sse_fn!(le, _mm_cmple_ps);
        sse_fn!(eq, _mm_cmpeq_ps);
        sse_fn!(ne, _mm_cmpneq_ps);
        sse_fn!(min, _mm_min_ps);
        sse_fn!(max, _mm_max_ps);
        sse_fn!(and, _mm_and_ps);
        sse_fn!(or, _mm_or_ps);
        #[inline(always)]
        fn abs(self) -> Self {
            // SAFETY: SSE2 is part of the x86-64 baseline.
            unsafe {
                let m = _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff));
                Sse8(_mm_and_ps(self.0, m), _mm_and_ps(self.1, m))
            }
        }
        #[inline(always)]
        fn and_not(self, o: Self) -> Self {
            // SAFETY: SSE2 is part of the x86-64 baseline.
            unsafe { Sse8(_mm_andnot_ps(o.0, self.0), _mm_andnot_ps(o.1, self.1)) }
        }
        #[inline(always)]
        fn select(self, a: Self, b: Self) -> Self {
            a.and(self).or(b.and_not(self))
        }
        #[inline(always)]
        fn bits(self) -> u32 {
            // SAFETY: SSE2 is part of the x86-64 baseline.
            unsafe { (_mm_movemask_ps(self.0) | (_mm_movemask_ps(self.1) << 4)) as u32 }
        }
    }

    macro_rules! avx_binop {
        ($trait:ident, $method:ident, $intr:ident) => {
            impl std::ops::$trait for Avx8 {
                type Output = Self;
                #[inline(always)]
                fn $method(self, o: Self) -> Self {
                    // SAFETY: an `Avx8` exists only in code running on an AVX2 CPU.
                    unsafe { Avx8($intr(self.0, o.0)) }
                }
            }
        };
    }
    avx_binop!(Add, add, _mm256_add_ps);
    avx_binop!(Sub, sub, _mm256_sub_ps);
    avx_binop!(Mul, mul, _mm256_mul_ps);
    avx_binop!(Div, div, _mm256_div_ps);

    macro_rules! avx_fn {
        ($method:ident, $intr:ident) => {
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: an `Avx8` exists only in code running on an AVX2 CPU.
                unsafe { Avx8($intr(self.0, o.0)) }
            }
        };
    }
    macro_rules! avx_cmp {
        ($method:ident, $pred:ident) => {
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: an `Avx8` exists only in code running on an AVX2 CPU.
                unsafe { Avx8(_mm256_cmp_ps::<$pred>(self.0, o.0)) }
            }
        };
    }

    impl Lanes for Avx8 {
        #[inline(always)]
        fn splat(x: f32) -> Self {
            // SAFETY: an `Avx8` is built only in code running on an AVX2 CPU.
            unsafe { Avx8(_mm256_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(x: &F8) -> Self {
            // SAFETY: `F8` is 32-byte aligned and holds 8 f32s; AVX2 CPU as above.
            unsafe { Avx8(_mm256_load_ps(x.0.as_ptr())) }
        }
        #[inline(always)]
        fn store(self) -> F8 {
            let mut r = F8([0.0; 8]);
            // SAFETY: as in `load`.
            unsafe { _mm256_store_ps(r.0.as_mut_ptr(), self.0) };
            r
        }
        // Ordered predicates as Rust's `<`, `>`, `<=`, `==`; unordered `!=`.
        avx_cmp!(lt, _CMP_LT_OQ);
        avx_cmp!(gt, _CMP_GT_OQ);
        avx_cmp!(le, _CMP_LE_OQ);
        avx_cmp!(eq, _CMP_EQ_OQ);
        avx_cmp!(ne, _CMP_NEQ_UQ);
        avx_fn!(min, _mm256_min_ps);
        avx_fn!(max, _mm256_max_ps);
        avx_fn!(and, _mm256_and_ps);
        avx_fn!(or, _mm256_or_ps);
        #[inline(always)]
        fn abs(self) -> Self {
            // SAFETY: an `Avx8` exists only in code running on an AVX2 CPU.
            unsafe {
                Avx8(_mm256_and_ps(
                    self.0,
                    _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff)),
                ))
            }
        }
        #[inline(always)]
        fn and_not(self, o: Self) -> Self {
            // SAFETY: an `Avx8` exists only in code running on an AVX2 CPU.
            unsafe { Avx8(_mm256_andnot_ps(o.0, self.0)) }
        }
        #[inline(always)]
        fn select(self, a: Self, b: Self) -> Self {
            // SAFETY: an `Avx8` exists only in code running on an AVX2 CPU.
            unsafe { Avx8(_mm256_blendv_ps(b.0, a.0, self.0)) }
        }
        #[inline(always)]
        fn bits(self) -> u32 {
            // SAFETY: an `Avx8` exists only in code running on an AVX2 CPU.
            unsafe { _mm256_movemask_ps(self.0) as u32 }
        }
    }
}

#[cfg(target_arch = "x86_64")]
use x86::{Avx8, Sse8 as Baseline};

#[cfg(not(target_arch = "x86_64"))]
use portable::Scalar8 as Baseline;

/// Marks a rectangle candidate (no triangle index), as `Leaf::INSTANCE` does.
pub(crate) const NO_PRIMITIVE: u32 = u32::MAX;

/// Up to [`LANES`] world-space triangles; unused lanes hold NaN vertices, which every
/// comparison of the test rejects.
struct TriangleBatch {
    /// `p[3 * vertex + axis]`.
    p: [F8; 9],
    instance: [u32; LANES],
    primitive: [u32; LANES],
}

/// The padded world boxes of up to [`LANES`] consecutive triangle batches.
struct BoxGroup {
    lo: [F8; 3],
    hi: [F8; 3],
    /// Bit `l` set when lane `l` holds a batch.
    valid: u32,
}

/// Up to [`LANES`] rectangles with their world → object transforms; unused lanes have NaN
/// half extents, which the inside test rejects.
struct RectangleBatch {
    /// Columns of the linear part of world → object (`m[3 * column + row]`), then the
    /// translation (`m[9 + row]`).
    m: [F8; 12],
    /// The instance transform is the identity: the world ray is used as it is, as
    /// `object_ray` does.
    identity: F8,
    half_width_m: F8,
    half_height_m: F8,
    instance: [u32; LANES],
}

/// A leaf that is neither a baked triangle nor a rectangle (sphere, disk, instanced mesh):
/// tested by [`crate::Geometry`] itself, after a test of its padded world box.
pub(crate) struct OtherLeaf {
    pub lo: Vec3A,
    pub hi: Vec3A,
    pub instance: u32,
}

/// The closest triangle or rectangle hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Candidate {
    pub t: f32,
    pub instance: u32,
    /// Triangle index in the instance's mesh, or [`NO_PRIMITIVE`] for a rectangle.
    pub primitive: u32,
    /// World-space barycentrics (0 for a rectangle).
    pub b1: f32,
    pub b2: f32,
}

/// The leaves of a scene small enough to be tested all at once.
pub(crate) struct SmallScene {
    triangles: Vec<TriangleBatch>,
    groups: Vec<BoxGroup>,
    /// Batch 0 is always tested; batch `1 + LANES·g + l` has its box in lane `l` of
    /// `rectangle_groups[g]`.
    rectangles: Vec<RectangleBatch>,
    rectangle_groups: Vec<BoxGroup>,
    pub others: Vec<OtherLeaf>,
    /// The widest kernels to run (`prism_cpu::active()` at build; the AVX2 ones when it
    /// allows AVX2).
    simd: prism_cpu::Simd,
}

/// What a leaf given to [`SmallSceneBuilder`] is.
pub(crate) struct SmallSceneBuilder {
    triangles: Vec<([Vec3A; 3], u32, u32)>,
    rectangles: Vec<(Rectangle, Transform, u32)>,
    others: Vec<OtherLeaf>,
}

impl SmallSceneBuilder {
    pub fn new() -> Self {
        Self {
            triangles: Vec::new(),
            rectangles: Vec::new(),
            others: Vec::new(),
        }
    }

    /// A baked world-space triangle (`primitive` of `instance`), in leaf order.
    pub fn triangle(&mut self, p: [Vec3A; 3], instance: u32, primitive: u32) {
        self.triangles.push((p, instance, primitive));
    }

    pub fn rectangle(&mut self, r: Rectangle, to_world: Transform, instance: u32) {
        self.rectangles.push((r, to_world, instance));
    }

    /// Any other instance leaf, with its world box (min, max).
    pub fn other(&mut self, lo: Vec3A, hi: Vec3A, instance: u32) {
        let b = padded_aabb(lo, hi);
        self.others.push(OtherLeaf {
            lo: b.min,
            hi: b.max,
            instance,
        });
    }

    pub fn build(self) -> SmallScene {
        // Batches: consecutive triangles, a new batch when the current one is full, or when
        // the instance changes and the batch is at least half full (so a cuboid's 12
        // triangles get batches of their own whose box is the cuboid's, while many
        // single-triangle instances still share batches).
        let mut runs: Vec<Vec<([Vec3A; 3], u32, u32)>> = Vec::new();
        for &tri in &self.triangles {
            let start_new = match runs.last() {
                None => true,
                Some(run) => {
                    run.len() == LANES || (run[run.len() - 1].1 != tri.1 && run.len() >= LANES / 2)
                }
            };
            if start_new {
                runs.push(Vec::with_capacity(LANES));
            }
            runs.last_mut().expect("pushed above").push(tri);
        }
        let mut triangles = Vec::with_capacity(runs.len());
        let mut groups: Vec<BoxGroup> = Vec::new();
        for (i, run) in runs.iter().enumerate() {
            let mut batch = TriangleBatch {
                p: [F8::splat(f32::NAN); 9],
                instance: [0; LANES],
                primitive: [0; LANES],
            };
            let mut lo = Vec3A::splat(f32::INFINITY);
            let mut hi = Vec3A::splat(f32::NEG_INFINITY);
            for (l, &(p, instance, primitive)) in run.iter().enumerate() {
                for (v, pv) in p.iter().enumerate() {
                    for axis in 0..3 {
                        batch.p[3 * v + axis].0[l] = pv[axis];
                    }
                    lo = lo.min(*pv);
                    hi = hi.max(*pv);
                }
                batch.instance[l] = instance;
                batch.primitive[l] = primitive;
            }
            triangles.push(batch);
            push_box(&mut groups, i, lo, hi);
        }
        let ordered = rectangles_in_batch_order(self.rectangles);
        let mut rectangle_groups: Vec<BoxGroup> = Vec::new();
        for (i, chunk) in ordered.chunks(LANES).enumerate().skip(1) {
            let mut lo = Vec3A::splat(f32::INFINITY);
            let mut hi = Vec3A::splat(f32::NEG_INFINITY);
            for (r, to_world, _) in chunk {
                let (l, h) = rectangle_world_box(r, to_world);
                lo = lo.min(l);
                hi = hi.max(h);
            }
            push_box(&mut rectangle_groups, i - 1, lo, hi);
        }
        let rectangles = ordered
            .chunks(LANES)
            .map(|chunk| {
                let mut batch = RectangleBatch {
                    m: [F8::splat(0.0); 12],
                    identity: F8::splat(0.0),
                    half_width_m: F8::splat(f32::NAN),
                    half_height_m: F8::splat(f32::NAN),
                    instance: [0; LANES],
                };
                for (l, (r, to_world, instance)) in chunk.iter().enumerate() {
                    // The exact `f32`s of the stored inverse (`Mat4::from(Affine3A)` copies them).
                    let m = to_world.inverse_matrix();
                    let cols = [m.x_axis, m.y_axis, m.z_axis, m.w_axis];
                    for (c, col) in cols.iter().enumerate() {
                        for row in 0..3 {
                            batch.m[3 * c + row].0[l] = col[row];
                        }
                    }
                    batch.identity.0[l] =
                        f32::from_bits(if to_world.is_identity() { u32::MAX } else { 0 });
                    batch.half_width_m.0[l] = r.half_width_m;
                    batch.half_height_m.0[l] = r.half_height_m;
                    batch.instance[l] = *instance;
                }
                batch
            })
            .collect();
        SmallScene {
            triangles,
            groups,
            rectangles,
            rectangle_groups,
            others: self.others,
            simd: prism_cpu::active(),
        }
    }
}

/// Puts the box (min, max) of batch `i` into lane `i % LANES` of the group that holds it,
/// starting a new group at every multiple of [`LANES`]. Padded like the BVH's leaf boxes
/// (`padded_aabb`), so the slab test never culls a ray that grazes a leaf lying in a box
/// face.
fn push_box(groups: &mut Vec<BoxGroup>, i: usize, lo: Vec3A, hi: Vec3A) {
    let b = padded_aabb(lo, hi);
    let lane = i % LANES;
    if lane == 0 {
        groups.push(BoxGroup {
            lo: [F8::splat(f32::INFINITY); 3],
            hi: [F8::splat(f32::NEG_INFINITY); 3],
            valid: 0,
        });
    }
    let g = groups.last_mut().expect("pushed above");
    for axis in 0..3 {
        g.lo[axis].0[lane] = b.min[axis];
        g.hi[axis].0[lane] = b.max[axis];
    }
    g.valid |= 1 << lane;
}

/// World box of a rectangle (its four corners: the object box is flat).
fn rectangle_world_box(r: &Rectangle, to_world: &Transform) -> (Vec3A, Vec3A) {
    let (lo, hi) = r.bounds();
    to_world.bounds(lo, hi)
}

/// The rectangles in the order their batches take: up to [`LANES`] as they come; beyond,
/// the [`LANES`] largest by world area first (batch 0, tested without a box), the rest by
/// the 30-bit Morton code of their box centres, so that each later batch is compact.
fn rectangles_in_batch_order(
    mut rectangles: Vec<(Rectangle, Transform, u32)>,
) -> Vec<(Rectangle, Transform, u32)> {
    if rectangles.len() <= LANES {
        return rectangles;
    }
    let area = |(r, t, _): &(Rectangle, Transform, u32)| {
        let u = t.vector(Vec3A::new(2.0 * r.half_width_m, 0.0, 0.0));
        let v = t.vector(Vec3A::new(0.0, 2.0 * r.half_height_m, 0.0));
        u.cross(v).length()
    };
    // Largest first; equal areas keep their scene order (a stable sort).
    rectangles.sort_by(|a, b| area(b).total_cmp(&area(a)));
    let mut rest = rectangles.split_off(LANES);
    let centre = |(r, t, _): &(Rectangle, Transform, u32)| {
        let (lo, hi) = rectangle_world_box(r, t);
        (lo + hi) * 0.5
    };
    let (lo, hi) = rest.iter().map(centre).fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), c| (lo.min(c), hi.max(c)),
    );
    let extent = (hi - lo).max(Vec3A::splat(f32::MIN_POSITIVE));
    let morton = |c: Vec3A| {
        let q = ((c - lo) / extent * 1023.0).clamp(Vec3A::ZERO, Vec3A::splat(1023.0));
        obvhs::ploc::morton::morton_encode_u32(q.x as u16, q.y as u16, q.z as u16)
    };
    rest.sort_by_key(|r| morton(centre(r)));
    rectangles.extend(rest);
    rectangles
}

impl SmallScene {
    /// Closest triangle or rectangle hit in `(ray.t_min, t_max)`; `wt` is the watertight
    /// precomputation of the same ray.
    #[inline]
    pub fn closest(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        wt: &WatertightRay,
        t_max: f32,
    ) -> Option<Candidate> {
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 only on a CPU that has it.
            return unsafe { closest_avx2(self, origin, direction, wt, t_max) };
        }
        closest_kernel::<Baseline>(self, origin, direction, wt, t_max)
    }

    /// Whether a triangle or rectangle lies in `(ray.t_min, t_max)` (stops at the first
    /// batch with a hit).
    #[inline]
    pub fn any(&self, origin: Vec3A, direction: Vec3A, wt: &WatertightRay, t_max: f32) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 only on a CPU that has it.
            return unsafe { any_avx2(self, origin, direction, wt, t_max) };
        }
        any_kernel::<Baseline>(self, origin, direction, wt, t_max)
    }

    /// The same scene with the kernels of `simd` (for the tests that check every ISA's
    /// kernels agree).
    pub(crate) fn with_simd(mut self, simd: prism_cpu::Simd) -> Self {
        self.simd = simd;
        self
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn closest_avx2(
    s: &SmallScene,
    origin: Vec3A,
    direction: Vec3A,
    wt: &WatertightRay,
    t_max: f32,
) -> Option<Candidate> {
    closest_kernel::<Avx8>(s, origin, direction, wt, t_max)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn any_avx2(
    s: &SmallScene,
    origin: Vec3A,
    direction: Vec3A,
    wt: &WatertightRay,
    t_max: f32,
) -> bool {
    any_kernel::<Avx8>(s, origin, direction, wt, t_max)
}

/// Per-ray constants, broadcast to every lane.
#[derive(Clone, Copy)]
struct RayConsts<L> {
    o: [L; 3],
    d: [L; 3],
    /// Safe reciprocal direction of the slab test (`bvh_ray`: ±10¹⁸ for zero components).
    inv: [L; 3],
    shear_x: [L; 3],
    shear_y: [L; 3],
    pick_z: [L; 3],
    sz: L,
    t_min: L,
    t_max: L,
}

impl<L: Lanes> RayConsts<L> {
    #[inline(always)]
    fn new(origin: Vec3A, direction: Vec3A, wt: &WatertightRay, t_max: f32) -> Self {
        let inv = bvh_ray(origin, direction, wt.t_min, t_max).inv_direction;
        let v = |v: Vec3A| [L::splat(v.x), L::splat(v.y), L::splat(v.z)];
        Self {
            o: v(origin),
            d: v(direction),
            inv: v(inv),
            shear_x: v(wt.shear_x),
            shear_y: v(wt.shear_y),
            pick_z: v(wt.pick_z),
            sz: L::splat(wt.sz),
            t_min: L::splat(wt.t_min),
            t_max: L::splat(t_max),
        }
    }
}

/// Per-lane best hit so far; `key` is the order key of the leaf (see `closest_kernel`) as
/// an `f32` (exact below 2²⁴), +∞ while the lane has none.
#[derive(Clone, Copy)]
struct Best<L> {
    t: L,
    key: L,
    b1: L,
    b2: L,
}

impl<L: Lanes> Best<L> {
    #[inline(always)]
    fn update(&mut self, ok: L, t: L, key: L, b1: L, b2: L) {
        let take = ok.and(t.lt(self.t));
        self.t = take.select(t, self.t);
        self.key = take.select(key, self.key);
        self.b1 = take.select(b1, self.b1);
        self.b2 = take.select(b2, self.b2);
    }
}

/// Bit `l` set for each lane whose box the ray enters within `(t_min, t_max)`; the slab
/// test of obvhs' nodes, on padded boxes and with the BVH's reciprocal direction.
#[inline(always)]
fn box_mask<L: Lanes>(g: &BoxGroup, r: &RayConsts<L>, t_max: f32) -> u32 {
    let mut near = r.t_min;
    let mut far = L::splat(t_max);
    for axis in 0..3 {
        let t0 = (L::load(&g.lo[axis]) - r.o[axis]) * r.inv[axis];
        let t1 = (L::load(&g.hi[axis]) - r.o[axis]) * r.inv[axis];
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    near.le(far).bits() & g.valid
}

/// The watertight test of [`WatertightRay::intersect`] on every lane of `b` within
/// `(t_min, t_max)`: the mask of lanes that hit, `t`, `b1`, `b2`, and the bits of lanes with
/// an edge function exactly 0 (left to the scalar test, which recomputes them in f64).
#[inline(always)]
fn triangle_lanes<L: Lanes>(b: &TriangleBatch, r: &RayConsts<L>) -> (L, L, L, L, u32) {
    // Vertices relative to the origin (`p - origin`), then `m * shear` of the scalar test:
    // ((x·s.x) + (y·s.y)) + (z·s.z), exactly.
    let rel = |v: usize| {
        [
            L::load(&b.p[3 * v]) - r.o[0],
            L::load(&b.p[3 * v + 1]) - r.o[1],
            L::load(&b.p[3 * v + 2]) - r.o[2],
        ]
    };
    let (a, bb, c) = (rel(0), rel(1), rel(2));
    let sh = |v: &[L; 3], s: &[L; 3]| (v[0] * s[0] + v[1] * s[1]) + v[2] * s[2];
    let (xa, xb, xc) = (sh(&a, &r.shear_x), sh(&bb, &r.shear_x), sh(&c, &r.shear_x));
    let (ya, yb, yc) = (sh(&a, &r.shear_y), sh(&bb, &r.shear_y), sh(&c, &r.shear_y));
    let (za, zb, zc) = (sh(&a, &r.pick_z), sh(&bb, &r.pick_z), sh(&c, &r.pick_z));
    // Edge functions (paper eq. 4), plain products.
    let u = xc * yb - yc * xb;
    let v = xa * yc - ya * xc;
    let w = xb * ya - yb * xa;
    let zero8 = L::splat(0.0);
    let zero = u.eq(zero8).or(v.eq(zero8)).or(w.eq(zero8));
    let neg = u.lt(zero8).or(v.lt(zero8)).or(w.lt(zero8));
    let pos = u.gt(zero8).or(v.gt(zero8)).or(w.gt(zero8));
    // glam's `element_sum`: (u + v) + (w + 0).
    let det = (u + v) + (w + zero8);
    // glam's `dot`: (u·za + v·zb) + w·zc.
    let t_scaled = ((u * za + v * zb) + w * zc) * r.sz;
    let lo = r.t_min * det;
    let hi = r.t_max * det;
    let inside = det
        .gt(zero8)
        .and(t_scaled.gt(lo))
        .and(t_scaled.lt(hi))
        .or(det.lt(zero8).and(t_scaled.lt(lo)).and(t_scaled.gt(hi)));
    let inv_det = L::splat(1.0) / det;
    let t = t_scaled * inv_det;
    let ok = inside
        .and(t.gt(r.t_min))
        .and(t.lt(r.t_max))
        .and_not(zero)
        .and_not(neg.and(pos));
    (ok, t, v * inv_det, w * inv_det, zero.bits())
}

/// [`Rectangle::intersect`] on every lane of `b`, in each lane's object space, within
/// `(t_min, t_max)`: the mask of lanes that hit, and `t`.
#[inline(always)]
fn rectangle_lanes<L: Lanes>(b: &RectangleBatch, r: &RayConsts<L>) -> (L, L) {
    let m = |i: usize| L::load(&b.m[i]);
    // glam's `Mat3A * v`: ((x_axis·v.x) + (y_axis·v.y)) + (z_axis·v.z), then
    // `+ translation` for a point; the world ray itself for identity instances.
    let lin = |v: &[L; 3], row: usize| (m(row) * v[0] + m(3 + row) * v[1]) + m(6 + row) * v[2];
    let id = L::load(&b.identity);
    let ox = id.select(r.o[0], lin(&r.o, 0) + m(9));
    let oy = id.select(r.o[1], lin(&r.o, 1) + m(10));
    let oz = id.select(r.o[2], lin(&r.o, 2) + m(11));
    let dx = id.select(r.d[0], lin(&r.d, 0));
    let dy = id.select(r.d[1], lin(&r.d, 1));
    let dz = id.select(r.d[2], lin(&r.d, 2));
    let zero8 = L::splat(0.0);
    // `-oz / dz`: negation is exact, so `0 - oz` differs only for oz = +0 (giving +0 where
    // `-oz` gives -0), and then t = ±0 is rejected by `t > t_min` for any t_min ≥ 0 either way.
    let t = (zero8 - oz) / dz;
    let (px, py) = (ox + t * dx, oy + t * dy);
    let ok = dz
        .ne(zero8)
        .and(t.gt(r.t_min))
        .and(t.lt(r.t_max))
        .and(px.abs().le(L::load(&b.half_width_m)))
        .and(py.abs().le(L::load(&b.half_height_m)));
    (ok, t)
}

/// The scalar watertight test of lane `l` of `b` (for lanes with a zero edge function).
#[inline(always)]
fn scalar_lane(b: &TriangleBatch, l: usize, wt: &WatertightRay, t_max: f32) -> Option<TriangleHit> {
    let v = |k: usize| Vec3A::new(b.p[3 * k].0[l], b.p[3 * k + 1].0[l], b.p[3 * k + 2].0[l]);
    wt.intersect(v(0), v(1), v(2), t_max)
}

/// Lane numbers 0..8 as `f32`.
static LANE_INDEX: F8 = F8([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);

/// `base + l` for each lane `l`, as `f32` keys (exact: `base` stays far below 2²⁴).
#[inline(always)]
fn keys<L: Lanes>(base: usize) -> L {
    L::splat(base as f32) + L::load(&LANE_INDEX)
}

/// Closest hit over all batches. Order keys: triangle lane `l` of batch `i` is `8·i + l`,
/// rectangle lanes follow; the lowest key wins a tie of equal `t` across lanes.
#[inline(always)]
fn closest_kernel<L: Lanes>(
    s: &SmallScene,
    origin: Vec3A,
    direction: Vec3A,
    wt: &WatertightRay,
    t_max: f32,
) -> Option<Candidate> {
    let r = RayConsts::<L>::new(origin, direction, wt, t_max);
    let inf = L::splat(f32::INFINITY);
    let zero8 = L::splat(0.0);
    let mut best = Best {
        t: inf,
        key: inf,
        b1: zero8,
        b2: zero8,
    };
    let rect_base = s.triangles.len() * LANES;
    // Rectangles first: in a room they bound the ray early, so that boxes behind a wall
    // are skipped. Batch 0 (the largest) always; the others where the ray meets their box
    // before the closest hit so far.
    if let Some(rb) = s.rectangles.first() {
        let (ok, t) = rectangle_lanes(rb, &r);
        best.update(ok, t, keys(rect_base), zero8, zero8);
    }
    for (gi, g) in s.rectangle_groups.iter().enumerate() {
        let bound = min_lane(&best.t.store()).min(t_max);
        let mut mask = box_mask(g, &r, bound);
        while mask != 0 {
            let j = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let bi = 1 + gi * LANES + j;
            let (ok, t) = rectangle_lanes(&s.rectangles[bi], &r);
            best.update(ok, t, keys(rect_base + bi * LANES), zero8, zero8);
        }
    }
    // Lanes with a zero edge function, tested by the scalar code: (t, key, b1, b2).
    let mut extra: Option<(f32, f32, f32, f32)> = None;
    for (gi, g) in s.groups.iter().enumerate() {
        let bound = min_lane(&best.t.store()).min(t_max);
        let mut mask = box_mask(g, &r, bound);
        while mask != 0 {
            let j = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let bi = gi * LANES + j;
            let b = &s.triangles[bi];
            let (ok, t, b1, b2, mut zero) = triangle_lanes(b, &r);
            best.update(ok, t, keys(bi * LANES), b1, b2);
            while zero != 0 {
                let l = zero.trailing_zeros() as usize;
                zero &= zero - 1;
                if let Some(h) = scalar_lane(b, l, wt, t_max) {
                    let key = (bi * LANES + l) as f32;
                    if extra.is_none_or(|(t0, k0, _, _)| h.t < t0 || (h.t == t0 && key < k0)) {
                        extra = Some((h.t, key, h.b1, h.b2));
                    }
                }
            }
        }
    }
    // Reduction: the smallest `t`, then among lanes at exactly that `t` the lowest key (a
    // tie needs the loop; one lane is the rule).
    let bt = best.t.store();
    let t_best = min_lane(&bt);
    let mut win = extra;
    let mut at_best = best.t.eq(L::splat(t_best)).bits();
    if t_best < f32::INFINITY {
        let (bk, bb1, bb2) = (best.key.store(), best.b1.store(), best.b2.store());
        while at_best != 0 {
            let l = at_best.trailing_zeros() as usize;
            at_best &= at_best - 1;
            let c = (bt.0[l], bk.0[l], bb1.0[l], bb2.0[l]);
            if win.is_none_or(|(t0, k0, _, _)| c.0 < t0 || (c.0 == t0 && c.1 < k0)) {
                win = Some(c);
            }
        }
    }
    let (t, key, b1, b2) = win?;
    let key = key as usize;
    let (batch, lane) = (key / LANES, key % LANES);
    Some(if key >= rect_base {
        Candidate {
            t,
            instance: s.rectangles[batch - s.triangles.len()].instance[lane],
            primitive: NO_PRIMITIVE,
            b1: 0.0,
            b2: 0.0,
        }
    } else {
        let b = &s.triangles[batch];
        Candidate {
            t,
            instance: b.instance[lane],
            primitive: b.primitive[lane],
            b1,
            b2,
        }
    })
}

/// The smallest lane (all lanes are numbers or +∞).
#[inline(always)]
fn min_lane(t: &F8) -> f32 {
    let mut m = t.0[0];
    for &x in &t.0[1..] {
        m = if x < m { x } else { m };
    }
    m
}

/// Whether any triangle or rectangle is hit in `(t_min, t_max)`. Triangles first: in a room
/// the occluders of a shadow ray are the objects inside it, rarely the walls.
#[inline(always)]
fn any_kernel<L: Lanes>(
    s: &SmallScene,
    origin: Vec3A,
    direction: Vec3A,
    wt: &WatertightRay,
    t_max: f32,
) -> bool {
    let r = RayConsts::<L>::new(origin, direction, wt, t_max);
    for (gi, g) in s.groups.iter().enumerate() {
        let mut mask = box_mask(g, &r, t_max);
        while mask != 0 {
            let j = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let b = &s.triangles[gi * LANES + j];
            let (ok, _, _, _, mut zero) = triangle_lanes(b, &r);
            if ok.bits() != 0 {
                return true;
            }
            while zero != 0 {
                let l = zero.trailing_zeros() as usize;
                zero &= zero - 1;
                if scalar_lane(b, l, wt, t_max).is_some() {
                    return true;
                }
            }
        }
    }
    if let Some(rb) = s.rectangles.first() {
        if rectangle_lanes(rb, &r).0.bits() != 0 {
            return true;
        }
    }
    s.rectangle_groups.iter().enumerate().any(|(gi, g)| {
        let mut mask = box_mask(g, &r, t_max);
        while mask != 0 {
            let j = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if rectangle_lanes(&s.rectangles[1 + gi * LANES + j], &r)
                .0
                .bits()
                != 0
            {
                return true;
            }
        }
        false
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane of the batch tests rounds exactly as the scalar tests it replaces:
    /// `WatertightRay::intersect` for triangles, `Rectangle::intersect` in the object space
    /// of `object_ray` for rectangles (same `t` bits, same hit or miss).
    #[test]
    fn lanes_round_exactly_as_the_scalar_tests() {
        use crate::ray::Ray;
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(21);
        let v = |rng: &mut rand_pcg::Pcg64| {
            Vec3A::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
        };
        let tris: Vec<[Vec3A; 3]> = (0..8)
            .map(|_| [v(&mut rng), v(&mut rng), v(&mut rng)])
            .collect();
        let rects: Vec<(Rectangle, Transform)> = (0..8)
            .map(|i| {
                let t = Transform::translate(v(&mut rng))
                    .compose(&Transform::rotate(v(&mut rng), i as f32 + 0.3).unwrap())
                    .compose(&Transform::scale(Vec3A::new(1.0, 2.0, 0.5)).unwrap());
                let r = Rectangle {
                    half_width_m: 0.5,
                    half_height_m: 0.3,
                };
                (r, if i == 2 { Transform::IDENTITY } else { t })
            })
            .collect();
        let mut b = SmallSceneBuilder::new();
        for (i, &p) in tris.iter().enumerate() {
            b.triangle(p, 0, i as u32);
        }
        for (i, &(r, t)) in rects.iter().enumerate() {
            b.rectangle(r, t, i as u32);
        }
        let s = b.build();
        let (mut tri_hits, mut rect_hits) = (0, 0);
        for _ in 0..20_000 {
            let (o, d) = (2.0 * v(&mut rng), v(&mut rng));
            let t_max = if rng.gen_bool(0.5) {
                f32::INFINITY
            } else {
                rng.gen_range(0.1..3.0)
            };
            let wt = WatertightRay::new(o, d, 1e-3);
            let r = RayConsts::<Baseline>::new(o, d, &wt, t_max);
            let (ok, t, b1, b2, zero) = triangle_lanes(&s.triangles[0], &r);
            let (ok, t, b1, b2) = (ok.bits(), t.store(), b1.store(), b2.store());
            for (l, p) in tris.iter().enumerate() {
                if zero & (1 << l) != 0 {
                    continue;
                }
                let h = wt.intersect(p[0], p[1], p[2], t_max);
                assert_eq!(h.is_some(), ok & (1 << l) != 0, "{o:?} {d:?} lane {l}");
                if let Some(h) = h {
                    tri_hits += 1;
                    assert_eq!(
                        (h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()),
                        (t.0[l].to_bits(), b1.0[l].to_bits(), b2.0[l].to_bits())
                    );
                }
            }
            let (ok, t) = rectangle_lanes(&s.rectangles[0], &r);
            let (ok, t) = (ok.bits(), t.store());
            for (l, (rect, to_world)) in rects.iter().enumerate() {
                let (oo, od) = if to_world.is_identity() {
                    (o, d)
                } else {
                    (to_world.inverse_point(o), to_world.inverse_vector(d))
                };
                let h = rect.intersect(&Ray::new(oo, od, 1e-3, t_max));
                assert_eq!(h.is_some(), ok & (1 << l) != 0, "{o:?} {d:?} lane {l}");
                if let Some(h) = h {
                    rect_hits += 1;
                    assert_eq!(h.to_bits(), t.0[l].to_bits());
                }
            }
        }
        assert!(
            tri_hits > 1000 && rect_hits > 1000,
            "{tri_hits} {rect_hits}"
        );
    }

    /// Every ISA's kernels give the baseline kernels' answers bit for bit (each ISA the
    /// machine runs, `prism_cpu::each_isa`; the others are reported as skipped).
    #[test]
    fn every_isa_gives_the_baseline_kernels_bits() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        fn v(rng: &mut rand_pcg::Pcg64) -> Vec3A {
            Vec3A::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
        }
        let build = |tris: &[[Vec3A; 3]], rects: &[(Transform, f32)]| {
            let mut b = SmallSceneBuilder::new();
            for (i, &p) in tris.iter().enumerate() {
                b.triangle(p, (i / 5) as u32, i as u32);
            }
            for (i, &(t, hw)) in rects.iter().enumerate() {
                b.rectangle(
                    Rectangle {
                        half_width_m: hw,
                        half_height_m: 0.5 * hw,
                    },
                    t,
                    100 + i as u32,
                );
            }
            b.build()
        };
        let tris: Vec<[Vec3A; 3]> = (0..37)
            .map(|_| [v(&mut rng), v(&mut rng), v(&mut rng)])
            .collect();
        let rects: Vec<(Transform, f32)> = (0..11)
            .map(|i| {
                let t = Transform::translate(v(&mut rng))
                    .compose(&Transform::rotate(v(&mut rng), i as f32).unwrap())
                    .compose(&Transform::scale(Vec3A::new(1.0, 2.0, 0.5)).unwrap());
                (if i == 3 { Transform::IDENTITY } else { t }, 0.4)
            })
            .collect();
        let base = build(&tris, &rects).with_simd(prism_cpu::Simd::SCALAR);
        let wide: Vec<(prism_cpu::Simd, SmallScene)> = prism_cpu::each_isa()
            .into_iter()
            .map(|simd| (simd, build(&tris, &rects).with_simd(simd)))
            .collect();
        let key = |c: Option<Candidate>| {
            c.map(|c| {
                (
                    c.t.to_bits(),
                    c.instance,
                    c.primitive,
                    c.b1.to_bits(),
                    c.b2.to_bits(),
                )
            })
        };
        for _ in 0..20_000 {
            let (o, d) = (2.0 * v(&mut rng), v(&mut rng));
            let wt = WatertightRay::new(o, d, 1e-4);
            let t_max = if rng.gen_bool(0.5) {
                f32::INFINITY
            } else {
                rng.gen_range(0.1..3.0)
            };
            let want = base.closest(o, d, &wt, t_max);
            let want_any = base.any(o, d, &wt, t_max);
            assert_eq!(want.is_some(), want_any);
            for (simd, scene) in &wide {
                let got = scene.closest(o, d, &wt, t_max);
                assert_eq!(key(got), key(want), "{simd} {o:?} {d:?}");
                assert_eq!(scene.any(o, d, &wt, t_max), want_any, "{simd} {o:?} {d:?}");
            }
        }
    }
}
