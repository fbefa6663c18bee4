//! The photons of one pass and the tree that finds them: a balanced bounding-volume
//! hierarchy over the photons' spheres (each photon a sphere of its own gather radius, as
//! Jarosz et al. 2008's beam radiance estimate stores them, §4.1 "BBH"), split at the
//! median of the longest axis, at most `LEAF_PHOTONS` photons per leaf. The same tree
//! answers the three questions the photon integrators ask:
//!
//! - every photon whose sphere contains a point (the surface gather, Jensen 1996 eq. 9),
//!   or whose centre lies within a given radius of it (the per-pixel radius of stochastic
//!   progressive photon mapping, Hachisuka & Jensen 2009);
//! - every photon whose sphere a ray segment crosses, with the segment parameter of its
//!   centre's projection (the beam radiance estimate, Jarosz et al. 2008 eq. 13);
//! - the k nearest photons of a photon (`photon`'s k-NN radius).

use glam::Vec3A;
use prism_spectrum::SampledSpectrum;

/// Photons per leaf: a leaf's spheres are tested one by one.
const LEAF_PHOTONS: usize = 8;

/// A stored photon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    /// Where it landed (a surface point, or a real scattering point in a medium), metres.
    pub p: [f32; 3],
    /// Unit direction it travelled in when it arrived.
    pub direction: [f32; 3],
    /// Flux per lane, W·nm⁻¹, already divided by the photons shot this pass. In a medium
    /// the photon was deposited with density ∝ σs, so β carries the σs of the beam
    /// estimate (see `beam.rs`).
    pub beta: [f32; 4],
    /// Gather radius, metres.
    pub radius_m: f32,
    /// Scattering events of its light path before it was stored, plus one for a medium
    /// photon (its own scattering).
    pub depth: u8,
    /// Lanes 1–3 ended at a dispersive surface: only the hero lane carries flux.
    pub hero_only: bool,
    /// The medium it scattered in (`u16::MAX`: a surface photon).
    pub medium: u16,
}

impl Photon {
    #[inline]
    pub fn position(&self) -> Vec3A {
        Vec3A::from_array(self.p)
    }

    #[inline]
    pub fn direction(&self) -> Vec3A {
        Vec3A::from_array(self.direction)
    }

    #[inline]
    pub fn beta(&self) -> SampledSpectrum {
        SampledSpectrum::new(self.beta)
    }
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3A,
    hi: Vec3A,
    /// Leaf: photons [a, b). Inner: children a and b.
    a: u32,
    b: u32,
    leaf: bool,
}

/// Bytes of tree per stored photon, at most (for the memory estimate): a node per
/// `LEAF_PHOTONS / 2` photons or fewer.
pub const TREE_BYTES_PER_PHOTON: usize =
    std::mem::size_of::<Photon>() + 2 * std::mem::size_of::<Node>() / (LEAF_PHOTONS / 2);

/// The photons of a map, reordered, and their hierarchy.
#[derive(Clone, Debug, Default)]
pub struct PhotonTree {
    photons: Vec<Photon>,
    nodes: Vec<Node>,
}

impl PhotonTree {
    /// The tree over `photons` (their radii as given).
    pub fn build(mut photons: Vec<Photon>) -> Self {
        let mut nodes = Vec::with_capacity(2 * photons.len() / LEAF_PHOTONS + 1);
        if !photons.is_empty() {
            let n = photons.len();
            build_node(&mut photons, 0, n, &mut nodes);
        }
        Self { photons, nodes }
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }

    /// Sets every photon's radius to the distance to its `k`-th nearest other photon (at
    /// most `max_radius_m`, so a lone photon does not blur the whole scene) and refits the
    /// bounds. The query runs on the radius-0 tree that `build` made from zero radii.
    pub fn set_nearest_neighbour_radii(&mut self, k: usize, max_radius_m: f32) {
        use rayon::prelude::*;
        let radii: Vec<f32> = self
            .photons
            .par_iter()
            .map(|ph| {
                self.kth_nearest_distance(ph.position(), k + 1)
                    .min(max_radius_m)
                    .max(1e-7)
            })
            .collect();
        for (ph, r) in self.photons.iter_mut().zip(radii) {
            ph.radius_m = r;
        }
        self.refit();
    }

    /// Distance from `x` to its `k`-th nearest photon (∞ with fewer photons).
    fn kth_nearest_distance(&self, x: Vec3A, k: usize) -> f32 {
        // A max-heap of the k best squared distances, kept sorted (k is small).
        let mut best: Vec<f32> = Vec::with_capacity(k + 1);
        let mut stack = Vec::with_capacity(64);
        if self.nodes.is_empty() {
            return f32::INFINITY;
        }
        stack.push(0u32);
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            let d2 = box_distance_squared(node.lo, node.hi, x);
            if best.len() == k && d2 >= best[k - 1] {
                continue;
            }
            if node.leaf {
                for ph in &self.photons[node.a as usize..node.b as usize] {
                    let d2 = (ph.position() - x).length_squared();
                    if best.len() < k || d2 < best[k - 1] {
                        let at = best.partition_point(|&b| b <= d2);
                        best.insert(at, d2);
                        best.truncate(k);
                    }
                }
            } else {
                // Nearer child last, so it is searched first.
                let (a, b) = (&self.nodes[node.a as usize], &self.nodes[node.b as usize]);
                let (da, db) = (
                    box_distance_squared(a.lo, a.hi, x),
                    box_distance_squared(b.lo, b.hi, x),
                );
                if da < db {
                    stack.push(node.b);
                    stack.push(node.a);
                } else {
                    stack.push(node.a);
                    stack.push(node.b);
                }
            }
        }
        if best.len() == k {
            best[k - 1].sqrt()
        } else {
            f32::INFINITY
        }
    }

    /// Recomputes every node's bounds from its photons' spheres (children follow their
    /// parent in `nodes`, so one backward sweep sees children first).
    fn refit(&mut self) {
        for i in (0..self.nodes.len()).rev() {
            let node = self.nodes[i];
            let (lo, hi) = if node.leaf {
                sphere_bounds(&self.photons[node.a as usize..node.b as usize])
            } else {
                let (a, b) = (self.nodes[node.a as usize], self.nodes[node.b as usize]);
                (a.lo.min(b.lo), a.hi.max(b.hi))
            };
            self.nodes[i].lo = lo;
            self.nodes[i].hi = hi;
        }
    }

    /// Calls `f` with every photon whose sphere contains `x`.
    #[inline]
    pub fn for_each_containing(&self, x: Vec3A, mut f: impl FnMut(&Photon)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if x.cmplt(node.lo).any() || x.cmpgt(node.hi).any() {
                continue;
            }
            if node.leaf {
                for ph in &self.photons[node.a as usize..node.b as usize] {
                    let r = ph.radius_m;
                    if (ph.position() - x).length_squared() < r * r {
                        f(ph);
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = node.a;
                stack[top + 1] = node.b;
                top += 2;
            }
        }
    }

    /// Calls `f` with every photon whose centre lies within `radius_m` of `x` (the
    /// photons' own radii play no part: the nodes' boxes hold the centres all the same).
    #[inline]
    pub fn for_each_within(&self, x: Vec3A, radius_m: f32, mut f: impl FnMut(&Photon)) {
        if self.nodes.is_empty() {
            return;
        }
        let r2 = radius_m * radius_m;
        let mut stack = [0u32; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if box_distance_squared(node.lo, node.hi, x) >= r2 {
                continue;
            }
            if node.leaf {
                for ph in &self.photons[node.a as usize..node.b as usize] {
                    if (ph.position() - x).length_squared() < r2 {
                        f(ph);
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = node.a;
                stack[top + 1] = node.b;
                top += 2;
            }
        }
    }

    /// Calls `f(photon, t)` with every photon whose sphere the segment o + t·d, t ∈
    /// [t0, t1] (`d` unit) passes within the photon's radius of, with the parameter t of
    /// the centre's projection on the line, itself in [t0, t1] (the disc the photon
    /// presents to the ray, perpendicular to it, is crossed there).
    #[inline]
    pub fn for_each_crossed(
        &self,
        o: Vec3A,
        d: Vec3A,
        t0: f32,
        t1: f32,
        mut f: impl FnMut(&Photon, f32),
    ) {
        if self.nodes.is_empty() || t1 <= t0 {
            return;
        }
        // A zero component gets a huge finite reciprocal: 0 · ∞ would be NaN in the slab
        // test at a node face through the origin.
        let inv = Vec3A::select(d.cmpeq(Vec3A::ZERO), Vec3A::splat(f32::MAX), Vec3A::ONE / d);
        let mut stack = [0u32; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            // Slab test of the segment against the node's box.
            let ta = (node.lo - o) * inv;
            let tb = (node.hi - o) * inv;
            let near = ta.min(tb).max_element().max(t0);
            let far = ta.max(tb).min_element().min(t1);
            if near > far {
                continue;
            }
            if node.leaf {
                for ph in &self.photons[node.a as usize..node.b as usize] {
                    let v = ph.position() - o;
                    let t = v.dot(d);
                    if t < t0 || t > t1 {
                        continue;
                    }
                    let r = ph.radius_m;
                    if v.length_squared() - t * t < r * r {
                        f(ph, t);
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = node.a;
                stack[top + 1] = node.b;
                top += 2;
            }
        }
    }
}

fn sphere_bounds(photons: &[Photon]) -> (Vec3A, Vec3A) {
    let mut lo = Vec3A::splat(f32::INFINITY);
    let mut hi = Vec3A::splat(f32::NEG_INFINITY);
    for ph in photons {
        let p = ph.position();
        let r = Vec3A::splat(ph.radius_m);
        lo = lo.min(p - r);
        hi = hi.max(p + r);
    }
    (lo, hi)
}

/// Builds the node of photons [start, end) and its subtree; returns its index.
fn build_node(photons: &mut [Photon], start: usize, end: usize, nodes: &mut Vec<Node>) -> u32 {
    let index = nodes.len();
    let (lo, hi) = sphere_bounds(&photons[start..end]);
    nodes.push(Node {
        lo,
        hi,
        a: start as u32,
        b: end as u32,
        leaf: true,
    });
    if end - start <= LEAF_PHOTONS {
        return index as u32;
    }
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = (start + end) / 2;
    photons[start..end].select_nth_unstable_by(mid - start, |a, b| a.p[axis].total_cmp(&b.p[axis]));
    let left = build_node(photons, start, mid, nodes);
    let right = build_node(photons, mid, end, nodes);
    nodes[index].a = left;
    nodes[index].b = right;
    nodes[index].leaf = false;
    index as u32
}

fn box_distance_squared(lo: Vec3A, hi: Vec3A, x: Vec3A) -> f32 {
    let d = (lo - x).max(Vec3A::ZERO).max(x - hi);
    d.length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn photon(p: Vec3A, r: f32) -> Photon {
        Photon {
            p: p.to_array(),
            direction: [0.0, -1.0, 0.0],
            beta: [1.0; 4],
            radius_m: r,
            depth: 1,
            hero_only: false,
            medium: 0,
        }
    }

    /// Pseudo-random points in the unit cube.
    fn cloud(n: usize, r: f32) -> Vec<Photon> {
        let mut rng = crate::integrator::medium_transport::MediumRng::new(5);
        (0..n)
            .map(|_| photon(Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform()), r))
            .collect()
    }

    /// The tree's point and segment queries find exactly what a linear scan finds.
    #[test]
    fn queries_match_a_linear_scan() {
        let photons = cloud(5000, 0.05);
        let tree = PhotonTree::build(photons.clone());
        let mut rng = crate::integrator::medium_transport::MediumRng::new(9);
        for _ in 0..200 {
            let x = Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform());
            let mut found = 0;
            tree.for_each_containing(x, |_| found += 1);
            let expected = photons
                .iter()
                .filter(|p| (p.position() - x).length_squared() < p.radius_m * p.radius_m)
                .count();
            assert_eq!(found, expected);
            let radius_m = 0.02 + 0.1 * rng.uniform();
            let mut within = 0;
            tree.for_each_within(x, radius_m, |_| within += 1);
            let expected = photons
                .iter()
                .filter(|p| (p.position() - x).length_squared() < radius_m * radius_m)
                .count();
            assert_eq!(within, expected);
            let d = Vec3A::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            )
            .normalize();
            let (t0, t1) = (0.1, 0.9);
            let mut crossed = 0;
            tree.for_each_crossed(x, d, t0, t1, |_, _| crossed += 1);
            let expected = photons
                .iter()
                .filter(|p| {
                    let v = p.position() - x;
                    let t = v.dot(d);
                    t >= t0 && t <= t1 && v.length_squared() - t * t < p.radius_m * p.radius_m
                })
                .count();
            assert_eq!(crossed, expected);
        }
    }

    /// The k-NN radius is the k-th smallest distance to the other photons.
    #[test]
    fn nearest_neighbour_radii_match_a_sort() {
        let photons = cloud(800, 0.0);
        let mut tree = PhotonTree::build(photons.clone());
        tree.set_nearest_neighbour_radii(10, f32::INFINITY);
        for ph in tree.photons().iter().take(50) {
            let mut d: Vec<f32> = photons
                .iter()
                .map(|q| (q.position() - ph.position()).length())
                .collect();
            d.sort_by(f32::total_cmp);
            // d[0] is the photon itself.
            assert!(
                (ph.radius_m - d[10]).abs() < 1e-6,
                "{} {}",
                ph.radius_m,
                d[10]
            );
        }
    }
}
