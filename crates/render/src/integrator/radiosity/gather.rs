//! The solved scene a final gather reads: the radiosity solution, the map from hits to
//! its patches, and the interpolated gather's structures (paper §5), built per receiver
//! element the first time a camera path reaches it.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

use glam::Vec3A;
use prism_geometry::SurfaceInteraction;
use prism_radiosity::{Radiosity, ReceiverGather};
use prism_spectrum::{SampledSpectrum, SampledWavelengths, N_SPECTRUM_SAMPLES};

use super::patches::PatchMap;
use super::SceneVisibility;
use crate::bsdf::TransportMode;
use crate::integrator::scatter_vertex::ScatterVertex;
use crate::integrator::SolutionGather;
use crate::scene_build::RenderScene;

pub struct SolvedScene {
    pub solution: Radiosity,
    pub map: PatchMap,
    /// The interpolated gather's bound ε; 0 traces every gather ray.
    pub gather_epsilon: f32,
    /// Per hierarchy node: its gather structure once a camera path reached it.
    receivers: Vec<OnceLock<Option<Box<ReceiverGather>>>>,
    built: GatherCounters,
}

/// What the interpolated gather built (for the statistics line).
#[derive(Default)]
struct GatherCounters {
    receivers: AtomicU64,
    interpolated_sources: AtomicU64,
    listed_sources: AtomicU64,
    bytes: AtomicU64,
}

impl SolvedScene {
    pub fn new(solution: Radiosity, map: PatchMap, gather_epsilon: f32) -> Self {
        let nodes = if gather_epsilon > 0.0 {
            solution.node_count()
        } else {
            0
        };
        Self {
            solution,
            map,
            gather_epsilon,
            receivers: (0..nodes).map(|_| OnceLock::new()).collect(),
            built: GatherCounters::default(),
        }
    }

    /// One line on the interpolated gather's structures so far; `None` when it is off.
    pub fn gather_statistics(&self) -> Option<String> {
        if self.gather_epsilon <= 0.0 {
            return None;
        }
        let receivers = self.built.receivers.load(Ordering::Relaxed);
        let per = |n: &AtomicU64| n.load(Ordering::Relaxed) as f64 / receivers.max(1) as f64;
        Some(format!(
            "radiosity gather (ε {}): {receivers} receiver elements, {:.1} interpolated and \
             {:.1} listed sources per element, {:.1} MiB",
            self.gather_epsilon,
            per(&self.built.interpolated_sources),
            per(&self.built.listed_sources),
            self.built.bytes.load(Ordering::Relaxed) as f64 / 1048576.0
        ))
    }

    fn receiver(&self, scene: &RenderScene, leaf: u32) -> Option<&ReceiverGather> {
        self.receivers
            .get(leaf as usize)?
            .get_or_init(|| {
                let vis = SceneVisibility(scene, &self.map);
                let g = self
                    .solution
                    .receiver_gather(leaf, self.gather_epsilon, &vis)?;
                let b = &self.built;
                b.receivers.fetch_add(1, Ordering::Relaxed);
                b.interpolated_sources
                    .fetch_add(u64::from(g.interpolated_sources), Ordering::Relaxed);
                b.listed_sources
                    .fetch_add(g.listed().len() as u64, Ordering::Relaxed);
                b.bytes
                    .fetch_add(g.memory_bytes() as u64, Ordering::Relaxed);
                Some(Box::new(g))
            })
            .as_deref()
    }
}

/// f of `vertex` towards `wi` (f·cos divided by the cosine, so that it multiplies an
/// irradiance); zero where the vertex refuses the direction.
fn bsdf_towards(vertex: &ScatterVertex, wi: Vec3A) -> SampledSpectrum {
    vertex
        .eval(wi, TransportMode::Radiance)
        .map_or(SampledSpectrum::splat(0.0), |e| {
            let cos = e.wi_local.z.abs();
            if cos > 1e-4 {
                e.f_cos * (1.0 / cos)
            } else {
                SampledSpectrum::splat(0.0)
            }
        })
}

impl SolutionGather for SolvedScene {
    /// (B − B_e)/π of the leaf element under the hit, at the band of each lane; resolved
    /// when the element is seen from at least its own size (√area). On a tiled carrier the
    /// hit is on the tile's faces, which cover 1 − τ̄(ωo) of the leaf as seen from ωo
    /// (rays through the holes see what is behind; τ̄ of the pyramid cells the leaf
    /// covers): their radiance is the leaf's reflected radiance divided by that share.
    fn reflected_radiance(
        &self,
        si: &SurfaceInteraction,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
        seen_from_m: Option<f32>,
    ) -> Option<SampledSpectrum> {
        let Some(patch) = self.map.patch_of(si.instance_id, si.primitive_id, si.p, wo) else {
            return Some(SampledSpectrum::splat(0.0));
        };
        // A directional patch (a tiled carrier) sends its exitance towards wo's bin.
        let leaf = self.solution.leaf_towards(patch, si.p, wo);
        if seen_from_m.is_some_and(|d| d * d < leaf.area_m2) {
            return None;
        }
        let e = self.solution.emission(patch);
        // At most a 20-fold gain: beyond that the faces are slivers the carrier's average
        // does not describe.
        let faces_share = self.map.carrier[si.instance_id as usize]
            .map_or(1.0, |_| (1.0 - leaf.see_through).max(0.05));
        Some(SampledSpectrum::from_fn(|lane| {
            let k = self.map.bands.band_of(wavelengths.wavelength_nm(lane));
            (leaf.radiosity[k] - e[k]).max(0.0) * std::f32::consts::FRAC_1_PI / faces_share
        }))
    }

    /// Paper §5: the receiver element's vertex hemispheres, blended at the hit and
    /// weighted by the BSDF per direction bin. Not for tiled carriers (their faces are not
    /// the element's plane) nor for hits outside the solution.
    fn interpolated_reflection(
        &self,
        scene: &RenderScene,
        si: &SurfaceInteraction,
        wo: Vec3A,
        vertex: &ScatterVertex,
        wavelengths: &SampledWavelengths,
    ) -> Option<(SampledSpectrum, u32)> {
        if self.gather_epsilon <= 0.0 || self.map.carrier[si.instance_id as usize].is_some() {
            return None;
        }
        let patch = self
            .map
            .patch_of(si.instance_id, si.primitive_id, si.p, wo)?;
        let leaf = self.solution.leaf_id(patch, si.p);
        let receiver = self.receiver(scene, leaf)?;
        let bands: [usize; N_SPECTRUM_SAMPLES] =
            std::array::from_fn(|lane| self.map.bands.band_of(wavelengths.wavelength_nm(lane)));
        if vertex.is_lambertian() {
            // f is the same towards every bin: one evaluation, along the patch's normal.
            let mut e = [0.0f32; N_SPECTRUM_SAMPLES];
            receiver.interpolate_total(si.p, &bands, &mut e);
            let f = bsdf_towards(vertex, self.map.normals[patch]);
            return Some((f * SampledSpectrum::from_fn(|lane| e[lane]), leaf));
        }
        let mut radiance = SampledSpectrum::splat(0.0);
        receiver.interpolate(si.p, &bands, |w, e| {
            radiance += bsdf_towards(vertex, w) * SampledSpectrum::from_fn(|lane| e[lane]);
        });
        Some((radiance, leaf))
    }

    /// Whether the gather ray's hit lies on a source of `receiver`'s gathering list.
    fn hits_listed_source(&self, receiver: u32, si: &SurfaceInteraction, wo: Vec3A) -> bool {
        let Some(patch) = self.map.patch_of(si.instance_id, si.primitive_id, si.p, wo) else {
            return false;
        };
        let leaf = self.solution.leaf_id(patch, si.p);
        self.receivers
            .get(receiver as usize)
            .and_then(|r| r.get())
            .and_then(|r| r.as_deref())
            .is_some_and(|r| r.is_listed(leaf))
    }
}
