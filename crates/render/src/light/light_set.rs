//! All lights of a scene: light selection in proportion to power (pbrt-v4 §12.6.3
//! `PowerLightSampler`), the map from hit instances to area lights, and the infinite lights
//! that escaping rays see.

use std::path::Path;

use prism_geometry::Geometry;
use prism_scene::{LightKind, SceneDescription, Strength};

use super::{Light, PointLight};
use crate::scene_build::spectrum::{build_spectrum, SpectrumRole};
use crate::scene_build::SceneBuildError;

/// `area_light_of_instance` value of instances that do not emit.
pub const NO_LIGHT: u32 = u32::MAX;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightSet {
    lights: Vec<Light>,
    /// Selection probabilities (sum 1) and their running sums.
    pmf: Vec<f32>,
    cdf: Vec<f32>,
    /// Per geometry instance: index of the area light it carries, or `NO_LIGHT`.
    instance_light: Vec<u32>,
    infinite: Vec<u32>,
}

impl LightSet {
    /// Lights given directly, selected in proportion to `power_w(scene_radius_m)`
    /// (uniformly if every power is zero). `instance_light` maps instances to lights.
    pub fn new(lights: Vec<Light>, instance_light: Vec<u32>, scene_radius_m: f32) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| l.power_w(scene_radius_m).max(0.0))
            .map(|p| if p.is_finite() { p } else { 0.0 })
            .collect();
        let total: f64 = powers.iter().sum();
        let pmf: Vec<f32> = if total > 0.0 {
            powers.iter().map(|p| (p / total) as f32).collect()
        } else {
            vec![1.0 / lights.len().max(1) as f32; lights.len()]
        };
        let mut cdf = Vec::with_capacity(pmf.len());
        let mut run = 0.0f32;
        for p in &pmf {
            run += p;
            cdf.push(run);
        }
        let infinite = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| l.is_infinite())
            .map(|(i, _)| i as u32)
            .collect();
        Self {
            lights,
            pmf,
            cdf,
            instance_light,
            infinite,
        }
    }

    /// Builds the scene's lights; `geometry` gives instance ids of area-light shapes.
    pub fn build(scene: &SceneDescription, geometry: &Geometry) -> Result<Self, SceneBuildError> {
        let file: &Path = &scene.file;
        let mut lights = Vec::new();
        for (i, l) in scene.lights.iter().enumerate() {
            let place = format!("lights[{i}]");
            let spectrum = build_spectrum(&l.spectrum, SpectrumRole::Illuminant)
                .map_err(|e| SceneBuildError::new(file, format!("{place}.spectrum"), e))?;
            match &l.kind {
                LightKind::Point { position_m } => {
                    let scale = match l.strength {
                        Strength::Scale(s) => s,
                        _ => {
                            return Err(SceneBuildError::new(
                                file,
                                place,
                                "photometric strengths are not implemented yet",
                            ))
                        }
                    };
                    lights.push(Light::Point(PointLight {
                        position_m: glam::DVec3::from(*position_m).as_vec3a(),
                        intensity: spectrum.scaled(scale as f32),
                    }));
                }
                // Interface skeleton: the emitter work replaces this.
                _ => {}
            }
        }
        let instance_light = vec![NO_LIGHT; geometry.instances().len()];
        Ok(Self::new(lights, instance_light, 1.0))
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

    /// Picks a light for a light sample: (index, selection probability).
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(u32, f32)> {
        if self.lights.is_empty() {
            return None;
        }
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.lights.len() - 1);
        let p = self.pmf[i];
        (p > 0.0).then_some((i as u32, p))
    }

    /// Probability that `sample` picks light `index`.
    #[inline]
    pub fn pmf(&self, index: u32) -> f32 {
        self.pmf.get(index as usize).copied().unwrap_or(0.0)
    }

    /// The area light carried by geometry instance `instance_id`, if any.
    #[inline]
    pub fn area_light_of_instance(&self, instance_id: u32) -> Option<u32> {
        match self.instance_light.get(instance_id as usize) {
            Some(&l) if l != NO_LIGHT => Some(l),
            _ => None,
        }
    }

    /// Indices of the infinite lights (environment, sky, directional with a size).
    pub fn infinite_lights(&self) -> &[u32] {
        &self.infinite
    }
}
