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

use glam::Vec3A;

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
    /// cosine there): [`ImportanceBound::importance`].
    pub fn importance(&self, p: Vec3A, n: Vec3A) -> f32 {
        ImportanceBound::new(self).importance(p, n)
    }
}

/// A `LightBounds` in the form its importance is evaluated from: the box's bounding sphere
/// and the cone's sines precomputed (a light BVH evaluates two per level per sample).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImportanceBound {
    centre: Vec3A,
    /// Squared radius of the box's bounding sphere (half its diagonal), m².
    radius2: f32,
    w: Vec3A,
    cos_o: f32,
    sin_o: f32,
    cos_e: f32,
    phi: f32,
    two_sided: bool,
}

impl ImportanceBound {
    pub fn centre(&self) -> Vec3A {
        self.centre
    }
    pub fn radius2(&self) -> f32 {
        self.radius2
    }
    pub fn axis(&self) -> Vec3A {
        self.w
    }
    pub fn cos_o(&self) -> f32 {
        self.cos_o
    }
    pub fn sin_o(&self) -> f32 {
        self.sin_o
    }
    pub fn cos_e(&self) -> f32 {
        self.cos_e
    }
    pub fn phi(&self) -> f32 {
        self.phi
    }
    pub fn two_sided(&self) -> bool {
        self.two_sided
    }

    pub fn new(b: &LightBounds) -> Self {
        let centre = b.centroid();
        let cos_o = b.normals.cos_theta;
        Self {
            centre,
            radius2: (b.hi - centre).length_squared(),
            w: b.normals.w,
            cos_o,
            sin_o: safe_sqrt(1.0 - cos_o * cos_o),
            cos_e: b.cos_theta_e,
            phi: b.phi,
            two_sided: b.two_sided,
        }
    }

    /// Conty Estevez & Kulla 2018 eq. 3 with pbrt-v4's cone arithmetic: φ cos θ′ / d²
    /// (· cos θ′_i at surfaces), 0 where θ′ ≥ θ_e. The distance is clamped to the bounding
    /// sphere's radius so points inside the box stay finite.
    #[inline]
    pub fn importance(&self, p: Vec3A, n: Vec3A) -> f32 {
        // cos(a − b) clamped to 1 when a < b; sin likewise to 0.
        let cos_sub = |sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32| {
            if cos_a > cos_b {
                1.0
            } else {
                cos_a * cos_b + sin_a * sin_b
            }
        };
        let sin_sub = |sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32| {
            if cos_a > cos_b {
                0.0
            } else {
                sin_a * cos_b - cos_a * sin_b
            }
        };
        let to_p = p - self.centre;
        let dist2 = to_p.length_squared();
        let wi = if dist2 > 0.0 {
            to_p / dist2.sqrt()
        } else {
            self.w
        };
        let mut cos_w = self.w.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
        // θ_b: the half-angle of the bounding sphere seen from p (all directions inside).
        let (sin_b, cos_b) = if dist2 <= self.radius2 {
            (0.0, -1.0)
        } else {
            let sin2 = self.radius2 / dist2;
            (sin2.sqrt(), safe_sqrt(1.0 - sin2))
        };
        let cos_x = cos_sub(sin_w, cos_w, self.sin_o, self.cos_o);
        let sin_x = sin_sub(sin_w, cos_w, self.sin_o, self.cos_o);
        let cos_p = cos_sub(sin_x, cos_x, sin_b, cos_b);
        if cos_p <= self.cos_e {
            return 0.0;
        }
        let d2 = dist2.max(self.radius2).max(f32::MIN_POSITIVE);
        let mut importance = self.phi * cos_p / d2;
        if n != Vec3A::ZERO {
            let cos_i = wi.dot(n).abs();
            let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
            importance *= cos_sub(sin_i, cos_i, sin_b, cos_b);
        }
        importance.max(0.0)
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
