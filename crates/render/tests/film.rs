//! Film: flat spectral radiance 1 gives Y = 1 within the Monte Carlo standard error,
//! per-pixel sample counts, AOVs, and bit-identical results for 1 and 2 rayon threads.

use glam::{UVec2, Vec2, Vec3A};
use prism_render::film::filter::{BlackmanHarrisFilter, BoxFilter, GaussianFilter, MitchellFilter};
use prism_render::film::xyz::{cd_m2_per_unit, cie_y_integral_nm, xyz_of_sample};
use prism_render::{
    AovSelection, Camera, CameraFrame, Film, FilmImage, FilmTile, Filter, PinholeCamera,
    PixelSampler, SurfaceAov,
};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

/// Renders flat radiance 1 with `spp` samples per pixel; returns the image and the
/// per-sample Y estimates (for the standard error).
fn render_flat(filter: Filter, spp: u32, seed: u64) -> (FilmImage, Vec<f64>) {
    let res = UVec2::new(24, 16);
    let mut film = Film::new(res, filter, AovSelection::NONE).unwrap();
    let sampler = PixelSampler::new(seed);
    let mut tile = film.new_tile(film.bounds());
    let mut ys = Vec::new();
    for pixel in film.bounds().pixels() {
        for i in 0..spp {
            let mut s = sampler.stream(pixel, i);
            let (_, weight) = film.sample_film_point(pixel, s.get_2d());
            let wl = SampledWavelengths::sample_visible(s.get_1d());
            ys.push(xyz_of_sample(SampledSpectrum::one(), &wl).y);
            tile.add_sample(pixel, SampledSpectrum::one(), &wl, weight, None);
        }
    }
    film.merge_tile(&tile);
    (film.finish(), ys)
}

fn mean_and_standard_error(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn flat_unit_radiance_gives_y_one_within_the_standard_error() {
    for filter in [
        Filter::Box(BoxFilter::default()),
        Filter::Gaussian(GaussianFilter::default()),
        Filter::BlackmanHarris(BlackmanHarrisFilter::default()),
    ] {
        let (image, ys) = render_flat(filter, 16, 1);
        let (_, se_sample) = mean_and_standard_error(&ys);
        assert!(se_sample > 0.0);
        // The image mean over pixels: each pixel averages its samples (weights ≈ 1), so its
        // standard error is that of the sample mean.
        let y: Vec<f64> = image.y.iter().map(|&v| f64::from(v)).collect();
        let (mean, se) = mean_and_standard_error(&y);
        assert!(
            (mean - 1.0).abs() < 4.0 * se.max(se_sample),
            "{filter:?}: mean Y {mean} ± {se}"
        );
        assert!(se < 0.01, "hero wavelengths keep the spread small: {se}");
        assert_eq!(image.cd_m2_per_unit, cd_m2_per_unit());
        assert!((image.cd_m2_per_unit - 683.002 * 106.857).abs() < 1.0);
        assert!((cie_y_integral_nm() - 106.857).abs() < 0.01);
        for (l, y) in image.luminance_cd_m2().iter().zip(&image.y) {
            assert!((f64::from(*l) - f64::from(*y) * 683.002 * cie_y_integral_nm()).abs() < 1e-2);
        }
        let spp = image.aov("spp.Y").unwrap();
        assert!(spp.values.iter().all(|&v| v == 16.0));
    }
}

#[test]
fn rgb_is_rec709_of_xyz() {
    let (image, _) = render_flat(Filter::default(), 4, 2);
    let m = prism_spectrum::rgb_space::RgbColorSpace::srgb().xyz_to_rgb;
    for (xyz, rgb) in image.xyz.iter().zip(&image.rgb) {
        let expected = m * glam::DVec3::from(xyz.map(f64::from));
        for k in 0..3 {
            assert!((f64::from(rgb[k]) - expected[k]).abs() < 1e-5);
        }
    }
    // Equal-energy white sits near D65 white: RGB ≈ (1.2, 0.95, 0.91) per unit Y (for
    // illuminant E in Rec.709), all positive.
    let mean_rgb = image
        .rgb
        .iter()
        .fold([0.0f32; 3], |a, c| [a[0] + c[0], a[1] + c[1], a[2] + c[2]]);
    assert!(mean_rgb.iter().all(|&c| c > 0.0));
}

/// A procedural scene: radiance varies with the ray direction and wavelength; a ground
/// plane y = 0 gives the AOVs.
fn shade(camera: &Camera, sampler: &PixelSampler, pass: u32, tile: &mut FilmTile) {
    for pixel in tile.bounds().pixels() {
        // Pixels get different sample counts, as a SamplePlan would give them.
        let spp = 1 + (pixel.x * 7 + pixel.y * 3) % 5;
        for i in 0..spp {
            // Sample indices continue across passes (at most 5 per pass).
            let mut s = sampler.stream(pixel, pass * 5 + i);
            let (film_point, weight) = tile.sample_film_point(pixel, s.get_2d());
            let wl = SampledWavelengths::sample_visible(s.get_1d());
            let lens = s.get_2d();
            let Some(rd) = camera.generate_ray(film_point, lens) else {
                tile.add_sample(pixel, SampledSpectrum::zero(), &wl, weight, None);
                continue;
            };
            let d = rd.ray.direction;
            let l = SampledSpectrum::from_fn(|k| {
                let lambda = wl.wavelength_nm(k);
                1.0 + 0.5 * (d.x * 3.0 + lambda * 0.01).sin() + d.y.max(0.0)
            });
            let aov = (d.y < 0.0).then(|| {
                let t = -rd.ray.origin.y / d.y;
                let hit = rd.ray.at(t);
                SurfaceAov {
                    depth_m: t,
                    normal: Vec3A::Y,
                    albedo_rgb: [0.5 + 0.1 * (hit.x).sin(), 0.4, 0.3],
                }
            });
            tile.add_sample(pixel, l, &wl, weight, aov.as_ref());
        }
    }
}

fn render_with_threads(threads: usize, tile_size: u32, filter: Filter) -> FilmImage {
    let res = UVec2::new(37, 23);
    let frame = CameraFrame::look_at(
        Vec3A::new(0.0, 1.0, 3.0),
        Vec3A::new(0.0, 1.0, 0.0),
        Vec3A::Y,
        res,
    )
    .unwrap();
    let camera = Camera::Pinhole(PinholeCamera::new(frame, 1.0).unwrap());
    let sampler = PixelSampler::new(1234);
    let mut film = Film::new(res, filter, AovSelection::SURFACE).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    // Two passes, as progressive rendering would do.
    for pass in 0..2 {
        pool.install(|| film.render_tiles(tile_size, |tile| shade(&camera, &sampler, pass, tile)));
    }
    film.finish()
}

fn bits(image: &FilmImage) -> Vec<u32> {
    let mut v: Vec<u32> = image.xyz.iter().flatten().map(|x| x.to_bits()).collect();
    v.extend(image.rgb.iter().flatten().map(|x| x.to_bits()));
    for plane in &image.aovs {
        v.extend(plane.values.iter().map(|x| x.to_bits()));
    }
    v
}

#[test]
fn same_seed_gives_bit_identical_images_for_one_and_two_threads() {
    for filter in [
        Filter::Gaussian(GaussianFilter::default()),
        Filter::Mitchell(MitchellFilter::default()),
    ] {
        let one = render_with_threads(1, 8, filter);
        let two = render_with_threads(2, 8, filter);
        assert_eq!(bits(&one), bits(&two));
        // Tiles do not share pixels, so the tile size does not matter either.
        let other_tiles = render_with_threads(2, 5, filter);
        assert_eq!(bits(&one), bits(&other_tiles));
        // And the image is not trivially constant.
        assert!(one.y.iter().any(|&y| (y - one.y[0]).abs() > 1e-3));
    }
}

#[test]
fn per_pixel_sample_counts_and_aovs_are_recorded() {
    let image = render_with_threads(2, 8, Filter::default());
    let names: Vec<&str> = image.aovs.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "spp.Y", "depth.Z", "normal.X", "normal.Y", "normal.Z", "albedo.R", "albedo.G",
            "albedo.B"
        ]
    );
    let spp = &image.aov("spp.Y").unwrap().values;
    let depth = &image.aov("depth.Z").unwrap().values;
    let ny = &image.aov("normal.Y").unwrap().values;
    for y in 0..image.height {
        for x in 0..image.width {
            let i = image.index(x, y);
            // Two passes of 1 + (7x + 3y) mod 5 samples.
            assert_eq!(spp[i], (2 * (1 + (x * 7 + y * 3) % 5)) as f32);
            // Camera 1 m above the ground looking level: the bottom rows hit
            // the ground (finite depth, normal up), the top rows see the sky.
            if y == image.height - 1 {
                assert!(
                    depth[i].is_finite() && depth[i] > 1.0 && depth[i] < 4.0,
                    "{}",
                    depth[i]
                );
                assert!((ny[i] - 1.0).abs() < 1e-6);
            }
            if y == 0 {
                assert!(depth[i].is_infinite());
                assert_eq!(ny[i], 0.0);
            }
        }
    }
    let _ = Vec2::ZERO;
}

#[test]
fn film_rejects_an_empty_resolution() {
    let e = Film::new(UVec2::new(0, 4), Filter::default(), AovSelection::NONE).unwrap_err();
    assert_eq!(e.parameter, "resolution");
}
