//! Camera descriptions: pinhole, thin lens, fisheye (four projections), orthographic and
//! spherical. Every camera looks along its local −Z with +Y up; `transform` (usually a
//! `look_at`) places it in the world.

use crate::reader::{Obj, Result, V};
use crate::schema::schema;
use crate::transform::{parse_transform, Transform};

#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Camera-to-world.
    pub transform: Transform,
    pub kind: CameraKind,
}

/// Which film extent a perspective field of view spans.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FovAxis {
    Horizontal,
    Vertical,
    Diagonal,
}

/// Fisheye mappings from the angle θ off the axis to the radius r on the image
/// (focal length f): equidistant r = fθ, equisolid r = 2f sin(θ/2), orthographic
/// r = f sin θ, stereographic r = 2f tan(θ/2) (Kannala & Brandt 2006, eqs. 1–4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FisheyeProjection {
    Equidistant,
    Equisolid,
    Orthographic,
    Stereographic,
}

impl FisheyeProjection {
    /// The largest full field of view in degrees, and whether it is reachable: 180° for
    /// orthographic, below 360° for stereographic (tan(θ/2) → ∞), 360° otherwise.
    pub fn max_fov_deg(self) -> (f64, bool) {
        match self {
            FisheyeProjection::Orthographic => (180.0, true),
            FisheyeProjection::Stereographic => (360.0, false),
            FisheyeProjection::Equidistant | FisheyeProjection::Equisolid => (360.0, true),
        }
    }
}

/// Circular: the whole image circle fits in the shorter film side. Cropped: the image circle
/// passes through the film corners (the field of view spans the diagonal; the film is filled).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FisheyeFit {
    Circular,
    Cropped,
}

#[derive(Debug, Clone, PartialEq)]
pub enum CameraKind {
    Pinhole {
        fov_rad: f64,
        fov_axis: FovAxis,
    },
    /// Focal length and field of view are both filled in (fov = 2·atan(w / 2f), focused at
    /// infinity); aperture radius = f / (2N) when an f-number was given.
    ThinLens {
        focal_length_m: f64,
        /// Horizontal, across `sensor_width_m`.
        fov_rad: f64,
        sensor_width_m: f64,
        aperture_radius_m: f64,
        f_number: Option<f64>,
        focus_distance_m: f64,
    },
    Fisheye {
        projection: FisheyeProjection,
        fov_rad: f64,
        fit: FisheyeFit,
    },
    Orthographic {
        /// Width of the film in the world, in metres (height follows the aspect ratio).
        width_m: f64,
    },
    /// Equirectangular 360° × 180°: u is longitude, v latitude.
    Spherical,
}

/// Pinhole at the origin looking down −Z, 60° horizontal field of view.
pub const DEFAULT_FOV_DEG: f64 = 60.0;
/// Full-frame sensor width (36 mm × 24 mm).
pub const DEFAULT_SENSOR_WIDTH_MM: f64 = 36.0;

impl Default for Camera {
    fn default() -> Self {
        Camera {
            transform: Transform::IDENTITY,
            kind: CameraKind::Pinhole {
                fov_rad: DEFAULT_FOV_DEG.to_radians(),
                fov_axis: FovAxis::Horizontal,
            },
        }
    }
}

const TYPES: [&str; 5] = [
    "pinhole",
    "thin_lens",
    "fisheye",
    "orthographic",
    "spherical",
];

/// A perspective field of view: strictly between 0° and 180°.
fn perspective_fov(o: &Obj) -> Result<f64> {
    match o.get("fov_deg") {
        None => Ok(DEFAULT_FOV_DEG.to_radians()),
        Some(v) => {
            let fov = v.f64()?;
            if fov > 0.0 && fov < 180.0 {
                Ok(fov.to_radians())
            } else {
                Err(v.err(format!(
                    "expected a field of view in (0, 180) degrees for a perspective camera, found {fov}"
                )))
            }
        }
    }
}

fn transform_of(o: &Obj) -> Result<Transform> {
    o.get("transform")
        .map_or(Ok(Transform::IDENTITY), |t| parse_transform(&t))
}

pub(crate) fn parse_camera(v: &V) -> Result<Camera> {
    match v.tag("camera", &TYPES, Some("pinhole"))? {
        "pinhole" => {
            let o = v.tagged_object(schema!("camera<pinhole>"))?;
            let fov_rad = perspective_fov(&o)?;
            let fov_axis = match o.one_of_or(
                "fov_axis",
                "field-of-view axis",
                &["horizontal", "vertical", "diagonal"],
                "horizontal",
            )? {
                "vertical" => FovAxis::Vertical,
                "diagonal" => FovAxis::Diagonal,
                _ => FovAxis::Horizontal,
            };
            Ok(Camera {
                transform: transform_of(&o)?,
                kind: CameraKind::Pinhole { fov_rad, fov_axis },
            })
        }
        "thin_lens" => {
            let o = v.tagged_object(schema!("camera<thin_lens>"))?;
            let sensor_width_m = o.positive_or("sensor_width_mm", DEFAULT_SENSOR_WIDTH_MM)? * 1e-3;
            let (focal_length_m, fov_rad) = match o.at_most_one(&["focal_length_mm", "fov_deg"])? {
                Some(("focal_length_mm", f)) => {
                    let f_m = f.positive()? * 1e-3;
                    (f_m, 2.0 * (sensor_width_m / (2.0 * f_m)).atan())
                }
                _ => {
                    let fov = perspective_fov(&o)?;
                    (sensor_width_m / (2.0 * (fov / 2.0).tan()), fov)
                }
            };
            let (aperture_radius_m, f_number) =
                match o.at_most_one(&["f_number", "aperture_radius_m"])? {
                    Some(("f_number", n)) => {
                        let n = n.positive()?;
                        (focal_length_m / (2.0 * n), Some(n))
                    }
                    Some((_, r)) => (r.non_negative()?, None),
                    None => {
                        return Err(o.v.err(
                            "missing field: a thin lens needs `f_number` or `aperture_radius_m`",
                        ))
                    }
                };
            let focus_distance_m = o
                .req("focus_distance_m", "the distance in focus, in metres")?
                .positive()?;
            Ok(Camera {
                transform: transform_of(&o)?,
                kind: CameraKind::ThinLens {
                    focal_length_m,
                    fov_rad,
                    sensor_width_m,
                    aperture_radius_m,
                    f_number,
                    focus_distance_m,
                },
            })
        }
        "fisheye" => {
            let o = v.tagged_object(schema!("camera<fisheye>"))?;
            let projection = match o.one_of_or(
                "projection",
                "fisheye projection",
                &["equidistant", "equisolid", "orthographic", "stereographic"],
                "equidistant",
            )? {
                "equisolid" => FisheyeProjection::Equisolid,
                "orthographic" => FisheyeProjection::Orthographic,
                "stereographic" => FisheyeProjection::Stereographic,
                _ => FisheyeProjection::Equidistant,
            };
            let (max, inclusive) = projection.max_fov_deg();
            let fov_deg = match o.get("fov_deg") {
                None => 180.0,
                Some(f) => {
                    let fov = f.f64()?;
                    let ok = fov > 0.0 && if inclusive { fov <= max } else { fov < max };
                    if !ok {
                        let close = if inclusive { ']' } else { ')' };
                        return Err(f.err(format!(
                            "expected a field of view in (0, {max}{close} degrees for the {} \
                             fisheye projection, found {fov}",
                            o.get("projection")
                                .and_then(|p| p.str().ok())
                                .unwrap_or("equidistant")
                        )));
                    }
                    fov
                }
            };
            let fit =
                match o.one_of_or("fit", "fisheye fit", &["circular", "cropped"], "circular")? {
                    "cropped" => FisheyeFit::Cropped,
                    _ => FisheyeFit::Circular,
                };
            Ok(Camera {
                transform: transform_of(&o)?,
                kind: CameraKind::Fisheye {
                    projection,
                    fov_rad: fov_deg.to_radians(),
                    fit,
                },
            })
        }
        "orthographic" => {
            let o = v.tagged_object(schema!("camera<orthographic>"))?;
            Ok(Camera {
                transform: transform_of(&o)?,
                kind: CameraKind::Orthographic {
                    width_m: o.positive_or("width_m", 2.0)?,
                },
            })
        }
        _ => {
            let o = v.tagged_object(schema!("camera<spherical>"))?;
            Ok(Camera {
                transform: transform_of(&o)?,
                kind: CameraKind::Spherical,
            })
        }
    }
}
