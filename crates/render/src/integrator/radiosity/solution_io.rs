//! A solved scene as files, which the CLI reads and writes (through its atomic outputs):
//! `--save-solution`/`--load-solution` (the solution's own bytes, `Radiosity::to_bytes`,
//! checked against the scene they are loaded for) and `--export-solution FILE.ply`
//! (per-vertex illuminance and luminance of every leaf element, for walk-throughs).

use std::path::Path;

use prism_radiosity::Radiosity;
use prism_spectrum::photometry::photopic_luminance_cd_per_m2;
use prism_spectrum::DenseSpectrum;

use super::gather::SolvedScene;
use super::patches::{scene_patches, SolutionBands};
use crate::scene_build::RenderScene;

/// `--load-solution FILE` (its `bytes`; `path` for messages): the solution, if it was
/// solved for `scene`'s patches.
pub fn load_solution(
    scene: &RenderScene,
    path: &Path,
    bytes: &[u8],
) -> Result<SolvedScene, String> {
    let solution = Radiosity::from_bytes(bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    // The bands of the scene's method (the render's spectral bins where it sets them).
    let bands = if let crate::integrator::Integrator::Radiosity(m) = scene.integrator {
        m.bands
    } else {
        SolutionBands::DEFAULT
    };
    let (patches, map) = scene_patches(scene, bands)?;
    if solution.bands() != bands.count {
        return Err(format!(
            "{}: this solution is in {} wavelength bands, the render asks for {} ({}): solve \
             it again with --save-solution, or render with the spectral bins it was solved in",
            path.display(),
            solution.bands(),
            bands.count,
            if bands == SolutionBands::DEFAULT {
                "the default".to_string()
            } else {
                format!("--spectral-bins {}", bands.count)
            }
        ));
    }
    if !solution.matches_patches(&patches) {
        return Err(format!(
            "{}: this solution was solved for another scene (its patches, reflectances or \
             emission differ from {}'s): solve it again with --save-solution",
            path.display(),
            scene.file.display()
        ));
    }
    // The scene's own ε; another method's scene (`prism converge`) gets the default.
    let gather_epsilon = if let crate::integrator::Integrator::Radiosity(m) = scene.integrator {
        m.gather_epsilon
    } else {
        super::DEFAULT_GATHER_EPSILON
    };
    Ok(SolvedScene::new(solution, map, gather_epsilon))
}

/// A band array (in `bands`) as a spectrum over 360–830 nm (zero outside the bands) and
/// its photometric value: lux of an irradiance, cd/m² of a radiance.
fn photometric(values: &[f32], bands: SolutionBands) -> f64 {
    let spectrum = DenseSpectrum::from_fn(|nm| {
        let band = (nm - bands.first_nm) / bands.width_nm;
        if (0.0..bands.count as f64).contains(&band) {
            f64::from(values[band as usize])
        } else {
            0.0
        }
    });
    photopic_luminance_cd_per_m2(&spectrum)
}

/// `--export-solution FILE.ply`'s text: ASCII PLY, one face per leaf element (its own vertices:
/// the solution is constant per element), with the element's illuminance (lx) and
/// luminance (cd/m², the Lambertian B/π) on each vertex. Covered elements (under other
/// geometry) are left out.
pub fn to_ply(solved: &SolvedScene) -> String {
    let mut vertices = String::new();
    let mut faces = String::new();
    let (mut vertex_count, mut face_count) = (0usize, 0usize);
    for leaf in solved.solution.leaves() {
        if leaf.covered_fraction >= 1.0 {
            continue;
        }
        let lux = photometric(leaf.irradiance, solved.map.bands);
        let radiance: Vec<f32> = leaf
            .radiosity
            .iter()
            .map(|b| b * std::f32::consts::FRAC_1_PI)
            .collect();
        let luminance = photometric(&radiance, solved.map.bands);
        let (corners, count) = leaf.shape.corners();
        for c in &corners[..count] {
            vertices.push_str(&format!(
                "{} {} {} {lux:.6e} {luminance:.6e}\n",
                c.x, c.y, c.z
            ));
        }
        faces.push_str(&count.to_string());
        for i in 0..count {
            faces.push_str(&format!(" {}", vertex_count + i));
        }
        faces.push('\n');
        vertex_count += count;
        face_count += 1;
    }
    let header = format!(
        "ply\nformat ascii 1.0\ncomment Prism radiosity solution: illuminance in lx, \
         luminance in cd/m2 (Lambertian B/pi), metres\nelement vertex {vertex_count}\n\
         property float x\nproperty float y\nproperty float z\n\
         property float illuminance_lx\nproperty float luminance_cd_m2\n\
         element face {face_count}\nproperty list uchar int vertex_indices\nend_header\n"
    );
    format!("{header}{vertices}{faces}")
}
