//! Spectral bins and the illumination AOV of the film: a flat spectrum of 1 gives 1 in every
//! bin and a blackbody gives its bin means, within Monte Carlo standard errors; the
//! illumination AOV is the plain per-sample mean of its XYZ; the render driver builds the
//! film the settings ask for.

use glam::UVec2;
use prism_render::film::xyz::xyz_of_sample;
use prism_render::{
    render, AovSelection, Film, FilmImage, Filter, PixelSampler, RenderScene, RenderSettings,
    SamplerKind, SpectralBins,
};
use prism_spectrum::blackbody::{blackbody_radiance, blackbody_radiance_f32};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

const PIXELS: UVec2 = UVec2::new(16, 8);

/// Renders `radiance(λ)` into a film with `bins` spectral bins, `spp` samples per pixel,
/// independent wavelength samples (so the pixels are independent replicates); filter
/// weights alternate 1 and 3 to check the Σw normalisation.
fn render_spectrum(bins: u32, spp: u32, radiance: impl Fn(f32) -> f32) -> FilmImage {
    let film = Film::new(PIXELS, Filter::default(), AovSelection::NONE)
        .unwrap()
        .with_spectral_bins(bins)
        .unwrap();
    let mut film = film;
    let sampler = PixelSampler::with_kind(SamplerKind::Independent, 99);
    let mut tile = film.new_tile(film.bounds());
    for pixel in film.bounds().pixels() {
        for i in 0..spp {
            let wl = SampledWavelengths::sample_visible(sampler.stream(pixel, i).get_1d());
            let l = SampledSpectrum::from_fn(|lane| radiance(wl.wavelength_nm(lane)));
            let weight = if i % 2 == 0 { 1.0 } else { 3.0 };
            tile.add_sample(pixel, l, &wl, weight, None);
        }
    }
    film.merge_tile(&tile);
    film.finish()
}

/// Mean over pixels of one bin plane and its standard error (pixels are independent).
fn mean_and_standard_error(plane: &[f32]) -> (f64, f64) {
    let n = plane.len() as f64;
    let mean = plane.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let var = plane
        .iter()
        .map(|&v| (f64::from(v) - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// (1/Δλ) ∫ over [lo, lo + Δλ] of `f` by composite Simpson with 0.01 nm steps.
fn bin_mean(f: impl Fn(f64) -> f64, lo_nm: f64, width_nm: f64) -> f64 {
    let n = ((width_nm / 0.01).ceil() as usize).max(2) & !1;
    let h = width_nm / n as f64;
    let mut sum = f(lo_nm) + f(lo_nm + width_nm);
    for i in 1..n {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(lo_nm + i as f64 * h);
    }
    sum * h / 3.0 / width_nm
}

#[test]
fn flat_unit_spectrum_gives_one_in_every_bin_within_the_standard_error() {
    for bins in [1u32, 16, 47] {
        let image = render_spectrum(bins, 64, |_| 1.0);
        let spectral = image.spectral.as_ref().expect("film has bins");
        assert_eq!(spectral.planes.len(), bins as usize);
        assert_eq!(spectral.centres_nm.len(), bins as usize);
        assert!((spectral.width_nm * f64::from(bins) - 470.0).abs() < 1e-9);
        for (b, plane) in spectral.planes.iter().enumerate() {
            assert_eq!(plane.len(), (PIXELS.x * PIXELS.y) as usize);
            let (mean, se) = mean_and_standard_error(plane);
            assert!(se > 0.0 || bins == 1, "bin {b}: no spread?");
            // One bin over the whole range: every lane lands in it, and L/p averaged over
            // the four stratified lanes is nearly constant, so allow a float floor too.
            assert!(
                (mean - 1.0).abs() < 5.0 * se + 1e-5,
                "{bins} bins, bin {b} ({} nm): {mean} ± {se}",
                spectral.centres_nm[b]
            );
        }
    }
}

#[test]
fn blackbody_gives_its_bin_means_within_the_standard_error() {
    let temperature_k = 3000.0;
    let bins = SpectralBins::new(20).unwrap();
    let image = render_spectrum(bins.count(), 64, |wl| {
        blackbody_radiance_f32(wl, temperature_k as f32)
    });
    let spectral = image.spectral.as_ref().unwrap();
    for b in 0..bins.count() {
        let want = bin_mean(
            |wl| blackbody_radiance(wl, temperature_k),
            bins.lower_edge_nm(b),
            bins.width_nm(),
        );
        let (mean, se) = mean_and_standard_error(&spectral.planes[b as usize]);
        assert!(
            (mean - want).abs() < 5.0 * se + 1e-5 * want,
            "bin {b} ({} nm): {mean} vs {want} ± {se}",
            bins.centre_nm(b)
        );
        // Units: W·m⁻²·sr⁻¹·nm⁻¹ — Planck at 3000 K gives ≈ 42 at 360 nm, ≈ 940 at 830 nm.
        assert!(want > 10.0 && want < 2e3, "{want}");
    }
}

#[test]
fn films_without_bins_have_no_spectral_planes_and_bad_counts_name_the_parameter() {
    let film = Film::new(PIXELS, Filter::default(), AovSelection::NONE).unwrap();
    assert!(film.spectral_bins().is_none());
    assert!(film.finish().spectral.is_none());
    for bad in [0, 472] {
        let e = Film::new(PIXELS, Filter::default(), AovSelection::NONE)
            .unwrap()
            .with_spectral_bins(bad)
            .unwrap_err();
        assert_eq!(e.parameter, "spectral_bins");
    }
}

#[test]
fn illumination_aov_is_the_plain_mean_of_its_xyz_over_all_samples_of_the_pixel() {
    let res = UVec2::new(3, 2);
    let selection = AovSelection {
        illumination: true,
        ..AovSelection::NONE
    };
    let mut film = Film::new(res, Filter::default(), selection).unwrap();
    let pixel = UVec2::new(1, 1);
    let mut want = glam::DVec3::ZERO;
    film.render_tiles(2, |tile| {
        if !tile.bounds().contains(pixel) {
            return;
        }
        for i in 0..8 {
            let wl = SampledWavelengths::sample_visible((i as f32 + 0.5) / 8.0);
            // Filter weights do not enter the AOV.
            tile.add_sample(pixel, SampledSpectrum::splat(5.0), &wl, 2.0, None);
            // Half of the samples hit something (the other half are misses: count 0).
            if i % 2 == 0 {
                let l = SampledSpectrum::splat(0.5 + i as f32);
                assert!(tile.add_illumination(pixel, l, &wl));
            }
        }
    });
    for i in (0..8).step_by(2) {
        let wl = SampledWavelengths::sample_visible((i as f32 + 0.5) / 8.0);
        want += xyz_of_sample(SampledSpectrum::splat(0.5 + i as f32), &wl);
    }
    want /= 8.0;
    let image = film.finish();
    let k = image.index(pixel.x, pixel.y);
    for (c, name) in ["illumination.X", "illumination.Y", "illumination.Z"]
        .iter()
        .enumerate()
    {
        let plane = &image.aov(name).unwrap_or_else(|| panic!("{name}")).values;
        assert!(
            (f64::from(plane[k]) - want[c]).abs() < 1e-6 * want[c],
            "{name}: {} vs {}",
            plane[k],
            want[c]
        );
        assert_eq!(plane[0], 0.0, "pixels without samples are 0");
    }
    assert!(image.aov("depth.Z").is_none());
}

/// `variance.Y` is the unbiased sample variance of the samples' Y (the film's XYZ of each
/// sample, unweighted), 0 where a pixel has fewer than two samples.
#[test]
fn variance_aov_is_the_sample_variance_of_the_samples_luminance() {
    let res = UVec2::new(2, 1);
    let selection = AovSelection {
        variance: true,
        ..AovSelection::NONE
    };
    let mut film = Film::new(res, Filter::default(), selection).unwrap();
    let pixel = UVec2::new(1, 0);
    let mut ys = Vec::new();
    film.render_tiles(4, |tile| {
        for i in 0..6 {
            let wl = SampledWavelengths::sample_visible((i as f32 + 0.5) / 6.0);
            let l = SampledSpectrum::splat(1.0 + i as f32);
            tile.add_sample(pixel, l, &wl, 1.0, None);
        }
        tile.add_sample(
            UVec2::ZERO,
            SampledSpectrum::splat(3.0),
            &SampledWavelengths::sample_visible(0.5),
            1.0,
            None,
        );
    });
    for i in 0..6 {
        let wl = SampledWavelengths::sample_visible((i as f32 + 0.5) / 6.0);
        ys.push(xyz_of_sample(SampledSpectrum::splat(1.0 + i as f32), &wl)[1]);
    }
    let mean = ys.iter().sum::<f64>() / 6.0;
    let want = ys.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / 5.0;
    let image = film.finish();
    let plane = &image.aov("variance.Y").expect("variance.Y").values;
    let got = f64::from(plane[image.index(pixel.x, pixel.y)]);
    assert!((got - want).abs() < 1e-6 * want, "{got} vs {want}");
    assert_eq!(plane[0], 0.0, "one sample: no variance");
}

#[test]
fn illumination_is_not_recorded_unless_selected() {
    let mut film = Film::new(UVec2::new(2, 2), Filter::default(), AovSelection::SURFACE).unwrap();
    let mut tile = film.new_tile(film.bounds());
    let wl = SampledWavelengths::sample_visible(0.25);
    tile.add_sample(UVec2::ZERO, SampledSpectrum::one(), &wl, 1.0, None);
    assert!(tile.add_illumination(UVec2::ZERO, SampledSpectrum::one(), &wl));
    film.merge_tile(&tile);
    let image = film.finish();
    assert!(image.aov("illumination.Y").is_none());
    assert!(image.aov("normal.X").is_some());
}

#[test]
fn render_builds_the_film_the_settings_ask_for() {
    let json = r#"{"integrator": "normal", "film": {"resolution": [8, 6]},
        "shapes": [{"type": "sphere", "transform": {"translate": [0, 0, -3]}}]}"#;
    let description = prism_scene::parse_scene_str(json, "test.json").unwrap();
    let scene = RenderScene::build(&description, None).unwrap();
    let settings = RenderSettings {
        spp: 2,
        spectral_bins: Some(SpectralBins::new(8).unwrap()),
        illumination_aov: true,
        ..RenderSettings::default()
    };
    assert_eq!(settings.sampler, SamplerKind::Sobol);
    let (image, _) = render(&scene, &settings, &|_| {});
    let spectral = image.spectral.as_ref().unwrap();
    assert_eq!(spectral.planes.len(), 8);
    // The diagnostic integrators write XYZ only, so the bins and illumination stay 0 until
    // a spectral integrator fills them.
    assert!(spectral.planes.iter().flatten().all(|&v| v == 0.0));
    for name in [
        "illumination.X",
        "illumination.Y",
        "illumination.Z",
        "depth.Z",
    ] {
        assert!(image.aov(name).is_some(), "{name}");
    }
    let (plain, _) = render(&scene, &RenderSettings::default(), &|_| {});
    assert!(plain.spectral.is_none() && plain.aov("illumination.Y").is_none());
}
