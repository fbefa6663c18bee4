//! pbrt-v4's environment images → Prism's equirectangular maps.
//!
//! pbrt-v4's `ImageInfiniteLight` stores the sphere in Clarberg's equal-area octahedral
//! square (pbrt-v4 `EqualAreaSphereToSquare`, "Fast Equal-Area Mapping of the (Hemi)Sphere
//! using SIMD", Clarberg 2008): a light-space direction d maps to (u, v) ∈ [0, 1]², row v = 0
//! at the image's top. Prism's `environment` light is equirectangular (light/environment.rs:
//! θ = π v, φ = 2π u, d = (sin φ sin θ, cos θ, −cos φ sin θ)). The importer resamples: each
//! equirectangular texel centre's direction, read as the same light-space direction,
//! looks up the square bilinearly (pbrt's lookup: texel centres at (i + ½)/N), and the light's
//! transform is pbrt's CTM, so world directions agree.

use std::f64::consts::PI;

use glam::DVec3;

use crate::error::{ImportError, Location};

/// The image at `path` that pbrt-v4 reads as an equal-area square (`what`: the directive,
/// for messages): an error unless it reads and is square.
pub fn read_square(
    path: &std::path::Path,
    at: &Location,
    what: &str,
) -> Result<prism_image::Image, ImportError> {
    let image = prism_image::io::read_image(path)
        .map_err(|e| ImportError::at(at, format!("{what} \"filename\": {e}")))?;
    if image.width() != image.height() {
        return Err(ImportError::at(
            at,
            format!(
                "{what} \"filename\" {}: {}×{} pixels; pbrt-v4 reads this image as a square \
                 (equal-area octahedral)",
                path.display(),
                image.width(),
                image.height()
            ),
        ));
    }
    Ok(image)
}

/// pbrt-v4's `EqualAreaSphereToSquare` (exact atan in place of its polynomial).
pub fn sphere_to_square(d: DVec3) -> (f64, f64) {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let a = x.max(y);
    let b = if a == 0.0 { 0.0 } else { x.min(y) / a };
    let mut phi = b.atan() * 2.0 / PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    (0.5 * (u.copysign(d.x) + 1.0), 0.5 * (v.copysign(d.y) + 1.0))
}

/// pbrt-v4's `EqualAreaSquareToSphere`, the inverse (for tests and the resampling's check).
pub fn square_to_sphere(u: f64, v: f64) -> DVec3 {
    let (u, v) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed_distance = 1.0 - (up + vp);
    let d = signed_distance.abs();
    let r = 1.0 - d;
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * PI / 4.0;
    let z = (1.0 - r * r).copysign(signed_distance);
    let cos_phi = phi.cos().copysign(u);
    let sin_phi = phi.sin().copysign(v);
    DVec3::new(
        cos_phi * r * (2.0 - r * r).max(0.0).sqrt(),
        sin_phi * r * (2.0 - r * r).max(0.0).sqrt(),
        z,
    )
}

/// The direction of Prism's equirectangular coordinates (u, v).
fn equirect_direction(u: f64, v: f64) -> DVec3 {
    let (theta, phi) = (PI * v, 2.0 * PI * u);
    DVec3::new(
        phi.sin() * theta.sin(),
        theta.cos(),
        -phi.cos() * theta.sin(),
    )
}

/// Bilinear lookup of a row-major `size`² square at (u, v), texel centres at (i + ½)/N,
/// clamped at the edges.
fn bilinear(square: &[[f32; 3]], size: usize, u: f64, v: f64) -> [f32; 3] {
    let n = size as f64;
    let x = (u * n - 0.5).clamp(0.0, n - 1.0);
    let y = (v * n - 0.5).clamp(0.0, n - 1.0);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(size - 1), (y0 + 1).min(size - 1));
    let (tx, ty) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let at = |xx: usize, yy: usize| square[yy * size + xx];
    let mut out = [0.0f32; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let top = at(x0, y0)[c] * (1.0 - tx) + at(x1, y0)[c] * tx;
        let bottom = at(x0, y1)[c] * (1.0 - tx) + at(x1, y1)[c] * tx;
        *o = top * (1.0 - ty) + bottom * ty;
    }
    out
}

/// The equirectangular map (2N × N texels, row-major, top row first) of a pbrt-v4
/// equal-area octahedral square of N × N texels.
pub fn octahedral_to_equirect(square: &[[f32; 3]], size: usize) -> (usize, usize, Vec<[f32; 3]>) {
    let (width, height) = (2 * size, size);
    let mut out = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let d = equirect_direction(
                (x as f64 + 0.5) / width as f64,
                (y as f64 + 0.5) / height as f64,
            );
            let (u, v) = sphere_to_square(d);
            out.push(bilinear(square, size, u, v));
        }
    }
    (width, height, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_square_and_the_sphere_map_to_each_other() {
        for k in 0..200 {
            let t = f64::from(k) + 0.5;
            let d = DVec3::new((t * 0.37).sin(), (t * 0.91).cos(), (t * 1.73).sin()).normalize();
            let (u, v) = sphere_to_square(d);
            assert!((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v));
            let back = square_to_sphere(u, v);
            assert!((back - d).length() < 1e-9, "{d} → ({u}, {v}) → {back}");
        }
        // pbrt's layout: +z at the centre, −z at the corners, +x to the right.
        let (u, v) = sphere_to_square(DVec3::Z);
        assert!((u - 0.5).abs() < 1e-12 && (v - 0.5).abs() < 1e-12);
        let (u, v) = sphere_to_square(DVec3::NEG_Z);
        assert!((u - 1.0).abs() < 1e-12 && (v - 1.0).abs() < 1e-12);
        let (u, _) = sphere_to_square(DVec3::X);
        assert!((u - 1.0).abs() < 1e-12);
    }

    #[test]
    fn each_texel_of_the_map_reads_the_square_in_its_own_direction() {
        // A square whose texel value is the direction of its centre (as colour, +1 so that
        // it is positive): the map's texels then hold their own directions, up to the
        // bilinear interpolation's error at this size.
        let size = 64;
        let square: Vec<[f32; 3]> = (0..size * size)
            .map(|i| {
                let (x, y) = (i % size, i / size);
                let d = square_to_sphere(
                    (x as f64 + 0.5) / size as f64,
                    (y as f64 + 0.5) / size as f64,
                );
                [(d.x + 1.0) as f32, (d.y + 1.0) as f32, (d.z + 1.0) as f32]
            })
            .collect();
        let (w, h, map) = octahedral_to_equirect(&square, size);
        assert_eq!((w, h), (128, 64));
        let mut worst = 0.0f64;
        for (i, texel) in map.iter().enumerate() {
            let d = equirect_direction(
                ((i % w) as f64 + 0.5) / w as f64,
                ((i / w) as f64 + 0.5) / h as f64,
            );
            let got = DVec3::new(
                f64::from(texel[0]) - 1.0,
                f64::from(texel[1]) - 1.0,
                f64::from(texel[2]) - 1.0,
            );
            worst = worst.max((got - d).length());
        }
        // Texels are 2.8° apart: the interpolated direction is within a few hundredths.
        assert!(worst < 0.08, "worst direction error {worst}");
    }
}
