//! The G-buffer: per pixel the primary hit the predictor reasons about (Bagher et al. 2013
//! §3, "Rendering G-buffers": position, normal, depth and material id, plus the curvature
//! its eq. 3 needs for the shears C_c and C_−c and the view direction for θ_x in P_x).
//!
//! render fills it from the camera ray through each pixel's centre (one hit per pixel);
//! prism-bandwidth only reads it.

use glam::{UVec2, Vec2, Vec3A};
use prism_geometry::{Curvature, Differentials};

use crate::error::{pixel_count, pixel_index, BandwidthError};

/// Largest |‖v‖ − 1| accepted for a unit vector (f32 normals from interpolation and
/// transforms are unit to ~1e-6; this only rejects vectors that were never normalised).
pub const UNIT_VECTOR_TOLERANCE: f32 = 1e-3;

/// The primary hit of one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GBufferHit {
    position_m: Vec3A,
    depth_m: f32,
    normal: Vec3A,
    curvature: Curvature,
    view_direction: Vec3A,
    material_id: u32,
    uv: Vec2,
    differentials: Differentials,
}

impl GBufferHit {
    /// A hit at world-space `position_m`, `depth_m` metres along the camera ray (the
    /// distance d′ of Bagher's eq. 4 from the surface to the camera), with the unit
    /// world-space shading `normal`, the surface's principal `curvature` (1/m), the unit
    /// `view_direction` from the hit towards the camera, and the scene's `material_id`.
    /// Errors name the parameter: non-finite values, negative depth, non-unit vectors.
    pub fn new(
        position_m: Vec3A,
        depth_m: f32,
        normal: Vec3A,
        curvature: Curvature,
        view_direction: Vec3A,
        material_id: u32,
    ) -> Result<Self, BandwidthError> {
        const CONTEXT: &str = "G-buffer hit";
        if !position_m.is_finite() {
            return Err(BandwidthError::invalid(
                CONTEXT,
                "position_m",
                position_m,
                "finite coordinates in metres",
            ));
        }
        if !(depth_m.is_finite() && depth_m >= 0.0) {
            return Err(BandwidthError::invalid(
                CONTEXT,
                "depth_m",
                depth_m,
                "a finite distance ≥ 0 m",
            ));
        }
        let unit = |v: Vec3A| v.is_finite() && (v.length() - 1.0).abs() <= UNIT_VECTOR_TOLERANCE;
        if !unit(normal) {
            return Err(BandwidthError::invalid(
                CONTEXT,
                "normal",
                normal,
                "a unit vector",
            ));
        }
        if !unit(view_direction) {
            return Err(BandwidthError::invalid(
                CONTEXT,
                "view_direction",
                view_direction,
                "a unit vector from the hit towards the camera",
            ));
        }
        if !(curvature.k1.is_finite() && curvature.k2.is_finite()) {
            return Err(BandwidthError::invalid(
                CONTEXT,
                "curvature",
                (curvature.k1, curvature.k2),
                "finite principal curvatures in 1/m",
            ));
        }
        Ok(Self {
            position_m,
            depth_m,
            normal,
            curvature,
            view_direction,
            material_id,
            uv: Vec2::ZERO,
            differentials: Differentials::default(),
        })
    }

    /// The same hit with the surface's texture coordinates (so that a probe reads the
    /// material's textures where the pixel sees them; (0, 0) unless given). Non-finite
    /// coordinates are an error.
    pub fn with_uv(mut self, uv: Vec2) -> Result<Self, BandwidthError> {
        if !uv.is_finite() {
            return Err(BandwidthError::invalid(
                "G-buffer hit",
                "uv",
                uv,
                "finite texture coordinates",
            ));
        }
        self.uv = uv;
        Ok(self)
    }

    /// The surface's texture coordinates at the hit.
    pub fn uv(&self) -> Vec2 {
        self.uv
    }

    /// The same hit with the camera ray's differentials there (one pixel step in x and y:
    /// ∂p in metres, ∂u, ∂v), so that a probe knows the footprint its texture lookups
    /// filter over (zero unless given). Non-finite values are an error.
    pub fn with_differentials(
        mut self,
        differentials: Differentials,
    ) -> Result<Self, BandwidthError> {
        let d = &differentials;
        let finite = d.dpdx.is_finite()
            && d.dpdy.is_finite()
            && [d.dudx, d.dvdx, d.dudy, d.dvdy]
                .iter()
                .all(|v| v.is_finite());
        if !finite {
            return Err(BandwidthError::invalid(
                "G-buffer hit",
                "differentials",
                *d,
                "finite ray differentials",
            ));
        }
        self.differentials = differentials;
        Ok(self)
    }

    /// The camera ray's differentials at the hit (zero when not given).
    pub fn differentials(&self) -> Differentials {
        self.differentials
    }

    /// World-space position, metres.
    pub fn position_m(&self) -> Vec3A {
        self.position_m
    }

    /// Distance from the camera along the primary ray, metres.
    pub fn depth_m(&self) -> f32 {
        self.depth_m
    }

    /// Unit world-space shading normal.
    pub fn normal(&self) -> Vec3A {
        self.normal
    }

    /// Principal curvatures (1/m) and directions (prism-geometry's sign convention: a
    /// sphere with outward normals has k1 = k2 = 1/r).
    pub fn curvature(&self) -> Curvature {
        self.curvature
    }

    /// Unit direction from the hit towards the camera (ω_{x→p} of Bagher's eq. 1).
    pub fn view_direction(&self) -> Vec3A {
        self.view_direction
    }

    /// cos θ_x = n · ω_{x→p}, the cosine in P_x of Bagher's eq. 3 (negative when the
    /// shading normal faces away from the camera).
    pub fn cos_theta_view(&self) -> f32 {
        self.normal.dot(self.view_direction)
    }

    /// The scene's material index (prism-geometry's `NO_MATERIAL` for the default).
    pub fn material_id(&self) -> u32 {
        self.material_id
    }
}

/// Per pixel the primary hit, or `None` where the camera ray misses (or the camera has no
/// ray, e.g. outside a fisheye's image circle). Row-major, top row first, like the film.
#[derive(Clone, Debug, PartialEq)]
pub struct GBuffer {
    resolution: UVec2,
    hits: Vec<Option<GBufferHit>>,
}

impl GBuffer {
    /// An empty G-buffer (every pixel a miss) of `resolution` ≥ 1×1.
    pub fn new(resolution: UVec2) -> Result<Self, BandwidthError> {
        let n = pixel_count("G-buffer", resolution)?;
        Ok(Self {
            resolution,
            hits: vec![None; n],
        })
    }

    /// A G-buffer from one entry per pixel (row-major).
    pub fn from_hits(
        resolution: UVec2,
        hits: Vec<Option<GBufferHit>>,
    ) -> Result<Self, BandwidthError> {
        let n = pixel_count("G-buffer", resolution)?;
        if hits.len() != n {
            return Err(BandwidthError::LengthMismatch {
                what: "G-buffer",
                resolution,
                found: hits.len(),
            });
        }
        Ok(Self { resolution, hits })
    }

    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    /// Sets the entry of `pixel` (an error when it lies outside the buffer).
    pub fn set(&mut self, pixel: UVec2, hit: Option<GBufferHit>) -> Result<(), BandwidthError> {
        let i = pixel_index("G-buffer", pixel, self.resolution)?;
        self.hits[i] = hit;
        Ok(())
    }

    /// The hit of `pixel`; `None` for a miss or a pixel outside the buffer.
    pub fn hit(&self, pixel: UVec2) -> Option<&GBufferHit> {
        let i = pixel_index("G-buffer", pixel, self.resolution).ok()?;
        self.hits[i].as_ref()
    }

    /// Every entry, row-major.
    pub fn hits(&self) -> &[Option<GBufferHit>] {
        &self.hits
    }

    /// Pixels with a hit, row-major, with their hit.
    pub fn iter_hits(&self) -> impl Iterator<Item = (UVec2, &GBufferHit)> {
        let width = self.resolution.x;
        self.hits.iter().enumerate().filter_map(move |(i, h)| {
            h.as_ref()
                .map(|h| (UVec2::new(i as u32 % width, i as u32 / width), h))
        })
    }

    /// Number of pixels with a hit.
    pub fn hit_count(&self) -> usize {
        self.hits.iter().filter(|h| h.is_some()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(depth_m: f32) -> GBufferHit {
        GBufferHit::new(
            Vec3A::new(0.0, 0.0, -depth_m),
            depth_m,
            Vec3A::Z,
            Curvature::default(),
            Vec3A::Z,
            3,
        )
        .unwrap()
    }

    #[test]
    fn hits_are_stored_row_major_and_read_back() {
        let mut g = GBuffer::new(UVec2::new(4, 3)).unwrap();
        assert_eq!(g.hit_count(), 0);
        g.set(UVec2::new(3, 2), Some(hit(2.0))).unwrap();
        g.set(UVec2::new(1, 0), Some(hit(5.0))).unwrap();
        assert_eq!(g.hit(UVec2::new(3, 2)).unwrap().depth_m(), 2.0);
        assert_eq!(g.hits()[11], Some(hit(2.0)));
        assert!(g.hit(UVec2::new(0, 0)).is_none());
        assert!(
            g.hit(UVec2::new(4, 0)).is_none(),
            "outside is a miss, not a panic"
        );
        let listed: Vec<(UVec2, f32)> = g.iter_hits().map(|(p, h)| (p, h.depth_m())).collect();
        assert_eq!(
            listed,
            vec![(UVec2::new(1, 0), 5.0), (UVec2::new(3, 2), 2.0)]
        );
        assert_eq!(g.hit_count(), 2);
        let h = g.hit(UVec2::new(1, 0)).unwrap();
        assert_eq!(h.material_id(), 3);
        assert_eq!(h.cos_theta_view(), 1.0);
    }

    #[test]
    fn bad_input_is_an_error_naming_what_is_wrong() {
        let e = GBuffer::new(UVec2::new(0, 3)).unwrap_err();
        assert!(e.to_string().contains("G-buffer"), "{e}");
        let e = GBuffer::from_hits(UVec2::new(2, 2), vec![None; 3]).unwrap_err();
        assert!(e.to_string().contains("needs 4 entries"), "{e}");
        let mut g = GBuffer::new(UVec2::new(2, 2)).unwrap();
        let e = g.set(UVec2::new(2, 0), None).unwrap_err();
        assert!(e.to_string().contains("outside the 2×2"), "{e}");
        let c = Curvature::default();
        let p = Vec3A::ZERO;
        for (e, parameter) in [
            (
                GBufferHit::new(p, -1.0, Vec3A::Z, c, Vec3A::Z, 0),
                "depth_m",
            ),
            (
                GBufferHit::new(p, 1.0, Vec3A::splat(1.0), c, Vec3A::Z, 0),
                "normal",
            ),
            (
                GBufferHit::new(p, 1.0, Vec3A::Z, c, Vec3A::ZERO, 0),
                "view_direction",
            ),
            (
                GBufferHit::new(Vec3A::splat(f32::NAN), 1.0, Vec3A::Z, c, Vec3A::Z, 0),
                "position_m",
            ),
        ] {
            let message = e.unwrap_err().to_string();
            assert!(message.contains(parameter), "{message}");
        }
    }
}
