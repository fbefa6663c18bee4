//! Periodic tiles and virtual ray tracing (Mostefaoui et al., "inhomogeneous surfaces" radiosity,
//! §2; their ref. [19]). A tile is a mesh modelled once over one period: its period lies in
//! its x–y plane, `[0, period_x] × [0, period_y]`, and z is the height above the carrier.
//! A [`Tiling`] repeats it over a grid of `cells` in its instance's object space; a ray that
//! enters the slab the tiles fill is followed through the grid cells (2-D DDA) and tested
//! against the one stored tile, shifted to each cell. Geometry that reaches over a cell's
//! edge (a strand crossing the period plane) is found too: each cell visited also tests the
//! neighbouring copies whose bounds reach into it.

use glam::Vec3A;

use crate::mesh::TriangleMesh;
use crate::mesh_bvh::{MeshBvh, MeshHit};

/// A tile repeated over `cells[0] × cells[1]` periods in the instance's object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tiling {
    /// The tile's mesh (added to the builder like any mesh; never flattened).
    pub mesh: crate::geometry::MeshId,
    /// Period along object x and y, metres.
    pub period_m: [f32; 2],
    /// Number of periods along x and y (≥ 1 each).
    pub cells: [u32; 2],
}

/// A hit on one copy of the tile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TileHit {
    /// Cell index `i + j·cells[0]`.
    pub cell: u32,
    pub hit: MeshHit,
}

impl Tiling {
    /// Object-space bounds of every copy: the tile's bounds widened by the grid.
    pub fn bounds(&self, tile_bounds: (Vec3A, Vec3A)) -> (Vec3A, Vec3A) {
        let (lo, hi) = tile_bounds;
        let span = Vec3A::new(
            (self.cells[0] - 1) as f32 * self.period_m[0],
            (self.cells[1] - 1) as f32 * self.period_m[1],
            0.0,
        );
        (lo, hi + span)
    }

    /// The object-space offset of cell `cell` (`i + j·cells[0]`).
    pub fn cell_offset(&self, cell: u32) -> Vec3A {
        let (i, j) = (cell % self.cells[0], cell / self.cells[0]);
        Vec3A::new(
            i as f32 * self.period_m[0],
            j as f32 * self.period_m[1],
            0.0,
        )
    }

    /// The [`crate::Hit::primitive_id`] of `triangle` (of `triangles`) in cell `cell`.
    pub fn primitive_id(cell: u32, triangle: u32, triangles: u32) -> u32 {
        cell * triangles + triangle
    }

    /// (cell, triangle) of a primitive id made by [`Self::primitive_id`].
    pub fn cell_and_triangle(primitive_id: u32, triangles: u32) -> (u32, u32) {
        (primitive_id / triangles, primitive_id % triangles)
    }

    /// Closest hit of the object-space ray `o + t·d`, `t` in `(t_min, t_max)`; the tile BVH's
    /// node test is `WIDE`'s.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub(crate) unsafe fn intersect_with<const WIDE: bool>(
        &self,
        tile: &MeshBvh,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<TileHit> {
        let mut best: Option<TileHit> = None;
        let mut t_best = t_max;
        self.walk(tile, o, d, t_min, t_max, |cell, offset| {
            // SAFETY: the caller's contract for `WIDE`.
            let copy_hit = unsafe { tile.intersect_with::<WIDE>(o - offset, d, t_min, t_best) };
            if let Some(hit) = copy_hit {
                t_best = hit.t;
                best = Some(TileHit { cell, hit });
            }
            (false, t_best)
        });
        best
    }

    /// Whether any copy lies on the object-space ray in `(t_min, t_max)`; the tile BVH's node
    /// test is `WIDE`'s.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub(crate) unsafe fn occluded_with<const WIDE: bool>(
        &self,
        tile: &MeshBvh,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> bool {
        let mut hit = false;
        self.walk(tile, o, d, t_min, t_max, |_, offset| {
            // SAFETY: the caller's contract for `WIDE`.
            hit = unsafe { tile.occluded_with::<WIDE>(o - offset, d, t_min, t_max) };
            (hit, t_max)
        });
        hit
    }

    /// Visits, in ray order, the grid cells the ray crosses inside the tiles' box and, for
    /// each, every copy whose bounds reach into that cell; `visit(cell, offset)` answers
    /// (stop, the closest t found so far). The walk ends once the next cell starts beyond
    /// that t: a hit at point p is on a copy that reaches into p's cell, which was visited
    /// before any cell the ray enters later.
    fn walk(
        &self,
        tile: &MeshBvh,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
        mut visit: impl FnMut(u32, Vec3A) -> (bool, f32),
    ) {
        let (tile_lo, tile_hi) = tile.bounds();
        if tile_lo.cmpgt(tile_hi).any() {
            return;
        }
        let (lo, hi) = self.bounds((tile_lo, tile_hi));
        // The ray's interval inside the box of all copies (slabs; 0·∞ gives NaN, which the
        // max/min below drop).
        let inv = d.recip();
        let t0 = (lo - o) * inv;
        let t1 = (hi - o) * inv;
        let mut enter = t_min;
        let mut exit = t_max;
        for k in 0..3 {
            if d[k] == 0.0 {
                if o[k] < lo[k] || o[k] > hi[k] {
                    return;
                }
                continue;
            }
            enter = enter.max(t0[k].min(t1[k]));
            exit = exit.min(t0[k].max(t1[k]));
        }
        if enter > exit || enter.is_nan() || exit.is_nan() {
            return;
        }
        let [px, py] = self.period_m;
        let [nx, ny] = [self.cells[0] as i64, self.cells[1] as i64];
        // Copies (i, j) that reach into grid cell (ci, cj): i·p + lo < (ci+1)·p and
        // i·p + hi > ci·p, i.e. ci + 1 − ⌈hi/p⌉ ≤ i ≤ ci + ⌈−lo/p⌉. Bounds within 10⁻⁴ of a
        // period plane count as on it (rounding of a tile modelled exactly on its period).
        let reach = |lo: f32, hi: f32, p: f32| -> (i64, i64) {
            (
                1 - (hi / p - 1e-4).ceil() as i64,
                (-lo / p - 1e-4).ceil() as i64,
            )
        };
        let (rx0, rx1) = reach(tile_lo.x, tile_hi.x, px);
        let (ry0, ry1) = reach(tile_lo.y, tile_hi.y, py);
        let p = o + d * enter;
        let mut ci = (p.x / px).floor() as i64;
        let mut cj = (p.y / py).floor() as i64;
        let step = |dk: f32| -> i64 {
            if dk > 0.0 {
                1
            } else {
                -1
            }
        };
        let (sx, sy) = (step(d.x), step(d.y));
        let next_boundary = |c: i64, s: i64, p: f32, ok: f32, dk: f32| -> f32 {
            if dk == 0.0 {
                f32::INFINITY
            } else {
                ((c + i64::from(s > 0)) as f32 * p - ok) / dk
            }
        };
        let mut t_next_x = next_boundary(ci, sx, px, o.x, d.x);
        let mut t_next_y = next_boundary(cj, sy, py, o.y, d.y);
        let (dt_x, dt_y) = ((px / d.x).abs(), (py / d.y).abs());
        // The ray crosses at most this many grid lines inside the box (plus slack for
        // rounding at the ends).
        let lines = |lo: f32, hi: f32, p: f32| ((hi - lo) / p).ceil() as i64 + 2;
        let max_steps = lines(lo.x, hi.x, px) + lines(lo.y, hi.y, py) + 2;
        let mut t_best = exit;
        for _ in 0..max_steps {
            for j in (cj + ry0).max(0)..=(cj + ry1).min(ny - 1) {
                for i in (ci + rx0).max(0)..=(ci + rx1).min(nx - 1) {
                    let cell = (i + j * nx) as u32;
                    let offset = Vec3A::new(i as f32 * px, j as f32 * py, 0.0);
                    let (stop, t) = visit(cell, offset);
                    if stop {
                        return;
                    }
                    t_best = t_best.min(t);
                }
            }
            let t_leave = t_next_x.min(t_next_y);
            if t_leave > t_best || t_leave > exit {
                return;
            }
            if t_next_x <= t_next_y {
                ci += sx;
                t_next_x += dt_x;
            } else {
                cj += sy;
                t_next_y += dt_y;
            }
        }
    }
}

/// Boundary edges of a tile that lie on its period planes (x = 0, x = period_x, y = 0,
/// y = period_y) and find no boundary edge at the same place on the opposite plane: open
/// seams, where the surface would end when the tile is repeated. Positions match within
/// `1e-5` of the period. Edges inside the period (the rim of a hole, a strand's free end)
/// are not seams.
pub fn open_seam_edges(mesh: &TriangleMesh, period_m: [f32; 2]) -> usize {
    use std::collections::HashMap;
    let tolerance = 1e-5 * period_m[0].max(period_m[1]);
    let key = |p: Vec3A| -> [i64; 3] {
        [
            (p.x / tolerance).round() as i64,
            (p.y / tolerance).round() as i64,
            (p.z / tolerance).round() as i64,
        ]
    };
    // Edges used by exactly one triangle.
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for tri in &mesh.indices {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let on_plane = |v: f32, plane: f32| (v - plane).abs() <= tolerance;
    let mut boundary: HashMap<([i64; 3], [i64; 3]), u32> = HashMap::new();
    let mut seam_edges: Vec<(Vec3A, Vec3A)> = Vec::new();
    let sorted = |a: [i64; 3], b: [i64; 3]| if a <= b { (a, b) } else { (b, a) };
    for (&(a, b), &n) in &uses {
        if n != 1 {
            continue;
        }
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        *boundary.entry(sorted(key(pa), key(pb))).or_default() += 1;
        let on = |plane_x: Option<f32>, plane_y: Option<f32>| {
            plane_x.is_some_and(|x| on_plane(pa.x, x) && on_plane(pb.x, x))
                || plane_y.is_some_and(|y| on_plane(pa.y, y) && on_plane(pb.y, y))
        };
        if on(Some(0.0), None)
            || on(Some(period_m[0]), None)
            || on(None, Some(0.0))
            || on(None, Some(period_m[1]))
        {
            seam_edges.push((pa, pb));
        }
    }
    seam_edges
        .iter()
        .filter(|(pa, pb)| {
            // The partner: the same edge shifted across the period, on the opposite plane.
            let shift = |p: Vec3A| -> Vec3A {
                let mut s = Vec3A::ZERO;
                if on_plane(pa.x, 0.0) && on_plane(pb.x, 0.0) {
                    s.x = period_m[0];
                } else if on_plane(pa.x, period_m[0]) && on_plane(pb.x, period_m[0]) {
                    s.x = -period_m[0];
                }
                if s.x == 0.0 {
                    if on_plane(pa.y, 0.0) && on_plane(pb.y, 0.0) {
                        s.y = period_m[1];
                    } else {
                        s.y = -period_m[1];
                    }
                }
                p + s
            };
            !boundary.contains_key(&sorted(key(shift(*pa)), key(shift(*pb))))
        })
        .count()
}
