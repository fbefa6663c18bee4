//! The predicted sample plan (Bagher et al. 2013 §2, §3.1; docs/bandwidth.md): a G-buffer of
//! pixel-centre hits, the shading probe's n_b light samples at each, eqs. 5, 6 and 9 per
//! pixel (prism-bandwidth's `predict_pixel`), eq. 11's levels and the allocation of camera
//! samples. Runs once before the first pass; its per-pixel numbers become the EXR layers
//! `bandwidth.S`, `bandwidth.A`, `bandwidth.B`, `plan.level`, `plan.variance`, `plan.spp`.
//!
//! Eq. 6 needs radians per pixel: it is measured from the camera itself, as the larger angle
//! between a pixel's centre ray and those of its right and lower neighbours, so a fisheye
//! or a wide pinhole gets its own footprint at every pixel, not f/W.

use glam::{DVec3, UVec2, Vec2, Vec3A};
use prism_bandwidth::pixel_prediction::MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX;
use prism_bandwidth::{
    allocate, four_neighbours, geometric_edges, model_variance, predict_pixel, Allocated,
    AllocationInputs, AllocationSettings, Bandwidth, BandwidthBuffer, GBufferHit, HierarchyInputs,
    IndirectEstimate, LightSample, MeanLuminance, PixelClass, PixelFootprint, PixelPrediction,
    PoolRadius, ProbeStride, SeenSurface, ShadingProbe, SurfacePoint, Upsampling,
    VarianceBandwidth, VisibilitySummary, DEFAULT_POOL_RADIUS, DEFAULT_PROBE_STRIDE,
};
use prism_spectrum::{SampledSpectrum, SampledWavelengths, XyzWeights};
use rayon::prelude::*;

use crate::film::AovPlane;
use crate::light::Light;
use crate::medium_interfaces::first_surface;
use crate::probe::{facing_normal, RenderProbe};
use crate::scene_build::RenderScene;

/// n_b: probe samples per pixel (Bagher: 16 suffice, Fig. 13).
pub const DEFAULT_PROBE_SAMPLES: u32 = 16;

/// One-bounce indirect estimates per pixel (`--plan-indirect`). Beyond the paper; the pooling
/// gives each pixel its window's estimates, so 4 per pixel allocate as well as 16 within
/// the noise of `tools/bench_plan_allocation.py` on nine scenes, for a sixth to a fifth less
/// of the predictor's time (docs/bandwidth.md, "indirect").
pub const DEFAULT_INDIRECT_SAMPLES: u32 = 4;

/// What the predictor is asked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PredictorSettings {
    /// n_b (`--plan-nb`).
    pub probe_samples: u32,
    pub allocation: AllocationSettings,
    pub variance_bandwidth: VarianceBandwidth,
    /// Shadow edges from the probe's shadow rays (`--plan-visibility`; off = the paper).
    pub visibility: bool,
    /// The colour noise of hero-wavelength sampling in V̂_p (`--plan-colour`; off: the
    /// luminance's variance alone, which misses chroma noise under spiky spectra).
    pub colour_noise: bool,
    /// One-bounce indirect estimates per pixel (`--plan-indirect`; 0 = the paper's
    /// direct-only probe; `ShadingProbe::sample_indirect`).
    pub indirect_samples: u32,
    /// V̂_p pooled over the (2r+1)² pixels of the same surface around each pixel
    /// (`--plan-pool-px`; `auto` = min(W, H)/32 px, 0 = the paper's per-pixel V̂_p;
    /// prism_bandwidth::variance_pooling).
    pub pool_radius: PoolRadius,
    /// The probe samples one pixel in S×S (`--plan-probe-stride`; `auto` = half the pooling
    /// radius, 1 = every pixel, as the paper; prism_bandwidth::sparse_probing).
    pub probe_stride: ProbeStride,
    /// `predicted-hier`: the plan is shaded hierarchically with lattices up to this level
    /// (`Prediction::make_hierarchical`, with the allocation's mean spp and seed); the
    /// automatic probe stride is then 1.
    pub hierarchical_max_level: Option<u32>,
}

impl PredictorSettings {
    /// `prism render --plan predicted`'s defaults for a mean of `mean_spp`: n_b = 16, a
    /// quarter of the budget uniform, the relative-error allocation, the probe's measured
    /// variance, shadow edges on, the automatic pooling radius and probe stride.
    pub const fn defaults(mean_spp: f64, seed: u64) -> Self {
        Self {
            probe_samples: DEFAULT_PROBE_SAMPLES,
            allocation: AllocationSettings {
                mean_spp,
                floor: prism_bandwidth::allocation::DEFAULT_FLOOR,
                allocation: prism_bandwidth::Allocation::RelativeError,
                seed,
            },
            variance_bandwidth: VarianceBandwidth::Measured,
            visibility: true,
            colour_noise: true,
            pool_radius: DEFAULT_POOL_RADIUS,
            indirect_samples: DEFAULT_INDIRECT_SAMPLES,
            probe_stride: DEFAULT_PROBE_STRIDE,
            hierarchical_max_level: None,
        }
    }
}

/// The predictor's answer for a whole image.
#[derive(Clone, Debug)]
pub struct Prediction {
    pub resolution: UVec2,
    /// Per pixel, row-major; the default (all zero) where the centre ray hits nothing.
    pub pixels: Vec<PixelPrediction>,
    pub buffer: BandwidthBuffer,
    pub allocated: Allocated,
    /// Per pixel what the centre ray sees (the pooling's and the up-sampling's classes).
    pub class: Vec<PixelClass>,
    /// Per pixel the centre hit (`None` where the ray escapes or nothing was predicted).
    pub surface: Vec<Option<SurfacePoint>>,
}

/// Why the predictor cannot plan a scene.
fn unsupported(why: &str) -> String {
    format!("the bandwidth predictor cannot plan this scene: {why}")
}

/// The unit direction of the camera ray through `film_point_px` at the lens centre, or
/// `None` where there is none (outside a fisheye's image circle).
fn centre_direction(scene: &RenderScene, film_point_px: Vec2) -> Option<Vec3A> {
    scene
        .camera
        .generate_ray_only(film_point_px, Vec2::splat(0.5))
        .map(|r| r.direction)
}

/// Every pixel's [`centre_direction`] (row-major), from which [`angular_footprint`] reads
/// each pixel's and its neighbours' without generating them again.
fn centre_directions(scene: &RenderScene) -> Vec<Option<Vec3A>> {
    let resolution = scene.resolution;
    let count = resolution.x as usize * resolution.y as usize;
    let mut directions = vec![None; count];
    directions
        .par_chunks_mut(resolution.x as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, d) in row.iter_mut().enumerate() {
                *d = centre_direction(scene, Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            }
        });
    directions
}

/// Radians between the centre ray of `pixel` and those of its right and lower neighbours
/// (the larger; towards the image's inside at its last column and row), or `None` where
/// the pixel has no ray. `directions` are [`centre_directions`]; a neighbour off an image
/// one pixel wide or high is generated here.
fn angular_footprint(
    scene: &RenderScene,
    directions: &[Option<Vec3A>],
    pixel: UVec2,
) -> Option<f32> {
    let resolution = scene.resolution;
    let d = directions[pixel.y as usize * resolution.x as usize + pixel.x as usize]?;
    let neighbour = |dx: i64, dy: i64| {
        let (x, y) = (i64::from(pixel.x) + dx, i64::from(pixel.y) + dy);
        if (0..i64::from(resolution.x)).contains(&x) && (0..i64::from(resolution.y)).contains(&y) {
            directions[y as usize * resolution.x as usize + x as usize]
        } else {
            let p = Vec2::new(
                pixel.x as f32 + 0.5 + dx as f32,
                pixel.y as f32 + 0.5 + dy as f32,
            );
            centre_direction(scene, p)
        }
    };
    let sx = if pixel.x + 1 < resolution.x { 1 } else { -1 };
    let sy = if pixel.y + 1 < resolution.y { 1 } else { -1 };
    let angle = |e: Vec3A| d.dot(e).clamp(-1.0, 1.0).acos();
    let ax = neighbour(sx, 0).map(angle).unwrap_or(0.0);
    let ay = neighbour(0, sy).map(angle).unwrap_or(0.0);
    Some(ax.max(ay))
}

/// The first zero of a uniform disc's Fourier transform, 2 J₁(πcf)/(πcf), times its
/// diameter c: a circle of confusion c px wide passes nothing above 1.2197/c cycles/px.
const DISC_CUTOFF_CYCLES: f32 = 1.2197;

/// A thin lens low-passes what lies out of focus (Soler et al. 2009, "Fourier depth of
/// field", §4: the aperture's spectrum filters the image): each surface pixel's b_p (shadow
/// and geometric edges included) is capped by the circle of confusion's cut-off at its centre hit, so
/// out-of-focus pixels need fewer samples for their detail. In-focus pixels (CoC ≤ 1 px)
/// and background pixels keep theirs; the lens adds no shading-variance term here.
fn defocus_low_pass(
    scene: &RenderScene,
    pixels: &mut [PixelPrediction],
    surface: &[Option<SurfacePoint>],
) {
    let crate::camera::Camera::ThinLens(lens) = &scene.camera else {
        return;
    };
    for (p, s) in pixels.iter_mut().zip(surface) {
        let Some(s) = s else {
            continue;
        };
        let coc_px = lens.circle_of_confusion_px(s.position_m);
        if coc_px > 1.0 {
            p.image_bandwidth_cycles_per_px = p
                .image_bandwidth_cycles_per_px
                .min(DISC_CUTOFF_CYCLES / coc_px);
        }
    }
}

/// A thin lens mixes what neighbouring pinhole pixels see (`prism_bandwidth::
/// defocus_mixing`): each pixel's V̂ and L̂ become its circle of confusion's mixture, the
/// circle taken at its centre hit (at infinity where the centre ray leaves the scene).
fn defocus_mixing(
    scene: &RenderScene,
    surface: &[Option<SurfacePoint>],
    own_mean_y: &[f32],
    modelled: &mut prism_bandwidth::variance_model::ModelledVariance,
) -> Result<(), String> {
    let crate::camera::Camera::ThinLens(lens) = &scene.camera else {
        return Ok(());
    };
    let at_infinity = lens.circle_of_confusion_at_infinity_px();
    let circle_of_confusion_px: Vec<f32> = surface
        .iter()
        .map(|s| s.map_or(at_infinity, |s| lens.circle_of_confusion_px(s.position_m)))
        .collect();
    prism_bandwidth::mix_over_circles_of_confusion(
        scene.resolution,
        prism_bandwidth::DefocusPlanes {
            circle_of_confusion_px: &circle_of_confusion_px,
            variance: &mut modelled.variance,
            luminance_variance: &mut modelled.luminance_variance,
            mean_y: &mut modelled.mean_y,
            own_mean_y,
        },
    )
    .map_err(|e| e.to_string())
}

/// What `pixel`'s centre ray meets (medium interfaces are crossed, as the render's rays
/// cross them).
enum CentreRay {
    /// A surface: its G-buffer hit (with curvature, which shading skips).
    Hit(GBufferHit),
    /// Nothing: the ray leaves the scene in this direction (world, unit).
    Escapes(Vec3A),
    /// No ray (outside a fisheye's image circle) or a degenerate hit.
    None,
}

fn centre_ray(scene: &RenderScene, pixel: UVec2) -> CentreRay {
    let film_point = Vec2::new(pixel.x as f32 + 0.5, pixel.y as f32 + 0.5);
    let Some(ray_differential) = scene.camera.generate_ray(film_point, Vec2::splat(0.5)) else {
        return CentreRay::None;
    };
    let ray = ray_differential.ray;
    let Some(hit) = first_surface(scene, &ray) else {
        return CentreRay::Escapes(ray.direction);
    };
    let mut si = scene.geometry.interaction(&ray, &hit);
    // The footprint the pixel's texture lookups filter over (the texture term t).
    si.compute_differentials(&ray_differential);
    let view = -ray.direction;
    // The side the camera sees: eq. 3's cosines are of that side.
    let normal = facing_normal(si.n_shading, view);
    match GBufferHit::new(
        si.p,
        hit.t,
        normal.normalize(),
        si.curvature,
        view,
        si.material_id,
    )
    .and_then(|hit| hit.with_uv(si.uv))
    .and_then(|hit| hit.with_differentials(si.differentials))
    {
        Ok(hit) => CentreRay::Hit(hit),
        Err(_) => CentreRay::None,
    }
}

/// ν_a of the infinite lights a pixel whose centre ray escapes along `direction` sees: an
/// environment map's eq. 7 value in that direction, a sun disk's only within its radius
/// plus two pixel footprints of the direction (elsewhere it adds nothing to what the pixel
/// sees), the others' (uniform or analytic skies) own.
fn background_angular_bandwidth(
    scene: &RenderScene,
    probe: &RenderProbe<'_>,
    direction: Vec3A,
    rad_per_px: f32,
) -> f32 {
    let lights = scene.lights.lights();
    scene
        .lights
        .infinite_lights()
        .iter()
        .map(|&index| match &lights[index as usize] {
            Light::Directional(sun) => {
                let half_angle_rad = (1.0 - sun.one_minus_cos_half_angle).clamp(-1.0, 1.0).acos();
                let off_rad = direction.dot(sun.to_light).clamp(-1.0, 1.0).acos();
                if off_rad <= half_angle_rad + 2.0 * rad_per_px {
                    lights[index as usize].bandwidth().angular_cycles_per_rad
                } else {
                    0.0
                }
            }
            Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_)
            | Light::Point(_)
            | Light::Spot(_)
            | Light::Area(_)
            | Light::Goniometric(_) => {
                probe
                    .light_bandwidths_towards(index as usize, direction, None)
                    .0
                    .angular_cycles_per_rad
            }
        })
        .fold(0.0f32, f32::max)
}

/// A mirror or smooth glass (a Dirac lobe) shows the sun's disk where the reflected cone of
/// the pixel's footprint reaches it (test f: "a mirror sphere reflecting the sun"). The
/// probe follows the centre ray's one mirror direction, which misses a 0.53° sun almost
/// everywhere on a curved mirror, as the centre ray of a background pixel misses it
/// (`background_angular_bandwidth`). The cone's half-angle per pixel: the view's own
/// spread plus twice the normal's turn across the footprint, 2·k·d·rad_per_px / cos θ_x
/// (k the larger principal curvature, d the depth). Within it of the sun's disk, the pixel
/// sees the disk's edge: b_p = the sun's ν_a times that spread (cycles/px, clamped as
/// eq. 6 clamps). Beyond the paper, like the shadow edges. For Dirac hits only.
fn mirrored_sun_bandwidth(scene: &RenderScene, hit: &GBufferHit, rad_per_px: f32) -> f32 {
    let (n, v) = (hit.normal(), hit.view_direction());
    let mirrored = 2.0 * n.dot(v) * n - v;
    let c = hit.curvature();
    let turn = 2.0 * c.k1.abs().max(c.k2.abs()) * hit.depth_m() * rad_per_px
        / hit.cos_theta_view().max(1e-3);
    let spread_rad = rad_per_px + turn;
    scene
        .lights
        .lights()
        .iter()
        .map(|light| match light {
            Light::Directional(sun) => {
                let half_angle_rad = (1.0 - sun.one_minus_cos_half_angle).clamp(-1.0, 1.0).acos();
                let off_rad = mirrored.dot(sun.to_light).clamp(-1.0, 1.0).acos();
                if off_rad <= half_angle_rad + spread_rad {
                    (light.bandwidth().angular_cycles_per_rad * spread_rad)
                        .min(prism_bandwidth::pixel_prediction::MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX)
                } else {
                    0.0
                }
            }
            Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_)
            | Light::Point(_)
            | Light::Spot(_)
            | Light::Area(_)
            | Light::Goniometric(_) => 0.0,
        })
        .fold(0.0f32, f32::max)
}

/// A texel's scale (ρ_p) at least a tenth of its material's mean: a pixel whose centre
/// hits a black texel still shares its footprint with lit ones (a checkerboard's black
/// cell beside a white one), and a scale of 0 would pool its V̂ and L̂ to exactly 0.
fn keep_texture_scales_off_zero(texture_scale: &mut [f32], class: &[PixelClass]) {
    let mut sums: std::collections::HashMap<u32, (f64, u32)> = std::collections::HashMap::new();
    for (scale, c) in texture_scale.iter().zip(class) {
        if let PixelClass::Material(id) = c {
            let entry = sums.entry(*id).or_default();
            entry.0 += f64::from(*scale);
            entry.1 += 1;
        }
    }
    for (scale, c) in texture_scale.iter_mut().zip(class) {
        if let PixelClass::Material(id) = c {
            let (sum, n) = sums[id];
            *scale = scale.max((0.1 * sum / f64::from(n)) as f32);
        }
    }
}

/// What the probe pass finds at one pixel, before the image-wide steps.
struct ProbedPixel {
    prediction: PixelPrediction,
    /// The larger principal curvature's magnitude at the centre hit (the MIP pyramid's).
    curvature_per_m: f32,
    /// ρ_p for the pooling (`RenderProbe::hit_material`; 1 off textured surfaces).
    texture_scale: f32,
    eye: Option<EyeGeometry>,
    class: PixelClass,
    surface: Option<SurfacePoint>,
    /// The centre hit scatters only in Dirac directions (`RenderProbe::hit_material`).
    dirac: bool,
    /// What a Dirac centre hit shows (`RenderProbe::seen_through_dirac`).
    seen: Option<SeenSurface>,
}

impl ProbedPixel {
    /// A pixel the predictor says nothing about (no footprint, or no hit and no infinite
    /// light).
    fn unpredicted() -> Self {
        Self {
            prediction: PixelPrediction::default(),
            curvature_per_m: 0.0,
            texture_scale: 1.0,
            eye: None,
            class: PixelClass::Unpredicted,
            surface: None,
            dirac: false,
            seen: None,
        }
    }
}

/// The wavelengths of an escaping pixel's quadrature (`escaping_pixel`): `count` stratified
/// sets over the RGB-output density with their CMF weights, built once per prediction since
/// every background pixel takes the same.
struct BackgroundQuadrature {
    wavelengths: Vec<SampledWavelengths>,
    weights: Vec<XyzWeights>,
}

impl BackgroundQuadrature {
    fn new(count: u32) -> Self {
        let wavelengths: Vec<SampledWavelengths> = (0..count)
            .map(|k| SampledWavelengths::sample_rgb_output((k as f32 + 0.5) / count as f32))
            .collect();
        let weights = wavelengths.iter().map(XyzWeights::new).collect();
        Self {
            wavelengths,
            weights,
        }
    }
}

/// A pixel that sees the infinite lights directly: its noise is colour noise alone (the
/// hero wavelengths' estimate of the radiance along the ray, over the stratified hero
/// wavelengths of `quadrature`) plus the anti-aliasing of the lights' own detail (b_p).
fn escaping_pixel(
    scene: &RenderScene,
    direction: Vec3A,
    quadrature: &BackgroundQuadrature,
    background_nu_a: f32,
    rad_per_px: f32,
    radiance: &mut Vec<SampledSpectrum>,
) -> PixelPrediction {
    let lights = &scene.lights;
    radiance.clear();
    radiance.resize(quadrature.wavelengths.len(), SampledSpectrum::splat(0.0));
    for &l in lights.infinite_lights() {
        lights
            .light(l)
            .add_infinite_radiance_each(direction, &quadrature.wavelengths, radiance);
    }
    let estimates = || {
        radiance
            .iter()
            .zip(&quadrature.weights)
            .map(|(&r, weights)| weights.xyz(r))
    };
    let count = radiance.len();
    let n = count.max(1) as f64;
    let mean = estimates().sum::<DVec3>() / n;
    // Unbiased sample variances: of the X, Y and Z lanes summed (the colour noise), and of
    // Y alone (what `--plan-colour off` follows).
    let (variance, luminance_variance) = if count > 1 {
        let (xyz, y) = estimates().fold((0.0, 0.0), |(xyz, y), x| {
            let d = x - mean;
            (xyz + d.length_squared(), y + d.y * d.y)
        });
        (xyz / (n - 1.0), y / (n - 1.0))
    } else {
        (0.0, 0.0)
    };
    PixelPrediction {
        bandwidth: Bandwidth {
            spatial_cycles_per_m: 0.0,
            angular_cycles_per_rad: background_nu_a,
        },
        image_bandwidth_cycles_per_px: (background_nu_a * rad_per_px)
            .min(MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX),
        variance: variance as f32,
        luminance_variance: luminance_variance as f32,
        shading_variance: 0.0,
        colour_variance: variance as f32,
        mean_y: mean.y as f32,
        indirect_variance: 0.0,
        measured_variance: 0.0,
        visibility: VisibilitySummary::default(),
    }
}

/// The mean and the unbiased sample variance of `values` (0, 0 when empty; variance 0
/// for one value).
fn mean_and_variance(values: impl Iterator<Item = f32> + Clone) -> (f32, f32) {
    let n = values.clone().count();
    if n == 0 {
        return (0.0, 0.0);
    }
    let count = n as f64;
    let mean = values.clone().map(f64::from).sum::<f64>() / count;
    let variance = if n > 1 {
        values.map(|v| (f64::from(v) - mean).powi(2)).sum::<f64>() / (count - 1.0)
    } else {
        0.0
    };
    (mean as f32, variance as f32)
}

/// Where a hit pixel's image bandwidth comes from, for the visibility pass: the eye
/// distance d′ (m), cos θ_x and the pixel's radians per pixel.
#[derive(Clone, Copy, Debug, Default)]
struct EyeGeometry {
    depth_m: f32,
    cos_theta_x: f32,
    rad_per_px: f32,
}

/// Shadow edges (`prism_bandwidth::visibility`): a pixel in an area light's penumbra (its
/// samples of one area light disagree), or whose visible share differs from a
/// 4-neighbour's beyond sampling noise (`VisibilitySummary::differs_from`), gets the
/// penumbra's spatial bandwidth (its own or, when all its light samples were visible, its
/// neighbours'), carried to the eye like a texture's (P_x then T_d′). An environment's
/// samples disagreeing is no edge by itself: in the sun's umbra under a visible sky every
/// pixel has both.
fn add_shadow_edges(
    resolution: UVec2,
    pixels: &mut [PixelPrediction],
    eye: &[Option<EyeGeometry>],
) {
    let before: Vec<VisibilitySummary> = pixels.iter().map(|p| p.visibility).collect();
    for i in 0..before.len() {
        let Some(eye) = eye[i] else { continue };
        let own = before[i];
        let mut edge = own.in_area_penumbra;
        let mut penumbra = own.penumbra_cycles_per_m;
        for n in four_neighbours(i, resolution) {
            if own.differs_from(&before[n]) {
                edge = true;
                penumbra = penumbra.max(before[n].penumbra_cycles_per_m);
            }
        }
        if !edge || penumbra <= 0.0 || eye.cos_theta_x <= 0.0 {
            continue;
        }
        let p = &mut pixels[i];
        let spatial = penumbra / eye.cos_theta_x;
        p.bandwidth.spatial_cycles_per_m += spatial;
        p.bandwidth.angular_cycles_per_rad += eye.depth_m * spatial;
        p.image_bandwidth_cycles_per_px = (p.bandwidth.angular_cycles_per_rad * eye.rad_per_px)
            .min(MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX);
    }
}

/// A pixel the probe skipped takes the nearest probed pixel's bandwidth ν (of its own
/// surface, within the pooling radius) and its shadow rays' summary, and turns ν into its
/// own b_p with its own footprint (eq. 6); its V̂ and L̂ come from the pooling.
fn borrow_from_probed(
    resolution: UVec2,
    pixels: &mut [PixelPrediction],
    class: &[PixelClass],
    probed: &[bool],
    eye: &[Option<EyeGeometry>],
    radius_px: u32,
) -> Result<(), String> {
    let donors = prism_bandwidth::nearest_probed(resolution, class, probed, radius_px)
        .map_err(|e| e.to_string())?;
    for (i, donor) in donors.iter().enumerate() {
        let (Some(j), Some(eye)) = (donor, eye[i]) else {
            continue;
        };
        let (bandwidth, visibility) = (pixels[*j].bandwidth, pixels[*j].visibility);
        let p = &mut pixels[i];
        p.bandwidth = bandwidth;
        p.visibility = visibility;
        p.image_bandwidth_cycles_per_px = p.image_bandwidth_cycles_per_px.max(
            (bandwidth.angular_cycles_per_rad * eye.rad_per_px)
                .min(MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX),
        );
    }
    Ok(())
}

/// What the probe needs at each surface pixel, shared by the G-buffer's pass and the pass
/// over the pixels off the probe's lattice.
struct ProbeWork<'a, 'p> {
    scene: &'a RenderScene,
    probe: &'p RenderProbe<'a>,
    /// n_b at a probed pixel (`samples_per_probed_pixel`).
    light_samples: u32,
    /// One-bounce indirect estimates at a probed pixel.
    indirect_samples: u32,
    variance_bandwidth: VarianceBandwidth,
    /// S of the probe's lattice (`ProbeStride::px`).
    stride_px: u32,
    background_quadrature: BackgroundQuadrature,
}

/// A thread's reusable buffers for the probe's samples.
#[derive(Default)]
struct ProbeScratch {
    samples: Vec<LightSample>,
    indirect: Vec<IndirectEstimate>,
    /// An escaping pixel's radiance per wavelength set of the background quadrature.
    background: Vec<SampledSpectrum>,
}

impl ProbeWork<'_, '_> {
    /// A surface pixel's prediction: the probe's where `probed` (eqs. 5, 6, 9 and the
    /// indirect estimates), otherwise the default that `borrow_from_probed` fills; both
    /// with the sun's bandwidth seen in a mirror where the centre hit is `dirac`
    /// (`RenderProbe::hit_material`).
    fn surface_prediction(
        &self,
        pixel: UVec2,
        hit: &GBufferHit,
        rad_per_px: f32,
        probed: bool,
        dirac: bool,
        scratch: &mut ProbeScratch,
    ) -> Result<PixelPrediction, String> {
        let mut p = if probed {
            let estimator_draws =
                self.probe
                    .sample_lights(pixel, hit, self.light_samples, &mut scratch.samples);
            let footprint = PixelFootprint {
                rad_per_px,
                probe_samples: self.light_samples,
                estimator_draws,
            };
            let mut p = predict_pixel(hit, &scratch.samples, footprint, self.variance_bandwidth)
                .map_err(|e| e.to_string())?;
            self.probe
                .sample_indirect(pixel, hit, self.indirect_samples, &mut scratch.indirect);
            let (mean, variance) = mean_and_variance(scratch.indirect.iter().map(|e| e.radiance_y));
            p.mean_y += mean;
            p.indirect_variance = variance;
            // The indirect light's own colour noise (dispersion through glass, spiky spectra
            // seen by a bounce), per camera sample.
            p.colour_variance +=
                mean_and_variance(scratch.indirect.iter().map(|e| e.lane_variance)).0;
            p
        } else {
            PixelPrediction::default()
        };
        if dirac {
            p.image_bandwidth_cycles_per_px = p
                .image_bandwidth_cycles_per_px
                .max(mirrored_sun_bandwidth(self.scene, hit, rad_per_px));
        }
        Ok(p)
    }

    /// Whether the probe samples `pixel` in the G-buffer's pass (the lattice of stride S).
    fn on_lattice(&self, pixel: UVec2) -> bool {
        prism_bandwidth::on_probe_lattice(pixel.x, pixel.y, self.stride_px)
    }

    /// The G-buffer's pass at `pixel`: its footprint from the centre `directions`
    /// ([`centre_directions`]), its centre hit or escape, and the probe's prediction where
    /// the pixel is on the probe's lattice.
    fn gbuffer_pixel(
        &self,
        pixel: UVec2,
        directions: &[Option<Vec3A>],
        scratch: &mut ProbeScratch,
    ) -> Result<ProbedPixel, String> {
        let Some(rad_per_px) =
            angular_footprint(self.scene, directions, pixel).filter(|a| *a > 0.0)
        else {
            return Ok(ProbedPixel::unpredicted());
        };
        match centre_ray(self.scene, pixel) {
            CentreRay::Hit(hit) => {
                let material = self.probe.hit_material(&hit);
                let dirac = material.dirac;
                let p = self.surface_prediction(
                    pixel,
                    &hit,
                    rad_per_px,
                    self.on_lattice(pixel),
                    dirac,
                    scratch,
                )?;
                let c = hit.curvature();
                Ok(ProbedPixel {
                    prediction: p,
                    curvature_per_m: c.k1.abs().max(c.k2.abs()),
                    texture_scale: material.texture_scale,
                    eye: Some(EyeGeometry {
                        depth_m: hit.depth_m(),
                        cos_theta_x: hit.cos_theta_view(),
                        rad_per_px,
                    }),
                    class: PixelClass::Material(hit.material_id()),
                    surface: Some(SurfacePoint {
                        position_m: hit.position_m(),
                        normal: hit.normal(),
                    }),
                    dirac,
                    seen: dirac.then(|| self.probe.seen_through_dirac(&hit)).flatten(),
                })
            }
            CentreRay::Escapes(direction) => Ok(ProbedPixel {
                prediction: escaping_pixel(
                    self.scene,
                    direction,
                    &self.background_quadrature,
                    background_angular_bandwidth(self.scene, self.probe, direction, rad_per_px),
                    rad_per_px,
                    &mut scratch.background,
                ),
                class: PixelClass::Background,
                ..ProbedPixel::unpredicted()
            }),
            CentreRay::None => Ok(ProbedPixel::unpredicted()),
        }
    }
}

/// Runs the predictor over every pixel of `scene` (in parallel on the current rayon pool).
pub fn predict(
    scene: &RenderScene,
    settings: &PredictorSettings,
    seed: u64,
) -> Result<Prediction, String> {
    predict_with_probe(
        scene,
        settings,
        RenderProbe::new(scene, seed).with_bandwidth_tables()?,
    )
}

/// [`predict`] with a probe whose BSDF and environment tables are built already (so that
/// a caller can time the tables apart from the per-pixel prediction).
pub fn predict_with_probe<'a>(
    scene: &'a RenderScene,
    settings: &PredictorSettings,
    mut probe: RenderProbe<'a>,
) -> Result<Prediction, String> {
    if settings.probe_samples == 0 {
        return Err("--plan-nb must be at least 1".into());
    }
    let resolution = scene.resolution;
    probe.trace_visibility = settings.visibility;
    let pool_radius_px = settings.pool_radius.px(resolution);
    let stride_px = settings
        .probe_stride
        .px(pool_radius_px, settings.hierarchical_max_level.is_some());
    let light_samples =
        prism_bandwidth::samples_per_probed_pixel(settings.probe_samples, stride_px);
    // Light beyond the first bounce only where the estimator carries it (max_depth > 1):
    // with direct light only, the indirect estimates would predict light the render lacks.
    let indirect_samples = if probe.estimator.carries_indirect() {
        prism_bandwidth::samples_per_probed_pixel(settings.indirect_samples, stride_px)
    } else {
        0
    };
    let probe_work = ProbeWork {
        scene,
        probe: &probe,
        light_samples,
        indirect_samples,
        variance_bandwidth: settings.variance_bandwidth,
        stride_px,
        background_quadrature: BackgroundQuadrature::new(settings.probe_samples),
    };
    // The lattice's pixels are probed in the G-buffer's pass; the pixels of surfaces with no
    // lattice pixel within the pooling radius, which only the G-buffer's classes find, in a
    // second pass (the centre rays are traced once, but for those few).
    let directions = centre_directions(scene);
    let count = resolution.x as usize * resolution.y as usize;
    let w = resolution.x as usize;
    let unpredicted = ProbedPixel::unpredicted();
    let mut pixels = vec![unpredicted.prediction; count];
    let mut curvature = vec![unpredicted.curvature_per_m; count];
    let mut texture_scale = vec![unpredicted.texture_scale; count];
    let mut eye = vec![unpredicted.eye; count];
    let mut class = vec![unpredicted.class; count];
    let mut surface = vec![unpredicted.surface; count];
    let mut dirac = vec![unpredicted.dirac; count];
    let mut seen = vec![unpredicted.seen; count];
    // Each row written straight into the image-wide buffers (no per-pixel record kept).
    (
        pixels.par_chunks_mut(w),
        curvature.par_chunks_mut(w),
        texture_scale.par_chunks_mut(w),
        eye.par_chunks_mut(w),
        class.par_chunks_mut(w),
        surface.par_chunks_mut(w),
        dirac.par_chunks_mut(w),
        seen.par_chunks_mut(w),
    )
        .into_par_iter()
        .enumerate()
        .try_for_each(|(y, row)| -> Result<(), String> {
            let y = y as u32;
            let mut scratch = ProbeScratch::default();
            let (pixels, curvature, texture_scale, eye, class, surface, dirac, seen) = row;
            for x in 0..w {
                let probed =
                    probe_work.gbuffer_pixel(UVec2::new(x as u32, y), &directions, &mut scratch)?;
                pixels[x] = probed.prediction;
                curvature[x] = probed.curvature_per_m;
                texture_scale[x] = probed.texture_scale;
                eye[x] = probed.eye;
                class[x] = probed.class;
                surface[x] = probed.surface;
                dirac[x] = probed.dirac;
                seen[x] = probed.seen;
            }
            Ok(())
        })?;
    let probed = prism_bandwidth::probed_pixels(resolution, &class, stride_px, pool_radius_px)
        .map_err(|e| e.to_string())?;
    let off_lattice: Vec<(usize, PixelPrediction)> = (0..count)
        .into_par_iter()
        .filter(|&i| {
            probed[i]
                && matches!(class[i], PixelClass::Material(_))
                && !probe_work.on_lattice(UVec2::new((i % w) as u32, (i / w) as u32))
        })
        .map_init(ProbeScratch::default, |scratch, i| {
            let pixel = UVec2::new((i % w) as u32, (i / w) as u32);
            let (Some(eye), CentreRay::Hit(hit)) = (eye[i], centre_ray(scene, pixel)) else {
                return Err(format!(
                    "pixel {pixel}: its centre ray no longer meets the surface it met (the \
                     G-buffer's rays are deterministic; this is a bug)"
                ));
            };
            let p = probe_work.surface_prediction(
                pixel,
                &hit,
                eye.rad_per_px,
                true,
                dirac[i],
                scratch,
            )?;
            Ok((i, p))
        })
        .collect::<Result<Vec<_>, String>>()?;
    for (i, p) in off_lattice {
        pixels[i] = p;
    }
    keep_texture_scales_off_zero(&mut texture_scale, &class);
    borrow_from_probed(
        resolution,
        &mut pixels,
        &class,
        &probed,
        &eye,
        pool_radius_px,
    )?;
    if settings.visibility {
        add_shadow_edges(resolution, &mut pixels, &eye);
    }
    // Each pixel's own L̂ (a skipped pixel's borrowed from its probed neighbour), before
    // the skipped pixels take their window's below.
    let own_mean_y: Vec<f32> = pixels.iter().map(|p| p.mean_y).collect();
    let mut modelled = model_variance(
        resolution,
        &pixels,
        &class,
        &texture_scale,
        &probed,
        pool_radius_px,
        settings.variance_bandwidth == VarianceBandwidth::Measured,
    )
    .map_err(|e| e.to_string())?;
    defocus_mixing(scene, &surface, &own_mean_y, &mut modelled)?;
    for (i, p) in pixels.iter_mut().enumerate() {
        p.variance = if settings.colour_noise {
            modelled.variance[i]
        } else {
            modelled.luminance_variance[i]
        };
        p.luminance_variance = modelled.luminance_variance[i];
        // A pixel the probe skipped has no samples of its own: its L̂ is its window's.
        if !probed[i] {
            p.mean_y = modelled.mean_y[i];
        }
    }
    // Silhouettes, creases and material edges inside a footprint, seen directly or in a
    // mirror: a step, not band-limited.
    let edges = geometric_edges(
        resolution,
        &class,
        &surface,
        &seen,
        MeanLuminance {
            pooled_y: &modelled.mean_y,
            own_y: &own_mean_y,
        },
    )
    .map_err(|e| e.to_string())?;
    for (p, edge) in pixels.iter_mut().zip(edges) {
        if edge {
            p.image_bandwidth_cycles_per_px = MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX;
        }
    }
    defocus_low_pass(scene, &mut pixels, &surface);
    let b: Vec<f32> = pixels
        .iter()
        .map(|p| p.image_bandwidth_cycles_per_px)
        .collect();
    let variance = if settings.colour_noise {
        &modelled.variance
    } else {
        &modelled.luminance_variance
    };
    let mean_y = &modelled.mean_y;
    let buffer = BandwidthBuffer::new(resolution, &b, variance, &curvature)
        .map_err(|e| unsupported(&e.to_string()))?;
    let levels = &buffer.levels()[0].shading_level;
    let allocated = allocate(
        resolution,
        AllocationInputs {
            variance,
            mean_y,
            shading_level: levels,
            uninformed: Some(&modelled.uninformed),
        },
        settings.allocation,
    )
    .map_err(|e| e.to_string())?;
    Ok(Prediction {
        resolution,
        pixels,
        buffer,
        allocated,
        class,
        surface,
    })
}

impl Prediction {
    /// Hierarchical shading (Bagher et al. 2013 §3.2) on this prediction: the lattice of
    /// shaded pixels from eq. 11's levels (at most `max_level`) and the bilateral weights of
    /// the others; the plan becomes the concentrated one (interpolated pixels get no camera
    /// samples, their density goes to their parents; `mean_spp` and `seed` round it).
    pub fn make_hierarchical(
        &mut self,
        max_level: u32,
        mean_spp: f64,
        seed: u64,
    ) -> Result<Upsampling, String> {
        let upsampling = Upsampling::plan(
            self.resolution,
            HierarchyInputs {
                shading_level: &self.buffer.levels()[0].shading_level,
                class: &self.class,
                surface: &self.surface,
                max_level,
            },
        )
        .map_err(|e| e.to_string())?;
        self.allocated = upsampling
            .concentrate(&self.allocated, mean_spp, seed)
            .map_err(|e| e.to_string())?;
        Ok(upsampling)
    }

    /// The EXR layers of the prediction (docs/bandwidth.md): ν_s (cycles/m), ν_a
    /// (cycles/rad), b_p (cycles/px), eq. 11's level, V̂_p and the planned camera samples.
    pub fn aov_planes(&self) -> Vec<AovPlane> {
        let plane = |name: &str, f: &dyn Fn(usize) -> f32| AovPlane {
            name: name.to_string(),
            values: (0..self.pixels.len()).map(f).collect(),
        };
        let plan = &self.allocated.plan;
        let w = self.resolution.x as usize;
        let levels = &self.buffer.levels()[0].shading_level;
        vec![
            plane("bandwidth.S", &|i| {
                self.pixels[i].bandwidth.spatial_cycles_per_m
            }),
            plane("bandwidth.A", &|i| {
                self.pixels[i].bandwidth.angular_cycles_per_rad
            }),
            plane("bandwidth.B", &|i| {
                self.pixels[i].image_bandwidth_cycles_per_px
            }),
            plane("plan.level", &|i| levels[i] as f32),
            plane("plan.variance", &|i| self.pixels[i].variance),
            plane("plan.spp", &|i| {
                plan.camera_samples(UVec2::new((i % w) as u32, (i / w) as u32)) as f32
            }),
        ]
    }
}
