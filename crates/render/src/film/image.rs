//! The film's finished output: what prism-image writes to EXR (docs/architecture.md "Units and
//! conventions": unprefixed R, G, B linear Rec.709; header `prism:cd_m2_per_unit`; AOV
//! layers with prefixed channel names).

/// One AOV channel, row-major, `width × height` values.
#[derive(Clone, Debug, PartialEq)]
pub struct AovPlane {
    /// EXR channel name: `spp.Y`, `depth.Z`, `normal.X`/`.Y`/`.Z`, `albedo.R`/`.G`/`.B`,
    /// `illumination.X`/`.Y`/`.Z`.
    pub name: String,
    pub values: Vec<f32>,
}

/// The spectral bins of a finished film: equal bins over 360–830 nm.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralPlanes {
    /// Bin centres in nm, increasing.
    pub centres_nm: Vec<f64>,
    /// Width of every bin in nm (470 nm / number of bins).
    pub width_nm: f64,
    /// One row-major plane per bin: the pixel's mean spectral radiance over the bin,
    /// W·m⁻²·sr⁻¹·nm⁻¹, filter-weighted like the XYZ.
    pub planes: Vec<Vec<f32>>,
}

/// A finished film. All planes are row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmImage {
    pub width: u32,
    pub height: u32,
    /// CIE 1931 XYZ, normalised so that a flat spectral radiance of 1 gives Y = 1.
    pub xyz: Vec<[f32; 3]>,
    /// Linear Rec.709 (sRGB primaries, D65) RGB from `xyz`
    /// (`RgbColorSpace::srgb().xyz_to_rgb`), not clamped.
    pub rgb: Vec<[f32; 3]>,
    /// The Y plane of `xyz`.
    pub y: Vec<f32>,
    /// Multiply Y by this for luminance in cd/m²: 683.002 · ∫ȳ dλ.
    pub cd_m2_per_unit: f64,
    /// AOV channels: always `spp.Y` (samples per pixel), then the enabled AOVs.
    pub aovs: Vec<AovPlane>,
    /// Spectral bins, when the film has them (`Film::with_spectral_bins`).
    pub spectral: Option<SpectralPlanes>,
}

impl FilmImage {
    /// The AOV channel called `name`.
    pub fn aov(&self, name: &str) -> Option<&AovPlane> {
        self.aovs.iter().find(|p| p.name == name)
    }

    /// The luminance plane in cd/m² (Y · `cd_m2_per_unit`), e.g. for a `luminance.Y` layer.
    pub fn luminance_cd_m2(&self) -> Vec<f32> {
        self.y
            .iter()
            .map(|&y| (f64::from(y) * self.cd_m2_per_unit) as f32)
            .collect()
    }

    /// Row-major index of pixel (x, y).
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }
}

impl FilmImage {
    /// Fills the pixels that hierarchical shading interpolates (Bagher et al. 2013 §3.2)
    /// from their shaded parents: the colour planes, the spectral bins and the per-sample
    /// AOV means (depth, normal, albedo, illumination). `spp.Y` keeps their 0 and
    /// `variance.Y` its 0 (nothing was sampled there); the predictor's `bandwidth.*` and
    /// `plan.*` layers are per pixel already.
    pub fn upsample(
        &mut self,
        upsampling: &prism_bandwidth::Upsampling,
    ) -> Result<(), prism_bandwidth::BandwidthError> {
        upsampling.apply(&mut self.xyz)?;
        upsampling.apply(&mut self.rgb)?;
        upsampling.apply(&mut self.y)?;
        if let Some(spectral) = &mut self.spectral {
            for plane in &mut spectral.planes {
                upsampling.apply(plane)?;
            }
        }
        for aov in &mut self.aovs {
            let interpolated = ["depth.", "normal.", "albedo.", "illumination."]
                .iter()
                .any(|prefix| aov.name.starts_with(prefix));
            if interpolated {
                upsampling.apply(&mut aov.values)?;
            }
        }
        Ok(())
    }
}
