//! The film's raw accumulators as named planes: what a checkpoint or a sample-range part
//! stores so that a render can continue (`Film::set_sums`) or parts can be added
//! (`FilmSums::add`) with the sums themselves, not the normalised image — a mean cannot be
//! continued or weighted without them. Sum planes hold the exact fixed-point sums
//! (`fixed_sum`), so adding parts gives the film of the whole range bit for bit; integer
//! planes are the counts. The order of the planes is fixed by the film's AOVs, bins and light plane, so
//! two films of the same configuration have the same names in the same order.

use glam::UVec2;

use super::light_splats::LightPlane;
use super::tile::{AovAccum, PixelAccum};
use super::{AovSelection, Film, Filter, FixedSum, FixedSum3, SpectralBins};

/// One exact sum per pixel, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct SumPlane {
    pub name: String,
    pub values: Vec<FixedSum>,
}

/// One count per pixel, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct CountPlane {
    pub name: String,
    pub values: Vec<u32>,
}

/// A film's accumulators (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct FilmSums {
    pub resolution: UVec2,
    pub aov_selection: AovSelection,
    pub spectral_bins: Option<SpectralBins>,
    pub sums: Vec<SumPlane>,
    pub counts: Vec<CountPlane>,
    /// Light paths whose splats the light plane holds; `None` without a light plane.
    pub light_paths: Option<u64>,
}

/// Why sums do not fit a film or other sums.
#[derive(Clone, Debug, PartialEq)]
pub struct SumsMismatch(pub String);

impl std::fmt::Display for SumsMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SumsMismatch {}

const PIXEL_SUMS: [&str; 5] = ["xyz.X", "xyz.Y", "xyz.Z", "weight", "own_weight"];
const AOV_SUMS: [&str; 12] = [
    "depth",
    "normal.X",
    "normal.Y",
    "normal.Z",
    "albedo.R",
    "albedo.G",
    "albedo.B",
    "illumination.X",
    "illumination.Y",
    "illumination.Z",
    "y",
    "y_sq",
];
const LIGHT_SUMS: [&str; 3] = ["light.X", "light.Y", "light.Z"];

fn pixel_values(p: &PixelAccum) -> [FixedSum; 5] {
    let [x, y, z] = p.xyz_sum.0;
    [x, y, z, p.weight_sum, p.own_weight_sum]
}

fn aov_values(a: &AovAccum) -> [FixedSum; 12] {
    let ([nx, ny, nz], [ar, ag, ab], [ix, iy, iz]) = (
        a.surface.normal().0,
        a.surface.albedo().0,
        a.illumination_sum.0,
    );
    [
        a.surface.depth(),
        nx,
        ny,
        nz,
        ar,
        ag,
        ab,
        ix,
        iy,
        iz,
        a.y_sum,
        a.y_sq_sum,
    ]
}

/// Planes `prefix` + `names[k]` of the k-th value of each pixel's `values` (one pass over
/// the pixels: the limbs of the surface sums are joined once per pixel).
fn planes<const N: usize>(
    names: &[&str; N],
    prefix: &str,
    values: impl ExactSizeIterator<Item = [FixedSum; N]>,
) -> Vec<SumPlane> {
    let mut planes: Vec<SumPlane> = names
        .iter()
        .map(|name| SumPlane {
            name: format!("{prefix}{name}"),
            values: Vec::with_capacity(values.len()),
        })
        .collect();
    for v in values {
        for (plane, value) in planes.iter_mut().zip(v) {
            plane.values.push(value);
        }
    }
    planes
}

impl Film {
    /// The film's accumulators as planes (see [`FilmSums`]).
    pub fn sums(&self) -> FilmSums {
        let n = self.pixels.len();
        let mut sums = planes(&PIXEL_SUMS, "", self.pixels.iter().map(pixel_values));
        let mut counts = vec![CountPlane {
            name: "samples".into(),
            values: self.pixels.iter().map(|p| p.sample_count).collect(),
        }];
        if self.aov_selection.any() {
            sums.extend(planes(&AOV_SUMS, "aov.", self.aovs.iter().map(aov_values)));
            counts.push(CountPlane {
                name: "hits".into(),
                values: self.aovs.iter().map(|a| a.hit_count).collect(),
            });
        }
        let bins = self.spectral_bins.map_or(0, |b| b.count() as usize);
        for b in 0..bins {
            sums.push(SumPlane {
                name: format!("bin.{b}"),
                values: (0..n).map(|i| self.spectral[i * bins + b]).collect(),
            });
        }
        if let Some(light) = &self.light {
            for (k, name) in LIGHT_SUMS.iter().enumerate() {
                sums.push(SumPlane {
                    name: (*name).into(),
                    values: light.xyz_sum.iter().map(|v| v.0[k]).collect(),
                });
            }
            if !light.spectral_sum.is_empty() {
                for b in 0..bins {
                    sums.push(SumPlane {
                        name: format!("light.bin.{b}"),
                        values: (0..n).map(|i| light.spectral_sum[i * bins + b]).collect(),
                    });
                }
            }
        }
        FilmSums {
            resolution: self.resolution,
            aov_selection: self.aov_selection,
            spectral_bins: self.spectral_bins,
            sums,
            counts,
            light_paths: self.light.as_ref().map(|l| l.paths),
        }
    }

    /// Replaces the film's accumulators by `sums` (from [`Film::sums`] of a film of the
    /// same resolution, AOVs and bins): the film then continues exactly where that one was.
    pub fn set_sums(&mut self, sums: &FilmSums) -> Result<(), SumsMismatch> {
        // A film without a light plane yet takes sums that bring one.
        sums.check_layout(&layout(
            self.aov_selection,
            self.spectral_bins,
            sums.light_paths.is_some(),
        ))?;
        let n = self.pixels.len();
        let get = |name: &str| -> &[FixedSum] {
            sums.sums
                .iter()
                .find(|p| p.name == name)
                .map_or(&[], |p| &p.values)
        };
        let count = |name: &str| -> &[u32] {
            sums.counts
                .iter()
                .find(|p| p.name == name)
                .map_or(&[], |p| &p.values)
        };
        let px: Vec<&[FixedSum]> = PIXEL_SUMS.iter().map(|s| get(s)).collect();
        let samples = count("samples");
        let triple = |planes: &[&[FixedSum]], i: usize| {
            FixedSum3([planes[0][i], planes[1][i], planes[2][i]])
        };
        for (i, p) in self.pixels.iter_mut().enumerate() {
            p.xyz_sum = triple(&px[0..3], i);
            p.weight_sum = px[3][i];
            p.own_weight_sum = px[4][i];
            p.sample_count = samples[i];
        }
        if self.aov_selection.any() {
            let av: Vec<&[FixedSum]> = AOV_SUMS.iter().map(|s| get(&format!("aov.{s}"))).collect();
            let hits = count("hits");
            for (i, a) in self.aovs.iter_mut().enumerate() {
                for (lane, plane) in av[..7].iter().enumerate() {
                    a.surface.set(lane, plane[i]);
                }
                a.illumination_sum = triple(&av[7..10], i);
                a.y_sum = av[10][i];
                a.y_sq_sum = av[11][i];
                a.hit_count = hits[i];
            }
        }
        let bins = self.spectral_bins.map_or(0, |b| b.count() as usize);
        for b in 0..bins {
            let values = get(&format!("bin.{b}"));
            for (pixel, v) in self.spectral.chunks_exact_mut(bins).zip(values) {
                pixel[b] = *v;
            }
        }
        self.light = sums.light_paths.map(|paths| {
            let mut light = LightPlane::new(n, self.spectral_bins);
            let lx: Vec<&[FixedSum]> = LIGHT_SUMS.iter().map(|s| get(s)).collect();
            for (i, v) in light.xyz_sum.iter_mut().enumerate() {
                *v = triple(&lx, i);
            }
            if !light.spectral_sum.is_empty() {
                for b in 0..bins {
                    let values = get(&format!("light.bin.{b}"));
                    for (pixel, v) in light.spectral_sum.chunks_exact_mut(bins).zip(values) {
                        pixel[b] = *v;
                    }
                }
            }
            light.paths = paths;
            light
        });
        Ok(())
    }

    /// An empty film of the configuration of `sums` holding them, to normalise into an
    /// image ([`Film::finish`]). The filter is the default box: finishing does not use it.
    pub fn from_sums(sums: &FilmSums) -> Result<Film, SumsMismatch> {
        let mut film = Film::new(sums.resolution, Filter::default(), sums.aov_selection)
            .map_err(|e| SumsMismatch(e.to_string()))?;
        if let Some(bins) = sums.spectral_bins {
            film = film.with_bins(bins);
        }
        if sums.light_paths.is_some() {
            film.light = Some(LightPlane::new(film.pixels.len(), film.spectral_bins));
        }
        film.set_sums(sums)?;
        Ok(film)
    }
}

/// Plane names of a film with these AOVs, bins and (or not) a light plane.
fn layout(
    aovs: AovSelection,
    bins: Option<SpectralBins>,
    light: bool,
) -> (Vec<String>, Vec<String>) {
    let mut sums: Vec<String> = PIXEL_SUMS.iter().map(|s| (*s).to_string()).collect();
    let mut counts = vec!["samples".to_string()];
    if aovs.any() {
        sums.extend(AOV_SUMS.iter().map(|s| format!("aov.{s}")));
        counts.push("hits".into());
    }
    let nb = bins.map_or(0, |b| b.count());
    sums.extend((0..nb).map(|b| format!("bin.{b}")));
    if light {
        sums.extend(LIGHT_SUMS.iter().map(|s| (*s).to_string()));
        sums.extend((0..nb).map(|b| format!("light.bin.{b}")));
    }
    (sums, counts)
}

impl FilmSums {
    /// The plane names this configuration must have.
    fn expected_layout(&self) -> (Vec<String>, Vec<String>) {
        layout(
            self.aov_selection,
            self.spectral_bins,
            self.light_paths.is_some(),
        )
    }

    fn check_layout(&self, expected: &(Vec<String>, Vec<String>)) -> Result<(), SumsMismatch> {
        let n = self.resolution.x as usize * self.resolution.y as usize;
        let names: Vec<&str> = self.sums.iter().map(|p| p.name.as_str()).collect();
        let expected_sums = &expected.0;
        if names != expected_sums.iter().map(String::as_str).collect::<Vec<_>>() {
            return Err(SumsMismatch(format!(
                "the sums hold the planes [{}]; this film has [{}] (different AOVs, spectral \
                 bins or method)",
                names.join(", "),
                expected_sums.join(", ")
            )));
        }
        let count_names: Vec<&str> = self.counts.iter().map(|p| p.name.as_str()).collect();
        if count_names != expected.1.iter().map(String::as_str).collect::<Vec<_>>() {
            return Err(SumsMismatch(format!(
                "the sums hold the counts [{}]; this film has [{}]",
                count_names.join(", "),
                expected.1.join(", ")
            )));
        }
        if let Some(p) = self.sums.iter().find(|p| p.values.len() != n) {
            return Err(SumsMismatch(format!(
                "plane {} has {} values; a {}×{} film needs {n}",
                p.name,
                p.values.len(),
                self.resolution.x,
                self.resolution.y
            )));
        }
        if let Some(p) = self.counts.iter().find(|p| p.values.len() != n) {
            return Err(SumsMismatch(format!(
                "count plane {} has {} values; a {}×{} film needs {n}",
                p.name,
                p.values.len(),
                self.resolution.x,
                self.resolution.y
            )));
        }
        Ok(())
    }

    /// Checks that the planes are those of the configuration the sums claim.
    pub fn check(&self) -> Result<(), SumsMismatch> {
        self.check_layout(&self.expected_layout())
    }

    /// Adds `other` (sums of other samples of the same render: same resolution, AOVs,
    /// bins) plane by plane. A part with a light plane gives the sum one.
    pub fn add(&mut self, other: &FilmSums) -> Result<(), SumsMismatch> {
        if self.resolution != other.resolution {
            return Err(SumsMismatch(format!(
                "{}×{} and {}×{} films",
                self.resolution.x, self.resolution.y, other.resolution.x, other.resolution.y
            )));
        }
        if self.aov_selection != other.aov_selection || self.spectral_bins != other.spectral_bins {
            return Err(SumsMismatch(
                "the films record different AOVs or spectral bins".into(),
            ));
        }
        if self.light_paths.is_some() != other.light_paths.is_some() {
            return Err(SumsMismatch(
                "one film holds light-path splats and the other does not (different methods)"
                    .into(),
            ));
        }
        other.check()?;
        self.check()?;
        for (dst, src) in self.sums.iter_mut().zip(&other.sums) {
            for (d, s) in dst.values.iter_mut().zip(&src.values) {
                *d += *s;
            }
        }
        for (dst, src) in self.counts.iter_mut().zip(&other.counts) {
            for (d, s) in dst.values.iter_mut().zip(&src.values) {
                *d += s;
            }
        }
        if let (Some(a), Some(b)) = (&mut self.light_paths, other.light_paths) {
            *a += b;
        }
        Ok(())
    }

    /// Camera samples of each pixel (row-major).
    pub fn sample_counts(&self) -> &[u32] {
        self.counts
            .iter()
            .find(|p| p.name == "samples")
            .map_or(&[], |p| &p.values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::AovSelection;
    use glam::{DVec3, Vec2};

    fn film_with_samples(seed: u32) -> Film {
        let mut film = Film::new(UVec2::new(5, 3), Filter::default(), AovSelection::ALL)
            .unwrap()
            .with_spectral_bins(3)
            .unwrap();
        film.render_tiles(2, |tile| {
            let b = tile.bounds();
            for p in b.pixels() {
                for k in 0..3 {
                    let v = f64::from(p.x * 7 + p.y * 3 + k + seed) * 0.1;
                    let point = p.as_vec2() + Vec2::splat(0.5);
                    tile.add_sample_xyz_at(p, point, DVec3::new(v, v * 0.5, v * 0.25), 1.0, None);
                }
            }
        });
        film
    }

    #[test]
    fn sums_round_trip_and_continue_exactly() {
        let film = film_with_samples(1);
        let sums = film.sums();
        sums.check().unwrap();
        let restored = Film::from_sums(&sums).unwrap();
        assert_eq!(restored.sums(), sums);
        assert_eq!(restored.finish(), film.finish());
    }

    #[test]
    fn adding_sums_adds_counts_and_refuses_other_layouts() {
        let a = film_with_samples(1).sums();
        let b = film_with_samples(2).sums();
        let mut total = a.clone();
        total.add(&b).unwrap();
        assert!(total.sample_counts().iter().all(|&c| c == 6));
        // Exact: b + a is a + b, bit for bit.
        let mut reversed = b.clone();
        reversed.add(&a).unwrap();
        assert_eq!(reversed, total);
        let other = Film::new(UVec2::new(5, 3), Filter::default(), AovSelection::NONE)
            .unwrap()
            .sums();
        assert!(total.add(&other).is_err());
    }
}
