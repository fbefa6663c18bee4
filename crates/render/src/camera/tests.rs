//! The packet tracer's batched camera rays (a crate-private fast path, so tested here).

use std::f32::consts::PI;

use glam::{UVec2, Vec2, Vec3A};

use super::*;

const RES: UVec2 = UVec2::new(400, 300);

/// A camera pose away from the origin and tilted, so the transforms are exercised.
fn frame() -> CameraFrame {
    CameraFrame::look_at(
        Vec3A::new(1.0, 2.0, 3.0),
        Vec3A::new(-2.0, 1.5, -1.0),
        Vec3A::Y,
        RES,
    )
    .unwrap()
}

fn all_cameras() -> Vec<Camera> {
    let mut cams = vec![
        Camera::Pinhole(PinholeCamera::new(frame(), 1.2).unwrap()),
        Camera::ThinLens(
            ThinLensCamera::new(
                frame(),
                FocalSpec::FocalLengthMm(35.0),
                ApertureSpec::FNumber(2.8),
                2.0,
                36.0,
            )
            .unwrap(),
        ),
        Camera::Orthographic(OrthographicCamera::new(frame(), 3.0).unwrap()),
        Camera::Spherical(SphericalCamera::new(frame()).unwrap()),
    ];
    for p in FisheyeProjection::ALL {
        for c in [FisheyeCoverage::Circular, FisheyeCoverage::Cropped] {
            let fov = if p == FisheyeProjection::Orthographic {
                PI
            } else {
                1.5 * PI
            };
            cams.push(Camera::Fisheye(
                FisheyeCamera::new(frame(), p, c, fov).unwrap(),
            ));
        }
    }
    cams
}

#[test]
fn batched_camera_rays_are_the_single_rays_bit_for_bit() {
    // The pinhole's batch is its own vector loop (the packet tracer's camera rays); the
    // others go one by one. Film points off the pixel grid, lens samples varied.
    let points: Vec<Vec2> = (0..=23)
        .flat_map(|i| {
            (0..=17).map(move |j| {
                // Film corners inclusive, nudged inside [0, W) × [0, H), then off the grid.
                let s = RES.as_vec2() - 2e-3;
                Vec2::splat(1e-3)
                    + Vec2::new(i as f32 / 23.0 * s.x, j as f32 / 17.0 * s.y)
                    + Vec2::new(0.37, 0.61)
            })
        })
        .collect();
    for camera in all_cameras() {
        for chunk in points.chunks_exact(16) {
            let film: [Vec2; 16] = chunk.try_into().unwrap();
            let lens: [Vec2; 16] = std::array::from_fn(|k| {
                Vec2::new((k as f32 * 0.13) % 1.0, (k as f32 * 0.29) % 1.0)
            });
            let many = camera.generate_rays_only_many(&film, &lens);
            for k in 0..16 {
                let one = camera.generate_ray_only(film[k], lens[k]);
                let bits = |r: &Option<Ray>| {
                    r.map(|r| {
                        let (o, d) = (r.origin.to_array(), r.direction.to_array());
                        (o.map(f32::to_bits), d.map(f32::to_bits), r.t_min, r.t_max)
                    })
                };
                assert_eq!(bits(&many[k]), bits(&one), "{camera:?} at {:?}", film[k]);
            }
        }
    }
}
