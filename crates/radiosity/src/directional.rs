//! Directional energy on two-sided see-through surfaces (Mostefaoui et al. §3, on Sillion
//! 1995's general reflectance): the two sides of a tiled carrier keep their irradiance per
//! incident direction bin and their exitance per outgoing bin ([`crate::bins`], in the
//! surface's frame), per element. A side's exitance towards bin o is
//!
//!   M(o) = B_e + π Σ_i Γ(i → o) E(i),
//!
//! summed over the irradiance E(i) arriving on its own side (Γ is the BRDF there) and on
//! the other side (Γ is the BTDF: the scattered transmission). A link from the side carries
//! M towards its receiver instead of the side's radiosity, and a link to it adds to the bin
//! its source lies in. The radiosity B = B_e + Σ_o (M(o) − B_e) Ω⊥(o)/π is what the rest of
//! the solution (the oracle, push–pull, clusters) reads.

use std::sync::Arc;

use glam::Vec3A;

use crate::bins::{self, HEMISPHERE_BINS, SPHERE_BINS};
use crate::element::ElementShape;
use crate::tile_cells::{CellWeights, TileLattice};

/// The Γ pyramid of a two-sided directional surface (a tiled carrier).
#[derive(Clone, Debug, PartialEq)]
pub struct DirectionalSurface {
    /// Its frame: x, y and z, the front side's normal (unit, orthogonal; left-handed where
    /// a mirroring transform placed the surface).
    pub frame: [Vec3A; 3],
    /// Where its tile's periods lie: an element reads the pyramid's cells it covers
    /// ([`TileLattice::cell_weights`]).
    pub lattice: TileLattice,
    /// Levels of the pyramid (1: the whole period only).
    pub levels: u32,
    /// Γ(i → o) per (pyramid cell, incident sphere bin, outgoing sphere bin, band), 1/sr:
    /// the radiance leaving the cell towards o per unit irradiance on the surface's plane
    /// from i. Outgoing bins on i's side give the BRDF, the others the BTDF. Light that
    /// passes through holes unscattered is not in it (the geometry lets it through).
    pub gamma: Vec<f32>,
    /// τ̄ per (pyramid cell, sphere bin): the share of the cell a viewer looking back along
    /// the bin's directions sees through, averaged over them.
    pub view_transparency: Vec<f32>,
}

impl DirectionalSurface {
    /// The sphere bin of world direction `w` (unit) in the surface's frame.
    pub fn bin_of(&self, w: Vec3A) -> usize {
        let [x, y, z] = self.frame;
        bins::bin_of(Vec3A::new(w.dot(x), w.dot(y), w.dot(z)))
    }

    /// The pyramid cells that describe element `shape` of the surface.
    pub fn cell_weights(&self, shape: &ElementShape) -> CellWeights {
        self.lattice.cell_weights(self.levels, shape)
    }

    /// τ̄ towards world direction `w` (unit, leaving the surface) over the cells `cells`.
    pub fn see_through(&self, cells: &CellWeights, w: Vec3A) -> f32 {
        let bin = self.bin_of(w);
        cells
            .iter()
            .map(|(c, weight)| weight * self.view_transparency[c * SPHERE_BINS + bin])
            .sum()
    }
}

/// Finer pyramids for directional surfaces, made when the solution's elements first get
/// small enough to read a level their surface lacks (the renderer simulates the tile
/// again).
pub trait FinerPyramids {
    /// `surface`, the surface of input patch `patch`'s side, with a pyramid of `levels`
    /// levels or as many of them as it may have; `None` where it may have no more than it
    /// has.
    fn with_levels(
        &self,
        patch: usize,
        surface: &DirectionalSurface,
        levels: u32,
    ) -> Result<Option<Arc<DirectionalSurface>>, String>;
}

/// Surfaces keep the pyramids they were given.
pub struct NoFinerPyramids;

impl FinerPyramids for NoFinerPyramids {
    fn with_levels(
        &self,
        _: usize,
        _: &DirectionalSurface,
        _: u32,
    ) -> Result<Option<Arc<DirectionalSurface>>, String> {
        Ok(None)
    }
}

/// One side of a directional surface: what makes an input patch directional.
#[derive(Clone, Debug, PartialEq)]
pub struct DirectionalSide {
    pub surface: Arc<DirectionalSurface>,
    /// The front (+z) side, or the back.
    pub front: bool,
    /// The input patch of the other side.
    pub partner: u32,
}

impl DirectionalSide {
    /// The bin (`0..HEMISPHERE_BINS`) of world direction `w` (unit, leaving the side) on
    /// this side; a direction behind the side's plane is taken mirrored through it (a
    /// source straddling the plane is seen at grazing angles).
    pub fn side_bin(&self, w: Vec3A) -> usize {
        self.surface.bin_of(w) % HEMISPHERE_BINS
    }

    /// Side bin `bin` as a sphere bin.
    fn sphere_bin(&self, bin: usize) -> usize {
        if self.front {
            bin
        } else {
            bin + HEMISPHERE_BINS
        }
    }
}

/// No slot: the node is not an element of a directional patch.
pub(crate) const NO_SLOT: u32 = u32::MAX;

/// The per-element directional values of a solution's directional patches.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct DirectionalState {
    pub(crate) bands: usize,
    /// Per input patch: its side, `None` for diffuse patches.
    pub(crate) sides: Vec<Option<DirectionalSide>>,
    /// Per node: its slot in the arrays below, `NO_SLOT` for other nodes.
    pub(crate) slot: Vec<u32>,
    /// Per slot × side bin × band: irradiance gathered over the node's own links.
    pub(crate) gathered: Vec<f32>,
    /// Per slot × side bin × band: direct irradiance (the mean over the element's points).
    pub(crate) direct: Vec<f32>,
    /// Per slot × side bin × band: irradiance arriving (links, pushed, direct) from the
    /// last push–pull, at a leaf and as the area average above it (what the other side's
    /// elements transmit).
    pub(crate) irradiance: Vec<f32>,
    /// Per slot × side bin × band: exitance M towards the bin (area average below the
    /// node).
    pub(crate) exitance: Vec<f32>,
}

impl DirectionalState {
    pub(crate) fn new(sides: Vec<Option<DirectionalSide>>, bands: usize) -> Self {
        Self {
            bands,
            sides,
            ..Self::default()
        }
    }

    /// Whether any patch is directional (every cost below is skipped otherwise).
    pub(crate) fn any(&self) -> bool {
        self.sides.iter().any(Option::is_some)
    }

    /// Values per slot.
    pub(crate) fn stride(&self) -> usize {
        HEMISPHERE_BINS * self.bands
    }

    /// Gives slots to the nodes from `slot.len()` on whose patch is directional
    /// (`patch_of(node)`, `None` for clusters).
    pub(crate) fn grow(&mut self, nodes: usize, patch_of: impl Fn(usize) -> Option<u32>) {
        for n in self.slot.len()..nodes {
            let directional = patch_of(n).is_some_and(|p| self.sides[p as usize].is_some());
            if directional {
                let slots = self.gathered.len() / self.stride().max(1);
                self.slot.push(slots as u32);
                let grown = (slots + 1) * self.stride();
                self.gathered.resize(grown, 0.0);
                self.direct.resize(grown, 0.0);
                self.irradiance.resize(grown, 0.0);
                self.exitance.resize(grown, 0.0);
            } else {
                self.slot.push(NO_SLOT);
            }
        }
    }

    pub(crate) fn slot_of(&self, node: u32) -> Option<usize> {
        self.slot
            .get(node as usize)
            .copied()
            .filter(|&s| s != NO_SLOT)
            .map(|s| s as usize)
    }

    pub(crate) fn range(&self, slot: usize) -> std::ops::Range<usize> {
        slot * self.stride()..(slot + 1) * self.stride()
    }

    /// The exitance of the node in `slot` (an element of `side`) towards world direction
    /// `w` (unit, leaving it).
    pub(crate) fn exitance_towards(&self, slot: usize, side: &DirectionalSide, w: Vec3A) -> &[f32] {
        let bin = side.side_bin(w);
        &self.exitance[self.range(slot)][bin * self.bands..][..self.bands]
    }

    /// Memory the directional values hold, bytes.
    pub(crate) fn memory_bytes(&self) -> u64 {
        (self.slot.len() * 4
            + (self.gathered.len()
                + self.direct.len()
                + self.irradiance.len()
                + self.exitance.len())
                * 4) as u64
    }
}

/// The exitance per side bin of a leaf of `side` (`out`, side bin × band) from the
/// irradiance per side bin arriving on it (`own`) and on its partner over the same area
/// (`partner`), with emission `emission`, by the Γ of the pyramid cells `cells` it covers;
/// its radiosity per band into `radiosity`.
pub(crate) fn leaf_exitance(
    side: &DirectionalSide,
    cells: &CellWeights,
    own: &[f32],
    partner: Option<&[f32]>,
    emission: &[f32],
    out: &mut [f32],
    radiosity: &mut [f32],
) {
    let bands = emission.len();
    let cell_values = SPHERE_BINS * SPHERE_BINS * bands;
    // The side's outgoing bins are contiguous among the sphere bins.
    let first_out = side.sphere_bin(0);
    out.fill(0.0);
    let sources = [(side.front, Some(own)), (!side.front, partner)];
    for (cell, weight) in cells.iter() {
        let gamma = &side.surface.gamma[cell * cell_values..][..cell_values];
        for (front, irradiance) in sources {
            let Some(irradiance) = irradiance else {
                continue;
            };
            let first_in = if front { 0 } else { HEMISPHERE_BINS };
            for (i, e) in irradiance.chunks_exact(bands).enumerate() {
                if e.iter().all(|&v| v == 0.0) {
                    continue;
                }
                // Γ(i → o) for the side's outgoing bins o, one after another.
                let row = &gamma[((first_in + i) * SPHERE_BINS + first_out) * bands..]
                    [..HEMISPHERE_BINS * bands];
                for (m, g) in out.chunks_exact_mut(bands).zip(row.chunks_exact(bands)) {
                    for ((m, g), e) in m.iter_mut().zip(g).zip(e) {
                        *m += weight * g * e;
                    }
                }
            }
        }
    }
    radiosity.copy_from_slice(emission);
    for (o, m) in out.chunks_exact_mut(bands).enumerate() {
        let weight = bins::projected_solid_angle_sr(o);
        for ((m, b), e) in m.iter_mut().zip(radiosity.iter_mut()).zip(emission) {
            // M = B_e + π L; B gathers L over the bin's projected solid angle.
            *b += weight * *m;
            *m = e + std::f32::consts::PI * *m;
        }
    }
}

/// Adds irradiance `e` (per band) arriving from world direction `towards_source` to the
/// per-side-bin irradiance `out` of `side`.
pub(crate) fn add_arrival(
    side: &DirectionalSide,
    towards_source: Vec3A,
    e: &[f32],
    out: &mut [f32],
) {
    let bands = e.len();
    let bin = side.side_bin(towards_source);
    for (o, v) in out[bin * bands..][..bands].iter_mut().zip(e) {
        *o += v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_lattice() -> TileLattice {
        TileLattice {
            origin: Vec3A::ZERO,
            period: [Vec3A::X, Vec3A::Y],
        }
    }

    /// Γ = ρ/π into every bin on the light's side, τ_s/π on the other.
    fn lambertian(reflectance: f32, transmittance: f32) -> Arc<DirectionalSurface> {
        let mut gamma = vec![0.0; SPHERE_BINS * SPHERE_BINS];
        for i in 0..SPHERE_BINS {
            for o in 0..SPHERE_BINS {
                let same = bins::is_above(i) == bins::is_above(o);
                gamma[i * SPHERE_BINS + o] =
                    if same { reflectance } else { transmittance } / std::f32::consts::PI;
            }
        }
        Arc::new(DirectionalSurface {
            frame: [Vec3A::X, Vec3A::Y, Vec3A::Z],
            lattice: unit_lattice(),
            levels: 1,
            gamma,
            view_transparency: vec![0.0; SPHERE_BINS],
        })
    }

    #[test]
    fn a_lambertian_gamma_reflects_and_transmits_its_albedos_uniformly() {
        let surface = lambertian(0.6, 0.2);
        let front = DirectionalSide {
            surface: surface.clone(),
            front: true,
            partner: 1,
        };
        let back = DirectionalSide {
            surface,
            front: false,
            partner: 0,
        };
        // 2 W/m² on the front from one grazing bin, 1 on the back from near its normal.
        let mut on_front = vec![0.0; HEMISPHERE_BINS];
        add_arrival(
            &front,
            Vec3A::new(0.9, 0.1, 0.3).normalize(),
            &[2.0],
            &mut on_front,
        );
        let mut on_back = vec![0.0; HEMISPHERE_BINS];
        add_arrival(
            &back,
            Vec3A::new(0.0, 0.1, -1.0).normalize(),
            &[1.0],
            &mut on_back,
        );
        assert_eq!(on_back.iter().sum::<f32>(), 1.0);
        let (mut m, mut b) = (vec![0.0; HEMISPHERE_BINS], [0.0]);
        leaf_exitance(
            &front,
            &CellWeights::TOP,
            &on_front,
            Some(&on_back),
            &[0.5],
            &mut m,
            &mut b,
        );
        // B = B_e + ρ E_front + τ_s E_back, the same towards every bin.
        let expected = 0.5 + 0.6 * 2.0 + 0.2 * 1.0;
        assert!((b[0] - expected).abs() < 1e-5, "{}", b[0]);
        for v in m {
            assert!((v - expected).abs() < 1e-5, "{v}");
        }
        leaf_exitance(
            &back,
            &CellWeights::TOP,
            &on_back,
            Some(&on_front),
            &[0.0],
            &mut [0.0; 32],
            &mut b,
        );
        assert!((b[0] - (0.6 * 1.0 + 0.2 * 2.0)).abs() < 1e-5, "{}", b[0]);
    }

    #[test]
    fn a_side_bins_directions_on_its_own_side_in_the_surfaces_frame() {
        let surface = Arc::new(DirectionalSurface {
            frame: [Vec3A::Y, Vec3A::Z, Vec3A::X],
            lattice: unit_lattice(),
            levels: 1,
            gamma: Vec::new(),
            view_transparency: Vec::new(),
        });
        let back = DirectionalSide {
            surface,
            front: false,
            partner: 0,
        };
        // Straight out of the back (−x here) is ring 0 of the back hemisphere.
        assert!(back.side_bin(-Vec3A::X) < bins::SECTORS);
        // Grazing along the plane: the outer ring.
        let grazing = back.side_bin(Vec3A::new(-0.05, 1.0, 0.0).normalize());
        assert!(grazing >= HEMISPHERE_BINS - bins::SECTORS, "{grazing}");
    }
}
