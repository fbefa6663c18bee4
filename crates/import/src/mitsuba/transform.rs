//! Mitsuba `<transform>`: translate, rotate, scale, matrix and lookat steps, each applied
//! after the ones before (M = step · M), as Mitsuba's XML parser composes them.

use glam::{DMat4, DVec3, DVec4};

use crate::error::ImportError;
use crate::mitsuba::props::{number_list, parse_number, vector3};
use crate::mitsuba::xml::Element;

/// The local-to-world matrix of a `<transform>` element.
pub fn parse_transform(t: &Element) -> Result<DMat4, ImportError> {
    let mut m = DMat4::IDENTITY;
    for step in &t.children {
        let s = match step.tag.as_str() {
            "translate" => DMat4::from_translation(vector3(step)?),
            "scale" => {
                let v = match step.attr("value") {
                    Some(v) => {
                        let xs = number_list(step, v)?;
                        match xs.as_slice() {
                            [s] => DVec3::splat(*s),
                            [x, y, z] => DVec3::new(*x, *y, *z),
                            _ => {
                                return Err(ImportError::at(
                                    &step.at,
                                    format!("<scale>: expected 1 or 3 numbers, found \"{v}\""),
                                ))
                            }
                        }
                    }
                    None => {
                        let one = |n: &str| -> Result<f64, ImportError> {
                            match step.attr(n) {
                                None => Ok(1.0),
                                Some(v) => parse_number(v.trim()).ok_or_else(|| {
                                    ImportError::at(
                                        &step.at,
                                        format!("<scale> {n}: expected a number, found \"{v}\""),
                                    )
                                }),
                            }
                        };
                        DVec3::new(one("x")?, one("y")?, one("z")?)
                    }
                };
                DMat4::from_scale(v)
            }
            "rotate" => {
                let angle_deg =
                    parse_number(step.require_attr("angle")?.trim()).ok_or_else(|| {
                        ImportError::at(
                            &step.at,
                            "<rotate>: expected a number in `angle` (degrees)",
                        )
                    })?;
                let axis = vector3(step)?;
                if axis.length_squared() == 0.0 {
                    return Err(ImportError::at(
                        &step.at,
                        "<rotate>: expected a non-zero axis (x, y, z or value)",
                    ));
                }
                DMat4::from_axis_angle(axis.normalize(), angle_deg.to_radians())
            }
            "matrix" => {
                let v = step.require_attr("value")?;
                let xs = number_list(step, v)?;
                if xs.len() != 16 {
                    return Err(ImportError::at(
                        &step.at,
                        format!(
                            "<matrix>: expected 16 numbers (row-major 4×4), found {}",
                            xs.len()
                        ),
                    ));
                }
                let row =
                    |r: usize| DVec4::new(xs[4 * r], xs[4 * r + 1], xs[4 * r + 2], xs[4 * r + 3]);
                DMat4::from_cols(row(0), row(1), row(2), row(3)).transpose()
            }
            "lookat" => {
                let point = |n: &str| -> Result<DVec3, ImportError> {
                    let v = step.require_attr(n)?;
                    let xs = number_list(step, v)?;
                    match xs.as_slice() {
                        [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
                        _ => Err(ImportError::at(
                            &step.at,
                            format!("<lookat> {n}: expected 3 numbers, found \"{v}\""),
                        )),
                    }
                };
                let origin = point("origin")?;
                let target = point("target")?;
                let up = match step.attr("up") {
                    Some(_) => point("up")?,
                    None => DVec3::Y,
                };
                look_at(origin, target, up).ok_or_else(|| {
                    ImportError::at(
                        &step.at,
                        "<lookat>: expected origin ≠ target and `up` not parallel to the view direction",
                    )
                })?
            }
            other => {
                return Err(ImportError::at(
                    &step.at,
                    format!(
                        "<transform>: unknown step <{other}>, expected <translate>, <rotate>, \
                         <scale>, <matrix> or <lookat>"
                    ),
                ))
            }
        };
        m = s * m;
    }
    Ok(m)
}

/// Mitsuba's `Transform4f::look_at`: columns (left, up, direction, origin), so local +Z looks
/// at the target and local +X points to the viewer's left.
pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (target - origin).try_normalize()?;
    let left = up.normalize_or_zero().cross(dir).try_normalize()?;
    let new_up = dir.cross(left);
    Some(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_points_local_z_at_the_target() {
        let m = look_at(DVec3::new(0.0, 0.0, 3.9), DVec3::ZERO, DVec3::Y).unwrap();
        assert!((m.transform_vector3(DVec3::Z) - DVec3::NEG_Z).length() < 1e-12);
        assert!((m.transform_vector3(DVec3::X) - DVec3::NEG_X).length() < 1e-12);
        assert!((m.transform_point3(DVec3::ZERO) - DVec3::new(0.0, 0.0, 3.9)).length() < 1e-12);
    }
}
