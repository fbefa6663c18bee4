//! The surface elements of the hierarchy: an input patch (a parallelogram or a triangle) and
//! the sub-elements its regular 4-way subdivision makes (Hanrahan, Salzman & Aupperle 1991
//! quadtrees; a triangle splits at its edge midpoints).

use glam::Vec3A;

/// A planar element `p0 + u·e1 + v·e2`, `(u, v)` in the unit square (parallelogram) or the
/// unit triangle `u + v ≤ 1`. It is one-sided: it receives and emits on the side its normal
/// `e1 × e2` points to (a two-sided surface is two elements, one per side).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ElementShape {
    Parallelogram { p0: Vec3A, e1: Vec3A, e2: Vec3A },
    Triangle { p0: Vec3A, e1: Vec3A, e2: Vec3A },
}

impl ElementShape {
    fn parts(&self) -> (Vec3A, Vec3A, Vec3A) {
        match *self {
            ElementShape::Parallelogram { p0, e1, e2 } | ElementShape::Triangle { p0, e1, e2 } => {
                (p0, e1, e2)
            }
        }
    }

    /// Area in m².
    pub fn area_m2(&self) -> f32 {
        let (_, e1, e2) = self.parts();
        let cross = e1.cross(e2).length();
        match self {
            ElementShape::Parallelogram { .. } => cross,
            ElementShape::Triangle { .. } => 0.5 * cross,
        }
    }

    /// Unit normal of the side that receives and emits.
    pub fn normal(&self) -> Vec3A {
        let (_, e1, e2) = self.parts();
        e1.cross(e2).normalize_or_zero()
    }

    /// The point at parameters `(u, v)`.
    pub fn point(&self, u: f32, v: f32) -> Vec3A {
        let (p0, e1, e2) = self.parts();
        p0 + u * e1 + v * e2
    }

    /// The centroid.
    pub fn centre(&self) -> Vec3A {
        match self {
            ElementShape::Parallelogram { .. } => self.point(0.5, 0.5),
            ElementShape::Triangle { .. } => self.point(1.0 / 3.0, 1.0 / 3.0),
        }
    }

    /// The corners, counter-clockwise seen from the normal's side.
    pub fn corners(&self) -> ([Vec3A; 4], usize) {
        let (p0, e1, e2) = self.parts();
        match self {
            ElementShape::Parallelogram { .. } => ([p0, p0 + e1, p0 + e1 + e2, p0 + e2], 4),
            ElementShape::Triangle { .. } => ([p0, p0 + e1, p0 + e2, p0 + e2], 3),
        }
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3A, Vec3A) {
        let (c, n) = self.corners();
        let lo = c[..n]
            .iter()
            .fold(Vec3A::splat(f32::INFINITY), |a, &p| a.min(p));
        let hi = c[..n]
            .iter()
            .fold(Vec3A::splat(f32::NEG_INFINITY), |a, &p| a.max(p));
        (lo, hi)
    }

    /// The four sub-elements of the regular split, in the order [`Self::child_at`] uses.
    pub fn children(&self) -> [ElementShape; 4] {
        let (p0, e1, e2) = self.parts();
        let (h1, h2) = (0.5 * e1, 0.5 * e2);
        match self {
            ElementShape::Parallelogram { .. } => {
                let at = |i: f32, j: f32| ElementShape::Parallelogram {
                    p0: p0 + i * h1 + j * h2,
                    e1: h1,
                    e2: h2,
                };
                [at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0), at(1.0, 1.0)]
            }
            ElementShape::Triangle { .. } => [
                ElementShape::Triangle { p0, e1: h1, e2: h2 },
                ElementShape::Triangle {
                    p0: p0 + h1,
                    e1: h1,
                    e2: h2,
                },
                ElementShape::Triangle {
                    p0: p0 + h2,
                    e1: h1,
                    e2: h2,
                },
                // The middle triangle, inverted: same orientation since (−h1) × (−h2) = h1 × h2.
                ElementShape::Triangle {
                    p0: p0 + h1 + h2,
                    e1: -h1,
                    e2: -h2,
                },
            ],
        }
    }

    /// The child holding parameters `(u, v)` and the parameters within it.
    pub fn child_at(&self, u: f32, v: f32) -> (usize, f32, f32) {
        match self {
            ElementShape::Parallelogram { .. } => {
                let i = usize::from(u >= 0.5);
                let j = usize::from(v >= 0.5);
                (i + 2 * j, 2.0 * u - i as f32, 2.0 * v - j as f32)
            }
            ElementShape::Triangle { .. } => {
                if u >= 0.5 {
                    (1, 2.0 * u - 1.0, 2.0 * v)
                } else if v >= 0.5 {
                    (2, 2.0 * u, 2.0 * v - 1.0)
                } else if u + v < 0.5 {
                    (0, 2.0 * u, 2.0 * v)
                } else {
                    (3, 1.0 - 2.0 * u, 1.0 - 2.0 * v)
                }
            }
        }
    }

    /// The parameters of the point of the element's plane nearest to `p`.
    pub fn parameters_of(&self, p: Vec3A) -> (f32, f32) {
        let (p0, e1, e2) = self.parts();
        let d = p - p0;
        let (a, b, c) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (r1, r2) = (d.dot(e1), d.dot(e2));
        let det = a * c - b * b;
        if det <= 0.0 {
            return (0.0, 0.0);
        }
        ((c * r1 - b * r2) / det, (a * r2 - b * r1) / det)
    }

    /// The point of the element nearest to `p`'s projection onto its plane, kept `inset`
    /// (in parameter units) inside its edges.
    pub fn nearest_inner_point(&self, p: Vec3A, inset: f32) -> Vec3A {
        let (u, v) = self.parameters_of(p);
        let (mut u, mut v) = (u.clamp(inset, 1.0 - inset), v.clamp(inset, 1.0 - inset));
        if let ElementShape::Triangle { .. } = self {
            let excess = u + v - (1.0 - inset);
            if excess > 0.0 {
                // Back onto the hypotenuse, along its normal.
                u = (u - 0.5 * excess).max(inset);
                v = (v - 0.5 * excess).max(inset);
            }
        }
        self.point(u, v)
    }

    /// Quadrature nodes: `(u, v, weight)` with weights summing to 1 over the element,
    /// `n × n` Gauss–Legendre points on the square (mapped onto a triangle by the Duffy
    /// transform `(u, v(1 − u))`, weight ∝ 1 − u).
    pub fn quadrature(&self, n: usize) -> Vec<(f32, f32, f32)> {
        let rule = gauss_legendre_unit(n);
        let mut nodes = Vec::with_capacity(rule.len() * rule.len());
        for &(x, wx) in &rule {
            for &(y, wy) in &rule {
                match self {
                    ElementShape::Parallelogram { .. } => nodes.push((x, y, wx * wy)),
                    ElementShape::Triangle { .. } => {
                        nodes.push((x, y * (1.0 - x), 2.0 * wx * wy * (1.0 - x)))
                    }
                }
            }
        }
        nodes
    }
}

/// Gauss–Legendre nodes and weights on [0, 1] (weights sum to 1): 1, 2, 3 or 4 points,
/// composite (cells of 4) above 4.
pub fn gauss_legendre_unit(n: usize) -> Vec<(f32, f32)> {
    let base: &[(f64, f64)] = match n {
        0 | 1 => &[(0.0, 2.0)],
        2 => &[
            (-0.577_350_269_189_625_8, 1.0),
            (0.577_350_269_189_625_8, 1.0),
        ],
        3 => &[
            (-0.774_596_669_241_483_4, 0.555_555_555_555_555_6),
            (0.0, 0.888_888_888_888_889),
            (0.774_596_669_241_483_4, 0.555_555_555_555_555_6),
        ],
        _ => &[
            (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
            (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        ],
    };
    let cells = if n > 4 { n.div_ceil(4) } else { 1 };
    let mut nodes = Vec::with_capacity(cells * base.len());
    for c in 0..cells {
        for &(t, w) in base {
            let x = (c as f64 + 0.5 * (t + 1.0)) / cells as f64;
            nodes.push((x as f32, (0.5 * w / cells as f64) as f32));
        }
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_tile_the_parent_and_child_at_inverts_them() {
        let shapes = [
            ElementShape::Parallelogram {
                p0: Vec3A::new(0.1, 0.2, 0.3),
                e1: Vec3A::new(1.0, 0.2, 0.0),
                e2: Vec3A::new(0.1, 0.7, 0.3),
            },
            ElementShape::Triangle {
                p0: Vec3A::new(0.1, 0.2, 0.3),
                e1: Vec3A::new(1.0, 0.2, 0.0),
                e2: Vec3A::new(0.1, 0.7, 0.3),
            },
        ];
        for s in shapes {
            let kids = s.children();
            let sum: f32 = kids.iter().map(|k| k.area_m2()).sum();
            assert!((sum - s.area_m2()).abs() < 1e-5 * s.area_m2());
            for k in &kids {
                assert!(k.normal().dot(s.normal()) > 0.9999);
            }
            for &(u, v) in &[(0.1, 0.2), (0.7, 0.1), (0.2, 0.6), (0.3, 0.4), (0.45, 0.45)] {
                let p = s.point(u, v);
                let (c, cu, cv) = s.child_at(u, v);
                assert!((kids[c].point(cu, cv) - p).length() < 1e-5, "{s:?} {u} {v}");
                let (pu, pv) = s.parameters_of(p);
                assert!((pu - u).abs() < 1e-5 && (pv - v).abs() < 1e-5);
            }
            let w: f32 = s.quadrature(8).iter().map(|q| q.2).sum();
            assert!((w - 1.0).abs() < 1e-5);
        }
    }
}
