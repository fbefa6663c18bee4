//! Connecting a light subpath prefix of s vertices with a camera subpath prefix of t
//! vertices (Veach 1997 §10.2; pbrt-v3 §16.3.3 `ConnectBDPT`), and the multiple importance
//! sampling weight of that strategy against all others that make a path of the same
//! length (§10.2.1, pbrt-v3 §16.3.4 `MISWeight`, here with the balance or power heuristic).

use glam::Vec2;
use prism_geometry::Ray;
use prism_scene::MisHeuristic;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::vertex::{BdptVertex, Subpath};
use crate::bsdf::TransportMode;
use crate::integrator::{PathCounters, PathTracer};
use crate::light::LightSample;
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;

/// The contribution of one strategy: radiance (camera side) or a splat at a film point
/// (t = 1), with its MIS weight applied and its weight for diagnostics.
#[derive(Clone, Copy, Debug)]
pub struct Connection {
    /// Unweighted contribution C*(s, t).
    pub unweighted: SampledSpectrum,
    /// MIS weight w(s, t).
    pub weight: f32,
    /// Where a t = 1 connection lands on the film, px.
    pub film_point_px: Option<Vec2>,
}

/// Variates of a connection: the light choice and light point for s = 1, the lens point
/// for t = 1.
#[derive(Clone, Copy, Debug)]
pub struct ConnectionVariates {
    pub u_light_choice: f32,
    pub u_light: Vec2,
    pub u_lens: Vec2,
}

/// Transmittance of the segment between two vertices: 0 or 1, or through opacity masks and
/// panes exactly (`PathTracer::segment_transmittance`).
fn visibility(
    scene: &RenderScene,
    tracer: &PathTracer,
    a: &BdptVertex,
    b: &BdptVertex,
    wavelengths: &SampledWavelengths,
    counters: &mut PathCounters,
) -> SampledSpectrum {
    counters.rays += 1;
    let (from, to) = (a.p, b.p);
    if b.is_infinite_light() || a.is_infinite_light() {
        let (p, d) = if b.is_infinite_light() {
            (from, (to - from).normalize())
        } else {
            (to, (from - to).normalize())
        };
        return tracer.segment_transmittance(scene, Ray::spawn(p, d), d, wavelengths, counters);
    }
    let d = to - from;
    let len = d.length();
    if len == 0.0 {
        return SampledSpectrum::splat(0.0);
    }
    tracer.segment_transmittance(
        scene,
        Ray::spawn_to(from, to),
        d / len,
        wavelengths,
        counters,
    )
}

/// The geometry term of a connection between two scattering vertices: visibility over
/// the squared distance. The cosines of pbrt-v3's `G` are already in each vertex's
/// `BdptVertex::f` (f·|cos θ| at surfaces; a phase function has none).
fn inverse_square_with_visibility(
    scene: &RenderScene,
    tracer: &PathTracer,
    a: &BdptVertex,
    b: &BdptVertex,
    wavelengths: &SampledWavelengths,
    counters: &mut PathCounters,
) -> SampledSpectrum {
    let d2 = (a.p - b.p).length_squared();
    if d2 == 0.0 {
        return SampledSpectrum::splat(0.0);
    }
    visibility(scene, tracer, a, b, wavelengths, counters) * (1.0 / d2)
}

/// Strategy (s, t) of the two subpaths, MIS-weighted with `mis` (weight 1 for `None`).
/// `None` when the strategy cannot contribute.
#[allow(clippy::too_many_arguments)]
pub fn connect(
    scene: &RenderScene,
    tracer: &PathTracer,
    mis: Option<MisHeuristic>,
    light: &mut Subpath,
    camera: &mut Subpath,
    s: usize,
    t: usize,
    variates: &ConnectionVariates,
    wavelengths: &SampledWavelengths,
    le_cache: &mut SpectrumCache,
    counters: &mut PathCounters,
) -> Option<Connection> {
    let lights = &scene.lights;
    // A camera path that escaped cannot be connected to (its last vertex is at infinity).
    if t > 1 && s != 0 && camera.vertices[t - 1].is_infinite_light() {
        return None;
    }
    let mut sampled: Option<BdptVertex> = None;
    let mut film_point_px = None;
    let l: SampledSpectrum = if s == 0 {
        // The camera path ends on a light.
        let pt = &camera.vertices[t - 1];
        if !pt.is_light() {
            return None;
        }
        pt.le(
            scene,
            &camera.surfaces,
            &camera.vertices[t - 2],
            wavelengths,
        ) * pt.beta
    } else if t == 1 {
        // Connect a light-path vertex to a point on the lens.
        let qs = &light.vertices[s - 1];
        if !qs.scatters() || !qs.is_connectible(lights, &light.surfaces) {
            return None;
        }
        let cs = scene.camera.sample_wi(qs.p, variates.u_lens)?;
        if cs.pdf_per_sr <= 0.0 || cs.importance <= 0.0 {
            return None;
        }
        let camera_vertex = BdptVertex::camera(
            cs.p_lens_m,
            cs.n_lens,
            SampledSpectrum::splat(cs.importance / cs.pdf_per_sr),
        );
        let c = qs.beta
            * qs.f(&light.surfaces, &camera_vertex, TransportMode::Importance)
            * camera_vertex.beta;
        if c.is_black() {
            return None;
        }
        let c = c * visibility(scene, tracer, qs, &camera_vertex, wavelengths, counters);
        film_point_px = Some(cs.film_point_px);
        sampled = Some(camera_vertex);
        c
    } else if s == 1 {
        // Sample a point on a light and connect the camera path to it.
        let pt = &camera.vertices[t - 1];
        if !pt.scatters() || !pt.is_connectible(lights, &camera.surfaces) {
            return None;
        }
        let (index, pmf) = lights.sample(variates.u_light_choice)?;
        let light_source = lights.light(index);
        let ls: LightSample = light_source.sample_li_cached(
            lights.emission_key(index),
            &pt.light_context(),
            variates.u_light,
            wavelengths,
            le_cache,
        )?;
        if ls.pdf <= 0.0 || ls.radiance.is_black() {
            return None;
        }
        let beta = ls.radiance * (1.0 / (ls.pdf * pmf));
        let mut light_vertex = if light_source.is_infinite() {
            BdptVertex::infinite_light(Some(index), ls.p_light, beta, 0.0)
        } else {
            BdptVertex::light(index, ls.p_light, ls.n_light, beta, 0.0)
        };
        light_vertex.pdf_fwd = light_vertex.pdf_light_origin(scene, pt);
        let c = pt.beta
            * pt.f(&camera.surfaces, &light_vertex, TransportMode::Radiance)
            * light_vertex.beta;
        if c.is_black() {
            return None;
        }
        let c = c * visibility(scene, tracer, pt, &light_vertex, wavelengths, counters);
        sampled = Some(light_vertex);
        c
    } else {
        // Connect the two subpaths' end vertices.
        let (qs, pt) = (&light.vertices[s - 1], &camera.vertices[t - 1]);
        if !qs.scatters()
            || !pt.scatters()
            || !qs.is_connectible(lights, &light.surfaces)
            || !pt.is_connectible(lights, &camera.surfaces)
        {
            return None;
        }
        let c = qs.beta
            * qs.f(&light.surfaces, pt, TransportMode::Importance)
            * pt.f(&camera.surfaces, qs, TransportMode::Radiance)
            * pt.beta;
        if c.is_black() {
            return None;
        }
        c * inverse_square_with_visibility(scene, tracer, qs, pt, wavelengths, counters)
    };
    if l.is_black() || l.has_non_finite() {
        if l.has_non_finite() {
            counters.non_finite_contributions += 1;
        }
        return None;
    }
    // Without a heuristic (light tracing: one strategy) the weight is 1.
    let weight = match mis {
        Some(mis) => mis_weight(scene, mis, light, camera, sampled, s, t),
        None => 1.0,
    };
    Some(Connection {
        unweighted: l,
        weight,
        film_point_px,
    })
}

fn remap0(x: f32) -> f32 {
    if x != 0.0 {
        x
    } else {
        1.0
    }
}

/// The MIS weight of strategy (s, t) (pbrt-v3 §16.3.4): the densities of the connection's
/// vertices under the other strategies are filled in, then the ratios r_i = p_i / p_s
/// accumulate outwards along both subpaths; w = 1 / (1 + Σ r_i^β) with β = 1 (balance) or
/// 2 (power, Veach 1997 eq. 9.13). The subpaths are restored before it returns: only the
/// fields it overwrites are saved (pbrt-v3's `ScopedAssignment`s), a vertex is ~160 bytes.
fn mis_weight(
    scene: &RenderScene,
    mis: MisHeuristic,
    light: &mut Subpath,
    camera: &mut Subpath,
    sampled: Option<BdptVertex>,
    s: usize,
    t: usize,
) -> f32 {
    if s + t == 2 {
        return 1.0;
    }
    // (pdf_rev, delta) of the camera's last two and the light's last two vertices.
    let field = |v: &BdptVertex| (v.pdf_rev, v.delta);
    let camera_end = field(&camera.vertices[t - 1]);
    let camera_before_end = (t > 1).then(|| field(&camera.vertices[t - 2]));
    let light_end = (s > 0).then(|| field(&light.vertices[s - 1]));
    let light_before_end = (s > 1).then(|| field(&light.vertices[s - 2]));
    // The strategy's own sampled vertex replaces the subpath's first.
    let replaced = if s == 1 {
        let first = light.vertices[0];
        light.vertices[0] = sampled.expect("s = 1 samples a light vertex");
        Some((true, first))
    } else if t == 1 {
        let first = camera.vertices[0];
        camera.vertices[0] = sampled.expect("t = 1 samples a camera vertex");
        Some((false, first))
    } else {
        None
    };
    let w = mis_weight_in_place(scene, mis, light, camera, s, t);
    match replaced {
        Some((true, first)) => light.vertices[0] = first,
        Some((false, first)) => camera.vertices[0] = first,
        None => {}
    }
    let put = |v: &mut BdptVertex, (pdf_rev, delta): (f32, bool)| {
        v.pdf_rev = pdf_rev;
        v.delta = delta;
    };
    // The saved fields are the original vertices' (saved before the replacement), so
    // putting them back is right for a restored index 0 too.
    put(&mut camera.vertices[t - 1], camera_end);
    if let Some(f) = camera_before_end {
        put(&mut camera.vertices[t - 2], f);
    }
    if let Some(f) = light_end {
        put(&mut light.vertices[s - 1], f);
    }
    if let Some(f) = light_before_end {
        put(&mut light.vertices[s - 2], f);
    }
    w
}

fn mis_weight_in_place(
    scene: &RenderScene,
    mis: MisHeuristic,
    light: &mut Subpath,
    camera: &mut Subpath,
    s: usize,
    t: usize,
) -> f32 {
    let power = |r: f32| match mis {
        MisHeuristic::Balance => r,
        MisHeuristic::Power => r * r,
    };
    // The connection vertices are not Dirac under this strategy.
    camera.vertices[t - 1].delta = false;
    if s > 0 {
        light.vertices[s - 1].delta = false;
    }
    let pt = camera.vertices[t - 1];
    let pt_minus = (t > 1).then(|| camera.vertices[t - 2]);
    let qs = (s > 0).then(|| light.vertices[s - 1]);
    let qs_minus = (s > 1).then(|| light.vertices[s - 2]);
    // pt's density under the light side's sampling.
    camera.vertices[t - 1].pdf_rev = match &qs {
        Some(qs) => qs.pdf(
            scene,
            &light.surfaces,
            qs_minus.as_ref(),
            &pt,
            TransportMode::Importance,
        ),
        None => pt_minus
            .as_ref()
            .map_or(0.0, |pm| pt.pdf_light_origin(scene, pm)),
    };
    // pt−1's density under the light side's sampling (through pt).
    if let Some(pm) = &pt_minus {
        camera.vertices[t - 2].pdf_rev = match &qs {
            Some(qs) => pt.pdf(
                scene,
                &camera.surfaces,
                Some(qs),
                pm,
                TransportMode::Radiance,
            ),
            None => pt.pdf_light(scene, pm),
        };
    }
    // qs's and qs−1's densities under the camera side's sampling.
    if let Some(qs) = &qs {
        light.vertices[s - 1].pdf_rev = pt.pdf(
            scene,
            &camera.surfaces,
            pt_minus.as_ref(),
            qs,
            TransportMode::Radiance,
        );
        if let Some(qm) = &qs_minus {
            light.vertices[s - 2].pdf_rev = qs.pdf(
                scene,
                &light.surfaces,
                Some(&pt),
                qm,
                TransportMode::Importance,
            );
        }
    }
    let mut sum_ri = 0.0f32;
    let mut ri = 1.0f32;
    for i in (1..t).rev() {
        let v = &camera.vertices[i];
        ri *= remap0(v.pdf_rev) / remap0(v.pdf_fwd);
        if !v.delta && !camera.vertices[i - 1].delta {
            sum_ri += power(ri);
        }
    }
    ri = 1.0;
    for i in (0..s).rev() {
        let v = &light.vertices[i];
        ri *= remap0(v.pdf_rev) / remap0(v.pdf_fwd);
        let delta_light_vertex = if i > 0 {
            light.vertices[i - 1].delta
        } else {
            light.vertices[0].is_delta_light(&scene.lights)
        };
        if !v.delta && !delta_light_vertex {
            sum_ri += power(ri);
        }
    }
    let w = 1.0 / (1.0 + sum_ri);
    if w.is_finite() {
        w
    } else {
        0.0
    }
}
