//! The path tracer at a fluorescent surface (material/fluorescent.rs): each lane chooses
//! on its own between reflection and re-radiation, so each stays a single-wavelength
//! estimator and none has to end (Mojzík, Fichet & Wilkie 2018, "Handling fluorescence in
//! a uni-directional spectral path tracer", keep hero wavelengths through fluorescence
//! the same way).
//!
//! A camera path meets the emission wavelength λ_o (the lane's transport wavelength) first
//! and asks which excitation fed it. The BRDF is (R(λ_o)·δ(λ_i − λ_o) + M(λ_i, λ_o))/π, so
//! per lane, with c(λ_o) = ∫ |M|(λ, λ_o) dλ:
//! - reflect with probability P = |R|/(|R| + c): weight R/P, wavelength kept;
//! - else re-radiate: λ_i drawn ∝ |M|(·, λ_o) (`ReradiationMatrix::sample_excitation`,
//!   density p), weight M(λ_i, λ_o)/((1 − P)·p), and the lane's transport moves to λ_i
//!   (`LaneWavelengths::shift_transport`): every later BSDF, light and texture lookup is at
//!   λ_i, while the film still credits the lane's sensor wavelength.
//!
//! Both are Lambertian in direction, so the lanes share one cosine-sampled direction: the
//! vertex scatters as a Lambertian lobe whose "reflectance" is the per-lane weight, and
//! next-event estimation at that vertex is at each lane's new wavelength. A signed matrix
//! (`negatives: keep`) samples |M| and carries the sign in the weight.
//!
//! `FluorescenceLanes::Hero` instead ends the secondary lanes (hero pdf quartered, as
//! dispersion does) at every vertex where some lane re-radiates: the event is symmetric in
//! the lanes, whose wavelengths and choice variates are rotated copies of the hero's, so
//! the hero alone stays unbiased.

use prism_scene::FluorescenceLanes;
use prism_spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

use super::dimensions::ReradiationDimensions;
use super::lane_wavelengths::LaneWavelengths;
use crate::bsdf::{Bsdf, BsdfLobe, Lambert};
use crate::material::FluorescentSurface;
use crate::sampler::SampleStream;

/// `u` rotated by lane `lane` (the hero-wavelength rotation, Wilkie et al. 2014), so the
/// four lanes' choices are stratified against each other.
#[inline]
pub(crate) fn rotated(u: f32, lane: usize) -> f32 {
    let x = u + lane as f32 / N_SPECTRUM_SAMPLES as f32;
    if x >= 1.0 {
        x - 1.0
    } else {
        x
    }
}

/// Per-lane weights of the choice at a fluorescent vertex, and the lanes' new transport
/// wavelengths (`None`: the lane reflected and keeps its wavelength).
pub(crate) fn choose(
    surface: &FluorescentSurface,
    lanes: &LaneWavelengths,
    u_choice: f32,
    u_excitation: f32,
) -> (SampledSpectrum, [Option<f32>; N_SPECTRUM_SAMPLES]) {
    let transport = lanes.transport();
    let reflectance = surface.reflectance.eval(transport);
    let live = lanes.sensor().pdf();
    let mut weight = SampledSpectrum::splat(0.0);
    let mut shifted = [None; N_SPECTRUM_SAMPLES];
    for lane in 0..N_SPECTRUM_SAMPLES {
        // A lane ended by dispersion carries nothing the film keeps.
        if live[lane] == 0.0 {
            continue;
        }
        let lambda_out_nm = transport.lambda()[lane];
        let r = reflectance[lane];
        let c = surface.matrix.column_magnitude_integral(lambda_out_nm);
        let total = r.abs() + c;
        // Also false for NaN.
        if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        if rotated(u_choice, lane) * total < r.abs() {
            weight[lane] = r * (total / r.abs());
        } else if let Some((lambda_in_nm, pdf)) = surface
            .matrix
            .sample_excitation(lambda_out_nm, rotated(u_excitation, lane))
        {
            if pdf > 0.0 {
                let m = surface.matrix.eval(lambda_in_nm, lambda_out_nm);
                weight[lane] = m * total / (c * pdf);
                shifted[lane] = Some(lambda_in_nm);
            }
        }
    }
    (weight, shifted)
}

/// The path tracer's step at a fluorescent vertex: draws the lanes' choices from the
/// vertex's re-radiation dimensions, moves the lanes that re-radiate to their excitation
/// wavelengths (or, in `Hero` mode, ends the secondaries if any does), and turns `bsdf`
/// (the reflected part's Lambertian) into the Lambertian lobe of the weights.
pub(crate) fn scatter(
    mode: FluorescenceLanes,
    surface: &FluorescentSurface,
    bsdf: &mut Bsdf<'_>,
    lanes: &mut LaneWavelengths,
    stream: &SampleStream,
    dims: ReradiationDimensions,
) {
    let (mut weight, shifted) = choose(
        surface,
        lanes,
        stream.get_1d_at(dims.choice()),
        stream.get_1d_at(dims.excitation()),
    );
    for (lane, lambda_in_nm) in shifted.iter().enumerate() {
        if let Some(lambda_in_nm) = lambda_in_nm {
            lanes.shift_transport(lane, *lambda_in_nm);
        }
    }
    match mode {
        FluorescenceLanes::All => {}
        FluorescenceLanes::Hero => {
            if shifted.iter().any(Option::is_some) {
                lanes.terminate_secondary();
                for lane in 1..N_SPECTRUM_SAMPLES {
                    weight[lane] = 0.0;
                }
            }
        }
    }
    bsdf.lobe = BsdfLobe::Lambert(Lambert {
        reflectance: weight,
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::{ReradiationMatrix, SampledWavelengths, Spectrum, WavelengthGrid};

    /// R = 0.3 and M = 0.002 nm⁻¹ from 350–450 nm into 500–600 nm.
    fn surface() -> FluorescentSurface {
        let ex = WavelengthGrid::new(300.0, 10.0, 54).unwrap();
        let em = WavelengthGrid::new(300.0, 10.0, 54).unwrap();
        let matrix = ReradiationMatrix::from_fn(ex, em, |i, o| {
            if (350.0..=450.0).contains(&i) && (500.0..=600.0).contains(&o) {
                0.002
            } else {
                0.0
            }
        })
        .unwrap();
        FluorescentSurface {
            reflectance: Spectrum::constant(0.3),
            matrix,
            reradiation: "test".into(),
            negatives: None,
        }
    }

    /// E[weight] over the choice and excitation variates is R(λ_o)·S(λ_o) + ∫M(λ, λ_o)S(λ)dλ
    /// for any S: with S = 1 it is R + c(λ_o) per lane.
    #[test]
    fn the_expected_weight_is_reflectance_plus_the_gathered_fraction() {
        let s = surface();
        let lanes = LaneWavelengths::new(SampledWavelengths::sample_uniform(0.41));
        let n = 400;
        let mut sum = [0.0f64; N_SPECTRUM_SAMPLES];
        for a in 0..n {
            for b in 0..n {
                let (u1, u2) = ((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
                let (w, _) = choose(&s, &lanes, u1, u2);
                for (lane, total) in sum.iter_mut().enumerate() {
                    *total += w[lane] as f64;
                }
            }
        }
        for (lane, total) in sum.iter().enumerate() {
            let lo = lanes.transport().lambda()[lane];
            let expected = 0.3 + s.matrix.column_integral(lo) as f64;
            let mean = total / (n * n) as f64;
            assert!(
                (mean - expected).abs() < 2e-3 * expected,
                "lane {lane} at {lo} nm: {mean} vs {expected}"
            );
        }
    }
}
