//! All lights of a scene: light selection in proportion to power (pbrt-v4 §12.6.3
//! `PowerLightSampler`), or for light samples at a shading point one of
//! [`ShadingSelection`] (from [`LIGHT_BVH_MIN_BOUNDED`] lights with bounds on, a light BVH,
//! light_bvh.rs); the map from hit instances to area lights, and the infinite lights that
//! escaping rays see.
//!
//! Which selection a caller uses is part of its estimator: next-event estimation in the
//! path tracer, its medium and photon-camera variants and the illuminance sensors (whose
//! gather rays the path tracer weighs) calls `sample_at`/`pmf_at`; light paths (BDPT,
//! photons) and the predictor's probe choose by power (`sample`, `pmf`), as their weights
//! assume.

use std::ops::Range;

use prism_geometry::Geometry;
use prism_scene::SceneDescription;
use prism_spectrum::Spectrum;

use super::build::build_lights;
use super::light_bounds::light_bounds;
use super::light_bvh::LightBvh;
use super::scene_sphere::SceneSphere;
use super::selection_table::SelectionTable;
use super::{Light, LightSampleContext};
use crate::scene_build::{shape_instance_ranges, SceneBuildError};

/// `area_light_of_instance` value of instances that do not emit.
pub const NO_LIGHT: u32 = u32::MAX;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightSet {
    lights: Vec<Light>,
    /// Selection in proportion to power.
    power: SelectionTable,
    /// Lights at infinity apart, the rest by power (`ShadingSelection::InfiniteApart`).
    infinite_apart: SelectionTable,
    /// Per geometry instance: index of the area light it carries, or `NO_LIGHT`.
    instance_light: Vec<u32>,
    infinite: Vec<u32>,
    /// The scene's bounding sphere (set by `build`; zero radius from `new`).
    scene: SceneSphere,
    /// The light BVH over the lights with bounds (set by `build` when any has them).
    bvh: Option<LightBvh>,
    /// How `sample_at`/`pmf_at` choose.
    selection: ShadingSelection,
    /// Each hit samples every light at infinity chosen apart (`samples_per_light_sample`);
    /// `false`: one choice among all lights per light sample.
    sample_each_infinite: bool,
    /// Per light, its key in a path's light `SpectrumCache` ([`Self::emission_key`]).
    emission_keys: Vec<u32>,
}

/// Distinct emission spectra [`LightSet`] looks for equal ones among; past this many, a
/// light keeps its own key (scenes of many lights have few kinds of luminaire).
const EMISSION_KINDS_MAX: usize = 64;

/// How light samples at shading points choose a light (`prism render --light-selection`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShadingSelection {
    /// In proportion to power, lights at infinity included (pbrt-v4 `PowerLightSampler`).
    Power,
    /// Lights at infinity apart, each with probability 1 / (their count + 1); the others
    /// share the rest in proportion to power (`SelectionTable::infinite_apart`). The same
    /// as `Power` where a scene has lights of only one kind.
    #[default]
    InfiniteApart,
    /// Through the light BVH (lights at infinity apart as in `InfiniteApart`).
    Bvh,
}

/// From this many lights with bounds on, light samples at shading points choose through
/// the light BVH; below it from `SelectionTable::infinite_apart` (a handful of lights gains
/// little from the tree).
pub const LIGHT_BVH_MIN_BOUNDED: usize = 8;

impl LightSet {
    /// Lights given directly, selected in proportion to `power_w(scene_radius_m)`
    /// (uniformly if every power is zero), at shading points with the lights at infinity
    /// apart. `instance_light` maps instances to lights.
    pub fn new(lights: Vec<Light>, instance_light: Vec<u32>, scene_radius_m: f32) -> Self {
        let powers: Vec<f64> = lights.iter().map(|l| l.power_w(scene_radius_m)).collect();
        let at_infinity: Vec<bool> = lights.iter().map(Light::is_infinite).collect();
        let infinite = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| l.is_infinite() && !l.is_delta())
            .map(|(i, _)| i as u32)
            .collect();
        Self {
            power: SelectionTable::proportional(&powers),
            infinite_apart: SelectionTable::infinite_apart(&powers, &at_infinity),
            instance_light,
            infinite,
            scene: SceneSphere {
                center_m: glam::Vec3A::ZERO,
                radius_m: scene_radius_m,
            },
            bvh: None,
            selection: ShadingSelection::InfiniteApart,
            sample_each_infinite: true,
            emission_keys: emission_keys(&lights),
            lights,
        }
    }

    /// Light `l`'s key in a path's light `SpectrumCache` (`Light::sample_li_cached`,
    /// `Light::emitted_radiance_cached`): the first light whose uniform emission spectrum
    /// equals `l`'s, so a room of identical luminaires evaluates it once per path (and
    /// wavelength shift), not once per luminaire it samples or meets.
    #[inline]
    pub fn emission_key(&self, l: u32) -> u32 {
        self.emission_keys[l as usize]
    }

    /// Builds the scene's lights; `geometry` must have been built from `scene`
    /// (`build_geometry`): area lights find their shape's instances in it by the order in
    /// which shapes add instances (`shape_instance_ranges`).
    pub fn build(scene: &SceneDescription, geometry: &Geometry) -> Result<Self, SceneBuildError> {
        let ranges = shape_instance_ranges(scene);
        let expected = ranges.last().map_or(0, |r| r.end as usize);
        if expected != geometry.instances().len() {
            return Err(SceneBuildError::new(
                &scene.file,
                "lights",
                format!(
                    "internal error: the geometry has {} instances but the scene's shapes make {expected}",
                    geometry.instances().len()
                ),
            ));
        }
        Self::build_with_instances(scene, geometry, &ranges)
    }

    /// As `build`, with the instance ids of each shape given (`build_geometry_with_instances`).
    pub fn build_with_instances(
        scene: &SceneDescription,
        geometry: &Geometry,
        shape_instances: &[Range<u32>],
    ) -> Result<Self, SceneBuildError> {
        let built = build_lights(scene, geometry, shape_instances)?;
        let mut set = Self::new(built.lights, built.instance_light, built.scene.radius_m);
        set.scene = built.scene;
        set.build_bvh(geometry);
        Ok(set)
    }

    /// The light BVH: each light's bounds (an area light's box is its instances'), the
    /// lights at infinity apart; on from [`LIGHT_BVH_MIN_BOUNDED`] bounded lights.
    fn build_bvh(&mut self, geometry: &Geometry) {
        let mut boxes: Vec<Option<(glam::Vec3A, glam::Vec3A)>> = vec![None; self.lights.len()];
        for (instance, &l) in self.instance_light.iter().enumerate() {
            if l == NO_LIGHT {
                continue;
            }
            if let Some((lo, hi)) = geometry.instance_world_bounds(instance as u32) {
                let b = &mut boxes[l as usize];
                *b = Some(b.map_or((lo, hi), |(a, c)| (a.min(lo), c.max(hi))));
            }
        }
        let radius = self.scene.radius_m;
        let mut bounded = Vec::new();
        let mut infinite = Vec::new();
        for (i, light) in self.lights.iter().enumerate() {
            let phi = light.power_w(radius);
            let phi = if phi.is_finite() {
                phi.max(0.0) as f32
            } else {
                0.0
            };
            match light_bounds(light, boxes[i], phi) {
                Some(b) => bounded.push((i as u32, b)),
                None if light.is_infinite() => infinite.push(i as u32),
                // An area light whose shape has no instance box emits nowhere.
                None => {}
            }
        }
        if bounded.is_empty() {
            return;
        }
        let bvh = LightBvh::build(bounded, infinite, self.lights.len());
        if bvh.bounded_count() >= LIGHT_BVH_MIN_BOUNDED {
            self.selection = ShadingSelection::Bvh;
        }
        self.bvh = Some(bvh);
    }

    /// Sets how `sample_at`/`pmf_at` choose; `false` (and nothing changed) for `Bvh` where
    /// `build` made no light BVH (no light with bounds).
    pub fn set_shading_selection(&mut self, selection: ShadingSelection) -> bool {
        match selection {
            ShadingSelection::Bvh if self.bvh.is_none() => false,
            ShadingSelection::Bvh | ShadingSelection::Power | ShadingSelection::InfiniteApart => {
                self.selection = selection;
                true
            }
        }
    }

    /// How `sample_at`/`pmf_at` choose.
    pub fn shading_selection(&self) -> ShadingSelection {
        self.selection
    }

    /// Whether choosing lights at infinity apart differs from choosing by power here: the
    /// scene has lights at infinity beside other lights with power, or two or more lights at
    /// infinity alone that each take a sample at every hit.
    pub fn infinite_apart_differs_from_power(&self) -> bool {
        self.shading_table() != &self.power
    }

    /// Light samples a hit takes for each light sample it asks for: one per light at
    /// infinity and one for the other lights where those at infinity are chosen apart
    /// beside lights with power (`ShadingSelection::InfiniteApart` or `Bvh`), one per light
    /// at infinity where two or more light the scene alone, else 1. The choice gives each
    /// light at infinity one equal slice at the start of the unit interval (1 / (count + 1),
    /// or 1 / count alone), so light samples stratified over that many slices
    /// (`PathTracer::trace`) take every light at infinity and one of the others, and the
    /// choice between them adds no noise (docs/lights.md, "Light samples per hit").
    pub fn samples_per_light_sample(&self) -> u32 {
        if !self.sample_each_infinite {
            return 1;
        }
        let (apart, others) = match self.selection {
            ShadingSelection::Power => (0, true),
            ShadingSelection::InfiniteApart => (
                self.infinite_apart.infinite_apart_count(),
                self.infinite_apart.others_apart(),
            ),
            ShadingSelection::Bvh => (
                self.light_bvh().map_or(0, LightBvh::infinite_apart_count),
                true,
            ),
        };
        if apart == 0 {
            1
        } else {
            apart as u32 + u32::from(others)
        }
    }

    /// Whether each hit samples every light at infinity chosen apart
    /// (`samples_per_light_sample`; on by default) or makes one choice among all lights per
    /// light sample (`prism render --light-samples-per-hit one`).
    pub fn set_sample_each_infinite(&mut self, on: bool) {
        self.sample_each_infinite = on;
    }

    /// See `set_sample_each_infinite`.
    pub fn sample_each_infinite(&self) -> bool {
        self.sample_each_infinite
    }

    /// Lights in the light BVH `build` made, on or off (0 without one).
    pub fn bounded_light_count(&self) -> usize {
        self.bvh.as_ref().map_or(0, LightBvh::bounded_count)
    }

    /// The light BVH when light samples at shading points use it.
    pub fn light_bvh(&self) -> Option<&LightBvh> {
        self.bvh
            .as_ref()
            .filter(|_| self.selection == ShadingSelection::Bvh)
    }

    /// The table light samples at shading points choose from where they do not use the
    /// light BVH.
    #[inline]
    pub(crate) fn shading_table(&self) -> &SelectionTable {
        match self.selection {
            ShadingSelection::Power => &self.power,
            // Only lights at infinity, one choice per hit: by power, as before they each
            // took a sample.
            ShadingSelection::InfiniteApart | ShadingSelection::Bvh
                if !self.sample_each_infinite && !self.infinite_apart.others_apart() =>
            {
                &self.power
            }
            ShadingSelection::InfiniteApart | ShadingSelection::Bvh => &self.infinite_apart,
        }
    }

    /// Picks a light for a light sample at `ctx` as `shading_selection` says:
    /// (index, probability).
    #[inline]
    pub fn sample_at(&self, ctx: &LightSampleContext, u: f32) -> Option<(u32, f32)> {
        match self.light_bvh() {
            Some(bvh) => bvh.sample(ctx.p, ctx.n, u),
            None => self.shading_table().sample(u),
        }
    }

    /// Probability that `sample_at(ctx, ·)` picks light `index`.
    #[inline]
    pub fn pmf_at(&self, ctx: &LightSampleContext, index: u32) -> f32 {
        match self.light_bvh() {
            Some(bvh) => bvh.pmf(ctx.p, ctx.n, index),
            None => self.shading_table().pmf(index),
        }
    }

    /// The scene's bounding sphere that the infinite lights use.
    pub fn scene_sphere(&self) -> &SceneSphere {
        &self.scene
    }

    pub fn len(&self) -> usize {
        self.lights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    #[inline]
    pub fn light(&self, index: u32) -> &Light {
        &self.lights[index as usize]
    }

    /// Picks a light in proportion to power: (index, selection probability).
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(u32, f32)> {
        self.power.sample(u)
    }

    /// Probability that `sample` picks light `index`.
    #[inline]
    pub fn pmf(&self, index: u32) -> f32 {
        self.power.pmf(index)
    }

    /// The area light carried by geometry instance `instance_id`, if any.
    #[inline]
    pub fn area_light_of_instance(&self, instance_id: u32) -> Option<u32> {
        match self.instance_light.get(instance_id as usize) {
            Some(&l) if l != NO_LIGHT => Some(l),
            _ => None,
        }
    }

    /// Indices of the lights that rays leaving the scene see (environment, sky,
    /// directional with an angular diameter > 0; not ideal directional light).
    pub fn infinite_lights(&self) -> &[u32] {
        &self.infinite
    }
}

/// [`LightSet::emission_key`] of every light: lights with the same uniform emission
/// spectrum (`Light::uniform_emission`) share the first one's index; others keep their own.
fn emission_keys(lights: &[Light]) -> Vec<u32> {
    let mut kinds: Vec<(&Spectrum, u32)> = Vec::new();
    (0..lights.len() as u32)
        .map(|i| {
            let Some(spectrum) = lights[i as usize].uniform_emission() else {
                return i;
            };
            if let Some(&(_, key)) = kinds.iter().find(|(s, _)| *s == spectrum) {
                return key;
            }
            if kinds.len() < EMISSION_KINDS_MAX {
                kinds.push((spectrum, i));
            }
            i
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::test_support::build_scene;

    #[test]
    fn lights_are_chosen_in_proportion_to_power() {
        let dir = tempfile::tempdir().unwrap();
        let json = r#"{"lights": [{"type": "point", "power_lm": 100}, {"type": "point", "power_lm": 300}]}"#;
        let (_, lights) = build_scene(dir.path(), json).unwrap();
        assert!((lights.pmf(0) - 0.25).abs() < 1e-6 && (lights.pmf(1) - 0.75).abs() < 1e-6);
        assert_eq!(lights.sample(0.2).map(|s| s.0), Some(0));
        assert_eq!(lights.sample(0.3).map(|s| s.0), Some(1));
        assert!(lights.infinite_lights().is_empty());
    }

    /// Lights with equal uniform spectra share one cache key, the first one's; a different
    /// strength or spectrum, or a light without a uniform spectrum, keeps its own. A light
    /// sample through the cache is the uncached sample, bit for bit.
    #[test]
    fn equal_emission_spectra_share_a_cache_key() {
        let dir = tempfile::tempdir().unwrap();
        let lamp = |x: f32, lm: f32, k: f32| {
            format!(
                r#"{{"type": "point", "position_m": [{x}, 2, 0], "power_lm": {lm},
                    "spectrum": {{"blackbody_k": {k}}}}}"#
            )
        };
        let json = format!(
            r#"{{"lights": [{}, {}, {}, {}, {{"type": "sky", "luminance_cd_m2": 100}}, {}]}}"#,
            lamp(0.0, 400.0, 3000.0),
            lamp(1.0, 400.0, 3000.0),
            lamp(2.0, 800.0, 3000.0),
            lamp(3.0, 400.0, 5000.0),
            lamp(4.0, 400.0, 3000.0),
        );
        let (_, lights) = build_scene(dir.path(), &json).unwrap();
        let keys: Vec<u32> = (0..6).map(|l| lights.emission_key(l)).collect();
        assert_eq!(keys, [0, 0, 2, 3, 4, 0]);

        let ctx = LightSampleContext {
            p: glam::Vec3A::ZERO,
            n: glam::Vec3A::Y,
        };
        let wavelengths = prism_spectrum::SampledWavelengths::sample_visible(0.37);
        let mut cache = crate::spectrum_cache::SpectrumCache::new();
        for l in [0, 1, 2, 5, 1] {
            let light = lights.light(l);
            let u = glam::Vec2::new(0.3, 0.6);
            let cached = light
                .sample_li_cached(lights.emission_key(l), &ctx, u, &wavelengths, &mut cache)
                .unwrap();
            let plain = light.sample_li(&ctx, u, &wavelengths).unwrap();
            assert_eq!(
                cached.radiance.to_array().map(f32::to_bits),
                plain.radiance.to_array().map(f32::to_bits),
                "light {l}"
            );
        }
    }

    #[test]
    fn infinite_lights_take_their_power_from_the_scene_radius() {
        // A unit sphere: bounding box [−1, 1]³, radius √3. A sky of radiance L sends
        // 4π · π r² ∫L dλ into it; a point of intensity I emits 4π ∫I dλ.
        let dir = tempfile::tempdir().unwrap();
        let json = r#"{"shapes": [{"type": "sphere"}],
            "lights": [{"type": "sky", "scale": 2, "spectrum": 1}, {"type": "point", "scale": 3, "spectrum": 1},
                       {"type": "directional", "scale": 1, "spectrum": 1}]}"#;
        let scene = prism_scene::parse_scene_str(json, dir.path().join("scene.json")).unwrap();
        let geometry = crate::scene_build::build_geometry(&scene).unwrap();
        let lights = LightSet::build(&scene, &geometry).unwrap();
        assert!((lights.scene_sphere().radius_m - 3f32.sqrt()).abs() < 1e-5);
        let pi = std::f64::consts::PI;
        let span = 470.0; // ∫ 1 dλ over 360–830 nm
        let sky = 4.0 * pi * pi * 3.0 * 2.0 * span;
        let point = 4.0 * pi * 3.0 * span;
        let sun = pi * 3.0 * span;
        let total = sky + point + sun;
        for (i, p) in [sky, point, sun].into_iter().enumerate() {
            let pmf = f64::from(lights.pmf(i as u32));
            assert!(
                (pmf - p / total).abs() < 1e-5,
                "light {i}: {pmf} vs {}",
                p / total
            );
        }
        // The ideal directional light is infinite but no escaping ray sees it.
        assert!(lights.light(2).is_infinite() && lights.light(2).is_delta());
        assert_eq!(lights.infinite_lights(), &[0]);
        let (_, with_ranges) = build_scene(dir.path(), json).unwrap();
        assert_eq!(with_ranges, lights);
    }

    #[test]
    fn every_example_scene_builds_its_lights() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut stack = vec![root];
        let mut count = 0;
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                } else if path.extension().is_some_and(|e| e == "json") {
                    let scene = prism_scene::load_scene(&path).unwrap();
                    let geometry = crate::scene_build::build_geometry(&scene).unwrap();
                    let lights = LightSet::build(&scene, &geometry)
                        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                    // A daylight sky brings its sun as a second emitter.
                    let skies = scene
                        .lights
                        .iter()
                        .filter(|l| matches!(l.kind, prism_scene::LightKind::Daylight(_)))
                        .count();
                    let n = scene.lights.len();
                    assert!(
                        (n..=n + skies).contains(&lights.len()),
                        "{}",
                        path.display()
                    );
                    count += 1;
                }
            }
        }
        assert!(count > 0);
    }
}
