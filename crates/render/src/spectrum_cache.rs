//! `SpectrumCache`: spectra evaluated once per path at its wavelengths.
//!
//! An area light's L(λ) and a constant material reflectance do not depend on the point or
//! direction, and a path's wavelengths keep their values (terminating the secondaries only
//! zeroes their pdfs), while the path tracer evaluated them at every light sample, emission
//! hit and scattering event: for the Cornell box's light a 477-sample table (≈ 90
//! instructions), for its RGB reflectances the sigmoid polynomial, ≈ 7 evaluations per
//! camera sample in all.
//!
//! Entries are keyed by (key, transport generation): when an event moves a lane's transport
//! wavelength (`LaneWavelengths::shift_transport`), every cached spectrum is stale and is
//! evaluated again at the new wavelengths.

use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use crate::integrator::LaneWavelengths;

/// Wavelengths a cache can key on: the values spectra are evaluated at and a generation
/// that changes whenever those values change.
pub trait TransportWavelengths {
    fn transport(&self) -> &SampledWavelengths;
    fn generation(&self) -> u32;
}

impl TransportWavelengths for SampledWavelengths {
    #[inline(always)]
    fn transport(&self) -> &SampledWavelengths {
        self
    }
    /// Plain wavelengths never shift: one generation.
    #[inline(always)]
    fn generation(&self) -> u32 {
        0
    }
}

impl TransportWavelengths for LaneWavelengths {
    #[inline(always)]
    fn transport(&self) -> &SampledWavelengths {
        LaneWavelengths::transport(self)
    }
    #[inline(always)]
    fn generation(&self) -> u32 {
        LaneWavelengths::generation(self)
    }
}

/// Spectra at one path's wavelengths, keyed by a small integer (a light's index in the
/// `LightSet`, a material id) and the wavelengths' generation. Four direct-mapped slots
/// (key mod 4): scenes with more keys only evaluate more often. Start a new one for every
/// path (`new`).
#[derive(Clone, Copy, Debug)]
pub struct SpectrumCache {
    /// (generation << 32 | key, value).
    slots: [(u64, SampledSpectrum); 4],
}

impl Default for SpectrumCache {
    fn default() -> Self {
        Self::new()
    }
}

impl SpectrumCache {
    /// An empty cache (the key `u64::MAX` is never used: light indices and material ids
    /// are far below `u32::MAX`).
    #[inline]
    pub fn new() -> Self {
        Self {
            slots: [(u64::MAX, SampledSpectrum::splat(0.0)); 4],
        }
    }

    /// `spectrum`, the spectrum of `key`, at `wavelengths`' transport values: evaluated on
    /// the first request for `key` at this generation (or after another key took its slot).
    /// The caller keeps one key for one spectrum for the cache's life.
    #[inline]
    pub fn get(
        &mut self,
        key: u32,
        spectrum: &Spectrum,
        wavelengths: &impl TransportWavelengths,
    ) -> SampledSpectrum {
        let full_key = (u64::from(wavelengths.generation()) << 32) | u64::from(key);
        let slot = &mut self.slots[(key % 4) as usize];
        if slot.0 != full_key {
            *slot = (full_key, spectrum.eval(wavelengths.transport()));
        }
        slot.1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cached_values_are_the_evaluations() {
        let wl = SampledWavelengths::sample_visible(0.3);
        let spectra: Vec<Spectrum> = (0..6)
            .map(|k| Spectrum::piecewise_linear(&[400.0, 700.0], &[k as f64, 2.0]).unwrap())
            .collect();
        let mut cache = SpectrumCache::new();
        // Keys 0 and 4 share a slot: alternating them must still give each its own value.
        for key in [0u32, 1, 4, 0, 5, 1, 4, 2, 3, 0] {
            let s = &spectra[key as usize];
            assert_eq!(cache.get(key, s, &wl), s.eval(&wl), "key {key}");
        }
    }
}
