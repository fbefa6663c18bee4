//! Film: per-pixel XYZ accumulation in exact fixed point (`fixed_sum`: sums that do not
//! depend on the order samples arrive in, so sample-range parts merge bit for bit) with
//! filter weights and sample counts, optional
//! surface AOVs, an optional illumination AOV and optional spectral bins, tile-parallel
//! rendering with deterministic merging, and the finished image (pbrt-v4 §5.4 "Film and
//! imaging", `RGBFilm` / `GBufferFilm` / `SpectralFilm`, with XYZ in place of RGB).
//!
//! Pixels may receive different sample counts (a `SamplePlan` decides); each pixel's value
//! is Σ wᵢ XYZᵢ / Σ wᵢ with wᵢ = f/p from filter importance sampling, and `spp.Y` records
//! its count.

pub mod filter;
mod filter_sampler;
mod filter_table;
pub mod fixed_sum;
mod image;
mod light_splats;
pub mod memory_estimate;
pub mod spectral_bins;
mod sums;
mod tile;
pub mod xyz;

pub use filter::Filter;
pub use filter_sampler::{FilterSample, FilterSampler};
pub use fixed_sum::{FixedSum, FixedSum3};
pub use image::{AovPlane, FilmImage, SpectralPlanes};
pub use light_splats::LightSplats;
pub use memory_estimate::FilmMemory;
pub use spectral_bins::{film_wavelength_density, SpectralBins};
pub use sums::{CountPlane, FilmSums, SumPlane, SumsMismatch};
pub use tile::{FilmTile, SurfaceAov, TileBounds};

use std::sync::Arc;

use glam::{DVec3, UVec2, Vec2};
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use crate::error::InvalidParameter;
use light_splats::LightPlane;
use tile::{AovAccum, PixelAccum};

/// Which AOVs the film records (`spp.Y` is always recorded).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct AovSelection {
    /// `depth.Z`: mean distance to the first hit over the samples that hit (m; +∞ if none).
    pub depth: bool,
    /// `normal.X/Y/Z`: mean first-hit shading normal over all samples (misses count 0).
    pub normal: bool,
    /// `albedo.R/G/B`: mean first-hit albedo over all samples (misses count 0).
    pub albedo: bool,
    /// `illumination.X/Y/Z`: mean XYZ (beauty normalisation) over all samples of the light
    /// a neutral white Lambertian surface would reflect at the first hit
    /// (`FilmTile::add_illumination`; misses count 0). For scene-based white balance
    /// (`prism tonemap --wb scene`).
    pub illumination: bool,
    /// `variance.Y`: the sample variance (n − 1) of the camera samples' Y (beauty
    /// normalisation, unweighted) per pixel, 0 below two samples: the measured variance a
    /// sample plan can be judged by (`path+oracle`, docs/bandwidth.md).
    pub variance: bool,
}

impl AovSelection {
    pub const NONE: AovSelection = AovSelection {
        depth: false,
        normal: false,
        albedo: false,
        illumination: false,
        variance: false,
    };
    /// The first-hit surface AOVs: depth, normal, albedo.
    pub const SURFACE: AovSelection = AovSelection {
        depth: true,
        normal: true,
        albedo: true,
        illumination: false,
        variance: false,
    };
    /// Every AOV.
    pub const ALL: AovSelection = AovSelection {
        depth: true,
        normal: true,
        albedo: true,
        illumination: true,
        variance: true,
    };

    pub fn any(&self) -> bool {
        self.depth || self.normal || self.albedo || self.illumination || self.variance
    }
}

/// Makes empty tiles of a film (`Film::tile_maker`).
#[derive(Clone, Debug)]
pub struct TileMaker {
    resolution: UVec2,
    aov_selection: AovSelection,
    spectral_bins: Option<SpectralBins>,
    filter_sampler: Arc<FilterSampler>,
    splat: bool,
}

impl TileMaker {
    /// An empty tile over `bounds` (clipped to the film).
    pub fn new_tile(&self, bounds: TileBounds) -> FilmTile {
        let b = TileBounds {
            min: bounds.min.min(self.resolution),
            max: bounds
                .max
                .min(self.resolution)
                .max(bounds.min.min(self.resolution)),
        };
        let mut tile = FilmTile::new(
            b,
            self.aov_selection,
            self.spectral_bins,
            Arc::clone(&self.filter_sampler),
        );
        if self.splat {
            tile.splat = Some(tile::SplatBuffer::new(
                b,
                self.resolution,
                self.filter_sampler.filter().radius_px(),
            ));
        }
        tile
    }
}

/// The film: accumulators for every pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    resolution: UVec2,
    filter_sampler: Arc<FilterSampler>,
    aov_selection: AovSelection,
    pixels: Vec<PixelAccum>,
    aovs: Vec<AovAccum>,
    spectral_bins: Option<SpectralBins>,
    /// Σ w · L̂_b per pixel and bin, pixel-major; empty without spectral bins.
    spectral: Vec<FixedSum>,
    /// Reconstruct by splatting (see `with_splatting`).
    splat: bool,
    /// Light-side contributions (`light_splats`), once an estimator splats light paths.
    light: Option<LightPlane>,
}

impl Film {
    /// An empty film of `resolution` (≥ 1 × 1) reconstructing with `filter`.
    pub fn new(
        resolution: UVec2,
        filter: Filter,
        aov_selection: AovSelection,
    ) -> Result<Self, InvalidParameter> {
        if resolution.x == 0 || resolution.y == 0 {
            return Err(InvalidParameter::new(
                "film",
                "resolution",
                format!("{}×{}", resolution.x, resolution.y),
                "width and height ≥ 1 pixel",
            ));
        }
        let n = resolution.x as usize * resolution.y as usize;
        Ok(Self {
            resolution,
            filter_sampler: Arc::new(FilterSampler::new(filter)),
            aov_selection,
            pixels: vec![PixelAccum::default(); n],
            aovs: if aov_selection.any() {
                vec![AovAccum::default(); n]
            } else {
                Vec::new()
            },
            spectral_bins: None,
            spectral: Vec::new(),
            splat: false,
            light: None,
        })
    }

    /// The same film with `count` equal spectral bins over 360–830 nm (1..=471; else an
    /// error naming `spectral_bins`). Call before rendering: the spectral sums start at 0.
    pub fn with_spectral_bins(self, count: u32) -> Result<Self, InvalidParameter> {
        Ok(self.with_bins(SpectralBins::new(count)?))
    }

    /// The same film with spectral `bins` (see `with_spectral_bins`).
    pub fn with_bins(mut self, bins: SpectralBins) -> Self {
        self.spectral = vec![FixedSum::ZERO; self.pixels.len() * bins.count() as usize];
        self.spectral_bins = Some(bins);
        self
    }

    /// The same film recording `selection`. Call before rendering: the AOV sums start at 0.
    pub fn with_aovs(mut self, selection: AovSelection) -> Self {
        self.aov_selection = selection;
        if !selection.any() {
            self.aovs = Vec::new();
        } else if self.aovs.len() == self.pixels.len() {
            // Cleared in place: a new buffer of a 256² film is ≈ 6 MB of page faults.
            self.aovs.fill(AovAccum::default());
        } else {
            self.aovs = vec![AovAccum::default(); self.pixels.len()];
        }
        self
    }

    /// The spectral bins, if the film has them.
    pub fn spectral_bins(&self) -> Option<SpectralBins> {
        self.spectral_bins
    }

    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    pub fn filter(&self) -> &Filter {
        self.filter_sampler.filter()
    }

    pub fn aov_selection(&self) -> AovSelection {
        self.aov_selection
    }

    /// The whole film as one rectangle.
    pub fn bounds(&self) -> TileBounds {
        TileBounds {
            min: UVec2::ZERO,
            max: self.resolution,
        }
    }

    /// The film point (px) of a camera sample of `pixel` with filter variate `u`, and its
    /// weight: pixel centre + an offset drawn from the filter.
    /// (`FilmTile::sample_film_point` does the same inside a tile.)
    #[inline]
    pub fn sample_film_point(&self, pixel: UVec2, u: Vec2) -> (Vec2, f32) {
        self.filter_sampler.sample_film_point(pixel, u)
    }

    /// The film cut into tiles of `tile_size_px` (≥ 1; clamped) square, row-major.
    pub fn tiles(&self, tile_size_px: u32) -> Vec<TileBounds> {
        let t = tile_size_px.max(1);
        let mut out = Vec::new();
        for y0 in (0..self.resolution.y).step_by(t as usize) {
            for x0 in (0..self.resolution.x).step_by(t as usize) {
                let min = UVec2::new(x0, y0);
                out.push(TileBounds {
                    min,
                    max: (min + UVec2::splat(t)).min(self.resolution),
                });
            }
        }
        out
    }

    /// An empty tile over `bounds` (clipped to the film).
    pub fn new_tile(&self, bounds: TileBounds) -> FilmTile {
        self.tile_maker().new_tile(bounds)
    }

    /// What makes this film's tiles, without borrowing the film (so that tiles can be
    /// made while the film is being merged into).
    pub fn tile_maker(&self) -> TileMaker {
        TileMaker {
            resolution: self.resolution,
            aov_selection: self.aov_selection,
            spectral_bins: self.spectral_bins,
            filter_sampler: Arc::clone(&self.filter_sampler),
            splat: self.splat,
        }
    }

    /// Camera samples pixel `pixel` holds (0 outside the film).
    pub fn sample_count(&self, pixel: UVec2) -> u32 {
        if pixel.x >= self.resolution.x || pixel.y >= self.resolution.y {
            return 0;
        }
        self.pixels[pixel.y as usize * self.resolution.x as usize + pixel.x as usize].sample_count
    }

    /// The same film reconstructing by splatting (`true`: every sample reaches every pixel
    /// within the filter radius, Mitsuba 3's `ImageBlock`) or by filter importance sampling
    /// (`false`, the default of `Film::new`; pbrt-v4 §8.8).
    pub fn with_splatting(mut self, splat: bool) -> Self {
        self.splat = splat;
        self
    }

    /// True when the film splats.
    pub fn splats(&self) -> bool {
        self.splat
    }

    /// Adds a tile's sums into the film. The sums are exact (`fixed_sum`), so merging
    /// tiles in any order gives the same film.
    pub fn merge_tile(&mut self, tile: &FilmTile) {
        if let Some(buffer) = &tile.splat {
            let width = self.resolution.x as usize;
            for (k, pixel) in buffer.bounds.pixels().enumerate() {
                let i = pixel.y as usize * width + pixel.x as usize;
                let [x, y, z, w] = buffer.pixel_sums(k);
                self.pixels[i].xyz_sum += FixedSum3([x, y, z]);
                self.pixels[i].weight_sum += w;
            }
        }
        let b = tile.bounds();
        for (k, pixel) in b.pixels().enumerate() {
            let i = pixel.y as usize * self.resolution.x as usize + pixel.x as usize;
            self.pixels[i].merge(&tile.pixels[k]);
            if let (Some(dst), Some(src)) = (self.aovs.get_mut(i), tile.aovs.get(k)) {
                dst.merge(src);
            }
            if let Some(bins) = self.spectral_bins {
                let n = bins.count() as usize;
                let src = &tile.spectral[k * n..(k + 1) * n];
                for (d, s) in self.spectral[i * n..(i + 1) * n].iter_mut().zip(src) {
                    *d += *s;
                }
            }
        }
    }

    /// Adds the sums of `other`, a film of the same resolution, filter, AOVs and bins that
    /// recorded other samples of the same render (adaptive sampling keeps half its samples
    /// in a second film to estimate the error, then merges the two). Camera-side sums only:
    /// `None` (nothing merged) when either film holds light-path splats or the films differ.
    pub fn merge_film(&mut self, other: &Film) -> Option<()> {
        if self.resolution != other.resolution
            || self.aov_selection != other.aov_selection
            || self.spectral_bins != other.spectral_bins
            || self.light.is_some()
            || other.light.is_some()
        {
            return None;
        }
        for (dst, src) in self.pixels.iter_mut().zip(&other.pixels) {
            dst.merge(src);
        }
        for (dst, src) in self.aovs.iter_mut().zip(&other.aovs) {
            dst.merge(src);
        }
        for (dst, src) in self.spectral.iter_mut().zip(&other.spectral) {
            *dst += *src;
        }
        Some(())
    }

    /// Renders every tile with `render_tile` on the current rayon pool (a
    /// `ThreadPool::install` around the call picks the pool) and merges the tiles
    /// in row-major order. `render_tile` must seed its samples per pixel (e.g. with
    /// `PixelSampler`), never per thread; then the film is bit-identical for any number of
    /// threads.
    pub fn render_tiles<F>(&mut self, tile_size_px: u32, render_tile: F)
    where
        F: Fn(&mut FilmTile) + Sync + Send,
    {
        let tiles: Vec<FilmTile> = self
            .tiles(tile_size_px)
            .into_par_iter()
            .map(|bounds| {
                let mut tile = self.new_tile(bounds);
                render_tile(&mut tile);
                tile
            })
            .collect();
        for tile in &tiles {
            self.merge_tile(tile);
        }
    }

    /// A copy of the colour sums only (no AOVs, no spectral bins): what [`Film::rgb`] needs,
    /// at the cost of one memcpy of 96 bytes per pixel. `prism converge` takes one at each
    /// checkpoint on the render thread and computes the image and its errors elsewhere.
    pub fn colour_snapshot(&self) -> Film {
        Film {
            resolution: self.resolution,
            filter_sampler: Arc::clone(&self.filter_sampler),
            aov_selection: AovSelection::NONE,
            pixels: self.pixels.clone(),
            aovs: Vec::new(),
            spectral_bins: None,
            spectral: Vec::new(),
            splat: self.splat,
            light: self.light.as_ref().map(|l| LightPlane {
                xyz_sum: l.xyz_sum.clone(),
                spectral_sum: Vec::new(),
                paths: l.paths,
            }),
        }
    }

    /// The finished image's linear sRGB pixels alone (row-major, top row first): equal to
    /// `finish().rgb`, without the XYZ, luminance, AOV and spectral planes.
    pub fn rgb(&self) -> Vec<[f32; 3]> {
        let xyz_to_rgb = RgbColorSpace::srgb().xyz_to_rgb;
        (0..self.pixels.len())
            .map(|i| (xyz_to_rgb * self.pixel_xyz(i)).as_vec3().to_array())
            .collect()
    }

    /// Pixel `i`'s XYZ: the mean of its camera samples plus the light-side contributions.
    #[inline]
    fn pixel_xyz(&self, i: usize) -> DVec3 {
        let camera = self.pixels[i].mean_xyz();
        match &self.light {
            None => camera,
            Some(light) => camera + light.xyz(i),
        }
    }

    /// An empty splat list for one work item of an estimator that connects light paths to
    /// the camera; the film starts its light plane (all zero) if it has none.
    pub fn light_splats(&mut self) -> LightSplats {
        if self.light.is_none() {
            self.light = Some(LightPlane::new(self.pixels.len(), self.spectral_bins));
        }
        self.empty_light_splats()
    }

    /// An empty splat list with this film's filter and bins (the light plane must exist:
    /// `light_splats` first).
    pub fn empty_light_splats(&self) -> LightSplats {
        LightSplats::new(
            self.resolution,
            Arc::clone(&self.filter_sampler),
            self.splat,
            self.spectral_bins,
        )
    }

    /// A splat list for estimators that do not splat: no normalisation computed, every
    /// splat refused.
    pub fn unused_light_splats(&self) -> LightSplats {
        LightSplats::unused(self.resolution, Arc::clone(&self.filter_sampler))
    }

    /// Adds one work item's light splats (call in a fixed work-item order).
    pub fn merge_light_splats(&mut self, splats: &LightSplats) {
        let pixels = self.pixels.len();
        let bins = self.spectral_bins;
        self.light
            .get_or_insert_with(|| LightPlane::new(pixels, bins))
            .merge(splats);
    }

    /// Light paths whose splats the film holds.
    pub fn light_paths(&self) -> u64 {
        self.light.as_ref().map_or(0, |l| l.paths)
    }

    /// Normalises the sums into the finished image.
    pub fn finish(&self) -> FilmImage {
        let xyz_to_rgb = RgbColorSpace::srgb().xyz_to_rgb;
        let n = self.pixels.len();
        let mut xyz = Vec::with_capacity(n);
        let mut rgb = Vec::with_capacity(n);
        let mut y = Vec::with_capacity(n);
        let mut spp = Vec::with_capacity(n);
        for (i, p) in self.pixels.iter().enumerate() {
            let v = self.pixel_xyz(i);
            let c = xyz_to_rgb * v;
            xyz.push(v.as_vec3().to_array());
            rgb.push(c.as_vec3().to_array());
            y.push(v.y as f32);
            spp.push(p.sample_count as f32);
        }
        let mut aovs = vec![AovPlane {
            name: "spp.Y".into(),
            values: spp,
        }];
        let sel = self.aov_selection;
        if sel.any() {
            let counts = self.pixels.iter().map(|p| p.sample_count);
            let per_sample = |sum: DVec3, count: u32| {
                if count > 0 {
                    sum / f64::from(count)
                } else {
                    DVec3::ZERO
                }
            };
            if sel.depth {
                let values = self
                    .aovs
                    .iter()
                    .map(|a| {
                        if a.hit_count > 0 {
                            (a.surface.depth().to_f64() / f64::from(a.hit_count)) as f32
                        } else {
                            f32::INFINITY
                        }
                    })
                    .collect();
                aovs.push(AovPlane {
                    name: "depth.Z".into(),
                    values,
                });
            }
            let planes = |field: fn(&AovAccum) -> FixedSum3, names: [&str; 3]| {
                let means: Vec<DVec3> = self
                    .aovs
                    .iter()
                    .zip(counts.clone())
                    .map(|(a, c)| per_sample(field(a).to_dvec3(), c))
                    .collect();
                (0..3)
                    .map(|k| AovPlane {
                        name: names[k].into(),
                        values: means.iter().map(|m| m[k] as f32).collect(),
                    })
                    .collect::<Vec<_>>()
            };
            if sel.normal {
                aovs.extend(planes(
                    |a| a.surface.normal(),
                    ["normal.X", "normal.Y", "normal.Z"],
                ));
            }
            if sel.albedo {
                aovs.extend(planes(
                    |a| a.surface.albedo(),
                    ["albedo.R", "albedo.G", "albedo.B"],
                ));
            }
            if sel.illumination {
                aovs.extend(planes(
                    |a| a.illumination_sum,
                    ["illumination.X", "illumination.Y", "illumination.Z"],
                ));
            }
            if sel.variance {
                let values = self
                    .aovs
                    .iter()
                    .zip(&self.pixels)
                    .map(|(a, p)| {
                        let n = f64::from(p.sample_count);
                        if n >= 2.0 {
                            let (sum, sum_sq) = (a.y_sum.to_f64(), a.y_sq_sum.to_f64());
                            ((sum_sq - sum * sum / n) / (n - 1.0)).max(0.0) as f32
                        } else {
                            0.0
                        }
                    })
                    .collect();
                aovs.push(AovPlane {
                    name: "variance.Y".into(),
                    values,
                });
            }
        }
        let spectral = self.spectral_bins.map(|bins| {
            let n = bins.count() as usize;
            let planes = (0..n)
                .map(|b| {
                    self.pixels
                        .iter()
                        .zip(self.spectral.chunks_exact(n))
                        .enumerate()
                        .map(|(i, (p, sums))| {
                            let own_weight = p.own_weight_sum.to_f64();
                            let camera = if own_weight != 0.0 {
                                sums[b].to_f64() / own_weight
                            } else {
                                0.0
                            };
                            match &self.light {
                                None => camera as f32,
                                Some(l) => (camera + l.spectral(i, b, n)) as f32,
                            }
                        })
                        .collect()
                })
                .collect();
            SpectralPlanes {
                centres_nm: bins.centres_nm(),
                width_nm: bins.width_nm(),
                planes,
            }
        });
        FilmImage {
            width: self.resolution.x,
            height: self.resolution.y,
            xyz,
            rgb,
            y,
            cd_m2_per_unit: xyz::cd_m2_per_unit(),
            aovs,
            spectral,
        }
    }
}
