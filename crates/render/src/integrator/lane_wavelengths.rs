//! Sensor and transport wavelengths of a path's four lanes.
//!
//! A camera sample is born with four wavelengths (hero + three rotated, Wilkie et al. 2014)
//! and their pdfs: what the film records its radiance at (`sensor`). Transport — every BSDF,
//! light, medium and texture lookup — evaluates at `transport`, which equals `sensor` until
//! an event moves a lane to another wavelength: a fluorescent re-emission (Donaldson matrix)
//! absorbs at one wavelength and emits at a longer one, while the film must still credit
//! the light to the wavelength the camera sample measures (pbrt-v4 keeps one set and cannot
//! express this; Mojzík et al. 2018 "Handling fluorescence in a uni-directional spectral
//! path tracer" keep the two apart the same way).
//!
//! `generation` counts changes of `transport`: per-path spectrum caches
//! (`SpectrumCache::get`) key on it, so a cached spectrum never outlives the wavelengths it
//! was evaluated at.

use prism_spectrum::SampledWavelengths;

/// The wavelengths a path carries per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaneWavelengths {
    sensor: SampledWavelengths,
    transport: SampledWavelengths,
    generation: u32,
}

impl LaneWavelengths {
    /// A path whose lanes transport at the wavelengths the sensor measures.
    #[inline(always)]
    pub fn new(sensor: SampledWavelengths) -> Self {
        Self {
            sensor,
            transport: sensor,
            generation: 0,
        }
    }

    /// What the film records: wavelengths and pdfs of the camera sample (lanes terminated by
    /// dispersion have pdf 0).
    #[inline(always)]
    pub fn sensor(&self) -> &SampledWavelengths {
        &self.sensor
    }

    /// What transport evaluates spectra at.
    #[inline(always)]
    pub fn transport(&self) -> &SampledWavelengths {
        &self.transport
    }

    /// Changes of `transport` so far (0 until an event shifts a lane).
    #[inline(always)]
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// A dispersive interface: only the hero lane stays (both sets; the hero's pdf
    /// quarters, `SampledWavelengths::terminate_secondary`).
    #[inline]
    pub fn terminate_secondary(&mut self) {
        self.sensor.terminate_secondary();
        self.transport.terminate_secondary();
    }

    /// Moves lane `lane`'s transport to `lambda_nm` (a re-emission); the sensor keeps the
    /// wavelength the lane was born with.
    pub fn shift_transport(&mut self, lane: usize, lambda_nm: f32) {
        let mut lambda = self.transport.lambda();
        lambda[lane] = lambda_nm;
        self.transport = SampledWavelengths::new(lambda, self.transport.pdf());
        self.generation = self.generation.wrapping_add(1);
    }

    /// True while every lane transports at its sensor wavelength.
    #[inline]
    pub fn transport_is_sensor(&self) -> bool {
        self.generation == 0 || self.transport.lambda() == self.sensor.lambda()
    }
}

impl From<SampledWavelengths> for LaneWavelengths {
    fn from(sensor: SampledWavelengths) -> Self {
        Self::new(sensor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum_cache::SpectrumCache;
    use prism_spectrum::Spectrum;

    #[test]
    fn shifting_a_lane_changes_transport_not_sensor_and_invalidates_caches() {
        let mut lanes = LaneWavelengths::new(SampledWavelengths::sample_visible(0.3));
        let spectrum = Spectrum::piecewise_linear(&[360.0, 830.0], &[0.0, 1.0]).unwrap();
        let mut cache = SpectrumCache::new();
        let before = cache.get(7, &spectrum, &lanes);
        assert_eq!(before, spectrum.eval(lanes.transport()));
        let born = lanes.sensor().lambda();
        lanes.shift_transport(0, 700.0);
        assert_eq!(lanes.sensor().lambda(), born);
        assert_eq!(lanes.transport().lambda()[0], 700.0);
        assert_eq!(lanes.generation(), 1);
        assert!(!lanes.transport_is_sensor());
        let after = cache.get(7, &spectrum, &lanes);
        assert_eq!(after, spectrum.eval(lanes.transport()));
        assert_ne!(after, before);
    }

    #[test]
    fn dispersion_terminates_both_sets() {
        let mut lanes = LaneWavelengths::new(SampledWavelengths::sample_visible(0.6));
        lanes.terminate_secondary();
        assert_eq!(lanes.sensor(), lanes.transport());
        assert!(lanes.transport_is_sensor());
        assert_eq!(lanes.sensor().pdf()[1], 0.0);
    }
}
