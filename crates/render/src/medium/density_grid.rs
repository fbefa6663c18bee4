//! The density of a grid medium: voxels over a box, looked up trilinearly, with a coarse
//! grid of majorants and the 3-D DDA that walks a ray through it (pbrt-v4 `GridMedium`,
//! `MajorantGrid`, `DDAMajorantIterator`). Densities are unitless scales of the medium's σ.
//!
//! Lookup convention: voxel values sit at voxel centres, (i + ½)/res of the box on each
//! axis (pbrt-v4 `SampledGrid`, Mitsuba 3 `gridvolume`), and in the half voxel between the
//! outermost centres and the box's faces the edge value is held (clamp to edge, as Mitsuba
//! 3's texture lookup; pbrt-v4 instead fades to 0 there). Clamping keeps a constant grid
//! constant over its whole box, so it equals a homogeneous medium of the same σ (issue 20
//! test 4). Outside the box the density is 0.

use glam::{Vec3, Vec3A};
use prism_geometry::Ray;

/// Majorant cells per axis (pbrt-v4's 16³).
pub const MAJORANT_RES: usize = 16;

/// A scalar density grid over `bounds_min_m`..`bounds_max_m`.
#[derive(Clone, Debug)]
pub struct DensityGrid {
    resolution: [usize; 3],
    bounds_min_m: Vec3A,
    extent_m: Vec3A,
    values: Vec<f32>,
    /// Max density per majorant cell, x fastest.
    majorants: Vec<f32>,
}

/// One stretch of a ray inside one majorant cell: density ≤ `majorant` on [t_min, t_max].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MajorantSegment {
    pub t_min: f32,
    pub t_max: f32,
    pub majorant: f32,
}

impl DensityGrid {
    /// A grid of `values` (x fastest, finite, ≥ 0) over the box; `None` when the value
    /// count is not the product of `resolution`, an axis is empty or the box is degenerate.
    pub fn new(
        resolution: [usize; 3],
        bounds_min_m: Vec3,
        bounds_max_m: Vec3,
        values: Vec<f32>,
    ) -> Option<Self> {
        let count = resolution.iter().product::<usize>();
        let valid = resolution.iter().all(|&r| r >= 1)
            && values.len() == count
            && values.iter().all(|v| v.is_finite() && *v >= 0.0)
            && bounds_min_m.is_finite()
            && bounds_max_m.is_finite()
            && bounds_min_m.cmplt(bounds_max_m).all();
        if !valid {
            return None;
        }
        let mut grid = Self {
            resolution,
            bounds_min_m: bounds_min_m.into(),
            extent_m: (bounds_max_m - bounds_min_m).into(),
            values,
            majorants: Vec::new(),
        };
        grid.majorants = grid.build_majorants();
        Some(grid)
    }

    /// The grid a `.vol` file holds, over `bounds_m` when given, else the file's box.
    pub fn from_vol(vol: super::vol_file::VolGrid, bounds_m: Option<(Vec3, Vec3)>) -> Option<Self> {
        let (min, max) = bounds_m.unwrap_or((vol.bounds_min_m, vol.bounds_max_m));
        Self::new(vol.resolution, min, max, vol.values)
    }

    #[inline]
    fn voxel(&self, x: usize, y: usize, z: usize) -> f32 {
        let [nx, ny, _] = self.resolution;
        self.values[(z * ny + y) * nx + x]
    }

    /// Density at `p_m`: trilinear over voxel centres, edge values held up to the box's
    /// faces, 0 outside the box.
    pub fn density(&self, p_m: Vec3A) -> f32 {
        let u = (p_m - self.bounds_min_m) / self.extent_m;
        if !(u.cmpge(Vec3A::ZERO).all() && u.cmple(Vec3A::ONE).all()) {
            return 0.0;
        }
        // Per axis: the two voxels around the point and the weight of the upper one.
        let axis = |a: usize| {
            let n = self.resolution[a];
            let s = u[a] * n as f32 - 0.5;
            let i0 = s.floor();
            let f = s - i0;
            let clamp = |i: f32| (i.max(0.0) as usize).min(n - 1);
            (clamp(i0), clamp(i0 + 1.0), f)
        };
        let ((x0, x1, fx), (y0, y1, fy), (z0, z1, fz)) = (axis(0), axis(1), axis(2));
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let plane = |z: usize| {
            lerp(
                lerp(self.voxel(x0, y0, z), self.voxel(x1, y0, z), fx),
                lerp(self.voxel(x0, y1, z), self.voxel(x1, y1, z), fx),
                fy,
            )
        };
        lerp(plane(z0), plane(z1), fz)
    }

    /// The inclusive voxel range whose trilinear support reaches [a, b] (fractions of the
    /// box) on one axis. Widened by 10⁻³ voxel so a point that rounding puts just outside
    /// a majorant cell still finds its voxels there.
    fn voxel_range(&self, axis: usize, a: f32, b: f32) -> (usize, usize) {
        let n = self.resolution[axis];
        let lo = (a * n as f32 - 0.5 - 1e-3).floor().max(0.0) as usize;
        let hi = ((b * n as f32 - 0.5 + 1e-3).floor() + 1.0).max(0.0) as usize;
        (lo.min(n - 1), hi.min(n - 1))
    }

    /// Max over every voxel a point of the cell can interpolate from: trilinear weights
    /// are ≥ 0 and sum to 1, so that max bounds the density anywhere in the cell.
    fn build_majorants(&self) -> Vec<f32> {
        let m = MAJORANT_RES;
        let cell = |i: usize| (i as f32 / m as f32, (i + 1) as f32 / m as f32);
        let mut out = Vec::with_capacity(m * m * m);
        for k in 0..m {
            let (z0, z1) = self.voxel_range(2, cell(k).0, cell(k).1);
            for j in 0..m {
                let (y0, y1) = self.voxel_range(1, cell(j).0, cell(j).1);
                for i in 0..m {
                    let (x0, x1) = self.voxel_range(0, cell(i).0, cell(i).1);
                    let mut max = 0.0f32;
                    for z in z0..=z1 {
                        for y in y0..=y1 {
                            for x in x0..=x1 {
                                max = max.max(self.voxel(x, y, z));
                            }
                        }
                    }
                    out.push(max);
                }
            }
        }
        out
    }

    /// The majorant of cell (i, j, k).
    #[inline]
    pub fn majorant(&self, cell: [usize; 3]) -> f32 {
        let m = MAJORANT_RES;
        self.majorants[(cell[2] * m + cell[1]) * m + cell[0]]
    }

    /// Voxels along x, y, z.
    pub fn resolution(&self) -> [usize; 3] {
        self.resolution
    }

    /// The grid's box (min, max), metres: the density is 0 outside it.
    pub fn bounds_m(&self) -> (Vec3A, Vec3A) {
        (self.bounds_min_m, self.bounds_min_m + self.extent_m)
    }

    /// The largest density anywhere (the max voxel).
    pub fn max_density(&self) -> f32 {
        self.values.iter().copied().fold(0.0, f32::max)
    }

    /// Walks `ray` over [t_min, t_max] through the majorant cells it crosses inside the
    /// box, in order. The segments tile the ray's overlap with the box: each starts where
    /// the previous one ended, the first at the box entry, the last at the exit.
    pub fn majorant_segments(&self, ray: &Ray) -> MajorantIter<'_> {
        MajorantIter::new(self, ray)
    }
}

/// pbrt-v4's `DDAMajorantIterator` over a `DensityGrid`'s majorant cells (Amanatides &
/// Woo 1987), in the box's unit-cube coordinates where t is the ray's own parameter.
#[derive(Clone, Debug)]
pub struct MajorantIter<'a> {
    grid: &'a DensityGrid,
    t_min: f32,
    t_max: f32,
    cell: [i32; 3],
    step: [i32; 3],
    /// The cell index past the grid on each axis (−1 or MAJORANT_RES).
    exit: [i32; 3],
    next_crossing_t: [f32; 3],
    delta_t: [f32; 3],
}

impl<'a> MajorantIter<'a> {
    fn new(grid: &'a DensityGrid, ray: &Ray) -> Self {
        let o = (ray.origin - grid.bounds_min_m) / grid.extent_m;
        let d = ray.direction / grid.extent_m;
        // Slab clip of [t_min, t_max] against the unit cube.
        let (mut t0, mut t1) = (ray.t_min, ray.t_max);
        for a in 0..3 {
            if d[a] == 0.0 {
                if !(0.0..=1.0).contains(&o[a]) {
                    t1 = f32::NEG_INFINITY; // parallel to the slab, outside it
                }
                continue;
            }
            let (near, far) = {
                let (ta, tb) = ((0.0 - o[a]) / d[a], (1.0 - o[a]) / d[a]);
                (ta.min(tb), ta.max(tb))
            };
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        let m = MAJORANT_RES as i32;
        let mut it = Self {
            grid,
            t_min: t0,
            t_max: t1,
            cell: [0; 3],
            step: [0; 3],
            exit: [0; 3],
            next_crossing_t: [f32::INFINITY; 3],
            delta_t: [0.0; 3],
        };
        // Empty overlap (or a NaN bound): yields nothing.
        if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) {
            it.t_max = it.t_min;
            return it;
        }
        let p = o + d * t0;
        for a in 0..3 {
            let c = ((p[a] * m as f32) as i32).clamp(0, m - 1);
            it.cell[a] = c;
            // d = −0 must walk like 0, not step down (pbrt-v4 normalises it the same way).
            if d[a] > 0.0 {
                it.step[a] = 1;
                it.exit[a] = m;
                it.next_crossing_t[a] = t0 + ((c + 1) as f32 / m as f32 - p[a]) / d[a];
                it.delta_t[a] = 1.0 / (m as f32 * d[a]);
            } else if d[a] < 0.0 {
                it.step[a] = -1;
                it.exit[a] = -1;
                it.next_crossing_t[a] = t0 + (c as f32 / m as f32 - p[a]) / d[a];
                it.delta_t[a] = -1.0 / (m as f32 * d[a]);
            } else {
                it.exit[a] = -1; // never reached: step 0, crossing at ∞
            }
        }
        it
    }
}

impl Iterator for MajorantIter<'_> {
    type Item = MajorantSegment;

    fn next(&mut self) -> Option<MajorantSegment> {
        // A crossing that rounding puts at the current t gives an empty stretch: step past
        // it (contiguity holds, as it ends where it starts).
        while self.t_min < self.t_max {
            let c = self.next_crossing_t;
            let axis = if c[0] < c[1] {
                if c[0] < c[2] {
                    0
                } else {
                    2
                }
            } else if c[1] < c[2] {
                1
            } else {
                2
            };
            let leaves_grid = self.cell[axis] + self.step[axis] == self.exit[axis];
            // The last cell runs to the clipped exit, so rounding between the slab clip and
            // the crossings can leave neither a gap nor an overlap at the end.
            let t_exit = if leaves_grid {
                self.t_max
            } else {
                self.t_max.min(c[axis])
            };
            let segment = MajorantSegment {
                t_min: self.t_min,
                t_max: t_exit,
                majorant: self.grid.majorant(self.cell.map(|i| i as usize)),
            };
            self.t_min = t_exit;
            if !leaves_grid && c[axis] < self.t_max {
                self.cell[axis] += self.step[axis];
                self.next_crossing_t[axis] += self.delta_t[axis];
            }
            if segment.t_max > segment.t_min {
                return Some(segment);
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic uniform variates for the tests (SplitMix64).
    struct Rng(u64);
    impl Rng {
        fn next_f32(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }
        fn vec3(&mut self, lo: f32, hi: f32) -> Vec3A {
            Vec3A::new(self.next_f32(), self.next_f32(), self.next_f32()) * (hi - lo)
                + Vec3A::splat(lo)
        }
    }

    fn random_grid(res: [usize; 3], seed: u64) -> DensityGrid {
        let mut rng = Rng(seed);
        let n = res.iter().product();
        // Sparse spikes over a low floor: majorants that are wrong by one voxel show.
        let values = (0..n)
            .map(|_| {
                let u = rng.next_f32();
                if u < 0.1 {
                    10.0 * rng.next_f32()
                } else {
                    0.1 * u
                }
            })
            .collect();
        DensityGrid::new(
            res,
            Vec3::new(-1.0, 0.0, -0.5),
            Vec3::new(1.0, 2.0, 1.5),
            values,
        )
        .unwrap()
    }

    #[test]
    fn trilinear_is_exact_on_a_linear_ramp() {
        // v = 6 + 2x + 3y − 0.5z at voxel centres, box [0,4]×[0,3]×[0,5] m, 1 m voxels.
        let res = [4, 3, 5];
        let f = |p: Vec3A| 6.0 + 2.0 * p.x + 3.0 * p.y - 0.5 * p.z;
        let mut values = Vec::new();
        for z in 0..5 {
            for y in 0..3 {
                for x in 0..4 {
                    values.push(f(Vec3A::new(
                        x as f32 + 0.5,
                        y as f32 + 0.5,
                        z as f32 + 0.5,
                    )));
                }
            }
        }
        let g = DensityGrid::new(res, Vec3::ZERO, Vec3::new(4.0, 3.0, 5.0), values).unwrap();
        let mut rng = Rng(7);
        for _ in 0..10_000 {
            // Inside the hull of the centres the ramp is reproduced exactly.
            let p = Vec3A::new(0.5, 0.5, 0.5) + rng.vec3(0.0, 1.0) * Vec3A::new(3.0, 2.0, 4.0);
            assert!(
                (g.density(p) - f(p)).abs() < 1e-4,
                "{p}: {} vs {}",
                g.density(p),
                f(p)
            );
        }
        // Between the outer centres and the faces the edge value is held.
        let edge = g.density(Vec3A::new(0.1, 1.5, 2.5));
        assert!((edge - f(Vec3A::new(0.5, 1.5, 2.5))).abs() < 1e-4);
        // Outside the box: 0.
        assert_eq!(g.density(Vec3A::new(-0.01, 1.0, 1.0)), 0.0);
        assert_eq!(g.density(Vec3A::new(1.0, 3.01, 1.0)), 0.0);
    }

    #[test]
    fn majorants_bound_the_density_everywhere() {
        for (res, seed) in [([5, 7, 3], 1), ([40, 33, 17], 2), ([1, 1, 1], 3)] {
            let g = random_grid(res, seed);
            let mut rng = Rng(seed + 100);
            for _ in 0..100_000 {
                let p = rng.vec3(0.0, 1.0);
                let p_m = g.bounds_min_m + p * g.extent_m;
                let cell = (p * MAJORANT_RES as f32)
                    .to_array()
                    .map(|c| (c as usize).min(MAJORANT_RES - 1));
                assert!(
                    g.density(p_m) <= g.majorant(cell),
                    "{res:?} at {p_m}: density {} > majorant {}",
                    g.density(p_m),
                    g.majorant(cell)
                );
            }
            // Conservative but not loose: no majorant exceeds the largest voxel.
            assert!(g.majorants.iter().all(|&m| m <= g.max_density()));
        }
    }

    #[test]
    fn dda_segments_tile_the_overlap_and_bound_the_density() {
        let g = random_grid([23, 9, 31], 5);
        let mut rng = Rng(11);
        let mut segments_seen = 0;
        for n in 0..2000 {
            let origin = rng.vec3(-3.0, 3.0);
            let target = rng.vec3(-1.0, 2.0);
            let mut direction = (target - origin) * (0.2 + 2.0 * rng.next_f32());
            // Axis-parallel rays (one or two direction components 0, one −0) too.
            if n % 7 == 0 {
                direction.x = 0.0;
            }
            if n % 11 == 0 {
                direction.y = -0.0;
            }
            if direction == Vec3A::ZERO {
                continue;
            }
            let (t_min, t_max) = if n % 3 == 0 {
                (0.0, f32::INFINITY)
            } else if n % 5 == 0 {
                // Negative t too: the parallel-and-outside case must stay empty there.
                (-2.0, 0.5)
            } else {
                (0.3 * rng.next_f32(), 0.5 + rng.next_f32())
            };
            let ray = Ray::new(origin, direction, t_min, t_max);
            // The overlap of [t_min, t_max] with the box, by a slab test in world space
            // (the iterator clips in the box's unit-cube coordinates).
            let lo = (g.bounds_min_m - origin) / direction;
            let hi = (g.bounds_min_m + g.extent_m - origin) / direction;
            let mut enter = t_min;
            let mut leave = t_max;
            for a in 0..3 {
                if direction[a] == 0.0 {
                    let o = origin[a];
                    if o < g.bounds_min_m[a] || o > g.bounds_min_m[a] + g.extent_m[a] {
                        leave = f32::NEG_INFINITY;
                    }
                } else {
                    enter = enter.max(lo[a].min(hi[a]));
                    leave = leave.min(lo[a].max(hi[a]));
                }
            }
            let segs: Vec<_> = g.majorant_segments(&ray).collect();
            if enter >= leave {
                assert!(segs.is_empty(), "ray {n} misses the box but got {segs:?}");
                continue;
            }
            assert!(
                !segs.is_empty(),
                "ray {n}: no segments over [{enter}, {leave}]"
            );
            let tol = 1e-5 * leave.abs().max(1.0);
            assert!(
                (segs[0].t_min - enter).abs() <= tol,
                "ray {n}: starts {}",
                segs[0].t_min
            );
            let last = segs.last().unwrap().t_max;
            assert!(
                (last - leave).abs() <= tol,
                "ray {n}: ends {last}, exit {leave}"
            );
            for w in segs.windows(2) {
                assert_eq!(w[0].t_max, w[1].t_min, "ray {n}: gap or overlap");
            }
            for s in &segs {
                assert!(s.t_min < s.t_max, "ray {n}: empty segment {s:?}");
                for k in 0..8 {
                    let t = s.t_min + (s.t_max - s.t_min) * (k as f32 + 0.5) / 8.0;
                    let d = g.density(origin + direction * t);
                    assert!(d <= s.majorant, "ray {n} at t {t}: {d} > {s:?}");
                }
            }
            segments_seen += segs.len();
        }
        assert!(
            segments_seen > 10_000,
            "only {segments_seen} segments: rays miss the box"
        );
    }

    #[test]
    fn a_constant_grids_optical_depth_is_sigma_times_length() {
        let c = 0.75;
        let sigma_t_per_m = 4.0;
        let g = DensityGrid::new(
            [7, 5, 6],
            Vec3::new(-1.0, -2.0, 0.0),
            Vec3::new(2.0, 1.0, 1.0),
            vec![c; 210],
        )
        .unwrap();
        // From outside through the box: in at the x = −1 face (y 0.2), out at the x = 2
        // face (y 0.8), so the length inside is 3 m along x over the direction's cosine.
        let direction = Vec3A::new(1.0, 0.2, 0.0).normalize();
        let ray = Ray::new(Vec3A::new(-2.0, 0.0, 0.5), direction, 0.0, f32::INFINITY);
        let length_m = 3.0 / direction.x;
        let mut by_majorant = 0.0f64;
        let mut by_quadrature = 0.0f64;
        for s in g.majorant_segments(&ray) {
            assert_eq!(s.majorant, c);
            let dt = (s.t_max - s.t_min) as f64;
            by_majorant += (sigma_t_per_m * s.majorant) as f64 * dt;
            for k in 0..16 {
                let t = s.t_min + (s.t_max - s.t_min) * (k as f32 + 0.5) / 16.0;
                by_quadrature += (sigma_t_per_m * g.density(ray.at(t))) as f64 * dt / 16.0;
            }
        }
        let expected = (sigma_t_per_m * c) as f64 * length_m as f64;
        assert!(
            (by_majorant - expected).abs() < 1e-4 * expected,
            "{by_majorant} vs {expected}"
        );
        assert!(
            (by_quadrature - expected).abs() < 1e-4 * expected,
            "{by_quadrature} vs {expected}"
        );
    }

    #[test]
    fn invalid_grids_are_refused() {
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        assert!(DensityGrid::new([2, 2, 2], lo, hi, vec![1.0; 7]).is_none());
        assert!(DensityGrid::new([2, 2, 0], lo, hi, vec![]).is_none());
        assert!(DensityGrid::new([1, 1, 1], lo, lo, vec![1.0]).is_none());
        assert!(DensityGrid::new([1, 1, 1], lo, hi, vec![-1.0]).is_none());
        assert!(DensityGrid::new([1, 1, 1], lo, hi, vec![1.0]).is_some());
    }

    #[test]
    fn a_vol_grid_keeps_its_box_unless_bounds_are_given() {
        let vol = super::super::vol_file::VolGrid {
            resolution: [2, 1, 1],
            bounds_min_m: Vec3::ZERO,
            bounds_max_m: Vec3::new(2.0, 1.0, 1.0),
            values: vec![1.0, 3.0],
        };
        let own = DensityGrid::from_vol(vol.clone(), None).unwrap();
        // Voxel centres at x 0.5 and 1.5: halfway between them is the mean.
        assert_eq!(own.density(Vec3A::new(1.0, 0.5, 0.5)), 2.0);
        let moved = DensityGrid::from_vol(
            vol,
            Some((Vec3::new(10.0, 0.0, 0.0), Vec3::new(14.0, 1.0, 1.0))),
        )
        .unwrap();
        assert_eq!(moved.density(Vec3A::new(1.0, 0.5, 0.5)), 0.0);
        assert_eq!(moved.density(Vec3A::new(12.0, 0.5, 0.5)), 2.0);
        assert_eq!(moved.density(Vec3A::new(10.5, 0.5, 0.5)), 1.0);
    }
}
