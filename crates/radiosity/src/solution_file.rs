//! A solution as bytes, to render more views of it later (`prism render
//! --save-solution`/`--load-solution`): the hierarchy, the links and every per-node value,
//! little-endian, after the magic `PRISMRAD` and a format version.

use std::sync::Arc;

use glam::Vec3A;

use crate::bins::SPHERE_BINS;
use crate::directional::{DirectionalSide, DirectionalState, DirectionalSurface, NO_SLOT};
use crate::element::ElementShape;
use crate::hierarchy::{Hierarchy, Node, NodeKind};
use crate::solver::{Link, LinkTotals, Radiosity, RadiositySettings};
use crate::tile_cells::{pyramid_cells, TileLattice, MAX_PYRAMID_LEVELS};

const MAGIC: &[u8; 8] = b"PRISMRAD";
const VERSION: u32 = 4;
const NONE: u32 = u32::MAX;

struct Writer(Vec<u8>);

impl Writer {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn vec3(&mut self, v: Vec3A) {
        self.f32(v.x);
        self.f32(v.y);
        self.f32(v.z);
    }
    fn f32s(&mut self, v: &[f32]) {
        v.iter().for_each(|&x| self.f32(x));
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(format!("truncated at byte {}", self.at));
        };
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().unwrap_or([0; 4]),
        ))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().unwrap_or([0; 8]),
        ))
    }
    fn f32(&mut self) -> Result<f32, String> {
        Ok(f32::from_le_bytes(
            self.take(4)?.try_into().unwrap_or([0; 4]),
        ))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().unwrap_or([0; 8]),
        ))
    }
    fn vec3(&mut self) -> Result<Vec3A, String> {
        Ok(Vec3A::new(self.f32()?, self.f32()?, self.f32()?))
    }
    fn f32s(&mut self, n: usize) -> Result<Vec<f32>, String> {
        (0..n).map(|_| self.f32()).collect()
    }
    /// A count that the rest of the bytes can hold at `bytes_each` bytes per item.
    fn count(&mut self, bytes_each: usize) -> Result<usize, String> {
        let n = self.u32()? as usize;
        if n.saturating_mul(bytes_each) > self.bytes.len() - self.at {
            return Err(format!(
                "a count of {n} at byte {} exceeds the file",
                self.at - 4
            ));
        }
        Ok(n)
    }
}

impl Radiosity {
    /// The solution as bytes (`from_bytes` reads them back).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer(MAGIC.to_vec());
        w.u32(VERSION);
        let s = &self.settings;
        w.u32(self.bands as u32);
        w.f32(s.error_bound_rel);
        w.u8(s.max_levels);
        w.u32(s.quadrature_nodes as u32);
        w.u32(s.visibility_rays as u32);
        w.f32(s.solve_tolerance_rel);
        w.u32(s.max_sweeps);
        w.f32(self.power_threshold);
        w.f32(self.emitter_power);
        w.u32(self.iterations);
        let h = &self.hierarchy;
        w.u32(h.patch_root.len() as u32);
        w.f32s(&self.reflectance);
        w.f32s(&self.emission);
        for side in &self.directional.sides {
            w.u8(u8::from(side.is_some()));
            if let Some(side) = side {
                w.u8(u8::from(side.front));
                w.u32(side.partner);
                // The two sides share their surface: the front side writes it.
                if side.front {
                    let surface = &side.surface;
                    surface.frame.iter().for_each(|&v| w.vec3(v));
                    w.vec3(surface.lattice.origin);
                    surface.lattice.period.iter().for_each(|&v| w.vec3(v));
                    w.u32(surface.levels);
                    w.f32s(&surface.gamma);
                    w.f32s(&surface.view_transparency);
                }
            }
        }
        h.patch_root.iter().for_each(|&v| w.u32(v));
        h.order.iter().for_each(|&v| w.u32(v));
        h.order_area_prefix.iter().for_each(|&v| w.f64(v));
        w.u32(h.nodes.len() as u32);
        w.u32(h.root);
        for node in &h.nodes {
            match node.kind {
                NodeKind::Cluster { children, patches } => {
                    w.u8(0);
                    w.u32(children[0]);
                    w.u32(children[1]);
                    w.u32(patches.0);
                    w.u32(patches.1);
                }
                NodeKind::Element {
                    shape,
                    patch,
                    level,
                    first_child,
                } => {
                    let (tag, p0, e1, e2) = match shape {
                        ElementShape::Parallelogram { p0, e1, e2 } => (1, p0, e1, e2),
                        ElementShape::Triangle { p0, e1, e2 } => (2, p0, e1, e2),
                    };
                    w.u8(tag);
                    w.vec3(p0);
                    w.vec3(e1);
                    w.vec3(e2);
                    w.u32(patch);
                    w.u8(level);
                    w.u32(first_child.unwrap_or(NONE));
                }
            }
            w.f32(node.area_m2);
            w.vec3(node.lo);
            w.vec3(node.hi);
        }
        w.f32s(&self.radiosity);
        w.f32s(&self.radiosity_max);
        w.f32s(&self.gathered);
        w.f32s(&self.direct);
        w.f32s(&self.irradiance);
        for v in &self.direct_variation {
            w.f32(v.unwrap_or(f32::NAN));
        }
        for c in &self.covered {
            w.u8(u8::from(c.is_some()));
            w.u64(c.unwrap_or(0));
        }
        w.f32s(&self.free_area);
        let d = &self.directional;
        w.u32((d.gathered.len() / d.stride()) as u32);
        d.slot.iter().for_each(|&v| w.u32(v));
        for values in [&d.gathered, &d.direct, &d.irradiance, &d.exitance] {
            w.f32s(values);
        }
        for links in &self.links {
            w.u32(links.len() as u32);
            for l in links {
                w.u32(l.source);
                w.f32(l.form_factor);
                w.u8(u8::from(l.partial));
                w.u32(l.source_shares.len() as u32);
                for &(node, share) in l.source_shares.iter() {
                    w.u32(node);
                    w.f32(share);
                }
            }
        }
        w.0
    }

    /// Reads `to_bytes`' output; an error says what is wrong and where.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, String> {
        if bytes.len() < 12 || &bytes[..8] != MAGIC {
            return Err("not a Prism radiosity solution (no PRISMRAD header)".into());
        }
        let mut r = Reader { bytes, at: 8 };
        let version = r.u32()?;
        if version != VERSION {
            return Err(format!(
                "solution format version {version}; this build reads version {VERSION}"
            ));
        }
        let bands = r.count(4)?;
        let settings = RadiositySettings {
            error_bound_rel: r.f32()?,
            max_levels: r.u8()?,
            quadrature_nodes: r.u32()? as usize,
            visibility_rays: r.u32()? as usize,
            solve_tolerance_rel: r.f32()?,
            max_sweeps: r.u32()?,
            memory_limit_bytes: None,
        };
        let power_threshold = r.f32()?;
        let emitter_power = r.f32()?;
        let iterations = r.u32()?;
        let patches = r.count(8 * bands.max(1))?;
        let reflectance = r.f32s(patches * bands)?;
        let emission = r.f32s(patches * bands)?;
        // (front, partner, the surface where this is the front side)
        let mut read_sides = Vec::with_capacity(patches);
        for _ in 0..patches {
            read_sides.push(if r.u8()? != 0 {
                let front = r.u8()? != 0;
                let partner = r.u32()?;
                if partner as usize >= patches {
                    return Err(format!(
                        "a directional side's partner {partner} of {patches}"
                    ));
                }
                let surface = if front {
                    let frame = [r.vec3()?, r.vec3()?, r.vec3()?];
                    let lattice = TileLattice {
                        origin: r.vec3()?,
                        period: [r.vec3()?, r.vec3()?],
                    };
                    let levels = r.u32()?;
                    if !(1..=MAX_PYRAMID_LEVELS).contains(&levels) {
                        return Err(format!("a directional surface of {levels} levels"));
                    }
                    let cells = pyramid_cells(levels);
                    let gamma = r.f32s(cells * SPHERE_BINS * SPHERE_BINS * bands)?;
                    let view_transparency = r.f32s(cells * SPHERE_BINS)?;
                    Some(Arc::new(DirectionalSurface {
                        frame,
                        lattice,
                        levels,
                        gamma,
                        view_transparency,
                    }))
                } else {
                    None
                };
                Some((front, partner, surface))
            } else {
                None
            });
        }
        let mut sides = Vec::with_capacity(patches);
        for side in &read_sides {
            sides.push(match side {
                Some((front, partner, surface)) => {
                    let surface = match surface {
                        Some(surface) => surface.clone(),
                        None => match &read_sides[*partner as usize] {
                            Some((true, _, Some(surface))) => surface.clone(),
                            _ => {
                                return Err(format!(
                                    "a directional back side's partner {partner} is not a \
                                     front side"
                                ))
                            }
                        },
                    };
                    Some(DirectionalSide {
                        surface,
                        front: *front,
                        partner: *partner,
                    })
                }
                None => None,
            });
        }
        let patch_root: Vec<u32> = (0..patches).map(|_| r.u32()).collect::<Result<_, _>>()?;
        let order: Vec<u32> = (0..patches).map(|_| r.u32()).collect::<Result<_, _>>()?;
        let order_area_prefix: Vec<f64> =
            (0..=patches).map(|_| r.f64()).collect::<Result<_, _>>()?;
        let node_count = r.count(17)?;
        let root = r.u32()?;
        let index = |v: u32, what: &str| -> Result<u32, String> {
            if (v as usize) < node_count {
                Ok(v)
            } else {
                Err(format!("{what} {v} is not a node (there are {node_count})"))
            }
        };
        index(root, "the root")?;
        let mut nodes = Vec::with_capacity(node_count);
        for _ in 0..node_count {
            let kind = match r.u8()? {
                0 => NodeKind::Cluster {
                    children: [index(r.u32()?, "a child")?, index(r.u32()?, "a child")?],
                    patches: (r.u32()?, r.u32()?),
                },
                tag @ (1 | 2) => {
                    let (p0, e1, e2) = (r.vec3()?, r.vec3()?, r.vec3()?);
                    let shape = if tag == 1 {
                        ElementShape::Parallelogram { p0, e1, e2 }
                    } else {
                        ElementShape::Triangle { p0, e1, e2 }
                    };
                    let patch = r.u32()?;
                    if patch as usize >= patches {
                        return Err(format!("patch {patch} of {patches}"));
                    }
                    let level = r.u8()?;
                    let first = r.u32()?;
                    let first_child = if first == NONE {
                        None
                    } else {
                        index(first.saturating_add(3), "a child")?;
                        Some(first)
                    };
                    NodeKind::Element {
                        shape,
                        patch,
                        level,
                        first_child,
                    }
                }
                other => return Err(format!("unknown node tag {other} at byte {}", r.at - 1)),
            };
            nodes.push(Node {
                kind,
                area_m2: r.f32()?,
                lo: r.vec3()?,
                hi: r.vec3()?,
            });
        }
        for &p in &patch_root {
            index(p, "a patch root")?;
        }
        let per_band = node_count * bands;
        let radiosity = r.f32s(per_band)?;
        let radiosity_max = r.f32s(node_count)?;
        let gathered = r.f32s(per_band)?;
        let direct = r.f32s(per_band)?;
        let irradiance = r.f32s(per_band)?;
        let direct_variation = (0..node_count)
            .map(|_| r.f32().map(|v| (!v.is_nan()).then_some(v)))
            .collect::<Result<_, _>>()?;
        let covered = (0..node_count)
            .map(|_| -> Result<Option<u64>, String> {
                let some = r.u8()? != 0;
                let mask = r.u64()?;
                Ok(some.then_some(mask))
            })
            .collect::<Result<_, _>>()?;
        let free_area = r.f32s(node_count)?;
        let mut directional = DirectionalState::new(sides, bands);
        let slots = r.count(4 * directional.stride())?;
        directional.slot = (0..node_count)
            .map(|_| match r.u32()? {
                NO_SLOT => Ok(NO_SLOT),
                s if (s as usize) < slots => Ok(s),
                s => Err(format!("directional slot {s} of {slots}")),
            })
            .collect::<Result<_, String>>()?;
        let values = slots * directional.stride();
        directional.gathered = r.f32s(values)?;
        directional.direct = r.f32s(values)?;
        directional.irradiance = r.f32s(values)?;
        directional.exitance = r.f32s(values)?;
        let mut links = Vec::with_capacity(node_count);
        for _ in 0..node_count {
            let n = r.count(13)?;
            let mut l = Vec::with_capacity(n);
            for _ in 0..n {
                let source = index(r.u32()?, "a link's source")?;
                let form_factor = r.f32()?;
                let partial = r.u8()? != 0;
                let share_count = r.count(8)?;
                let mut source_shares = Vec::with_capacity(share_count);
                for _ in 0..share_count {
                    source_shares.push((index(r.u32()?, "a link's share")?, r.f32()?));
                }
                let link = Link {
                    source,
                    form_factor,
                    partial,
                    source_shares: source_shares.into_boxed_slice(),
                };
                l.push(link);
            }
            links.push(l);
        }
        if r.at != bytes.len() {
            return Err(format!("{} bytes after the solution", bytes.len() - r.at));
        }
        Ok(Self {
            settings,
            bands,
            hierarchy: Hierarchy {
                nodes,
                root,
                patch_root,
                order,
                order_area_prefix,
            },
            reflectance,
            emission,
            radiosity,
            radiosity_max,
            gathered,
            directional,
            link_totals: LinkTotals::of(links.iter().flatten()),
            links,
            direct,
            direct_variation,
            covered,
            free_area,
            irradiance,
            power_threshold,
            emitter_power,
            iterations,
        })
    }
}
