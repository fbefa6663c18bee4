//! The interpolated final gather (Mostefaoui et al. §5). Per receiver element, the light
//! its sources reflect (B − B_e: light that bounced at least once) is stored on the
//! element's vertices in direction bins — the paper's 4D structure of u, v and two
//! direction dimensions — wherever a source's light varies over the element by at most ε
//! of the element's total. The sources that vary more (shadow boundaries, near sources)
//! form the gathering list: the renderer's gather rays read the solution only where they
//! hit a listed source. Built once per
//! element and reused by every view.

use glam::Vec3A;

use crate::element::ElementShape;
use crate::form_factor::{area_sample_factor, faces, point_to_polygon};
use crate::hierarchy::NodeKind;
use crate::solver::{sample_point, Radiosity, Visibility};

/// Direction bins per hemisphere: rings of equal solid angle × sectors.
const RINGS: usize = 4;
const SECTORS: usize = 8;
const BINS: usize = RINGS * SECTORS;
/// Points inside the receiver besides its vertices: they measure the variation.
const INTERIOR_POINTS: usize = 4;
/// Points on an element source (visibility) and on a cluster source (area samples).
const ELEMENT_SOURCE_POINTS: usize = 4;
const CLUSTER_SOURCE_POINTS: usize = 8;
/// An element nearer than this many times its own and the receiver's radii together is
/// opened before it is evaluated: one constant source cannot stand for it.
const NEAR_FACTOR: f32 = 2.0;
/// A cluster is opened unless it is this many times its radius away (about 11° across):
/// its few disk points would otherwise freeze their sampling error into the vertices.
const CLUSTER_NEAR_FACTOR: f32 = 10.0;
/// The most bands a gather holds.
pub const MAX_BANDS: usize = 64;

/// The gather structure of one receiver element.
#[derive(Clone, Debug, PartialEq)]
pub struct ReceiverGather {
    shape: ElementShape,
    bands: usize,
    vertices: usize,
    /// The direction bins holding light at any vertex.
    bins: Vec<u8>,
    /// Per vertex × used bin: Σ E_total · ω of what fell into it (the irradiance-weighted
    /// direction; E_total is the band sum).
    directions: Vec<Vec3A>,
    /// Per vertex × used bin × band: irradiance (the solution's units per m²).
    irradiance: Vec<f32>,
    /// Per vertex × band: the irradiance of all bins together.
    vertex_totals: Vec<f32>,
    /// The gathering list: the leaf ids ([`Radiosity::leaf_id`]) of the sources whose
    /// light varies too much over the receiver to be interpolated, sorted; the
    /// renderer's gather rays that hit one read the solution there.
    listed: Vec<u32>,
    /// Sources stored on the vertices.
    pub interpolated_sources: u32,
}

/// A source evaluated at the receiver's points.
struct Candidate {
    node: u32,
    /// Per receiver point: the band sum of its irradiance.
    totals: Vec<f32>,
    /// (receiver point, direction from it, irradiance per band).
    pieces: Vec<(usize, Vec3A, [f32; MAX_BANDS])>,
    /// Reflected radiosity per band: an element source's mean over its points (what
    /// its irradiance is computed from).
    reflected: [f32; MAX_BANDS],
}

/// The receiver as the evaluation sees it.
struct Receiver {
    patch: u32,
    normal: Vec3A,
    centre: Vec3A,
    radius_m: f32,
    points: Vec<Vec3A>,
    covered: Vec<bool>,
}

impl Radiosity {
    /// The hierarchy's node count: the range of [`Self::leaf_id`].
    pub fn node_count(&self) -> usize {
        self.hierarchy.nodes.len()
    }

    /// The leaf element of input patch `patch` holding point `p` (projected onto the
    /// patch's plane, clamped into it), as an index below [`Self::node_count`].
    pub fn leaf_id(&self, patch: usize, p: Vec3A) -> u32 {
        self.leaf_node(patch, p)
    }

    /// The gather structure of leaf element `leaf` (from [`Self::leaf_id`]) for the
    /// variation bound `epsilon` (relative to the element's total reflected irradiance);
    /// `None` when `leaf` is not an element.
    pub fn receiver_gather(
        &self,
        leaf: u32,
        epsilon: f32,
        vis: &dyn Visibility,
    ) -> Option<ReceiverGather> {
        assert!(self.bands <= MAX_BANDS, "at most {MAX_BANDS} bands");
        let NodeKind::Element { shape, patch, .. } = self.hierarchy.nodes[leaf as usize].kind
        else {
            return None;
        };
        let normal = shape.normal();
        let centre = shape.centre();
        let (corners, vertices) = shape.corners();
        // Vertices inset by 1 % towards the centre: a corner point on the edge of a wall
        // would send its rays along the wall.
        let points: Vec<Vec3A> = corners[..vertices]
            .iter()
            .map(|&c| c + 0.01 * (centre - c))
            .chain((0..INTERIOR_POINTS).map(|k| sample_point(&shape, k, 5)))
            .collect();
        // A point beyond an occluder that cuts the element (the floor a box sinks into)
        // counts as covered too: interpolating from it would carry that occluder's shadow
        // over the whole element.
        let mut covered: Vec<bool> = points.iter().map(|&p| vis.covered(p, normal)).collect();
        let anchor = if vis.covered(centre, normal) {
            (0..points.len()).find(|&k| !covered[k]).map(|k| points[k])
        } else {
            Some(centre)
        };
        if let Some(anchor) = anchor {
            for (k, &p) in points.iter().enumerate() {
                covered[k] = covered[k] || (p != anchor && !vis.visible(anchor, normal, p, normal));
            }
        }
        let radius_m = corners[..vertices]
            .iter()
            .map(|&c| (c - centre).length())
            .fold(0.0f32, f32::max);
        let rx = Receiver {
            patch,
            normal,
            centre,
            radius_m,
            points,
            covered,
        };
        let mut gather = ReceiverGather {
            shape,
            bands: self.bands,
            vertices,
            bins: Vec::new(),
            directions: Vec::new(),
            irradiance: Vec::new(),
            vertex_totals: Vec::new(),
            listed: Vec::new(),
            interpolated_sources: 0,
        };
        if rx.covered.iter().all(|&c| c) {
            return Some(gather);
        }

        let mut todo = Vec::new();
        self.sources_below(self.hierarchy.root, &rx, &mut todo);
        let mut candidates: Vec<Candidate> = todo
            .iter()
            .filter_map(|&s| self.evaluate(s, &rx, vis))
            .collect();
        // The element's total reflected irradiance: the scale of ε.
        let free: Vec<usize> = (0..rx.points.len()).filter(|&k| !rx.covered[k]).collect();
        let total = free
            .iter()
            .map(|&k| candidates.iter().map(|c| c.totals[k]).sum::<f32>())
            .sum::<f32>()
            / free.len() as f32;
        let threshold = epsilon * total;
        let spread = |c: &Candidate| {
            let (lo, hi) = free.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &k| {
                (lo.min(c.totals[k]), hi.max(c.totals[k]))
            });
            hi - lo
        };

        // Sources varying more than the bound are opened down to the leaves; leaves that
        // still vary go to the gathering list.
        let mut accepted: Vec<Candidate> = Vec::new();
        let mut listed: Vec<Candidate> = Vec::new();
        while let Some(c) = candidates.pop() {
            let leaf = self.hierarchy.children(c.node).count() == 0;
            // A near leaf is always listed: the gather ray that hits it sees the light
            // across it (the renderer continues the path there), not its mean.
            let near_leaf = leaf && self.is_near(c.node, &rx);
            if spread(&c) <= threshold && !near_leaf {
                accepted.push(c);
                continue;
            }
            if leaf {
                listed.push(c);
                continue;
            }
            let mut below = Vec::new();
            for child in self.hierarchy.children(c.node) {
                self.sources_below(child, &rx, &mut below);
            }
            candidates.extend(below.iter().filter_map(|&s| self.evaluate(s, &rx, vis)));
        }

        gather.interpolated_sources = accepted.len() as u32;
        gather.store(&accepted, &rx);
        gather.listed = listed.iter().map(|c| c.node).collect();
        gather.listed.sort_unstable();
        Some(gather)
    }

    /// The nodes at and below `s` to evaluate as sources for the receiver: those with
    /// light in front of its plane, other than its own patch, opened while near.
    fn sources_below(&self, s: u32, rx: &Receiver, out: &mut Vec<u32>) {
        let mut stack = vec![s];
        while let Some(s) = stack.pop() {
            let node = &self.hierarchy.nodes[s as usize];
            if self.radiosity_max[s as usize] <= 0.0 {
                continue;
            }
            if matches!(node.kind, NodeKind::Element { patch, .. } if patch == rx.patch) {
                continue;
            }
            // Entirely behind the receiver's plane (the box's farthest corner in front).
            let reach = (node.hi - node.lo) * 0.5;
            let mid = (node.hi + node.lo) * 0.5;
            let front = rx.normal.dot(mid - rx.centre) + reach.dot(rx.normal.abs());
            if front <= 0.0 {
                continue;
            }
            let near = self.is_near(s, rx);
            let mut children = self.hierarchy.children(s).peekable();
            if near && children.peek().is_some() {
                stack.extend(children);
            } else {
                out.push(s);
            }
        }
    }

    /// Whether node `s` is too near the receiver for one constant value to stand for it:
    /// an element within `NEAR_FACTOR` times their radii, a cluster within
    /// `CLUSTER_NEAR_FACTOR` times its own.
    fn is_near(&self, s: u32, rx: &Receiver) -> bool {
        let node = &self.hierarchy.nodes[s as usize];
        let radius_m = ((node.hi - node.lo) * 0.5).length();
        let distance = ((node.hi + node.lo) * 0.5 - rx.centre).length();
        match node.kind {
            NodeKind::Element { .. } => distance < NEAR_FACTOR * (radius_m + rx.radius_m),
            NodeKind::Cluster { .. } => {
                distance < CLUSTER_NEAR_FACTOR * radius_m + NEAR_FACTOR * rx.radius_m
            }
        }
    }

    /// Reflected radiosity (B − B_e) per band at point `y` of input patch `patch`; on a
    /// directional patch its reflected exitance towards `to`.
    fn reflected_at(&self, patch: u32, y: Vec3A, to: Vec3A, out: &mut [f32; MAX_BANDS]) {
        let b = self
            .leaf_towards(patch as usize, y, (to - y).normalize_or_zero())
            .radiosity;
        let e = self.emission(patch as usize);
        for k in 0..self.bands {
            out[k] = (b[k] - e[k]).max(0.0);
        }
    }

    /// The irradiance node `s` sends to each of the receiver's points; `None` when it
    /// reflects nothing towards them.
    fn evaluate(&self, s: u32, rx: &Receiver, vis: &dyn Visibility) -> Option<Candidate> {
        let bands = self.bands;
        let count = rx.points.len();
        let mut c = Candidate {
            node: s,
            totals: vec![0.0; count],
            pieces: Vec::new(),
            reflected: [0.0; MAX_BANDS],
        };
        match self.hierarchy.nodes[s as usize].kind {
            NodeKind::Element { shape, patch, .. } => {
                // Exact unoccluded factor × the free fraction of rays to its points; the
                // radiosity is the mean over those points (the leaves under them).
                let n_s = shape.normal();
                let ys: Vec<Vec3A> = (0..ELEMENT_SOURCE_POINTS)
                    .map(|j| sample_point(&shape, j, 6))
                    .collect();
                let mut b = [0.0f32; MAX_BANDS];
                for &y in &ys {
                    self.reflected_at(patch, y, rx.centre, &mut b);
                    for (r, &x) in c.reflected[..bands].iter_mut().zip(&b[..bands]) {
                        *r += x / ys.len() as f32;
                    }
                }
                if c.reflected[..bands].iter().all(|&x| x <= 0.0) {
                    return None;
                }
                let (corners, n) = shape.corners();
                let toward = shape.centre();
                for (k, &x) in rx.points.iter().enumerate() {
                    if rx.covered[k] {
                        continue;
                    }
                    let f = point_to_polygon(x, rx.normal, &corners[..n], n_s);
                    if f <= 0.0 {
                        continue;
                    }
                    // Visibility over the point pairs that face each other: the factor
                    // already leaves out the part behind the receiver's plane.
                    let facing = ys.iter().filter(|&&y| faces(x, rx.normal, y, n_s));
                    let (pairs, free) = facing.fold((0u32, 0u32), |(n, f), &y| {
                        (n + 1, f + u32::from(vis.visible(x, rx.normal, y, n_s)))
                    });
                    let f = if pairs == 0 {
                        f
                    } else {
                        f * free as f32 / pairs as f32
                    };
                    if f <= 0.0 {
                        continue;
                    }
                    let mut e = [0.0f32; MAX_BANDS];
                    for (x, &r) in e[..bands].iter_mut().zip(&c.reflected[..bands]) {
                        *x = f * r;
                    }
                    c.totals[k] = e[..bands].iter().sum();
                    c.pieces.push((k, (toward - x).normalize_or_zero(), e));
                }
            }
            NodeKind::Cluster { patches, .. } => {
                // Area-weighted points over the cluster's patches, each standing for the
                // cluster's area over the point count.
                let piece_m2 =
                    (self.hierarchy.cluster_area_m2(patches) / CLUSTER_SOURCE_POINTS as f64) as f32;
                let mut b = [0.0f32; MAX_BANDS];
                for j in 0..CLUSTER_SOURCE_POINTS {
                    let Some((patch, shape, y)) =
                        self.hierarchy
                            .cluster_point(patches, j, CLUSTER_SOURCE_POINTS, (7, 8))
                    else {
                        continue;
                    };
                    let n_s = shape.normal();
                    self.reflected_at(patch, y, rx.centre, &mut b);
                    if b[..bands].iter().all(|&x| x <= 0.0) {
                        continue;
                    }
                    for (k, &x) in rx.points.iter().enumerate() {
                        if rx.covered[k] {
                            continue;
                        }
                        let f = area_sample_factor(x, rx.normal, y, n_s, piece_m2);
                        if f <= 0.0 || !vis.visible(x, rx.normal, y, n_s) {
                            continue;
                        }
                        let mut e = [0.0f32; MAX_BANDS];
                        for i in 0..bands {
                            e[i] = f * b[i];
                        }
                        c.totals[k] += e[..bands].iter().sum::<f32>();
                        c.pieces.push((k, (y - x).normalize_or_zero(), e));
                    }
                }
            }
        }
        (!c.pieces.is_empty()).then_some(c)
    }
}

impl ReceiverGather {
    /// The direction bin of unit direction `w` in the receiver's hemisphere.
    fn bin_of(&self, w: Vec3A) -> usize {
        let (n, t, b) = frame(&self.shape);
        let cos_theta = w.dot(n).clamp(0.0, 1.0);
        let ring = (((1.0 - cos_theta) * RINGS as f32) as usize).min(RINGS - 1);
        let phi = w.dot(b).atan2(w.dot(t)).rem_euclid(std::f32::consts::TAU);
        let sector = ((phi / std::f32::consts::TAU * SECTORS as f32) as usize).min(SECTORS - 1);
        ring * SECTORS + sector
    }

    /// Bins the accepted sources' light at every point, then keeps the vertices' (a
    /// covered vertex takes the mean of the uncovered points, so that interpolating
    /// towards it does not darken the visible part).
    fn store(&mut self, accepted: &[Candidate], rx: &Receiver) {
        let bands = self.bands;
        let count = rx.points.len();
        let mut dense_e = vec![0.0f32; count * BINS * bands];
        let mut dense_d = vec![Vec3A::ZERO; count * BINS];
        let mut used = [false; BINS];
        for c in accepted {
            for (k, w, e) in &c.pieces {
                let bin = self.bin_of(*w);
                used[bin] = true;
                let cell = k * BINS + bin;
                let total: f32 = e[..bands].iter().sum();
                dense_d[cell] += *w * total;
                for i in 0..bands {
                    dense_e[cell * bands + i] += e[i];
                }
            }
        }
        let free: Vec<usize> = (0..count).filter(|&k| !rx.covered[k]).collect();
        for v in 0..self.vertices {
            if !rx.covered[v] {
                continue;
            }
            for bin in 0..BINS {
                let cell = v * BINS + bin;
                dense_d[cell] = free.iter().map(|&k| dense_d[k * BINS + bin]).sum::<Vec3A>()
                    / free.len() as f32;
                for i in 0..bands {
                    dense_e[cell * bands + i] = free
                        .iter()
                        .map(|&k| dense_e[(k * BINS + bin) * bands + i])
                        .sum::<f32>()
                        / free.len() as f32;
                }
            }
        }
        self.bins = (0..BINS as u8).filter(|&b| used[b as usize]).collect();
        for v in 0..self.vertices {
            for i in 0..bands {
                let total = (0..BINS)
                    .map(|bin| dense_e[(v * BINS + bin) * bands + i])
                    .sum();
                self.vertex_totals.push(total);
            }
        }
        for v in 0..self.vertices {
            for &bin in &self.bins {
                let cell = v * BINS + bin as usize;
                self.directions.push(dense_d[cell]);
                self.irradiance
                    .extend_from_slice(&dense_e[cell * bands..(cell + 1) * bands]);
            }
        }
    }

    /// The interpolated light arriving at point `p` of the element, in the bands
    /// `bands` (at most 16; a renderer's lanes): `each(direction, irradiance per entry of
    /// bands)` per direction bin, the vertices' values blended bilinearly (parallelogram)
    /// or barycentrically (triangle).
    pub fn interpolate(&self, p: Vec3A, bands: &[usize], mut each: impl FnMut(Vec3A, &[f32])) {
        let weights = self.weights(p);
        let used = self.bins.len();
        let stride = self.bands;
        let lanes = bands.len().min(16);
        let mut e = [0.0f32; 16];
        for b in 0..used {
            let mut d = Vec3A::ZERO;
            e[..lanes].fill(0.0);
            for (vertex, &w) in weights[..self.vertices].iter().enumerate() {
                let cell = vertex * used + b;
                d += w * self.directions[cell];
                let row = &self.irradiance[cell * stride..(cell + 1) * stride];
                for (x, &band) in e[..lanes].iter_mut().zip(bands) {
                    *x += w * row[band];
                }
            }
            let d = d.normalize_or_zero();
            if d != Vec3A::ZERO {
                each(d, &e[..lanes]);
            }
        }
    }

    /// The interpolated irradiance of all direction bins together at point `p`, in the
    /// bands `bands` (at most 16): what a Lambertian receiver reflects, times ρ/π.
    pub fn interpolate_total(&self, p: Vec3A, bands: &[usize], out: &mut [f32]) {
        out.fill(0.0);
        if self.vertex_totals.is_empty() {
            return; // every point covered: nothing stored
        }
        let weights = self.weights(p);
        for (vertex, &w) in weights[..self.vertices].iter().enumerate() {
            let row = &self.vertex_totals[vertex * self.bands..(vertex + 1) * self.bands];
            for (x, &band) in out.iter_mut().zip(bands) {
                *x += w * row[band];
            }
        }
    }

    /// The vertices' interpolation weights at `p`: bilinear (parallelogram) or
    /// barycentric (triangle).
    fn weights(&self, p: Vec3A) -> [f32; 4] {
        let (mut u, mut v) = self.shape.parameters_of(p);
        u = u.clamp(0.0, 1.0);
        v = v.clamp(0.0, 1.0);
        match self.shape {
            ElementShape::Parallelogram { .. } => {
                [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v]
            }
            ElementShape::Triangle { .. } => {
                let s = (u + v).max(1.0);
                let (u, v) = (u / s, v / s);
                [1.0 - u - v, u, v, 0.0]
            }
        }
    }

    /// The gathering list.
    pub fn listed(&self) -> &[u32] {
        &self.listed
    }

    /// Whether leaf `leaf` is on the gathering list.
    pub fn is_listed(&self, leaf: u32) -> bool {
        self.listed.binary_search(&leaf).is_ok()
    }

    /// Bytes held (for the statistics).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.bins.len()
            + self.directions.len() * std::mem::size_of::<Vec3A>()
            + (self.irradiance.len() + self.vertex_totals.len()) * 4
            + self.listed.len() * 4
    }
}

/// The receiver's frame: normal, tangent along its first edge, bitangent.
fn frame(shape: &ElementShape) -> (Vec3A, Vec3A, Vec3A) {
    let n = shape.normal();
    let (c, _) = shape.corners();
    let t = (c[1] - c[0]).normalize_or_zero();
    (n, t, n.cross(t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::{InputPatch, NoDirectLight, RadiositySettings, Unoccluded};

    /// A closed unit cube, every face emitting `emission` with reflectance `rho`.
    fn furnace(rho: f32, emission: f32) -> Radiosity {
        let (o, x, y, z) = (Vec3A::ZERO, Vec3A::X, Vec3A::Y, Vec3A::Z);
        // Inward-facing; the floor (normal +z) first.
        let faces = [
            (o, x, y),
            (z, y, x),
            (o, z, x),
            (y, x, z),
            (o, y, z),
            (x, z, y),
        ];
        let patches: Vec<InputPatch> = faces
            .iter()
            .enumerate()
            .map(|(i, &(p0, e1, e2))| InputPatch {
                shape: ElementShape::Parallelogram { p0, e1, e2 },
                reflectance: vec![rho; 2],
                emission: vec![emission; 2],
                surface: i as u32,
                directional: None,
            })
            .collect();
        let settings = RadiositySettings {
            error_bound_rel: 0.000_25,
            ..RadiositySettings::default()
        };
        let mut r = Radiosity::new(&patches, 2, settings).unwrap();
        for _ in 0..3 {
            r.iterate(&Unoccluded, &NoDirectLight).unwrap();
        }
        r
    }

    /// Inside the furnace every point receives E_reflected = ρE/(1 − ρ) from the other
    /// faces (B − B_e summed over the enclosure): the interpolated light plus the listed
    /// sources' exact factors must give it at the receiver's points.
    #[test]
    fn furnace_gather_receives_the_reflected_light() {
        let (rho, e) = (0.5f32, 1.0f32);
        let r = furnace(rho, e);
        let expected = rho * e / (1.0 - rho);
        for epsilon in [0.1f32, 0.01, 0.0] {
            let p = Vec3A::new(0.3, 0.6, 0.0);
            let leaf = r.leaf_id(0, p);
            let g = r.receiver_gather(leaf, epsilon, &Unoccluded).unwrap();
            let mut got = [0.0f32; 2];
            g.interpolate(p, &[0, 1], |_, e| {
                got[0] += e[0];
                got[1] += e[1];
            });
            let n = Vec3A::new(0.0, 0.0, 1.0);
            // A listed leaf's light, by its exact factor (what the traced gather reads).
            for &leaf in g.listed() {
                let NodeKind::Element { shape, patch, .. } = r.hierarchy.nodes[leaf as usize].kind
                else {
                    unreachable!("listed sources are leaf elements")
                };
                let (corners, count) = shape.corners();
                let reflected = r.node_radiosity(leaf)[0] - r.emission(patch as usize)[0];
                got[0] += reflected * point_to_polygon(p, n, &corners[..count], shape.normal());
            }
            let rel = (got[0] - expected).abs() / expected;
            assert!(
                rel < 0.03,
                "ε {epsilon}: gathered {} vs {expected} ({} listed)",
                got[0],
                g.listed().len()
            );
        }
    }

    /// With ε = 0 every varying source is listed; with a huge ε none is.
    #[test]
    fn epsilon_moves_sources_between_the_list_and_the_vertices() {
        let r = furnace(0.5, 1.0);
        let leaf = r.leaf_id(0, Vec3A::new(0.5, 0.5, 0.0));
        let all_listed = r.receiver_gather(leaf, 0.0, &Unoccluded).unwrap();
        let none_listed = r.receiver_gather(leaf, 1e6, &Unoccluded).unwrap();
        assert!(none_listed.listed().is_empty());
        assert!(all_listed.listed().len() > 4);
        for &leaf in all_listed.listed() {
            assert!(all_listed.is_listed(leaf));
            assert!(!none_listed.is_listed(leaf));
        }
    }
}
