//! Round trips through every file format, and the errors a user sees for bad files.

use std::path::PathBuf;

use prism_image::io::exr::{read_exr, write_exr, ExrCompression, ExrSampleType, ExrWriteOptions};
use prism_image::io::png::{read_png, write_png, PngBitDepth};
use prism_image::io::rgbe::{decode_rgbe, encode_rgbe, read_hdr, write_hdr};
use prism_image::io::spectral_exr::{
    emissive_channel_name, parse_spectral_channel, read_spectral_exr,
    write_exr_with_spectral_bands, write_spectral_exr, SpectralChannelKind, SpectralImage,
    EMISSIVE_UNITS_ATTRIBUTE, RADIANCE_UNITS, VERSION_ATTRIBUTE,
};
use prism_image::io::{read_image, write_image};
use prism_image::Image;
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::Observer;

fn scratch(name: &str) -> PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("prism-post-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A 37×23 HDR test image with values spanning 1e-3 … 1e4 and every channel distinct.
fn hdr_image(space: RgbColorSpace) -> Image {
    let (w, h) = (37, 23);
    let pixels = (0..w * h)
        .map(|i| {
            let t = i as f32 / (w * h) as f32;
            let v = 10f32.powf(-3.0 + 7.0 * t);
            [v, 0.5 * v + 0.01, 0.25 * v + 0.02 * (i % 7) as f32]
        })
        .collect();
    Image::new(w, h, pixels, space).unwrap()
}

#[test]
fn exr_float_round_trip_is_exact_with_layers_scale_and_colour_space() {
    let mut img = hdr_image(RgbColorSpace::rec2020());
    let n = img.width() * img.height();
    img.set_layer("depth", &["Z"], (0..n).map(|i| i as f32 * 0.5).collect())
        .unwrap();
    img.set_layer(
        "normal",
        &["X", "Y", "Z"],
        (0..3 * n).map(|i| (i % 5) as f32 - 2.0).collect(),
    )
    .unwrap();
    img.set_layer("spp", &["Y"], vec![64.0; n]).unwrap();
    img.cd_m2_per_unit = Some(72_983.4);
    img.metadata
        .insert("prism:scene".into(), "cornell.json".into());
    for compression in [
        ExrCompression::None,
        ExrCompression::Zip,
        ExrCompression::Piz,
    ] {
        let path = scratch("float.exr");
        let options = ExrWriteOptions {
            sample_type: ExrSampleType::F32,
            compression,
        };
        write_exr(&path, &img, &options).unwrap();
        let back = read_exr(&path).unwrap();
        assert_eq!(back.pixels(), img.pixels());
        assert_eq!(back.color_space.name, "Rec.2020");
        assert_eq!(back.cd_m2_per_unit, Some(72_983.4));
        assert_eq!(back.metadata.get("prism:scene").unwrap(), "cornell.json");
        for layer in img.layers() {
            let got = back.layer(&layer.name).expect("layer survives");
            assert_eq!(got, layer);
        }
    }
}

#[test]
fn exr_half_round_trip_is_within_half_precision() {
    let img = hdr_image(RgbColorSpace::srgb());
    let path = scratch("half.exr");
    let options = ExrWriteOptions {
        sample_type: ExrSampleType::F16,
        compression: ExrCompression::Zip,
    };
    write_exr(&path, &img, &options).unwrap();
    let back = read_exr(&path).unwrap();
    // Half has a 10-bit mantissa: round-to-nearest error ≤ 2^-11 relative (normal range;
    // every test value is ≥ 1e-3, far above the half normal minimum 6.1e-5).
    for (a, b) in img.pixels().iter().zip(back.pixels()) {
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() <= a[c] * 2f32.powi(-11), "{a:?} {b:?}");
        }
    }
    assert_eq!(back.color_space.name, "sRGB");
    assert_eq!(back.cd_m2_per_unit, None);
}

#[test]
fn exr_write_leaves_no_temporary_file_and_replaces_atomically() {
    let img = hdr_image(RgbColorSpace::srgb());
    // A directory of its own: the other tests write into `scratch` at the same time, and
    // their writers' temporary files would be counted here.
    let dir = scratch("atomic");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("atomic.exr");
    write_image(&path, &img).unwrap();
    write_image(&path, &img).unwrap();
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
    // Writing into a missing directory fails with an error naming the file.
    let bad = scratch("no-such-dir").join("x.exr");
    let err = write_image(&bad, &img).unwrap_err().to_string();
    assert!(err.contains("x.exr"), "{err}");
}

#[test]
fn rgbe_codec_error_is_within_its_mantissa_step() {
    // Shared exponent: each channel is quantised in steps of 2^(e-8) where 2^(e-1) ≤ max < 2^e,
    // and decoded at the step centre, so |error| ≤ half a step ≤ max · 2^-8.
    for &v in &[1e-6f32, 0.003, 0.5, 1.0, 1.7, 255.9, 1e5] {
        for rgb in [[v, v * 0.3, v * 0.01], [v * 0.2, v, 0.0]] {
            let back = decode_rgbe(encode_rgbe(rgb));
            let max = rgb.iter().cloned().fold(0.0, f32::max);
            for c in 0..3 {
                assert!(
                    (back[c] - rgb[c]).abs() <= max / 256.0,
                    "{rgb:?} → {back:?}"
                );
            }
        }
    }
    assert_eq!(encode_rgbe([0.0; 3]), [0; 4]);
    assert_eq!(encode_rgbe([f32::NAN, -1.0, f32::INFINITY]), [0; 4]);
}

#[test]
fn hdr_round_trip_keeps_values_to_rgbe_precision_and_colour_space() {
    for space in [RgbColorSpace::srgb(), RgbColorSpace::display_p3()] {
        let img = hdr_image(space.clone());
        let path = scratch("round.hdr");
        write_hdr(&path, &img).unwrap();
        let back = read_hdr(&path).unwrap();
        assert_eq!((back.width(), back.height()), (img.width(), img.height()));
        assert_eq!(back.color_space.name, space.name);
        for (a, b) in img.pixels().iter().zip(back.pixels()) {
            let max = a.iter().cloned().fold(0.0, f32::max);
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= max / 256.0);
            }
        }
    }
}

#[test]
fn hdr_reads_flat_scanlines_and_applies_exposure() {
    // A 2×1 picture (too narrow for RLE), exposure 2: stored values are twice the true ones.
    let path = scratch("flat.hdr");
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=2\n\n-Y 1 +X 2\n".to_vec();
    bytes.extend_from_slice(&encode_rgbe([1.0, 0.5, 0.25]));
    bytes.extend_from_slice(&encode_rgbe([4.0, 4.0, 4.0]));
    std::fs::write(&path, bytes).unwrap();
    let img = read_hdr(&path).unwrap();
    let expected = [[0.5, 0.25, 0.125], [2.0, 2.0, 2.0]];
    for (got, want) in img.pixels().iter().zip(expected) {
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= want[0] / 256.0, "{got:?}");
        }
    }
}

#[test]
fn bad_hdr_files_get_errors_naming_the_file_and_the_expectation() {
    let path = scratch("bad.hdr");
    std::fs::write(&path, b"P6\n2 2\n255\n").unwrap();
    let err = read_image(&path).unwrap_err().to_string();
    assert!(
        err.contains("bad.hdr") && err.contains("#?RADIANCE"),
        "{err}"
    );
    std::fs::write(&path, b"#?RADIANCE\n\n+Y 2 +X 2\n").unwrap();
    let err = read_image(&path).unwrap_err().to_string();
    assert!(err.contains("-Y <height> +X <width>"), "{err}");
    std::fs::write(&path, b"#?RADIANCE\n\n-Y 2 +X 2\n\x01\x02").unwrap();
    let err = read_image(&path).unwrap_err().to_string();
    assert!(err.contains("scanline 0"), "{err}");
    let err = read_image(&scratch("missing.exr")).unwrap_err().to_string();
    assert!(err.contains("missing.exr"), "{err}");
    let err = read_image(&scratch("x.tiff")).unwrap_err().to_string();
    assert!(err.contains(".exr"), "{err}");
}

#[test]
fn png_round_trips_within_one_code_value() {
    for (depth, max_code) in [(PngBitDepth::Eight, 255.0), (PngBitDepth::Sixteen, 65535.0)] {
        for space in [RgbColorSpace::srgb(), RgbColorSpace::rec2020()] {
            let (w, h) = (16, 9);
            let pixels = (0..w * h)
                .map(|i| {
                    let t = i as f32 / (w * h - 1) as f32;
                    [t, t * t, 1.0 - t]
                })
                .collect();
            let img = Image::new(w, h, pixels, space.clone()).unwrap();
            let path = scratch("round.png");
            write_png(&path, &img, depth).unwrap();
            let back = read_png(&path).unwrap();
            assert_eq!(back.color_space.name, space.name);
            for (a, b) in img.pixels().iter().zip(back.pixels()) {
                for c in 0..3 {
                    // Half a code step in the encoded domain, mapped back through the
                    // steepest slope of the decoding curve (sRGB: 1/12.92 near 0, ≤ 2.4 at 1;
                    // BT.2020: 1/4.5 near 0, ≤ 2.23 at 1).
                    let encoded_a = space.transfer.encode(a[c] as f64);
                    let encoded_b = space.transfer.encode(b[c] as f64);
                    assert!((encoded_a - encoded_b).abs() <= 0.5 / max_code + 1e-6);
                }
            }
        }
    }
}

/// Decoded samples (as the file's bytes) and colour chunks of a PNG, read with the `png`
/// crate's decoder.
fn decode_png(
    path: &std::path::Path,
) -> (
    png::OutputInfo,
    Vec<u8>,
    bool,
    Option<png::SourceChromaticities>,
) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0u8; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buffer).unwrap();
    buffer.truncate(info.buffer_size());
    let srgb = reader.info().srgb.is_some();
    let chrm = reader.info().source_chromaticities;
    (info, buffer, srgb, chrm)
}

#[test]
fn parallel_png_writer_decodes_to_the_sequential_writers_samples() {
    use prism_image::io::png::write_png_sequential;
    // Odd sizes, 1×1, one strip, many strips (641×413 at 16 bits: 68 rows per strip),
    // rows longer than a strip (50 000 px), and a 1-pixel-wide column of several strips.
    for (w, h) in [
        (1, 1),
        (3, 2),
        (37, 23),
        (641, 413),
        (50_000, 3),
        (1, 100_003),
    ] {
        let pixels: Vec<[f32; 3]> = (0..w * h)
            .map(|i| {
                let t = (i as f32 * 0.618_034).fract();
                let v = 10f32.powf(-4.0 + 5.0 * t);
                match i % 97 {
                    13 => [f32::NAN, -1.0, f32::INFINITY],
                    _ => [v, v * t, (1.0 - t) * 0.8],
                }
            })
            .collect();
        for space in [RgbColorSpace::srgb(), RgbColorSpace::rec2020()] {
            let img = Image::new(w, h, pixels.clone(), space.clone()).unwrap();
            for depth in [PngBitDepth::Eight, PngBitDepth::Sixteen] {
                let (fast, reference) = (scratch("parallel.png"), scratch("sequential.png"));
                write_png(&fast, &img, depth).unwrap();
                write_png_sequential(&reference, &img, depth).unwrap();
                let (info, samples, srgb, chrm) = decode_png(&fast);
                let (info_ref, samples_ref, srgb_ref, chrm_ref) = decode_png(&reference);
                assert_eq!((info.width, info.height), (w as u32, h as u32));
                assert_eq!(
                    (info.bit_depth, info.color_type),
                    (info_ref.bit_depth, info_ref.color_type)
                );
                assert!(samples == samples_ref, "{w}×{h} {depth:?} {}", space.name);
                assert_eq!((srgb, chrm), (srgb_ref, chrm_ref));
                // Same filter and encoder: no larger than the sequential file but for the
                // strips' table headers and flushes (this noise-like image is stored
                // rather than deflated wherever deflate would enlarge it: per strip here,
                // for the whole image in the `png` crate).
                let size = |p: &PathBuf| std::fs::metadata(p).unwrap().len() as f64;
                let strips = 1.0 + (samples.len() as f64 / 262_144.0).ceil();
                assert!(
                    size(&fast) <= size(&reference) + 70.0 * strips,
                    "{w}×{h}: {} vs {} bytes",
                    size(&fast),
                    size(&reference)
                );
            }
        }
    }
}

#[test]
fn parallel_png_writer_keeps_file_sizes_of_smooth_images() {
    use prism_image::io::png::write_png_sequential;
    // A smooth HDR gradient with texture (deflate shrinks it): same filter and encoder,
    // so the sizes differ only by the strips' 53-byte table headers and 4–5 byte flushes.
    let (w, h) = (1000, 300);
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let v = 10f32.powf(-3.0 + 4.0 * x) * (0.5 + 0.5 * (20.0 * y).sin().abs());
            [v, v * (0.3 + 0.7 * y), v * (1.0 - 0.6 * x)]
        })
        .collect();
    let img = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
    for depth in [PngBitDepth::Eight, PngBitDepth::Sixteen] {
        let (fast, reference) = (scratch("smooth-par.png"), scratch("smooth-seq.png"));
        write_png(&fast, &img, depth).unwrap();
        write_png_sequential(&reference, &img, depth).unwrap();
        assert!(decode_png(&fast).1 == decode_png(&reference).1);
        let size = |p: &PathBuf| std::fs::metadata(p).unwrap().len() as f64;
        let raw = (w * h * 3 * if depth == PngBitDepth::Eight { 1 } else { 2 }) as f64;
        let strips = raw / 262_144.0 + 1.0;
        assert!(size(&fast) < 0.9 * raw, "deflate did shrink it");
        assert!(
            (size(&fast) - size(&reference)).abs() <= 60.0 * strips,
            "{depth:?}: {} vs {} bytes",
            size(&fast),
            size(&reference)
        );
    }
}

#[test]
fn spectral_channel_names_follow_the_fichet_2021_layout() {
    assert_eq!(emissive_channel_name(550.0), "S0.550,000000nm");
    assert_eq!(emissive_channel_name(412.5), "S0.412,500000nm");
    let emissive = SpectralChannelKind::Emissive { stokes: 0 };
    assert_eq!(
        parse_spectral_channel("S0.550,000000nm"),
        Some((emissive, 550.0))
    );
    assert_eq!(parse_spectral_channel("S0.550nm"), Some((emissive, 550.0)));
    let (kind, nm) = parse_spectral_channel("S1.0,55um").unwrap();
    assert_eq!(kind, SpectralChannelKind::Emissive { stokes: 1 });
    assert!((nm - 550.0).abs() < 1e-9);
    let (kind, nm) = parse_spectral_channel("T.545,077THz").unwrap();
    assert_eq!(kind, SpectralChannelKind::Reflective);
    // λ = c / f = 299 792 458 / 545.077e12 m ≈ 550.0 nm.
    assert!((nm - 550.0).abs() < 1e-3, "{nm}");
    for not_spectral in ["R", "depth.Z", "S4.550nm", "S0.abcnm", "S0.550", "S0.nm"] {
        assert_eq!(parse_spectral_channel(not_spectral), None, "{not_spectral}");
    }
}

#[test]
fn spectral_exr_round_trip_has_layout_names_and_flat_spectrum_gives_y_one() {
    // Flat spectral radiance 1 on 360, 370, …, 830 nm covers the whole CMF grid, so the
    // interpolated spectrum is exactly 1 everywhere and Y = Σȳ/Σȳ = 1, X = Σx̄/Σȳ, Z = Σz̄/Σȳ.
    let wavelengths: Vec<f64> = (0..48).map(|i| 360.0 + 10.0 * i as f64).collect();
    let (w, h) = (3, 2);
    let n = wavelengths.len();
    let mut samples = vec![1.0f32; w * h * n];
    // Pixel 1 holds 2.5 everywhere: XYZ scales linearly.
    samples[n..2 * n].iter_mut().for_each(|v| *v = 2.5);
    let img = SpectralImage::new(w, h, wavelengths.clone(), samples).unwrap();
    let path = scratch("spectral.exr");
    write_spectral_exr(&path, &img, &ExrWriteOptions::default()).unwrap();

    // The file holds the layout's channel names and attributes.
    let raw = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let names: Vec<String> = raw.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    for wl in &wavelengths {
        assert!(names.contains(&emissive_channel_name(*wl)));
    }
    assert!(names.contains(&"S0.550,000000nm".to_string()));
    let attrs = &raw.layer_data[0].attributes.other;
    let text = |k: &str| match attrs.get(&exr::meta::attribute::Text::from(k)) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => t.to_string(),
        other => panic!("{k}: {other:?}"),
    };
    assert_eq!(text("spectralLayoutVersion"), "1.0");
    assert_eq!(text("emissiveUnits"), "W.m^-2.sr^-1");

    let back = read_spectral_exr(&path).unwrap();
    assert_eq!(back, img);

    let cmf = prism_spectrum::data::cmfs(Observer::Cie1931);
    let y_sum: f64 = cmf.y_bar.values().iter().sum();
    let x_expect = cmf.x_bar.values().iter().sum::<f64>() / y_sum;
    let z_expect = cmf.z_bar.values().iter().sum::<f64>() / y_sum;
    let xyz = back.to_xyz(Observer::Cie1931);
    // f32 accumulation over 48 bands: relative error ≲ 48 · 2^-24.
    let tol = 48.0 * 2f64.powi(-24) * 3.0;
    for (i, scale) in [(0, 1.0), (1, 2.5)] {
        assert!((xyz[i][0] as f64 - scale * x_expect).abs() < tol * scale);
        assert!((xyz[i][1] as f64 - scale).abs() < tol * scale);
        assert!((xyz[i][2] as f64 - scale * z_expect).abs() < tol * scale);
    }

    // Opened as an RGB image, the file gives its R, G, B (sRGB from that XYZ) with the
    // absolute scale 683.002 · Σȳ cd/m² per unit.
    let rgb = read_image(&path).unwrap();
    let expect_scale = 683.002 * y_sum;
    assert!((rgb.cd_m2_per_unit.unwrap() - expect_scale).abs() < 1e-9 * expect_scale);
    let y_rgb: f32 = rgb
        .pixel(0, 0)
        .iter()
        .zip(rgb.luminance_weights())
        .map(|(c, w)| c * w)
        .sum();
    assert!((y_rgb - 1.0).abs() < 1e-5);
}

#[test]
fn rgb_image_with_spectral_bands_keeps_rgb_layers_and_bands_in_one_file() {
    let mut img = hdr_image(RgbColorSpace::srgb());
    let n = img.width() * img.height();
    img.set_layer("luminance", &["Y"], vec![3.0; n]).unwrap();
    img.cd_m2_per_unit = Some(72_983.0);
    let wavelengths = [400.0, 500.0, 600.0];
    let planes: Vec<Vec<f32>> = (0..3)
        .map(|k| (0..n).map(|i| (k * 1000 + i) as f32).collect())
        .collect();
    // Its own directory: the atomic-write test checks the shared scratch folder for
    // temporary files while the tests run in parallel.
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("prism-post-bands");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rgb_and_bands.exr");
    write_exr_with_spectral_bands(
        &path,
        &img,
        &wavelengths,
        &planes,
        &ExrWriteOptions::default(),
    )
    .unwrap();
    // As an RGB image: the same pixels, layers and scale; the bands are not a layer.
    let back = read_exr(&path).unwrap();
    assert_eq!(back.pixels(), img.pixels());
    assert_eq!(back.layer("luminance").unwrap().samples, vec![3.0; n]);
    assert!(back.layer("S0").is_none());
    assert_eq!(back.cd_m2_per_unit, Some(72_983.0));
    assert_eq!(back.metadata[VERSION_ATTRIBUTE], "1.0");
    assert_eq!(back.metadata[EMISSIVE_UNITS_ATTRIBUTE], RADIANCE_UNITS);
    // As a spectral image: the bands, pixel-major.
    let spectral = read_spectral_exr(&path).unwrap();
    assert_eq!(spectral.wavelengths_nm, wavelengths);
    assert_eq!(spectral.emissive_units, RADIANCE_UNITS);
    for i in [0, 17, n - 1] {
        for (k, plane) in planes.iter().enumerate() {
            assert_eq!(spectral.samples[i * 3 + k], plane[i]);
        }
    }
    // Mismatched input is an error, not a panic, and writes nothing.
    let bad = dir.join("bad_bands.exr");
    for (wl, pl) in [
        (&[500.0, 400.0][..], &planes[..2]),
        (&wavelengths[..], &planes[..2]),
        (&[][..], &[][..]),
    ] {
        assert!(
            write_exr_with_spectral_bands(&bad, &img, wl, pl, &ExrWriteOptions::default()).is_err()
        );
    }
    let short = vec![vec![0.0f32; n - 1]];
    let e =
        write_exr_with_spectral_bands(&bad, &img, &[500.0], &short, &ExrWriteOptions::default())
            .unwrap_err();
    assert!(e.to_string().contains("500 nm"), "{e}");
    assert!(!bad.exists());
}

#[test]
fn spectral_reduction_interpolates_linearly_and_is_zero_outside() {
    // Two bands at 500 and 600 nm with values 0 and 1: L(λ) = (λ − 500)/100 on [500, 600],
    // zero elsewhere, so Y = Σ_{λ=500}^{600} (λ−500)/100 ȳ(λ) / Σ ȳ.
    let img = SpectralImage::new(1, 1, vec![500.0, 600.0], vec![0.0, 1.0]).unwrap();
    let cmf = prism_spectrum::data::cmfs(Observer::Cie1964);
    let yb = cmf.y_bar.values();
    let y_sum: f64 = yb.iter().sum();
    let want: f64 = (500..=600)
        .map(|l| (l as f64 - 500.0) / 100.0 * yb[l - 360])
        .sum::<f64>()
        / y_sum;
    let got = img.to_xyz(Observer::Cie1964)[0][1] as f64;
    assert!((got - want).abs() < 1e-6 * want, "{got} vs {want}");
}

#[test]
fn exr_without_rgb_or_spectral_channels_is_an_error_listing_the_channels() {
    let path = scratch("nocolor.exr");
    let mut img = hdr_image(RgbColorSpace::srgb());
    let n = img.width() * img.height();
    img.set_layer("depth", &["Z"], vec![1.0; n]).unwrap();
    write_exr(&path, &img, &ExrWriteOptions::default()).unwrap();
    // Rewrite with only the depth channel.
    let channels = exr::prelude::AnyChannels::sort(exr::prelude::SmallVec::from_vec(vec![
        exr::prelude::AnyChannel::new("depth.Z", exr::prelude::FlatSamples::F32(vec![1.0; n])),
    ]));
    let layer = exr::prelude::Layer::new(
        (img.width(), img.height()),
        exr::prelude::LayerAttributes::default(),
        exr::prelude::Encoding::default(),
        channels,
    );
    use exr::prelude::WritableImage;
    exr::prelude::Image::from_layer(layer)
        .write()
        .to_file(&path)
        .unwrap();
    let err = read_image(&path).unwrap_err().to_string();
    assert!(
        err.contains("nocolor.exr") && err.contains("depth.Z"),
        "{err}"
    );
}
