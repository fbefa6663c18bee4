//! The hierarchy the links connect: a binary cluster tree over the input patches (Smits,
//! Arvo & Greenberg 1994; split at the median centre along the widest axis) whose leaves
//! are the patches' root elements, each the root of its own lazily built quadtree.

use glam::Vec3A;

use crate::element::ElementShape;

/// A node: a cluster of input patches or a (sub-)element of one patch.
#[derive(Clone, Debug)]
pub(crate) struct Node {
    pub kind: NodeKind,
    /// Surface area below the node, m².
    pub area_m2: f32,
    pub lo: Vec3A,
    pub hi: Vec3A,
}

#[derive(Clone, Debug)]
pub(crate) enum NodeKind {
    Cluster {
        children: [u32; 2],
        /// Range of [`Hierarchy::order`] holding the cluster's patches.
        patches: (u32, u32),
    },
    Element {
        shape: ElementShape,
        patch: u32,
        level: u8,
        /// Index of the first of four consecutive children; `None` for a leaf.
        first_child: Option<u32>,
    },
}

pub(crate) struct Hierarchy {
    pub nodes: Vec<Node>,
    pub root: u32,
    /// Node of each input patch's root element.
    pub patch_root: Vec<u32>,
    /// Input patches in cluster order (each cluster's patches are contiguous).
    pub order: Vec<u32>,
    /// Prefix sums of the areas of `order` (length + 1), for area-weighted sampling.
    pub order_area_prefix: Vec<f64>,
}

impl Hierarchy {
    pub fn build(shapes: &[ElementShape]) -> Self {
        let mut nodes: Vec<Node> = shapes
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let (lo, hi) = s.bounds();
                Node {
                    kind: NodeKind::Element {
                        shape: *s,
                        patch: i as u32,
                        level: 0,
                        first_child: None,
                    },
                    area_m2: s.area_m2(),
                    lo,
                    hi,
                }
            })
            .collect();
        let patch_root = (0..shapes.len() as u32).collect();
        let mut order: Vec<u32> = (0..shapes.len() as u32).collect();
        let centres: Vec<Vec3A> = shapes.iter().map(|s| s.centre()).collect();
        let root = build_clusters(&mut nodes, &mut order, 0, &centres);
        let mut order_area_prefix = Vec::with_capacity(order.len() + 1);
        let mut acc = 0.0f64;
        order_area_prefix.push(0.0);
        for &p in &order {
            acc += f64::from(shapes[p as usize].area_m2());
            order_area_prefix.push(acc);
        }
        Self {
            nodes,
            root,
            patch_root,
            order,
            order_area_prefix,
        }
    }

    /// Point `k` of `count` area-weighted points over the patches of a cluster (its
    /// `patches` range of `order`): stratified over the cluster's area by `r2(k, streams.0)`
    /// and placed within its patch by that point's second coordinate and
    /// `r2(k, streams.1)`. The patch, its root element's shape and the point; `None` if the
    /// patch's root is not an element.
    pub fn cluster_point(
        &self,
        patches: (u32, u32),
        k: usize,
        count: usize,
        streams: (u32, u32),
    ) -> Option<(u32, ElementShape, Vec3A)> {
        let prefix = &self.order_area_prefix;
        let (a0, a1) = (prefix[patches.0 as usize], prefix[patches.1 as usize]);
        let (t, jitter) = crate::solver::r2(k as u32, streams.0);
        let target = a0 + (a1 - a0) * ((k as f64 + f64::from(t)) / count as f64);
        let i = prefix[patches.0 as usize..=patches.1 as usize]
            .partition_point(|&a| a <= target)
            .saturating_sub(1)
            .min((patches.1 - patches.0 - 1) as usize);
        let patch = self.order[patches.0 as usize + i];
        let NodeKind::Element { shape, .. } =
            self.nodes[self.patch_root[patch as usize] as usize].kind
        else {
            return None;
        };
        let (u, v) =
            crate::solver::fold_into(&shape, jitter, crate::solver::r2(k as u32, streams.1).0);
        Some((patch, shape, shape.point(u, v)))
    }

    /// The area of the patches in a cluster's `patches` range, m².
    pub fn cluster_area_m2(&self, patches: (u32, u32)) -> f64 {
        self.order_area_prefix[patches.1 as usize] - self.order_area_prefix[patches.0 as usize]
    }

    /// The children of node `n` (none for a leaf element).
    pub fn children(&self, n: u32) -> std::iter::Take<std::array::IntoIter<u32, 4>> {
        let (ids, count) = match self.nodes[n as usize].kind {
            NodeKind::Cluster { children, .. } => ([children[0], children[1], 0, 0], 2),
            NodeKind::Element {
                first_child: Some(f),
                ..
            } => ([f, f + 1, f + 2, f + 3], 4),
            NodeKind::Element {
                first_child: None, ..
            } => ([0; 4], 0),
        };
        ids.into_iter().take(count)
    }

    /// Creates the four children of element `n` if it has none.
    pub fn split_element(&mut self, n: u32) {
        let (shape, patch, level) = match self.nodes[n as usize].kind {
            NodeKind::Element {
                shape,
                patch,
                level,
                first_child: None,
            } => (shape, patch, level),
            NodeKind::Element { .. } | NodeKind::Cluster { .. } => return,
        };
        let first = self.nodes.len() as u32;
        for child in shape.children() {
            let (lo, hi) = child.bounds();
            self.nodes.push(Node {
                kind: NodeKind::Element {
                    shape: child,
                    patch,
                    level: level + 1,
                    first_child: None,
                },
                area_m2: child.area_m2(),
                lo,
                hi,
            });
        }
        if let NodeKind::Element { first_child, .. } = &mut self.nodes[n as usize].kind {
            *first_child = Some(first);
        }
    }
}

/// Builds the clusters over `order[..]` (whose first element sits at `offset` of the whole
/// order) and returns the subtree's root.
fn build_clusters(nodes: &mut Vec<Node>, order: &mut [u32], offset: u32, centres: &[Vec3A]) -> u32 {
    if order.len() == 1 {
        return order[0];
    }
    let (lo, hi) = order.iter().fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(centres[p as usize]), hi.max(centres[p as usize])),
    );
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        centres[a as usize][axis].total_cmp(&centres[b as usize][axis])
    });
    let (left, right) = order.split_at_mut(mid);
    let a = build_clusters(nodes, left, offset, centres);
    let b = build_clusters(nodes, right, offset + mid as u32, centres);
    let (na, nb) = (&nodes[a as usize], &nodes[b as usize]);
    let node = Node {
        kind: NodeKind::Cluster {
            children: [a, b],
            patches: (offset, offset + order.len() as u32),
        },
        area_m2: na.area_m2 + nb.area_m2,
        lo: na.lo.min(nb.lo),
        hi: na.hi.max(nb.hi),
    };
    nodes.push(node);
    nodes.len() as u32 - 1
}
