//! Light selection that depends on the shading point: a BVH over the lights with bounds,
//! descended by the importance of each child (Conty Estevez & Kulla 2018, §4–5; pbrt-v4
//! §12.6.3 `BVHLightSampler`). Lights at infinity have no bounds: they are chosen apart,
//! each with probability 1 / (their count + 1), the tree with the rest.
//!
//! The tree is built binary (pbrt-v4's bucketed split cost) and collapsed to four children
//! per node, whose importances are evaluated together in SIMD lanes ([`LightBounds4`]): half
//! the levels, one vector evaluation per level.
//!
//! `sample` and `pmf` agree exactly: `pmf` follows the light's recorded path from the root
//! (two bits per level) and multiplies the same child probabilities `sample` used.

use glam::Vec3A;

use super::light_bounds::{LightBounds, LightBounds4};

/// Buckets per axis of the split search (pbrt-v4 uses 12).
const BUCKETS: usize = 12;
/// Deeper than this the build splits at the median: every trail (two bits per level of
/// the four-wide tree) fits in 64 bits.
const MEDIAN_DEPTH: u32 = 48;

/// A node of the binary tree the build makes.
#[derive(Clone, Debug)]
enum BinaryNode {
    Leaf {
        light: u32,
        bounds: LightBounds,
    },
    /// Children: the next node and `second`.
    Interior {
        second: u32,
        bounds: LightBounds,
    },
}

impl BinaryNode {
    fn bounds(&self) -> &LightBounds {
        match self {
            BinaryNode::Leaf { bounds, .. } | BinaryNode::Interior { bounds, .. } => bounds,
        }
    }
}

/// What a slot of a four-wide node holds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Slot {
    Empty,
    /// A four-wide node, by index.
    Node(u32),
    /// A light, by its index in the `LightSet`.
    Light(u32),
}

#[derive(Clone, Debug, PartialEq)]
struct Node4 {
    bounds: LightBounds4,
    slots: [Slot; 4],
}

/// Where a descent of [`LightBvh::sample`] stands: the node it is at, its rescaled variate
/// and the probability of the choices so far.
#[derive(Clone, Copy, Debug)]
struct Descent {
    node: usize,
    u: f32,
    pmf: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct LightBvh {
    /// Four-wide nodes; the root is node 0 (none without bounded lights).
    nodes: Vec<Node4>,
    /// Lights without bounds (infinite), chosen uniformly among themselves.
    infinite: Vec<u32>,
    /// Per light of the set: (slot trail from the root, two bits per level; depth), or
    /// `None` for infinite lights.
    trails: Vec<Option<(u64, u32)>>,
}

impl LightBvh {
    /// Over `bounded` (light index, bounds) and `infinite` light indices, for a set of
    /// `light_count` lights.
    pub fn build(bounded: Vec<(u32, LightBounds)>, infinite: Vec<u32>, light_count: usize) -> Self {
        let mut bvh = Self {
            nodes: Vec::new(),
            infinite,
            trails: vec![None; light_count],
        };
        let mut items: Vec<(u32, LightBounds)> = bounded
            .into_iter()
            .filter(|(_, b)| b.phi > 0.0 && b.phi.is_finite())
            .collect();
        if !items.is_empty() {
            let mut binary = Vec::with_capacity(2 * items.len());
            build_binary(&mut binary, &mut items, 0);
            bvh.collapse(&binary, 0, 0, 0);
        }
        bvh
    }

    /// Number of lights in the tree.
    pub fn bounded_count(&self) -> usize {
        self.trails.iter().flatten().count()
    }

    pub fn infinite_count(&self) -> usize {
        self.infinite.len()
    }

    /// The four-wide node for binary node `b` (its children, or grandchildren where a
    /// child is interior), with `trail` and `depth` of the four-wide tree; returns its index.
    fn collapse(&mut self, binary: &[BinaryNode], b: usize, trail: u64, depth: u32) -> u32 {
        let mut members: Vec<usize> = match &binary[b] {
            BinaryNode::Leaf { .. } => vec![b],
            BinaryNode::Interior { second, .. } => vec![b + 1, *second as usize],
        };
        if members.len() == 2 {
            members = members
                .into_iter()
                .flat_map(|m| match &binary[m] {
                    BinaryNode::Leaf { .. } => vec![m],
                    BinaryNode::Interior { second, .. } => vec![m + 1, *second as usize],
                })
                .collect();
        }
        let index = self.nodes.len() as u32;
        let mut bounds: [Option<&LightBounds>; 4] = [None; 4];
        for (k, &m) in members.iter().enumerate() {
            bounds[k] = Some(binary[m].bounds());
        }
        self.nodes.push(Node4 {
            bounds: LightBounds4::new(bounds),
            slots: [Slot::Empty; 4],
        });
        for (k, &m) in members.iter().enumerate() {
            let slot_trail = trail | ((k as u64) << (2 * depth));
            let slot = match &binary[m] {
                BinaryNode::Leaf { light, .. } => {
                    self.trails[*light as usize] = Some((slot_trail, depth + 1));
                    Slot::Light(*light)
                }
                BinaryNode::Interior { .. } => {
                    Slot::Node(self.collapse(binary, m, slot_trail, depth + 1))
                }
            };
            self.nodes[index as usize].slots[k] = slot;
        }
        index
    }

    /// Lights at infinity chosen apart in front of the tree, each in its own slice of width
    /// 1 / (this + 1) at the start of the unit interval (`sample`); 0 without a tree.
    pub fn infinite_apart_count(&self) -> usize {
        if self.nodes.is_empty() {
            0
        } else {
            self.infinite.len()
        }
    }

    fn infinite_probability(&self) -> f32 {
        let tree = usize::from(!self.nodes.is_empty());
        let n = self.infinite.len() + tree;
        if n == 0 {
            0.0
        } else {
            self.infinite.len() as f32 / n as f32
        }
    }

    /// The slots' importances at node `node` and their sum, or `None` where no slot can
    /// contribute.
    #[inline]
    fn weights(&self, node: usize, p: Vec3A, n: Vec3A) -> Option<([f32; 4], f32)> {
        let w = self.nodes[node].bounds.importance(p, n).to_array();
        let total = (w[0] + w[1]) + (w[2] + w[3]);
        (total > 0.0 && total.is_finite()).then_some((w, total))
    }

    /// Picks a light for a light sample at `p` (normal `n`, zero in a medium) with `u` in
    /// [0, 1): (index, probability), or `None` where no light can contribute.
    pub fn sample(&self, p: Vec3A, n: Vec3A, u: f32) -> Option<(u32, f32)> {
        let mut descent = match self.start(u) {
            Ok(descent) => descent,
            Err(picked) => return picked,
        };
        loop {
            if let Some(picked) = self.step(&mut descent, p, n) {
                return picked;
            }
        }
    }

    /// [`Self::sample`] for `K` shading points at once, the same picks bit for bit: the
    /// descents advance a level each in turn, so their chains of dependent steps (each
    /// level's weights wait for the choice above) overlap on the core instead of running
    /// one after the other. Points not `active` pick nothing.
    pub fn sample_lanes<const K: usize>(
        &self,
        p: &[Vec3A; K],
        n: &[Vec3A; K],
        u: &[f32; K],
        active: &[bool; K],
    ) -> [Option<(u32, f32)>; K] {
        let mut picked = [None; K];
        let mut descents: [Option<Descent>; K] = [None; K];
        for k in 0..K {
            if active[k] {
                match self.start(u[k]) {
                    Ok(descent) => descents[k] = Some(descent),
                    Err(pick) => picked[k] = pick,
                }
            }
        }
        while descents.iter().any(Option::is_some) {
            for k in 0..K {
                if let Some(descent) = &mut descents[k] {
                    if let Some(pick) = self.step(descent, p[k], n[k]) {
                        picked[k] = pick;
                        descents[k] = None;
                    }
                }
            }
        }
        picked
    }

    /// A descent from the root for `u`, or the pick made without one (a light at
    /// infinity, or nothing where the tree is empty).
    #[inline(always)]
    fn start(&self, u: f32) -> Result<Descent, Option<(u32, f32)>> {
        let p_inf = self.infinite_probability();
        if u < p_inf {
            let k = self.infinite.len();
            let i = ((u / p_inf * k as f32) as usize).min(k - 1);
            return Err(Some((self.infinite[i], p_inf / k as f32)));
        }
        if self.nodes.is_empty() {
            return Err(None);
        }
        Ok(Descent {
            node: 0,
            u: ((u - p_inf) / (1.0 - p_inf)).min(1.0 - f32::EPSILON),
            pmf: 1.0 - p_inf,
        })
    }

    /// One level of a descent: the pick where it reaches a light (or finds no light that
    /// can contribute), else `None` with the descent moved to the chosen child.
    #[inline(always)]
    fn step(&self, descent: &mut Descent, p: Vec3A, n: Vec3A) -> Option<Option<(u32, f32)>> {
        let Some((w, total)) = self.weights(descent.node, p, n) else {
            return Some(None);
        };
        // The slot whose share of `total` holds u · total (the last live one at the top).
        let target = descent.u * total;
        let mut below = 0.0;
        let mut chosen = 3;
        for (k, &wk) in w.iter().enumerate() {
            if wk > 0.0 && target < below + wk {
                chosen = k;
                break;
            }
            below += wk;
        }
        while w[chosen] <= 0.0 {
            chosen -= 1;
        }
        descent.pmf *= w[chosen] / total;
        descent.u = ((target - below) / w[chosen]).clamp(0.0, 1.0 - f32::EPSILON);
        match self.nodes[descent.node].slots[chosen] {
            Slot::Light(light) => Some(Some((light, descent.pmf))),
            Slot::Node(next) => {
                descent.node = next as usize;
                None
            }
            Slot::Empty => Some(None),
        }
    }

    /// Probability that `sample` at `p`, `n` picks light `light`.
    pub fn pmf(&self, p: Vec3A, n: Vec3A, light: u32) -> f32 {
        let p_inf = self.infinite_probability();
        let Some(&trail) = self.trails.get(light as usize) else {
            return 0.0;
        };
        let Some((bits, depth)) = trail else {
            return if self.infinite.contains(&light) {
                p_inf / self.infinite.len() as f32
            } else {
                0.0
            };
        };
        let mut pmf = 1.0 - p_inf;
        let mut node = 0usize;
        for level in 0..depth {
            let Some((w, total)) = self.weights(node, p, n) else {
                return 0.0;
            };
            let k = ((bits >> (2 * level)) & 3) as usize;
            pmf *= w[k] / total;
            match self.nodes[node].slots[k] {
                Slot::Node(next) => node = next as usize,
                Slot::Light(_) | Slot::Empty => break,
            }
        }
        pmf
    }
}

/// Binary node over `items` (pbrt-v4's split) appended to `nodes` with its subtree; its index.
fn build_binary(nodes: &mut Vec<BinaryNode>, items: &mut [(u32, LightBounds)], depth: u32) -> u32 {
    let index = nodes.len() as u32;
    if let [(light, bounds)] = items {
        nodes.push(BinaryNode::Leaf {
            light: *light,
            bounds: *bounds,
        });
        return index;
    }
    let bounds = items[1..]
        .iter()
        .fold(items[0].1, |acc, (_, b)| acc.union(b));
    nodes.push(BinaryNode::Interior { second: 0, bounds });
    let mid = split(items, &bounds, depth);
    let (first, second) = items.split_at_mut(mid);
    build_binary(nodes, first, depth + 1);
    let second_index = build_binary(nodes, second, depth + 1);
    nodes[index as usize] = BinaryNode::Interior {
        second: second_index,
        bounds,
    };
    index
}

/// pbrt-v4's split cost of a group of lights: φ × the solid angle its normals and θ_e
/// sweep (M_Ω) × the area of its box, × how thin the box is along the split axis (K_r).
fn cost(b: &LightBounds, extent_ratio: f32) -> f32 {
    use std::f32::consts::PI;
    let theta_o = b.normals.cos_theta.clamp(-1.0, 1.0).acos();
    let theta_e = b.cos_theta_e.clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_o = theta_o.sin();
    let m_omega = 2.0 * PI * (1.0 - theta_o.cos())
        + PI / 2.0
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + theta_o.cos());
    let d = b.hi - b.lo;
    let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    b.phi * m_omega * extent_ratio * area.max(f32::MIN_POSITIVE)
}

/// The bucket of `b`'s centroid along `axis` between the centroids' bounds `clo`, `chi`
/// (which differ along it).
fn bucket(b: &LightBounds, axis: usize, clo: Vec3A, chi: Vec3A) -> usize {
    let (lo, hi) = (clo[axis], chi[axis]);
    (((b.centroid()[axis] - lo) / (hi - lo) * BUCKETS as f32) as usize).min(BUCKETS - 1)
}

/// Orders `items` and returns where the second child starts: the cheapest bucket boundary
/// over the three axes (pbrt-v4 `BVHLightSampler::buildBVH`), the median of the longest
/// axis where no boundary separates the centroids or the tree is deep.
fn split(items: &mut [(u32, LightBounds)], bounds: &LightBounds, depth: u32) -> usize {
    let (clo, chi) = items.iter().fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), (_, b)| (lo.min(b.centroid()), hi.max(b.centroid())),
    );
    let extent = bounds.hi - bounds.lo;
    let max_extent = extent.max_element();
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, first bucket of the second child)
    if depth < MEDIAN_DEPTH {
        for axis in 0..3 {
            let (lo, hi) = (clo[axis], chi[axis]);
            if hi <= lo {
                continue;
            }
            let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
            for (_, b) in items.iter() {
                let k = bucket(b, axis, clo, chi);
                buckets[k] = Some(match buckets[k] {
                    Some(acc) => acc.union(b),
                    None => *b,
                });
            }
            let ratio = if extent[axis] > 0.0 {
                max_extent / extent[axis]
            } else {
                1.0
            };
            for boundary in 1..BUCKETS {
                let merge = |range: std::ops::Range<usize>| {
                    buckets[range]
                        .iter()
                        .flatten()
                        .fold(None, |acc: Option<LightBounds>, b| {
                            Some(acc.map_or(*b, |a| a.union(b)))
                        })
                };
                let (Some(left), Some(right)) = (merge(0..boundary), merge(boundary..BUCKETS))
                else {
                    continue;
                };
                let c = cost(&left, ratio) + cost(&right, ratio);
                if best.is_none_or(|(bc, _, _)| c < bc) {
                    best = Some((c, axis, boundary));
                }
            }
        }
    }
    if let Some((_, axis, boundary)) = best {
        let mut mid = 0;
        for i in 0..items.len() {
            if bucket(&items[i].1, axis, clo, chi) < boundary {
                items.swap(i, mid);
                mid += 1;
            }
        }
        if mid > 0 && mid < items.len() {
            return mid;
        }
    }
    // Median of the longest centroid axis (ties broken by light index: deterministic).
    let spread = chi - clo;
    let axis = if spread.x >= spread.y && spread.x >= spread.z {
        0
    } else if spread.y >= spread.z {
        1
    } else {
        2
    };
    items.sort_by(|a, b| {
        a.1.centroid()[axis]
            .total_cmp(&b.1.centroid()[axis])
            .then(a.0.cmp(&b.0))
    });
    items.len() / 2
}

#[cfg(test)]
mod tests {
    use super::super::light_bounds::DirectionCone;
    use super::*;

    fn point_light(p: Vec3A, phi: f32) -> LightBounds {
        LightBounds {
            lo: p,
            hi: p,
            phi,
            normals: DirectionCone::entire_sphere(),
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }

    fn grid(n: usize) -> LightBvh {
        let bounded = (0..n * n)
            .map(|i| {
                let (x, z) = ((i % n) as f32, (i / n) as f32);
                (
                    i as u32,
                    point_light(Vec3A::new(x, 3.0, z), 1.0 + (i % 3) as f32),
                )
            })
            .collect();
        LightBvh::build(bounded, vec![(n * n) as u32], n * n + 1)
    }

    #[test]
    fn the_pmf_sums_to_one_and_equals_what_sample_returns() {
        let bvh = grid(10);
        assert_eq!((bvh.bounded_count(), bvh.infinite_count()), (100, 1));
        for (p, n) in [
            (Vec3A::new(2.3, 0.0, 4.1), Vec3A::Y),
            (Vec3A::new(-5.0, 1.0, 20.0), Vec3A::new(0.6, 0.8, 0.0)),
            (Vec3A::new(4.5, 3.0, 4.5), Vec3A::ZERO),
        ] {
            let total: f32 = (0..101).map(|l| bvh.pmf(p, n, l)).sum();
            assert!((total - 1.0).abs() < 1e-4, "{p}: {total}");
            for k in 0..1000 {
                let u = (k as f32 + 0.5) / 1000.0;
                let (l, pmf) = bvh.sample(p, n, u).unwrap();
                assert!(
                    (pmf - bvh.pmf(p, n, l)).abs() <= 1e-6 * pmf.max(1e-6),
                    "{l}"
                );
            }
        }
    }

    /// Descents side by side pick what each picks alone, bit for bit; inactive points pick
    /// nothing.
    #[test]
    fn lanes_pick_what_each_point_picks_alone() {
        let bvh = grid(10);
        let mut rng = prism_testkit::chi2::SplitMix64(3);
        let mut next = || rng.next_f32();
        for _ in 0..500 {
            let p: [Vec3A; 4] = std::array::from_fn(|_| {
                Vec3A::new(12.0 * next() - 1.0, 4.0 * next(), 12.0 * next() - 1.0)
            });
            let n: [Vec3A; 4] =
                std::array::from_fn(|k| if k == 3 { Vec3A::ZERO } else { Vec3A::Y });
            let u: [f32; 4] = std::array::from_fn(|_| next());
            let active = [true, true, false, true];
            let lanes = bvh.sample_lanes(&p, &n, &u, &active);
            for k in 0..4 {
                let alone = if active[k] {
                    bvh.sample(p[k], n[k], u[k])
                } else {
                    None
                };
                assert_eq!(
                    lanes[k].map(|(l, pmf)| (l, pmf.to_bits())),
                    alone.map(|(l, pmf)| (l, pmf.to_bits()))
                );
            }
        }
    }

    #[test]
    fn nearby_lights_are_chosen_more_often_than_far_ones() {
        let bvh = grid(10);
        let p = Vec3A::new(0.0, 0.0, 0.0);
        let near = bvh.pmf(p, Vec3A::Y, 0);
        let far = bvh.pmf(p, Vec3A::Y, 99);
        assert!(near > 20.0 * far, "{near} {far}");
        // The infinite light keeps 1 / (1 + 1).
        assert!((bvh.pmf(p, Vec3A::Y, 100) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn lights_behind_a_one_sided_panel_get_nothing() {
        let panel = |x: f32, down: bool| LightBounds {
            lo: Vec3A::new(x - 0.2, 2.0, -0.2),
            hi: Vec3A::new(x + 0.2, 2.0, 0.2),
            phi: 1.0,
            normals: DirectionCone::of_direction(if down { Vec3A::NEG_Y } else { Vec3A::Y }),
            cos_theta_e: 0.0,
            two_sided: false,
        };
        let bvh = LightBvh::build(
            vec![(0, panel(0.0, true)), (1, panel(1.0, false))],
            vec![],
            2,
        );
        let p = Vec3A::new(0.5, 0.0, 0.0);
        assert_eq!(bvh.pmf(p, Vec3A::Y, 1), 0.0);
        assert!((bvh.pmf(p, Vec3A::Y, 0) - 1.0).abs() < 1e-6);
        for k in 0..100 {
            assert_eq!(
                bvh.sample(p, Vec3A::Y, k as f32 / 100.0).map(|s| s.0),
                Some(0)
            );
        }
        // Above both panels only the upward one can light a point.
        let q = Vec3A::new(0.5, 4.0, 0.0);
        assert_eq!(bvh.pmf(q, Vec3A::NEG_Y, 0), 0.0);
    }

    /// Each lane gives its bound's importance as evaluated alone (lanes do not mix), an
    /// empty lane 0.
    #[test]
    fn four_lanes_evaluate_each_bound_alone() {
        let panel = LightBounds {
            lo: Vec3A::new(-0.3, 2.0, -0.3),
            hi: Vec3A::new(0.3, 2.0, 0.3),
            phi: 2.0,
            normals: DirectionCone::of_direction(Vec3A::NEG_Y),
            cos_theta_e: 0.0,
            two_sided: true,
        };
        let spot = LightBounds {
            normals: DirectionCone {
                w: Vec3A::new(0.6, -0.8, 0.0),
                cos_theta: 0.9,
            },
            cos_theta_e: 0.95,
            ..point_light(Vec3A::new(1.0, 2.5, -1.0), 3.0)
        };
        let lamp = point_light(Vec3A::new(-2.0, 1.0, 0.5), 1.0);
        let four = LightBounds4::new([Some(&panel), Some(&spot), Some(&lamp), None]);
        for (p, n) in [
            (Vec3A::ZERO, Vec3A::Y),
            (Vec3A::new(1.5, 0.0, -1.0), Vec3A::new(0.0, 0.6, 0.8)),
            (Vec3A::new(0.1, 2.0, 0.1), Vec3A::ZERO),
            (Vec3A::new(0.0, 5.0, 0.0), Vec3A::NEG_Y),
        ] {
            let lanes = four.importance(p, n).to_array();
            for (k, b) in [panel, spot, lamp].iter().enumerate() {
                let alone = b.importance(p, n);
                assert!(
                    (lanes[k] - alone).abs() <= 1e-5 * alone.max(1e-6),
                    "{p} lane {k}: {} vs {alone}",
                    lanes[k]
                );
            }
            assert_eq!(lanes[3], 0.0);
        }
    }

    #[test]
    fn identical_positions_still_build_a_shallow_tree() {
        let bounded = (0..1000)
            .map(|i| (i as u32, point_light(Vec3A::ONE, 1.0)))
            .collect();
        let bvh = LightBvh::build(bounded, vec![], 1000);
        let depth = bvh.trails.iter().flatten().map(|t| t.1).max().unwrap();
        assert!(depth <= 6, "{depth} four-wide levels");
        let total: f32 = (0..1000)
            .map(|l| bvh.pmf(Vec3A::ZERO, Vec3A::ZERO, l))
            .sum();
        assert!((total - 1.0).abs() < 1e-4);
    }
}
