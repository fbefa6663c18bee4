//! Which cells of a tile's pyramid describe an element of a tiled surface (Mostefaoui et al.
//! §3: a sub-patch that is a 2^−l part of one period reads level l of Γ). Level l splits
//! the period into 2^l × 2^l cells (level 0 is the whole period). An element reads the
//! finest level whose cells are at least its size, and where it straddles cells of that
//! level it reads their mean weighted by the area it covers of each: exact for the paper's
//! aligned sub-patches, and the area mean of the pyramid's finest fitting level elsewhere.

use glam::Vec3A;

use crate::element::ElementShape;

/// Where the tile lies on its surface: a corner of a period and one period along the
/// tile's x and y, world metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileLattice {
    pub origin: Vec3A,
    pub period: [Vec3A; 2],
}

/// The most levels a pyramid may have (4^7 cells at its base).
pub const MAX_PYRAMID_LEVELS: u32 = 8;

/// Cells over all levels of a pyramid of `levels` levels.
pub fn pyramid_cells(levels: u32) -> usize {
    ((1usize << (2 * levels)) - 1) / 3
}

/// The index of cell (u, v) of `level` among all levels' cells (level 0 first, then level
/// 1's four in row order, …; u along the tile's x).
pub fn cell_index(level: u32, u: u32, v: u32) -> usize {
    pyramid_cells(level) + ((v as usize) << level) + u as usize
}

/// At most three cells along each axis (two, and a sliver of a third where rounding puts
/// the element a hair over a cell's size).
const PER_AXIS: usize = 3;

/// The pyramid cells an element reads and their weights (summing to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellWeights {
    cells: [(u32, f32); PER_AXIS * PER_AXIS],
    len: usize,
}

impl CellWeights {
    /// The whole period: level 0 alone.
    pub const TOP: Self = Self {
        cells: [(0, 1.0); PER_AXIS * PER_AXIS],
        len: 1,
    };

    pub fn iter(&self) -> impl Iterator<Item = (usize, f32)> + '_ {
        self.cells[..self.len].iter().map(|&(c, w)| (c as usize, w))
    }
}

/// Relative slack on sizes and cell edges: an element that is a 2^−l part of a period up
/// to rounding reads level l, and no cell gets a sliver below it.
const SLACK: f32 = 1e-4;

impl TileLattice {
    /// The tile coordinates (in periods) of world point `p` on the surface's plane.
    fn periods_of(&self, p: Vec3A) -> [f32; 2] {
        // Dual basis of the two period vectors (they need not be orthogonal).
        let [a, b] = self.period;
        let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
        let det = aa * bb - ab * ab;
        let d = p - self.origin;
        let (da, db) = (d.dot(a), d.dot(b));
        [(bb * da - ab * db) / det, (aa * db - ab * da) / det]
    }

    /// The element's span in periods along the tile's x and y (lowest, highest) and its
    /// size (the larger side); `None` for a degenerate element.
    fn span(&self, shape: &ElementShape) -> Option<([f32; 2], [f32; 2], f32)> {
        let (corners, n) = shape.corners();
        let mut lo = [f32::INFINITY; 2];
        let mut hi = [f32::NEG_INFINITY; 2];
        for &c in &corners[..n] {
            let t = self.periods_of(c);
            for k in 0..2 {
                lo[k] = lo[k].min(t[k]);
                hi[k] = hi[k].max(t[k]);
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        (extent > 0.0 && extent.is_finite()).then_some((lo, hi, extent))
    }

    /// The pyramid level element `shape` reads where the pyramid is deep enough: the
    /// finest whose cells (2^−l periods) are at least its size (below
    /// `MAX_PYRAMID_LEVELS`).
    pub fn level_for(&self, shape: &ElementShape) -> u32 {
        self.span(shape).map_or(0, |(_, _, extent)| {
            level_of_size(extent, MAX_PYRAMID_LEVELS)
        })
    }

    /// The cells of a pyramid of `levels` levels that describe element `shape`.
    pub fn cell_weights(&self, levels: u32, shape: &ElementShape) -> CellWeights {
        if levels <= 1 {
            return CellWeights::TOP;
        }
        let Some((lo, hi, extent)) = self.span(shape) else {
            return CellWeights::TOP;
        };
        let level = level_of_size(extent, levels);
        if level == 0 {
            return CellWeights::TOP;
        }
        let side = 1u32 << level;
        let axis = |k: usize| axis_weights(lo[k], hi[k], side);
        let (us, vs) = (axis(0), axis(1));
        let mut out = CellWeights {
            cells: [(0, 0.0); PER_AXIS * PER_AXIS],
            len: 0,
        };
        for &(v, wv) in vs.iter().filter(|c| c.1 > 0.0) {
            for &(u, wu) in us.iter().filter(|c| c.1 > 0.0) {
                out.cells[out.len] = (cell_index(level, u, v) as u32, wu * wv);
                out.len += 1;
            }
        }
        out
    }
}

/// The finest level below `levels` whose cells are at least `extent` periods.
fn level_of_size(extent: f32, levels: u32) -> u32 {
    ((1.0 / extent).log2() + SLACK)
        .floor()
        .clamp(0.0, (levels - 1) as f32) as u32
}

/// Along one axis: the cells (of `side` per period, wrapped) that [lo, hi] (periods)
/// covers and the share of it in each; shares below `SLACK` are dropped.
fn axis_weights(lo: f32, hi: f32, side: u32) -> [(u32, f32); PER_AXIS] {
    let mut out = [(0u32, 0.0f32); PER_AXIS];
    let (a, b) = (lo * side as f32, hi * side as f32);
    let length = b - a;
    if length.is_nan() || length <= 0.0 {
        // A degenerate axis (a sliver element): the cell holding it.
        out[0] = ((a.floor() as i64).rem_euclid(i64::from(side)) as u32, 1.0);
        return out;
    }
    let first = a.floor();
    let mut total = 0.0;
    let mut n = 0;
    for k in 0..PER_AXIS + 1 {
        let cell = first + k as f32;
        if cell >= b {
            break;
        }
        let share = ((cell + 1.0).min(b) - cell.max(a)) / length;
        if share < SLACK {
            continue;
        }
        if n == PER_AXIS {
            break;
        }
        out[n] = ((cell as i64).rem_euclid(i64::from(side)) as u32, share);
        total += share;
        n += 1;
    }
    for c in &mut out[..n] {
        c.1 /= total;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice() -> TileLattice {
        // Periods of 0.5 m along x and 0.25 m along y, a corner at (1, 2, 0).
        TileLattice {
            origin: Vec3A::new(1.0, 2.0, 0.0),
            period: [Vec3A::new(0.5, 0.0, 0.0), Vec3A::new(0.0, 0.25, 0.0)],
        }
    }

    fn rect(x0: f32, y0: f32, wx: f32, wy: f32) -> ElementShape {
        ElementShape::Parallelogram {
            p0: Vec3A::new(x0, y0, 0.0),
            e1: Vec3A::new(wx, 0.0, 0.0),
            e2: Vec3A::new(0.0, wy, 0.0),
        }
    }

    #[test]
    fn an_aligned_quarter_period_reads_its_level_2_cell() {
        let l = lattice();
        // Periods (3.25, 1.5) to (3.5, 1.75): cell (1, 2) of level 2.
        let w = l.cell_weights(3, &rect(1.0 + 3.25 * 0.5, 2.0 + 1.5 * 0.25, 0.125, 0.0625));
        let cells: Vec<_> = w.iter().collect();
        assert_eq!(cells.len(), 1, "{cells:?}");
        assert_eq!(cells[0].0, cell_index(2, 1, 2));
        assert!((cells[0].1 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_whole_period_or_more_reads_the_top_and_levels_1_ignores_size() {
        let l = lattice();
        assert_eq!(
            l.cell_weights(3, &rect(1.1, 2.0, 0.5, 0.3)),
            CellWeights::TOP
        );
        assert_eq!(
            l.cell_weights(1, &rect(1.1, 2.0, 0.1, 0.05)),
            CellWeights::TOP
        );
    }

    #[test]
    fn a_straddling_element_reads_the_cells_it_covers_by_area() {
        let l = lattice();
        // Half a period wide, starting at 0.75 of a period in x (wrapping into the next
        // period's first cell): level 1, cells u = 1 and u = 0 half each; in y a quarter
        // period inside row 0 of level 1.
        let w = l.cell_weights(3, &rect(1.0 + 0.75 * 0.5, 2.0 + 0.1 * 0.25, 0.25, 0.0625));
        let mut cells: Vec<_> = w.iter().collect();
        cells.sort_by_key(|c| c.0);
        assert_eq!(cells.len(), 2, "{cells:?}");
        assert_eq!(cells[0].0, cell_index(1, 0, 0));
        assert_eq!(cells[1].0, cell_index(1, 1, 0));
        for c in cells {
            assert!((c.1 - 0.5).abs() < 1e-4, "{c:?}");
        }
        let sum: f32 = w.iter().map(|c| c.1).sum();
        assert!((sum - 1.0).abs() < 1e-5);
    }

    #[test]
    fn cell_indices_follow_the_pyramids_order() {
        assert_eq!(pyramid_cells(1), 1);
        assert_eq!(pyramid_cells(3), 21);
        assert_eq!(cell_index(0, 0, 0), 0);
        assert_eq!(cell_index(1, 1, 1), 4);
        assert_eq!(cell_index(2, 0, 0), 5);
        assert_eq!(cell_index(2, 3, 3), 20);
    }
}
