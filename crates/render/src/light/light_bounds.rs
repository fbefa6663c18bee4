//! Bounds of where a light is and where it emits, and the importance bound a light BVH
//! descends by (Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with
//! Adaptive Tree Splitting", §4; pbrt-v4 §12.6.3 `LightBounds`, `DirectionCone`).
//!
//! A `LightBounds` holds a box around the emitter, its power φ (a weight only), a cone of
//! emission normals (axis w, spread θ_o) and the angle θ_e beyond a normal that light still
//! leaves at. Its importance at a point p with normal n bounds the light's contribution up
//! to a constant: φ · cos θ′ / d² (· cos θ′_i at surfaces), θ′ the smallest angle between a
//! normal in the cone and the directions from the box to p. It is 0 only where no part of
//! the box can emit towards p (θ′ ≥ θ_e), so choosing by it is unbiased.

use glam::{Vec3A, Vec4};

use super::area::AreaShape;
use super::Light;

/// A cone of directions: axis `w` (unit) and cos of its half-angle (−1: every direction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionCone {
    pub w: Vec3A,
    pub cos_theta: f32,
}

impl DirectionCone {
    pub fn entire_sphere() -> Self {
        Self {
            w: Vec3A::Z,
            cos_theta: -1.0,
        }
    }

    /// The single direction `w`; every direction when `w` is zero or not finite.
    pub fn of_direction(w: Vec3A) -> Self {
        match w.try_normalize() {
            Some(w) => Self { w, cos_theta: 1.0 },
            None => Self::entire_sphere(),
        }
    }

    /// The smallest cone holding both (pbrt-v4 `Union(DirectionCone, DirectionCone)`).
    pub fn union(self, other: Self) -> Self {
        let (theta_a, theta_b) = (safe_acos(self.cos_theta), safe_acos(other.cos_theta));
        let theta_d = safe_acos(self.w.dot(other.w));
        let pi = std::f32::consts::PI;
        if (theta_d + theta_b).min(pi) <= theta_a {
            return self;
        }
        if (theta_d + theta_a).min(pi) <= theta_b {
            return other;
        }
        let theta_o = (theta_a + theta_d + theta_b) / 2.0;
        if theta_o >= pi {
            return Self::entire_sphere();
        }
        // Rotate a's axis towards b's by θ_o − θ_a.
        let axis = self.w.cross(other.w);
        if axis.length_squared() == 0.0 {
            return Self::entire_sphere();
        }
        let rotation = glam::Quat::from_axis_angle(axis.normalize().into(), theta_o - theta_a);
        Self {
            w: Vec3A::from(rotation * glam::Vec3::from(self.w)).normalize(),
            cos_theta: theta_o.cos(),
        }
    }
}

fn safe_acos(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).acos()
}

fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// Where a light is and emits (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// World box, metres.
    pub lo: Vec3A,
    pub hi: Vec3A,
    /// Power, W: a weight between lights.
    pub phi: f32,
    /// Emission normals.
    pub normals: DirectionCone,
    /// cos θ_e: light leaves up to θ_e beyond a normal (π/2 for surfaces).
    pub cos_theta_e: f32,
    pub two_sided: bool,
}

impl LightBounds {
    pub fn centroid(&self) -> Vec3A {
        0.5 * (self.lo + self.hi)
    }

    pub fn union(&self, other: &Self) -> Self {
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
            phi: self.phi + other.phi,
            normals: self.normals.union(other.normals),
            cos_theta_e: self.cos_theta_e.min(other.cos_theta_e),
            two_sided: self.two_sided || other.two_sided,
        }
    }

    /// The importance bound at `p` with unit normal `n` (zero `n`: a point in a medium, no
    /// cosine there): [`LightBounds4::importance`] of this bound alone.
    pub fn importance(&self, p: Vec3A, n: Vec3A) -> f32 {
        LightBounds4::new([Some(self), None, None, None])
            .importance(p, n)
            .x
    }
}

/// Up to four `LightBounds` in SIMD lanes, in the form their importance is evaluated from:
/// each box's bounding sphere and each cone's sine precomputed (an empty lane has φ = 0 and
/// importance 0). A light BVH evaluates the four children of a node at once.
#[derive(Clone, Debug, PartialEq)]
pub struct LightBounds4 {
    centre: [Vec4; 3],
    /// Squared radius of each box's bounding sphere (half its diagonal), m².
    radius2: Vec4,
    /// That radius, m, and 1 / its square (1/m², finite for points): `importance` then
    /// takes one square root and one division before its cones.
    radius: Vec4,
    inv_radius2: Vec4,
    w: [Vec4; 3],
    cos_o: Vec4,
    sin_o: Vec4,
    cos_e: Vec4,
    phi: Vec4,
    /// 1 for two-sided emitters, else 0.
    two_sided: Vec4,
}

impl LightBounds4 {
    pub fn new(bounds: [Option<&LightBounds>; 4]) -> Self {
        let lane =
            |f: &dyn Fn(&LightBounds) -> f32| Vec4::from_array(bounds.map(|b| b.map_or(0.0, f)));
        let sin = |c: f32| safe_sqrt(1.0 - c * c);
        Self {
            centre: [
                lane(&|b| b.centroid().x),
                lane(&|b| b.centroid().y),
                lane(&|b| b.centroid().z),
            ],
            radius2: lane(&|b| (b.hi - b.centroid()).length_squared()),
            radius: lane(&|b| (b.hi - b.centroid()).length()),
            inv_radius2: lane(&|b| {
                1.0 / (b.hi - b.centroid())
                    .length_squared()
                    .max(f32::MIN_POSITIVE)
            }),
            w: [
                lane(&|b| b.normals.w.x),
                lane(&|b| b.normals.w.y),
                lane(&|b| b.normals.w.z),
            ],
            cos_o: lane(&|b| b.normals.cos_theta),
            sin_o: lane(&|b| sin(b.normals.cos_theta)),
            cos_e: lane(&|b| b.cos_theta_e),
            phi: lane(&|b| b.phi),
            two_sided: lane(&|b| f32::from(u8::from(b.two_sided))),
        }
    }

    /// Conty Estevez & Kulla 2018 eq. 3 with pbrt-v4's cone arithmetic, per lane:
    /// φ cos θ′ / d² (· cos θ′_i at surfaces), 0 where θ′ ≥ θ_e. The distance is clamped
    /// to the bounding sphere's radius so points inside the box stay finite.
    #[inline]
    pub fn importance(&self, p: Vec3A, n: Vec3A) -> Vec4 {
        let zero = Vec4::ZERO;
        let one = Vec4::ONE;
        // cos(a − b) clamped to 1 when a < b; sin likewise to 0.
        let cos_sub = |sin_a: Vec4, cos_a: Vec4, sin_b: Vec4, cos_b: Vec4| {
            Vec4::select(cos_a.cmpgt(cos_b), one, cos_a * cos_b + sin_a * sin_b)
        };
        let sin_sub = |sin_a: Vec4, cos_a: Vec4, sin_b: Vec4, cos_b: Vec4| {
            Vec4::select(cos_a.cmpgt(cos_b), zero, sin_a * cos_b - cos_a * sin_b)
        };
        let safe_sqrt = |x: Vec4| x.max(zero).sqrt();
        let t = [
            Vec4::splat(p.x) - self.centre[0],
            Vec4::splat(p.y) - self.centre[1],
            Vec4::splat(p.z) - self.centre[2],
        ];
        let dist2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
        let away = dist2.cmpgt(zero);
        let inv = Vec4::select(away, one / dist2.sqrt(), zero);
        let wi = [0, 1, 2].map(|k| Vec4::select(away, t[k] * inv, self.w[k]));
        let mut cos_w = self.w[0] * wi[0] + self.w[1] * wi[1] + self.w[2] * wi[2];
        cos_w = Vec4::select(self.two_sided.cmpgt(zero), cos_w.abs(), cos_w);
        let sin_w = safe_sqrt(one - cos_w * cos_w);
        // θ_b: the half-angle of the bounding sphere seen from p (all directions inside).
        let inside = dist2.cmple(self.radius2);
        let sin_b = Vec4::select(inside, zero, self.radius * inv);
        let cos_b = Vec4::select(inside, -one, safe_sqrt(one - sin_b * sin_b));
        let cos_x = cos_sub(sin_w, cos_w, self.sin_o, self.cos_o);
        let sin_x = sin_sub(sin_w, cos_w, self.sin_o, self.cos_o);
        let cos_p = cos_sub(sin_x, cos_x, sin_b, cos_b);
        // 1 / max(d², r²): the bounding sphere's radius inside it.
        let inv_d2 = Vec4::select(away, (inv * inv).min(self.inv_radius2), self.inv_radius2);
        let mut importance = self.phi * cos_p * inv_d2;
        if n != Vec3A::ZERO {
            let cos_i = (wi[0] * n.x + wi[1] * n.y + wi[2] * n.z).abs();
            let sin_i = safe_sqrt(one - cos_i * cos_i);
            importance *= cos_sub(sin_i, cos_i, sin_b, cos_b);
        }
        let live = cos_p.cmpgt(self.cos_e) & self.phi.cmpgt(zero) & importance.cmpgt(zero);
        Vec4::select(live, importance, zero)
    }
}

/// The bounds of `light` with world box `(lo, hi)` (an area light's: its instances'),
/// power `phi_w`; `None` for lights at infinity, which a light BVH samples apart.
pub fn light_bounds(
    light: &Light,
    world_box: Option<(Vec3A, Vec3A)>,
    phi_w: f32,
) -> Option<LightBounds> {
    let point = |p: Vec3A| (p, p);
    let surface = |normals: DirectionCone, two_sided: bool| -> Option<LightBounds> {
        let (lo, hi) = world_box?;
        Some(LightBounds {
            lo,
            hi,
            phi: phi_w,
            normals,
            cos_theta_e: 0.0,
            two_sided,
        })
    };
    // A point that may emit in every direction (a luminaire's table is bounded as a point
    // light, as pbrt-v4 bounds its goniometric light).
    let isotropic = |p: Vec3A| {
        let (lo, hi) = point(p);
        Some(LightBounds {
            lo,
            hi,
            phi: phi_w,
            normals: DirectionCone::entire_sphere(),
            cos_theta_e: 0.0,
            two_sided: false,
        })
    };
    match light {
        Light::Point(l) => isotropic(l.position_m),
        Light::Goniometric(l) => isotropic(l.position_m),
        Light::Spot(l) => {
            let (lo, hi) = point(l.position_m);
            // pbrt-v4 `SpotLight::Bounds`: normals within the falloff start, light up to
            // the cone's edge beyond them.
            let theta_e = safe_acos(l.cos_cone) - safe_acos(l.cos_falloff_start);
            Some(LightBounds {
                lo,
                hi,
                phi: phi_w,
                normals: DirectionCone {
                    w: l.axis,
                    cos_theta: l.cos_falloff_start,
                },
                cos_theta_e: theta_e.cos(),
                two_sided: false,
            })
        }
        Light::Area(l) => match &l.shape {
            AreaShape::Rectangle(r) => {
                surface(DirectionCone::of_direction(r.normal()), l.two_sided)
            }
            AreaShape::Disk(d) => surface(DirectionCone::of_direction(d.normal()), l.two_sided),
            AreaShape::Sphere(_) | AreaShape::Mesh(_) => {
                surface(DirectionCone::entire_sphere(), l.two_sided)
            }
        },
        Light::Directional(_) | Light::Environment(_) | Light::Sky(_) | Light::Daylight(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panel(z: f32, facing_down: bool) -> LightBounds {
        LightBounds {
            lo: Vec3A::new(-0.5, -0.5, z),
            hi: Vec3A::new(0.5, 0.5, z),
            phi: 1.0,
            normals: DirectionCone::of_direction(if facing_down { Vec3A::NEG_Z } else { Vec3A::Z }),
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }

    #[test]
    fn a_panel_is_important_only_on_its_emitting_side_and_falls_off_with_distance() {
        let down = panel(2.0, true);
        let below = down.importance(Vec3A::ZERO, Vec3A::Z);
        assert!(below > 0.0);
        assert_eq!(
            down.importance(Vec3A::new(0.0, 0.0, 4.0), Vec3A::NEG_Z),
            0.0
        );
        let far = down.importance(Vec3A::new(0.0, 0.0, -8.0), Vec3A::Z);
        assert!(far < below / 10.0, "{far} {below}");
        // Two-sided: both sides.
        let both = LightBounds {
            two_sided: true,
            ..down
        };
        assert!(both.importance(Vec3A::new(0.0, 0.0, 4.0), Vec3A::NEG_Z) > 0.0);
        // A point facing away from the panel still counts (|cos|): transmission.
        assert!(down.importance(Vec3A::ZERO, Vec3A::NEG_Z) > 0.0);
    }

    #[test]
    fn cone_unions_hold_both_cones() {
        let a = DirectionCone::of_direction(Vec3A::Z);
        let b = DirectionCone::of_direction(Vec3A::X);
        let u = a.union(b);
        let half = std::f32::consts::FRAC_PI_4;
        assert!((u.cos_theta - half.cos()).abs() < 1e-5, "{u:?}");
        for w in [Vec3A::Z, Vec3A::X] {
            assert!(u.w.dot(w) >= u.cos_theta - 1e-5);
        }
        let opposite = a.union(DirectionCone::of_direction(Vec3A::NEG_Z));
        assert_eq!(opposite.cos_theta, -1.0);
        assert_eq!(a.union(a), a);
    }

    /// The bound is conservative: wherever an emitting point of the box sends light to p
    /// within θ_e of a normal in the cone, the importance is > 0 (random boxes, cones, p).
    #[test]
    fn importance_is_zero_only_where_no_light_can_arrive() {
        let mut state = 0x9E37_79B9u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / u32::MAX as f32
        };
        let v = |next: &mut dyn FnMut() -> f32| {
            Vec3A::new(next() * 4.0 - 2.0, next() * 4.0 - 2.0, next() * 4.0 - 2.0)
        };
        for _ in 0..20_000 {
            let (a, b) = (v(&mut next), v(&mut next));
            let w = v(&mut next).normalize();
            let cos_o = next() * 2.0 - 1.0;
            let cos_e = next();
            let bounds = LightBounds {
                lo: a.min(b),
                hi: a.max(b),
                phi: 1.0,
                normals: DirectionCone {
                    w,
                    cos_theta: cos_o,
                },
                cos_theta_e: cos_e,
                two_sided: false,
            };
            let p = v(&mut next) * 2.0;
            if bounds.importance(p, Vec3A::ZERO) > 0.0 {
                continue;
            }
            // No emitter point x in the box and normal m in the cone with the angle
            // between m and p − x below θ_e.
            for _ in 0..64 {
                let t = Vec3A::new(next(), next(), next());
                let x = bounds.lo + t * (bounds.hi - bounds.lo);
                let d = (p - x).normalize();
                let angle_to_axis = safe_acos(w.dot(d));
                let best = (angle_to_axis - safe_acos(cos_o)).max(0.0);
                assert!(
                    best.cos() <= cos_e + 1e-4,
                    "{bounds:?} p {p}: light reaches at {best} rad"
                );
            }
        }
    }
}
