//! What the predictor says of one pixel from its G-buffer hit and the probe's n_b light
//! samples (Bagher et al. 2013 §2.2 and §2.4): the image-space bandwidth ν (eq. 5), the
//! sampling rate b_p (eq. 6), the variance of the shading integrand V̂_p (eq. 9) and the
//! mean shading value L̂_p (the estimate the relative-error allocation divides by).

use crate::bandwidth::Bandwidth;
use crate::error::BandwidthError;
use crate::gbuffer::GBufferHit;
use crate::operators::{bound, normal_curvature, transport, Bounce};
use crate::probe::LightSample;
use crate::visibility::{penumbra_bandwidth, Visibility, VisibilitySummary};

/// The largest b_p the bandwidth buffer stores, cycles per pixel: eq. 11 clamps the level to
/// −2 (4×4 samples per pixel, ⌊log2(1/(2·2))⌋ = −2), so a higher rate (+∞ from a hard edge
/// or a point light seen in a mirror) says nothing more.
pub const MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX: f32 = 2.0;

/// Which angular bandwidth of sample i eq. 9 weights: the test of V̂ against a
/// measured variance keeps the one that ranks pixels better.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarianceBandwidth {
    /// ν_a of the light field arriving at x (|T_d| ν_l): how fast the incident radiance
    /// changes over the directions the shading integral sweeps. `--plan-variance eq9`.
    Incident,
    /// ν_a of eq. 4's one-bounce bandwidth at the eye, as the paper's eq. 9 writes it.
    OneBounce,
    /// Not eq. 9: the probe's `measured_variance` (an unbiased estimate of the per-camera-
    /// sample variance of the render's direct-light estimate, in Y², on the same scale as
    /// the colour noise of pixels that see the lights directly). The default: it ranks
    /// pixels by their measured variance better than eq. 9 (docs/bandwidth.md, test d).
    Measured,
}

/// The predictor's numbers for one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelPrediction {
    /// ν = [ν_s, ν_a] at the eye (eq. 5): cycles/m, cycles/rad; +∞ = not band-limited.
    pub bandwidth: Bandwidth,
    /// b_p (eq. 6), cycles per pixel, at most [`MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX`].
    pub image_bandwidth_cycles_per_px: f32,
    /// V̂_p: eq. 9 plus the samples' mean lane variance (colour noise of hero-wavelength
    /// sampling), in Y² (the probe's units squared).
    pub variance: f32,
    /// V̂_p less the colour noise: the per-sample variance of luminance (Y²). Equal to
    /// `variance` until the predictor's variance model sets both.
    pub luminance_variance: f32,
    /// V̂_p's shading part alone: eq. 9 (cycles·Y²/sr) or, for `Measured`, the draws'
    /// sample variance (Y²).
    pub shading_variance: f32,
    /// V̂_p's colour part alone: the samples' mean lane variance (Y²), to which the
    /// predictor adds its indirect estimates' (`ShadingProbe::sample_indirect`).
    pub colour_variance: f32,
    /// L̂_p: the mean of the n_b samples' weights λᵢ/pᵢ (blocked shadow rays count 0), plus
    /// the mean one-bounce indirect estimate where the probe takes them, Y.
    pub mean_y: f32,
    /// The per-sample variance of the probe's one-bounce indirect estimates (Y²; 0 without
    /// them; `ShadingProbe::sample_indirect`).
    pub indirect_variance: f32,
    /// The unbiased sample variance of the estimator's draws, each the sum of its samples'
    /// MIS-weighted values with their shadow rays' outcomes (blocked = 0): the per-camera-
    /// sample variance of the render's direct-light estimate at the hit (one light and one
    /// BSDF sample), in Y² (not eq. 9; what calibrates eq. 9's scale).
    pub measured_variance: f32,
    /// The shadow rays' outcomes (`visibility` module).
    pub visibility: VisibilitySummary,
}

/// How the pixel maps angles to pixels and how many samples the probe was asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelFootprint {
    /// Radians per pixel at this pixel: eq. 6's max(f_x/W, f_y/H) for a pinhole; a fisheye
    /// passes the largest singular value of its projection's Jacobian here.
    pub rad_per_px: f32,
    /// n_b: the samples requested (samples the probe could not take count as zero).
    pub probe_samples: u32,
    /// How many of the render estimator's draws (camera samples) the samples stand for
    /// (`ShadingProbe::sample_lights`' answer; `LightSample::draw` is below it).
    pub estimator_draws: u32,
}

/// ν^i of eq. 4 for one sample, or `None` for a sample that lights nothing (below the
/// horizon, zero weight) and so does not enter eq. 5.
fn one_bounce(hit: &GBufferHit, sample: &LightSample) -> Result<Option<Bandwidth>, BandwidthError> {
    let cos_theta_x = hit.cos_theta_view();
    if !(sample.cos_theta_i > 0.0 && cos_theta_x > 0.0) {
        return Ok(None);
    }
    let bounce = Bounce {
        curvature_per_m: normal_curvature(&hit.curvature(), sample.direction),
        cos_theta_i: sample.cos_theta_i.min(1.0),
        cos_theta_x: cos_theta_x.min(1.0),
        material: sample.material_bandwidth,
    };
    bounce
        .one_bounce(sample.light_bandwidth, sample.distance_m, hit.depth_m())
        .map(Some)
}

/// ν_a of the light field arriving at x: |T_d| ν_l (a distant light arrives unchanged).
fn incident_angular(sample: &LightSample) -> f32 {
    if sample.distance_m.is_finite() {
        bound(transport(sample.distance_m), sample.light_bandwidth).angular_cycles_per_rad
    } else {
        sample.light_bandwidth.angular_cycles_per_rad
    }
}

/// Σ wᵢ xᵢ / Σ wᵢ with 0·∞ = 0 (a sample of zero weight does not make ν infinite).
fn weighted_mean(pairs: impl Iterator<Item = (f32, f32)>) -> f32 {
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for (w, x) in pairs {
        if w > 0.0 {
            sum += f64::from(w) * f64::from(x);
            weight += f64::from(w);
        }
    }
    if weight > 0.0 {
        (sum / weight) as f32
    } else {
        0.0
    }
}

/// Eqs. 5, 6 and 9 at one pixel from the probe's samples at its hit.
pub fn predict_pixel(
    hit: &GBufferHit,
    samples: &[LightSample],
    footprint: PixelFootprint,
    variance_bandwidth: VarianceBandwidth,
) -> Result<PixelPrediction, BandwidthError> {
    if !(footprint.rad_per_px > 0.0 && footprint.rad_per_px.is_finite()) {
        return Err(BandwidthError::invalid(
            "pixel prediction",
            "rad_per_px",
            footprint.rad_per_px,
            "finite, > 0",
        ));
    }
    let n_b = footprint.probe_samples.max(samples.len() as u32);
    if n_b == 0 {
        return Ok(PixelPrediction::default());
    }
    let mut per_sample = Vec::with_capacity(samples.len());
    for sample in samples {
        per_sample.push((sample, one_bounce(hit, sample)?));
    }
    // Eq. 5: λᵢ = Lᵢ ρ cos θᵢ, here the estimator's weight λᵢ/pᵢ (the issue's `weight_y`):
    // with importance-sampled directions the plain λᵢ would over-count where pᵢ is high.
    let lit = || {
        per_sample
            .iter()
            .filter_map(|(s, nu)| nu.map(|nu| (s.weight_y(), nu)))
    };
    let bandwidth = Bandwidth {
        spatial_cycles_per_m: weighted_mean(lit().map(|(w, nu)| (w, nu.spatial_cycles_per_m))),
        angular_cycles_per_rad: weighted_mean(lit().map(|(w, nu)| (w, nu.angular_cycles_per_rad))),
    };
    // Eq. 6; NaN cannot arise (ν_a ≥ 0, rad_per_px finite > 0), ∞ is clamped.
    let image_bandwidth_cycles_per_px = (bandwidth.angular_cycles_per_rad * footprint.rad_per_px)
        .min(MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX);
    // Eq. 9 as a Monte Carlo mean over the probe's directions: (2π/n_b) Σ (ν_a + ν_ρa) χᵢ²/pᵢ.
    // A delta light is one direction, so it adds no variance to the shading integral.
    let n = f64::from(n_b);
    let measured_variance = draw_variance(samples, footprint.estimator_draws);
    let shading_variance = match variance_bandwidth {
        VarianceBandwidth::Incident | VarianceBandwidth::OneBounce => {
            let mut sum = 0.0f64;
            for (sample, nu) in &per_sample {
                let Some(nu) = nu else { continue };
                // A delta light is one direction; a blocked shadow ray (traced only with
                // `--plan-visibility on`) brings no light to integrate.
                if sample.is_delta() || sample.is_blocked() {
                    continue;
                }
                let nu_a = match variance_bandwidth {
                    VarianceBandwidth::Incident => incident_angular(sample),
                    VarianceBandwidth::OneBounce | VarianceBandwidth::Measured => {
                        nu.angular_cycles_per_rad
                    }
                };
                let chi = sample.chi_y();
                let term = (nu_a + sample.material_bandwidth.angular_cycles_per_rad) * chi * chi;
                if term > 0.0 {
                    sum += f64::from(term) / f64::from(sample.pdf_per_sr);
                }
            }
            std::f64::consts::TAU * sum / n
        }
        VarianceBandwidth::Measured => f64::from(measured_variance),
    };
    // Colour noise (beyond the paper; the "spectral" term): the lanes' variance,
    // averaged over the n_b samples like the weights.
    let lane_variance_sum: f64 = samples
        .iter()
        .filter(|s| !s.is_blocked())
        .map(|s| f64::from(s.lane_variance))
        .sum();
    let variance = (shading_variance + lane_variance_sum / n) as f32;
    // With shadow rays traced, blocked samples light nothing: L̂ is then the direct light
    // that arrives, not the unoccluded one (a shadow is dark, and its relative error large).
    let mean_y = (samples
        .iter()
        .map(|s| f64::from(s.visible_weight_y()))
        .sum::<f64>()
        / n) as f32;
    let mut visibility = VisibilitySummary::default();
    // Eq. 5's weighting for the penumbra: each blocked sample's penumbra counts by its share
    // of the light the traced samples would bring unoccluded, so that the shadow of a dim
    // part of a light (a grazing sample, an environment's dark texel with a sharp edge)
    // does not speak for the pixel.
    let (mut penumbra_sum, mut traced_weight) = (0.0f64, 0.0f64);
    for sample in samples {
        let weight = f64::from(sample.weight_y());
        match sample.visibility {
            Visibility::Unknown => {}
            Visibility::Visible => {
                visibility.traced += 1;
                visibility.visible += 1;
                traced_weight += weight;
            }
            Visibility::Blocked { blocker_distance_m } => {
                visibility.traced += 1;
                traced_weight += weight;
                visibility.in_area_penumbra |= is_area_light_sample(sample)
                    && samples.iter().any(|other| {
                        other.light_index == sample.light_index
                            && other.visibility == Visibility::Visible
                    });
                if weight > 0.0 {
                    penumbra_sum += weight
                        * f64::from(penumbra_bandwidth(
                            sample.emitter_bandwidth,
                            sample.is_delta(),
                            sample.distance_m,
                            blocker_distance_m,
                        ));
                }
            }
        }
    }
    if traced_weight > 0.0 {
        visibility.penumbra_cycles_per_m = (penumbra_sum / traced_weight) as f32;
    }
    Ok(PixelPrediction {
        bandwidth,
        image_bandwidth_cycles_per_px,
        variance,
        luminance_variance: variance,
        shading_variance: shading_variance as f32,
        colour_variance: (lane_variance_sum / n) as f32,
        mean_y,
        indirect_variance: 0.0,
        measured_variance,
        visibility,
    })
}

/// A sample of a light with a position and an extent (an area light): not a delta light,
/// at a finite distance.
fn is_area_light_sample(sample: &LightSample) -> bool {
    !sample.is_delta() && sample.distance_m.is_finite()
}

/// The unbiased sample variance of the estimator's draws (Y²): each draw's value is the sum
/// of its samples' `visible_estimator_y`, a draw with no sample is 0; 0 for fewer than two
/// draws or a sample whose draw is out of range (a probe that breaks its contract).
fn draw_variance(samples: &[LightSample], draws: u32) -> f32 {
    if draws <= 1 || samples.iter().any(|s| s.draw >= draws) {
        return 0.0;
    }
    let mut values = vec![0.0f64; draws as usize];
    for s in samples {
        values[s.draw as usize] += f64::from(s.visible_estimator_y());
    }
    let n = f64::from(draws);
    let mean = values.iter().sum::<f64>() / n;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bandwidth::MaterialBandwidth;
    use glam::Vec3A;
    use prism_geometry::Curvature;

    fn plane_hit(depth_m: f32) -> GBufferHit {
        GBufferHit::new(
            Vec3A::new(0.0, 0.0, 0.0),
            depth_m,
            Vec3A::Z,
            Curvature::default(),
            Vec3A::Z,
            0,
        )
        .unwrap()
    }

    fn sample(light: Bandwidth, rho: f32, radiance_y: f32, pdf: f32, d: f32) -> LightSample {
        let cos = 0.8f32;
        LightSample {
            direction: Vec3A::new((1.0 - cos * cos).sqrt(), 0.0, cos),
            radiance_y,
            pdf_per_sr: pdf,
            bsdf_cos_per_sr: cos / std::f32::consts::PI,
            cos_theta_i: cos,
            distance_m: d,
            light_bandwidth: light,
            emitter_bandwidth: light,
            light_index: 0,
            material_bandwidth: MaterialBandwidth::new(rho, 0.0).unwrap(),
            lane_variance: 0.0,
            visibility: Visibility::Unknown,
            estimator_y: 0.0,
            draw: 0,
        }
    }

    const FOOTPRINT: PixelFootprint = PixelFootprint {
        rad_per_px: 0.01,
        probe_samples: 16,
        estimator_draws: 16,
    };

    #[test]
    fn equal_bandwidths_average_to_themselves_and_b_p_is_nu_a_times_the_footprint() {
        let light = Bandwidth::distant_light(3.0).unwrap();
        let samples: Vec<_> = (0..4)
            .map(|k| sample(light, 5.0, 1.0 + k as f32, 0.5, f32::INFINITY))
            .collect();
        let p = predict_pixel(
            &plane_hit(2.0),
            &samples,
            FOOTPRINT,
            VarianceBandwidth::Incident,
        )
        .unwrap();
        let single = one_bounce(&plane_hit(2.0), &samples[0]).unwrap().unwrap();
        assert!((p.bandwidth.angular_cycles_per_rad - single.angular_cycles_per_rad).abs() < 1e-4);
        assert!(
            (p.image_bandwidth_cycles_per_px - single.angular_cycles_per_rad * 0.01).abs() < 1e-6
        );
    }

    /// The shadow-ray summary of a pixel on a plane 1 m away lit by `samples`.
    fn visibility_of(samples: &[LightSample]) -> VisibilitySummary {
        predict_pixel(
            &plane_hit(1.0),
            samples,
            FOOTPRINT,
            VarianceBandwidth::Incident,
        )
        .unwrap()
        .visibility
    }

    #[test]
    fn only_one_area_lights_disagreeing_samples_make_a_penumbra() {
        let lamp = Bandwidth::area_light(2.0).unwrap();
        let of = |light_index: u32, visibility: Visibility| LightSample {
            light_index,
            visibility,
            ..sample(lamp, 0.0, 1.0, 0.5, 2.0)
        };
        let blocked = Visibility::Blocked {
            blocker_distance_m: 1.0,
        };
        let in_penumbra = |samples: &[LightSample]| visibility_of(samples).in_area_penumbra;
        assert!(in_penumbra(&[of(0, Visibility::Visible), of(0, blocked)]));
        // In the shadow of lamp 1, lit by lamp 0: no penumbra of either.
        assert!(!in_penumbra(&[of(0, Visibility::Visible), of(1, blocked)]));
        // A distant light's samples disagreeing are no area penumbra.
        let sky = |visibility| LightSample {
            visibility,
            ..sample(lamp, 0.0, 1.0, 0.5, f32::INFINITY)
        };
        assert!(!in_penumbra(&[sky(Visibility::Visible), sky(blocked)]));
    }

    #[test]
    fn a_penumbra_counts_by_its_share_of_the_light() {
        // Sun-like light (ν_a 100) and a dim sky texel with a sharp edge (ν_a 10⁴), blocked
        // 0.5 m away: penumbrae 200 and 2·10⁴ cycles/m. The sky brings 1 % of the light.
        let blocked = |nu_a: f32, radiance_y: f32| LightSample {
            visibility: Visibility::Blocked {
                blocker_distance_m: 0.5,
            },
            ..sample(
                Bandwidth::distant_light(nu_a).unwrap(),
                5.0,
                radiance_y,
                0.5,
                f32::INFINITY,
            )
        };
        let penumbra = |samples: &[LightSample]| visibility_of(samples).penumbra_cycles_per_m;
        let sun = blocked(100.0, 99.0);
        let sky = blocked(1e4, 1.0);
        assert!((penumbra(&[sun, sky]) - (0.99 * 200.0 + 0.01 * 2e4)).abs() < 1e-2);
        // A visible sample brings light but no penumbra.
        let lit = LightSample {
            visibility: Visibility::Visible,
            ..sun
        };
        assert!((penumbra(&[sun, lit]) - 100.0).abs() < 1e-3);
        // Without shadow rays there is no penumbra.
        assert_eq!(
            penumbra(&[sample(
                Bandwidth::distant_light(1.0).unwrap(),
                5.0,
                1.0,
                0.5,
                1.0
            )]),
            0.0
        );
    }

    #[test]
    fn eq5_gives_more_credit_to_brighter_paths() {
        let low = Bandwidth::distant_light(1.0).unwrap();
        let high = Bandwidth::distant_light(10.0).unwrap();
        let hit = plane_hit(1.0);
        let nu = |a: LightSample, b: LightSample| {
            predict_pixel(&hit, &[a, b], FOOTPRINT, VarianceBandwidth::Incident)
                .unwrap()
                .bandwidth
                .angular_cycles_per_rad
        };
        let bright_high = nu(
            sample(low, 20.0, 1.0, 1.0, f32::INFINITY),
            sample(high, 20.0, 9.0, 1.0, f32::INFINITY),
        );
        let bright_low = nu(
            sample(low, 20.0, 9.0, 1.0, f32::INFINITY),
            sample(high, 20.0, 1.0, 1.0, f32::INFINITY),
        );
        assert!(bright_high > bright_low, "{bright_high} vs {bright_low}");
    }

    #[test]
    fn lambert_plane_under_a_uniform_sky_is_smooth_and_a_point_light_on_it_too() {
        // Lambert: ρ = 0 kills ν_a (the operators' test), so b_p = 0 and eq. 11's level is
        // the coarsest; a uniform sky has ν_a = 0, so V̂ = 0 too.
        let sky = sample(Bandwidth::ZERO, 0.0, 1.0, 0.5, f32::INFINITY);
        let p = predict_pixel(
            &plane_hit(3.0),
            &[sky; 16],
            FOOTPRINT,
            VarianceBandwidth::Incident,
        )
        .unwrap();
        assert_eq!(p.image_bandwidth_cycles_per_px, 0.0);
        assert_eq!(p.variance, 0.0);
        assert!((p.mean_y - 1.0 * (0.8 / std::f32::consts::PI) / 0.5).abs() < 1e-5);
        let point = sample(Bandwidth::POINT_LIGHT, 0.0, 1.0, 0.0, 2.0);
        let p = predict_pixel(
            &plane_hit(3.0),
            &[point],
            FOOTPRINT,
            VarianceBandwidth::Incident,
        )
        .unwrap();
        assert_eq!(p.bandwidth, Bandwidth::ZERO);
        assert_eq!(p.variance, 0.0, "a delta light is one direction");
    }

    #[test]
    fn eq9_grows_with_the_incident_and_material_bandwidths_and_with_chi_squared() {
        let hit = plane_hit(1.0);
        let v = |nu_l: f32, rho: f32, radiance: f32| {
            let s = sample(
                Bandwidth::distant_light(nu_l).unwrap(),
                rho,
                radiance,
                0.25,
                f32::INFINITY,
            );
            predict_pixel(&hit, &[s; 16], FOOTPRINT, VarianceBandwidth::Incident)
                .unwrap()
                .variance
        };
        let base = v(2.0, 3.0, 1.0);
        // (ν_a + ν_ρa) χ²/p · 2π: every factor exactly.
        let chi = 1.0 * (0.8 / std::f32::consts::PI) / 0.8;
        let expected = std::f32::consts::TAU * 5.0 * chi * chi / 0.25;
        assert!(
            (base - expected).abs() < 1e-4 * expected,
            "{base} vs {expected}"
        );
        assert!((v(4.0, 6.0, 1.0) - 2.0 * base).abs() < 1e-4 * base);
        assert!((v(2.0, 3.0, 3.0) - 9.0 * base).abs() < 1e-3 * base);
    }

    #[test]
    fn mirror_sphere_centre_matches_the_closed_form() {
        // The test a: b_p = ν_env (1 + 2 d′ c) · footprint at the centre of a mirror
        // sphere of curvature c seen from d′ (θ_i = θ_x = 0).
        let (radius_m, d_eye_m, nu_env) = (0.5f32, 3.0f32, 4.0f32);
        let curvature = Curvature {
            k1: 1.0 / radius_m,
            k2: 1.0 / radius_m,
            dir1: Vec3A::X,
            dir2: Vec3A::Y,
        };
        let hit = GBufferHit::new(Vec3A::ZERO, d_eye_m, Vec3A::Z, curvature, Vec3A::Z, 0).unwrap();
        let mirror = LightSample {
            direction: Vec3A::Z,
            radiance_y: 1.0,
            pdf_per_sr: 1.0,
            bsdf_cos_per_sr: 1.0,
            cos_theta_i: 1.0,
            distance_m: f32::INFINITY,
            light_bandwidth: Bandwidth::distant_light(nu_env).unwrap(),
            emitter_bandwidth: Bandwidth::distant_light(nu_env).unwrap(),
            light_index: 0,
            material_bandwidth: MaterialBandwidth::new(f32::INFINITY, 0.0).unwrap(),
            lane_variance: 0.0,
            visibility: Visibility::Unknown,
            estimator_y: 0.0,
            draw: 0,
        };
        let footprint = PixelFootprint {
            rad_per_px: 1e-3,
            probe_samples: 1,
            estimator_draws: 1,
        };
        let p = predict_pixel(&hit, &[mirror], footprint, VarianceBandwidth::Incident).unwrap();
        let expected = nu_env * (1.0 + 2.0 * d_eye_m / radius_m) * 1e-3;
        assert!(
            (p.image_bandwidth_cycles_per_px - expected).abs() < 1e-6,
            "{} vs {expected}",
            p.image_bandwidth_cycles_per_px
        );
    }

    #[test]
    fn lane_variance_adds_to_the_predicted_variance() {
        let flat = sample(Bandwidth::ZERO, 0.0, 1.0, 0.5, f32::INFINITY);
        let spiky = LightSample {
            lane_variance: 2.0,
            ..flat
        };
        let v = |s: LightSample, n: usize| {
            predict_pixel(
                &plane_hit(1.0),
                &vec![s; n],
                FOOTPRINT,
                VarianceBandwidth::Incident,
            )
            .unwrap()
            .variance
        };
        assert_eq!(v(flat, 16), 0.0);
        assert!((v(spiky, 16) - 2.0).abs() < 1e-6);
        assert!(
            (v(spiky, 8) - 1.0).abs() < 1e-6,
            "missing samples count as 0"
        );
    }

    #[test]
    fn failed_probe_samples_count_as_zero_in_the_means() {
        let s = sample(Bandwidth::ZERO, 0.0, 1.0, 0.5, f32::INFINITY);
        let all = predict_pixel(
            &plane_hit(1.0),
            &[s; 16],
            FOOTPRINT,
            VarianceBandwidth::Incident,
        )
        .unwrap();
        let half = predict_pixel(
            &plane_hit(1.0),
            &[s; 8],
            FOOTPRINT,
            VarianceBandwidth::Incident,
        )
        .unwrap();
        assert!((half.mean_y - 0.5 * all.mean_y).abs() < 1e-6);
    }

    #[test]
    fn an_unbounded_bandwidth_is_clamped_and_a_bad_footprint_is_an_error() {
        // A mirror (ρ = ∞) reflecting a point light: ν_a = ∞ at the eye.
        let s = sample(Bandwidth::POINT_LIGHT, f32::INFINITY, 1.0, 0.0, 1.0);
        let p = predict_pixel(
            &plane_hit(1.0),
            &[s],
            FOOTPRINT,
            VarianceBandwidth::OneBounce,
        )
        .unwrap();
        assert_eq!(
            p.image_bandwidth_cycles_per_px,
            MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX
        );
        let bad = PixelFootprint {
            rad_per_px: 0.0,
            probe_samples: 16,
            estimator_draws: 16,
        };
        let e = predict_pixel(&plane_hit(1.0), &[s], bad, VarianceBandwidth::Incident).unwrap_err();
        assert!(e.to_string().contains("rad_per_px"), "{e}");
    }

    #[test]
    fn the_measured_variance_is_over_the_estimators_draws() {
        // Two draws of two samples each (a light and a BSDF sample per camera sample): the
        // draws' values are 1 + 1 = 2 and 3 + 3 = 6, variance (2² + 2²)/1 = 8, whatever the
        // samples' spread inside a draw. A third, empty draw counts 0: values 2, 6, 0.
        let value = |estimator_y: f32, draw: u32| LightSample {
            estimator_y,
            draw,
            ..sample(Bandwidth::ZERO, 0.0, 1.0, 0.5, 2.0)
        };
        let samples = [value(1.0, 0), value(1.0, 0), value(3.0, 1), value(3.0, 1)];
        assert_eq!(draw_variance(&samples, 2), 8.0);
        assert!((draw_variance(&samples, 3) - 28.0 / 3.0).abs() < 1e-5);
        // A blocked sample brings nothing; a draw out of range breaks the contract.
        let blocked = LightSample {
            visibility: Visibility::Blocked {
                blocker_distance_m: 1.0,
            },
            ..value(3.0, 1)
        };
        assert_eq!(draw_variance(&[value(1.0, 0), blocked], 2), 0.5);
        assert_eq!(draw_variance(&samples, 1), 0.0);
        assert_eq!(draw_variance(&[value(1.0, 4)], 2), 0.0);
        let p = predict_pixel(
            &plane_hit(2.0),
            &samples,
            FOOTPRINT,
            VarianceBandwidth::Measured,
        )
        .unwrap();
        // 16 draws: 2, 6 and fourteen 0s, mean ½: (1.5² + 5.5² + 14·0.5²)/15 = 2.4.
        assert!((p.measured_variance - 2.4).abs() < 1e-5);
        assert!(
            (p.shading_variance - 2.4).abs() < 1e-5,
            "`Measured` is the same variance"
        );
    }
}
