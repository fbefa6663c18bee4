//! The transport operators on a bandwidth vector ν = [ν_s, ν_a] (Bagher et al. 2013 §2.1,
//! Fig. 4; eqs. 3 and 4), after Durand et al. 2005.
//!
//! ν is the half-size of a rectangle rect(ν) = [−ν_s, ν_s] × [−ν_a, ν_a] holding the
//! spectrum (`bandwidth` module). A linear operator M maps it to the parallelogram
//! M·rect(ν), whose bounding box has half-size |M|ν (entrywise absolute values). Bounding
//! after every step loses the shape: a point light (ν_l = [∞, 0]) seen through T_d is a
//! sheared line, which the BRDF's slab |Ω_a| ≤ ρ cuts to a finite segment, while its
//! bounding box is infinite in both axes. So eq. 4 is evaluated in two runs:
//!
//! - run 1, M₁ = C_c P_i T_d: the parallelogram M₁·rect(ν_l) is intersected exactly with
//!   B_{t,ρ}'s slab |Ω_a| ≤ ρ, and the polygon's bounding box is kept; t is added to ν_s;
//! - run 2, M₂ = T_{d′} P_x C_−c S: ν ← |M₂|ν.
//!
//! Conventions: 0·∞ = 0 (a zero matrix entry does not spread an unbounded axis); a distant
//! light (d = +∞) skips T_d; point and spot lights have ν_l = [∞, 0]
//! ([`Bandwidth::POINT_LIGHT`]). Frequencies are ordinary (cycles/m, cycles/rad): the
//! matrices are linear, so they carry no 2π.

use glam::{Mat2, Vec2, Vec3A};
use prism_geometry::Curvature;

use crate::bandwidth::{Bandwidth, MaterialBandwidth};
use crate::error::BandwidthError;

/// A 2×2 matrix from its rows (Fig. 4 writes them row by row).
fn rows(a: f32, b: f32, c: f32, d: f32) -> Mat2 {
    Mat2::from_cols(Vec2::new(a, c), Vec2::new(b, d))
}

/// T_d = [[1, 0], [−d, 1]]: free-space transport by d metres (an angular shear of the
/// spectrum).
pub fn transport(d_m: f32) -> Mat2 {
    rows(1.0, 0.0, -d_m, 1.0)
}

/// C_c = [[1, c], [0, 1]]: the curvature shear, c in 1/m (c of the reflection's incident
/// side; the outgoing side uses C_−c).
pub fn curvature_shear(c_per_m: f32) -> Mat2 {
    rows(1.0, c_per_m, 0.0, 1.0)
}

/// P_i = diag(cos θ_i, 1): re-parametrisation of the incident light field onto the surface.
pub fn project_incident(cos_theta_i: f32) -> Mat2 {
    rows(cos_theta_i, 0.0, 0.0, 1.0)
}

/// P_x = diag(1/cos θ_x, 1): re-parametrisation along the outgoing direction.
pub fn project_outgoing(cos_theta_x: f32) -> Mat2 {
    rows(1.0 / cos_theta_x, 0.0, 0.0, 1.0)
}

/// S = diag(1, −1): the mirror re-parametrisation.
pub fn mirror() -> Mat2 {
    rows(1.0, 0.0, 0.0, -1.0)
}

/// a·ν with 0·∞ = 0.
fn scale(a: f32, nu: f32) -> f32 {
    if a == 0.0 {
        0.0
    } else {
        a.abs() * nu
    }
}

/// |M|ν: the half-size of the bounding box of M·rect(ν) (0·∞ = 0).
pub fn bound(m: Mat2, nu: Bandwidth) -> Bandwidth {
    let (s, a) = (nu.spatial_cycles_per_m, nu.angular_cycles_per_rad);
    Bandwidth {
        spatial_cycles_per_m: scale(m.x_axis.x, s) + scale(m.y_axis.x, a),
        angular_cycles_per_rad: scale(m.x_axis.y, s) + scale(m.y_axis.y, a),
    }
}

/// One edge direction of M·rect(ν): the column `column` scaled by the half-width `half`,
/// finite, or an unbounded line along `column` (half = ∞ and column ≠ 0).
enum Generator {
    Finite(Vec2),
    Line(Vec2),
}

fn generator(column: Vec2, half: f32) -> Generator {
    match (half.is_infinite(), column == Vec2::ZERO) {
        (true, false) => Generator::Line(column),
        // 0·∞ = 0.
        (true, true) => Generator::Finite(Vec2::ZERO),
        (false, _) => Generator::Finite(column * half),
    }
}

/// Half-size of the bounding box of M·rect(ν) ∩ {|Ω_a| ≤ ρ} (B's slab; Bagher eq. 3), exact:
/// the clipped parallelogram has at most 8 vertices (4 corners, 2 cuts per clipping line),
/// and its bounding box is what survives band-limiting better than |M|ν would.
pub fn clip_bound(m: Mat2, nu: Bandwidth, rho_cycles_per_rad: f32) -> Bandwidth {
    if rho_cycles_per_rad.is_infinite() {
        return bound(m, nu);
    }
    let rho = rho_cycles_per_rad;
    let g1 = generator(m.x_axis, nu.spatial_cycles_per_m);
    let g2 = generator(m.y_axis, nu.angular_cycles_per_rad);
    match (g1, g2) {
        (Generator::Finite(a), Generator::Finite(b)) => clip_parallelogram(a, b, rho),
        (Generator::Line(line), Generator::Finite(b))
        | (Generator::Finite(b), Generator::Line(line)) => clip_strip(line, b, rho),
        (Generator::Line(l1), Generator::Line(l2)) => {
            if l1.perp_dot(l2) != 0.0 {
                // Two independent lines span the plane: only the slab remains.
                Bandwidth {
                    spatial_cycles_per_m: f32::INFINITY,
                    angular_cycles_per_rad: rho,
                }
            } else {
                // Parallel lines: one line (no finite thickness).
                clip_strip(l1, Vec2::ZERO, rho)
            }
        }
    }
}

/// The strip {t·line + w·b : t ∈ ℝ, |w| ≤ 1} cut by |y| ≤ ρ.
fn clip_strip(line: Vec2, b: Vec2, rho: f32) -> Bandwidth {
    if line.y == 0.0 {
        // A horizontal line: unbounded in Ω_s whatever ρ; Ω_a spans b's extent.
        return Bandwidth {
            spatial_cycles_per_m: f32::INFINITY,
            angular_cycles_per_rad: b.y.abs().min(rho),
        };
    }
    // y = t·l_y + w·b_y reaches every value: ν_a = ρ. With t = (y − w b_y)/l_y,
    // x = y·l_x/l_y + w·(b_x − b_y·l_x/l_y), maximal at |y| = ρ, |w| = 1.
    let slope = line.x / line.y;
    Bandwidth {
        spatial_cycles_per_m: scale(slope, rho) + (b.x - b.y * slope).abs(),
        angular_cycles_per_rad: rho,
    }
}

/// The parallelogram {u·a + w·b : |u|, |w| ≤ 1} cut by |y| ≤ ρ (Sutherland–Hodgman on the
/// two clipping lines), then bounded. The polygon is symmetric about the origin, so the
/// half-sizes are the largest |x| and |y| of its vertices.
fn clip_parallelogram(a: Vec2, b: Vec2, rho: f32) -> Bandwidth {
    // Each edge keeps at most its start and one cut, so 4 vertices become at most 8, then
    // 16 (a convex polygon gains one per cut; the bound holds for any input). On the
    // stack: this runs for every probe sample.
    const MAX_VERTICES: usize = 16;
    let mut polygon = [Vec2::ZERO; MAX_VERTICES];
    polygon[..4].copy_from_slice(&[a + b, a - b, -a - b, -a + b]);
    let mut len = 4;
    for sign in [1.0f32, -1.0] {
        // Keep sign·y ≤ ρ.
        let inside = |p: Vec2| sign * p.y <= rho;
        let mut clipped = [Vec2::ZERO; MAX_VERTICES];
        let mut clipped_len = 0;
        for i in 0..len {
            let (p, q) = (polygon[i], polygon[(i + 1) % len]);
            if inside(p) {
                clipped[clipped_len] = p;
                clipped_len += 1;
            }
            if inside(p) != inside(q) {
                let s = (sign * rho - p.y) / (q.y - p.y);
                clipped[clipped_len] = Vec2::new(p.x + s * (q.x - p.x), sign * rho);
                clipped_len += 1;
            }
        }
        polygon = clipped;
        len = clipped_len;
    }
    polygon[..len]
        .iter()
        .fold(Bandwidth::ZERO, |acc, p| Bandwidth {
            spatial_cycles_per_m: acc.spatial_cycles_per_m.max(p.x.abs()),
            angular_cycles_per_rad: acc.angular_cycles_per_rad.max(p.y.abs()),
        })
}

/// c of C_c: the normal curvature along the tangent direction of the flatland plane
/// (Euler: k1 cos²φ + k2 sin²φ, φ measured from `dir1`), 1/m. `direction` is any direction
/// whose projection onto the tangent plane spans that plane (e.g. ω_i); at normal incidence
/// the projection vanishes and the mean curvature (the average over φ) is used.
pub fn normal_curvature(curvature: &Curvature, direction: Vec3A) -> f32 {
    let along1 = direction.dot(curvature.dir1);
    let along2 = direction.dot(curvature.dir2);
    let length_sq = along1 * along1 + along2 * along2;
    if length_sq <= f32::EPSILON * direction.length_squared() {
        return curvature.mean();
    }
    (curvature.k1 * along1 * along1 + curvature.k2 * along2 * along2) / length_sq
}

/// The geometry of one bounce for eqs. 3 and 4.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounce {
    /// c: normal curvature at x along the flatland plane (`normal_curvature`), 1/m.
    pub curvature_per_m: f32,
    /// cos θ_i of P_i, in (0, 1].
    pub cos_theta_i: f32,
    /// cos θ_x of P_x (the outgoing, i.e. view, direction), in (0, 1].
    pub cos_theta_x: f32,
    /// ρ and t of B_{t,ρ}.
    pub material: MaterialBandwidth,
}

impl Bounce {
    fn check(&self) -> Result<(), BandwidthError> {
        if !self.curvature_per_m.is_finite() {
            return Err(BandwidthError::invalid(
                "bounce",
                "curvature_per_m",
                self.curvature_per_m,
                "finite",
            ));
        }
        for (name, cos) in [
            ("cos_theta_i", self.cos_theta_i),
            ("cos_theta_x", self.cos_theta_x),
        ] {
            if !(cos > 0.0 && cos <= 1.0) {
                return Err(BandwidthError::invalid("bounce", name, cos, "in (0, 1]"));
            }
        }
        Ok(())
    }

    /// Run 1 up to B: the bounding box of C_c P_i T_d·rect(ν) ∩ {|Ω_a| ≤ ρ}, plus t.
    fn band_limited(&self, incident: Bandwidth, d_m: f32) -> Bandwidth {
        let mut m1 = curvature_shear(self.curvature_per_m) * project_incident(self.cos_theta_i);
        if d_m.is_finite() {
            m1 *= transport(d_m);
        }
        let clipped = clip_bound(m1, incident, self.material.angular_cycles_per_rad);
        Bandwidth {
            spatial_cycles_per_m: clipped.spatial_cycles_per_m + self.material.texture_cycles_per_m,
            angular_cycles_per_rad: clipped.angular_cycles_per_rad,
        }
    }

    /// The outgoing part of R: P_x C_−c S.
    fn outgoing(&self) -> Mat2 {
        project_outgoing(self.cos_theta_x) * curvature_shear(-self.curvature_per_m) * mirror()
    }

    /// Eq. 3: R ν = P_x C_−c S B_{t,ρ} C_c P_i ν for the light field arriving at x.
    pub fn reflect(&self, incident: Bandwidth) -> Result<Bandwidth, BandwidthError> {
        self.check()?;
        Ok(bound(self.outgoing(), self.band_limited(incident, 0.0)))
    }

    /// Eq. 4: ν^i = T_{d′} R T_d ν_l, for a light at distance d (m; +∞ for a distant light,
    /// which skips T_d) and the eye at d′ (m, finite).
    pub fn one_bounce(
        &self,
        light: Bandwidth,
        light_distance_m: f32,
        eye_distance_m: f32,
    ) -> Result<Bandwidth, BandwidthError> {
        self.check()?;
        if light_distance_m.is_nan() || light_distance_m < 0.0 {
            return Err(BandwidthError::invalid(
                "bounce",
                "light_distance_m",
                light_distance_m,
                "≥ 0 (+∞ for a distant light)",
            ));
        }
        if !(eye_distance_m >= 0.0 && eye_distance_m.is_finite()) {
            return Err(BandwidthError::invalid(
                "bounce",
                "eye_distance_m",
                eye_distance_m,
                "finite, ≥ 0",
            ));
        }
        let m2 = transport(eye_distance_m) * self.outgoing();
        Ok(bound(m2, self.band_limited(light, light_distance_m)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_rng::Rng;

    fn nu(s: f32, a: f32) -> Bandwidth {
        Bandwidth::new(s, a).unwrap()
    }

    fn lambert_sphere(radius_m: f32, cos_i: f32, cos_x: f32) -> Bounce {
        Bounce {
            curvature_per_m: 1.0 / radius_m,
            cos_theta_i: cos_i,
            cos_theta_x: cos_x,
            material: MaterialBandwidth::new(0.0, 0.0).unwrap(),
        }
    }

    #[test]
    fn transport_and_curvature_invert_exactly() {
        for d in [0.0f32, 0.37, 2.5, 40.0] {
            assert_eq!(transport(d) * transport(-d), Mat2::IDENTITY);
            assert_eq!(curvature_shear(d) * curvature_shear(-d), Mat2::IDENTITY);
        }
        assert_eq!(mirror() * mirror(), Mat2::IDENTITY);
        assert_eq!(
            project_incident(0.5) * project_outgoing(0.5),
            Mat2::IDENTITY
        );
    }

    #[test]
    fn the_bound_holds_the_parallelogram_and_touches_it() {
        let mut rng = Rng(0x9e37_79b9);
        for _ in 0..200 {
            let m = rows(
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
            );
            let v = nu(rng.range(0.0, 10.0), rng.range(0.0, 10.0));
            let b = bound(m, v);
            let tol = |x: f32| 1e-5 * (1.0 + x);
            let mut reach = Vec2::ZERO;
            for _ in 0..64 {
                let p = m * Vec2::new(
                    rng.range(-1.0, 1.0) * v.spatial_cycles_per_m,
                    rng.range(-1.0, 1.0) * v.angular_cycles_per_rad,
                );
                assert!(p.x.abs() <= b.spatial_cycles_per_m + tol(b.spatial_cycles_per_m));
                assert!(p.y.abs() <= b.angular_cycles_per_rad + tol(b.angular_cycles_per_rad));
            }
            for (u, w) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let p = m * Vec2::new(u * v.spatial_cycles_per_m, w * v.angular_cycles_per_rad);
                reach = reach.max(p.abs());
            }
            // Touching: some corner reaches each side of the box.
            assert!((reach.x - b.spatial_cycles_per_m).abs() <= tol(b.spatial_cycles_per_m));
            assert!((reach.y - b.angular_cycles_per_rad).abs() <= tol(b.angular_cycles_per_rad));
        }
    }

    #[test]
    fn zero_times_infinity_is_zero() {
        // A point light through no transport: T_0 = I keeps [∞, 0], not [∞, NaN].
        let b = bound(transport(0.0), Bandwidth::POINT_LIGHT);
        assert!(b.spatial_cycles_per_m.is_infinite());
        assert_eq!(b.angular_cycles_per_rad, 0.0);
        // After a distance d the line is sheared into angle: both unbounded.
        let b = bound(transport(2.0), Bandwidth::POINT_LIGHT);
        assert!(b.spatial_cycles_per_m.is_infinite() && b.angular_cycles_per_rad.is_infinite());
    }

    #[test]
    fn the_clip_matches_brute_force_and_never_exceeds_the_bound() {
        let mut rng = Rng(12345);
        for _ in 0..100 {
            let m = rows(
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
            );
            let v = nu(rng.range(0.1, 10.0), rng.range(0.1, 10.0));
            let rho = rng.range(0.0, 20.0);
            let c = clip_bound(m, v, rho);
            let b = bound(m, v);
            assert!(c.spatial_cycles_per_m <= b.spatial_cycles_per_m * (1.0 + 1e-6));
            assert!(c.angular_cycles_per_rad <= rho.min(b.angular_cycles_per_rad) + 1e-6);
            // Brute force over a 401×401 grid of the rectangle.
            let mut best = Vec2::ZERO;
            let n = 400;
            for i in 0..=n {
                for j in 0..=n {
                    let u = 2.0 * i as f32 / n as f32 - 1.0;
                    let w = 2.0 * j as f32 / n as f32 - 1.0;
                    let p = m * Vec2::new(u * v.spatial_cycles_per_m, w * v.angular_cycles_per_rad);
                    if p.y.abs() <= rho {
                        best = best.max(p.abs());
                    }
                }
            }
            let scale = b.spatial_cycles_per_m.max(b.angular_cycles_per_rad);
            assert!(best.x <= c.spatial_cycles_per_m + 1e-4 * scale);
            assert!(
                c.spatial_cycles_per_m - best.x <= 0.02 * scale,
                "clip {c:?} brute {best} m {m} v {v:?} rho {rho}"
            );
            assert!(c.angular_cycles_per_rad - best.y <= 0.02 * scale);
        }
    }

    #[test]
    fn lambert_kills_the_angular_bandwidth() {
        for incident in [
            nu(5.0, 3.0),
            nu(0.0, 40.0),
            Bandwidth::POINT_LIGHT,
            nu(f32::INFINITY, f32::INFINITY),
        ] {
            let r = lambert_sphere(0.5, 0.8, 0.6).reflect(incident).unwrap();
            assert_eq!(r.angular_cycles_per_rad, 0.0, "{incident:?} → {r:?}");
        }
    }

    #[test]
    fn a_point_light_on_a_curved_diffuse_surface_stays_smooth() {
        let bounce = lambert_sphere(0.5, 0.8, 0.6);
        let nu_i = bounce.one_bounce(Bandwidth::POINT_LIGHT, 3.0, 4.0).unwrap();
        assert_eq!(nu_i, Bandwidth::ZERO);
        // Bounding before clipping (|C_c P_i T_d| ν_l, then min(ρ, ·)) loses it.
        let m1 = curvature_shear(2.0) * project_incident(0.8) * transport(3.0);
        let early = bound(m1, Bandwidth::POINT_LIGHT);
        assert!(early.spatial_cycles_per_m.is_infinite());
        // A textured diffuse surface shows its texture: ν_s = t/cos θ_x, ν_a = d′ν_s.
        let textured = Bounce {
            material: MaterialBandwidth::new(0.0, 30.0).unwrap(),
            ..bounce
        };
        let nu_t = textured
            .one_bounce(Bandwidth::POINT_LIGHT, 3.0, 4.0)
            .unwrap();
        assert!((nu_t.spatial_cycles_per_m - 50.0).abs() < 1e-4, "{nu_t:?}");
        assert!(
            (nu_t.angular_cycles_per_rad - 200.0).abs() < 1e-3,
            "{nu_t:?}"
        );
    }

    #[test]
    fn a_point_light_seen_in_a_glossy_lobe_is_finite_and_grows_with_rho() {
        // A point light at d on a flat glossy surface: the line (cos θ_i, −d)·s is cut at
        // |Ω_a| ≤ ρ, so ν_s = ρ cos θ_i / d before run 2.
        let flat = |rho: f32| Bounce {
            curvature_per_m: 0.0,
            cos_theta_i: 0.5,
            cos_theta_x: 1.0,
            material: MaterialBandwidth::new(rho, 0.0).unwrap(),
        };
        let r = flat(8.0).reflect(Bandwidth::POINT_LIGHT).unwrap();
        // At x (d = 0) the line is horizontal: unbounded in space, no angle.
        assert!(r.spatial_cycles_per_m.is_infinite());
        assert_eq!(r.angular_cycles_per_rad, 0.0);
        let a = flat(8.0)
            .one_bounce(Bandwidth::POINT_LIGHT, 2.0, 1.0)
            .unwrap();
        let b = flat(16.0)
            .one_bounce(Bandwidth::POINT_LIGHT, 2.0, 1.0)
            .unwrap();
        // Run 1: (ρ·cos θ_i/d, ρ) = (2, 8); run 2 with d′ = 1: (2 + 0, 2·1 + 8) = (2, 10).
        assert!((a.spatial_cycles_per_m - 2.0).abs() < 1e-5, "{a:?}");
        assert!((a.angular_cycles_per_rad - 10.0).abs() < 1e-5, "{a:?}");
        assert!(b.spatial_cycles_per_m > a.spatial_cycles_per_m);
    }

    #[test]
    fn a_distant_light_skips_transport_and_a_mirror_passes_everything() {
        let mirror_flat = Bounce {
            curvature_per_m: 0.0,
            cos_theta_i: 1.0,
            cos_theta_x: 1.0,
            material: MaterialBandwidth::new(f32::INFINITY, 0.0).unwrap(),
        };
        let env = nu(0.0, 5.0);
        // Flat mirror, eye at d′: the environment's angular content reaches the eye as is,
        // plus the spatial shear d′·ν_s = 0.
        let r = mirror_flat.one_bounce(env, f32::INFINITY, 3.0).unwrap();
        assert_eq!(r, nu(0.0, 5.0));
        // A curved mirror (c = 2/m): run 1 C_c: (c·ν_a, ν_a) = (10, 5); run 2 C_−c S then
        // T_d′: (10 + 2·5, 3·20 + 5) = (20, 65) — eq. 4's ν_env(1 + 2d′c) in angle.
        let curved = Bounce {
            curvature_per_m: 2.0,
            ..mirror_flat
        };
        let r = curved.one_bounce(env, f32::INFINITY, 3.0).unwrap();
        assert!((r.spatial_cycles_per_m - 20.0).abs() < 1e-4, "{r:?}");
        assert!(
            (r.angular_cycles_per_rad - 5.0 * (1.0 + 2.0 * 3.0 * 2.0)).abs() < 1e-3,
            "{r:?}"
        );
    }

    #[test]
    fn normal_curvature_follows_euler() {
        let c = Curvature {
            k1: 4.0,
            k2: 1.0,
            dir1: Vec3A::X,
            dir2: Vec3A::Y,
        };
        assert_eq!(normal_curvature(&c, Vec3A::new(1.0, 0.0, 0.3)), 4.0);
        assert_eq!(normal_curvature(&c, Vec3A::new(0.0, -2.0, 0.3)), 1.0);
        let diagonal = normal_curvature(&c, Vec3A::new(1.0, 1.0, 5.0));
        assert!((diagonal - 2.5).abs() < 1e-6);
        // Normal incidence: the mean.
        assert_eq!(normal_curvature(&c, Vec3A::Z), 2.5);
    }

    #[test]
    fn invalid_geometry_is_rejected_by_name() {
        let mut b = lambert_sphere(1.0, 0.0, 1.0);
        let e = b.reflect(Bandwidth::ZERO).unwrap_err().to_string();
        assert!(e.contains("cos_theta_i"), "{e}");
        b.cos_theta_i = 1.0;
        let e = b
            .one_bounce(Bandwidth::ZERO, -1.0, 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("light_distance_m"), "{e}");
        let e = b
            .one_bounce(Bandwidth::ZERO, 1.0, f32::INFINITY)
            .unwrap_err()
            .to_string();
        assert!(e.contains("eye_distance_m"), "{e}");
    }
}
