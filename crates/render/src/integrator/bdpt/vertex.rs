//! A subpath vertex of bidirectional path tracing (Veach 1997 §10.2; pbrt-v3 §16.3
//! `Vertex`, whose structure this follows): the camera, a light, or a scattering point, with
//! the throughput β of the subpath up to it and the densities the MIS weights need — each
//! vertex's forward density (of being sampled by its own subpath) and reverse density (of
//! being sampled by the other subpath), both per unit area (per unit solid angle for
//! vertices at infinity).

use glam::Vec3A;
use prism_geometry::{Frame, Ray, SurfaceInteraction};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use crate::bsdf::{Bsdf, TransportMode};
use crate::integrator::scatter_vertex::{MediumVertex, ScatterVertex, SurfaceVertex};
use crate::light::{LightHit, LightSampleContext, LightSet, NO_LIGHT};
use crate::scene_build::RenderScene;

/// What a vertex is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VertexKind {
    /// The camera: a point on the lens.
    Camera,
    /// A point on a light (light subpaths' first vertex, or the light sampled by s = 1).
    /// `index` is the light's index in the `LightSet`.
    Light { index: u32 },
    /// A direction to the infinite lights (a camera subpath that escaped, or the light
    /// vertex of an infinite light): its `p` is a point along the direction and its
    /// densities are per unit solid angle / per unit area of the scene's disk.
    InfiniteLight { index: Option<u32> },
    /// A surface that scatters (it may also emit: `emitter`); its BSDF and frame are entry
    /// `scatter` of the subpath's `Subpath::surfaces`, so that vertices stay small to copy.
    Surface {
        scatter: u32,
        /// Index of the area light this surface carries, or `NO_LIGHT`.
        emitter: u32,
    },
    /// A medium point.
    Medium(MediumVertex<'static>),
}

/// A surface vertex's scattering data (the heavy part: the hit and its BSDF).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceScatter<'a> {
    pub si: SurfaceInteraction,
    pub bsdf: Bsdf<'a>,
    pub frame: Frame,
    /// Unit direction back along the arriving ray (world).
    pub wo: Vec3A,
    pub check_sides: bool,
    /// `wo` in the shading frame and ωo·n_geometric, computed once (every connection views
    /// the vertex from `wo`).
    wo_local: Vec3A,
    wo_dot_ng: f32,
}

impl<'a> SurfaceScatter<'a> {
    pub fn new(
        si: SurfaceInteraction,
        bsdf: Bsdf<'a>,
        ray_direction: Vec3A,
        check_sides: bool,
    ) -> Self {
        let frame = Frame::from_zx(si.n_shading, si.dpdu);
        let wo = -ray_direction;
        Self {
            frame,
            wo_local: frame.to_local(wo),
            wo_dot_ng: wo.dot(si.n_geometric),
            si,
            bsdf,
            wo,
            check_sides,
        }
    }

    /// The vertex as the transport core's `ScatterVertex`, seen from `wo` (unit, world,
    /// pointing away from the surface).
    #[inline]
    pub fn seen_from(&self, wo: Vec3A) -> ScatterVertex<'_> {
        ScatterVertex::Surface(SurfaceVertex {
            si: &self.si,
            bsdf: &self.bsdf,
            frame: self.frame,
            wo_local: self.frame.to_local(wo),
            check_sides: self.check_sides,
            wo_dot_ng: wo.dot(self.si.n_geometric),
        })
    }

    /// The vertex seen from the direction it was reached from.
    #[inline]
    pub fn scatter_vertex(&self) -> ScatterVertex<'_> {
        ScatterVertex::Surface(SurfaceVertex {
            si: &self.si,
            bsdf: &self.bsdf,
            frame: self.frame,
            wo_local: self.wo_local,
            check_sides: self.check_sides,
            wo_dot_ng: self.wo_dot_ng,
        })
    }
}

/// A subpath: its vertices, and the scattering data of its surface vertices.
#[derive(Clone, Debug, Default)]
pub struct Subpath<'a> {
    pub vertices: Vec<BdptVertex>,
    pub surfaces: Vec<SurfaceScatter<'a>>,
}

impl<'a> Subpath<'a> {
    pub fn clear(&mut self) {
        self.vertices.clear();
        self.surfaces.clear();
    }

    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// Appends a surface vertex.
    pub fn push_surface(
        &mut self,
        scatter: SurfaceScatter<'a>,
        emitter: u32,
        beta: SampledSpectrum,
    ) {
        let si = scatter.si;
        self.vertices.push(BdptVertex {
            kind: VertexKind::Surface {
                scatter: self.surfaces.len() as u32,
                emitter,
            },
            p: si.p,
            n_geometric: si.n_geometric,
            n_shading: si.n_shading,
            beta,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
        });
        self.surfaces.push(scatter);
    }

    /// Removes the last vertex (a surface added by `push_surface`, or any other).
    pub fn pop(&mut self) {
        if let Some(BdptVertex {
            kind: VertexKind::Surface { .. },
            ..
        }) = self.vertices.pop()
        {
            self.surfaces.pop();
        }
    }
}

/// One vertex of a subpath.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BdptVertex {
    pub kind: VertexKind,
    /// Position, metres (world).
    pub p: Vec3A,
    /// Geometric normal (unit) for points on a surface (lights too), else zero.
    pub n_geometric: Vec3A,
    /// Shading normal (unit) for surfaces, `n_geometric` for lights, else zero.
    pub n_shading: Vec3A,
    /// Throughput of the subpath up to and including this vertex.
    pub beta: SampledSpectrum,
    /// The vertex scattered with a Dirac lobe (no connection can reach it).
    pub delta: bool,
    /// Density of this vertex under its own subpath's sampling.
    pub pdf_fwd: f32,
    /// Density of this vertex under the other subpath's sampling.
    pub pdf_rev: f32,
}

impl BdptVertex {
    pub fn camera(p: Vec3A, n: Vec3A, beta: SampledSpectrum) -> Self {
        Self {
            kind: VertexKind::Camera,
            p,
            n_geometric: Vec3A::ZERO,
            n_shading: n,
            beta,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
        }
    }

    pub fn light(index: u32, p: Vec3A, n: Vec3A, beta: SampledSpectrum, pdf_fwd: f32) -> Self {
        Self {
            kind: VertexKind::Light { index },
            p,
            n_geometric: n,
            n_shading: n,
            beta,
            delta: false,
            pdf_fwd,
            pdf_rev: 0.0,
        }
    }

    pub fn infinite_light(
        index: Option<u32>,
        p: Vec3A,
        beta: SampledSpectrum,
        pdf_fwd: f32,
    ) -> Self {
        Self {
            kind: VertexKind::InfiniteLight { index },
            p,
            n_geometric: Vec3A::ZERO,
            n_shading: Vec3A::ZERO,
            beta,
            delta: false,
            pdf_fwd,
            pdf_rev: 0.0,
        }
    }

    pub fn is_on_surface(&self) -> bool {
        self.n_geometric != Vec3A::ZERO
    }

    /// A light, or a surface that emits (what an s = 0 strategy ends on).
    pub fn is_light(&self) -> bool {
        match self.kind {
            VertexKind::Light { .. } | VertexKind::InfiniteLight { .. } => true,
            VertexKind::Surface { emitter, .. } => emitter != NO_LIGHT,
            VertexKind::Camera | VertexKind::Medium(_) => false,
        }
    }

    pub fn is_infinite_light(&self) -> bool {
        match self.kind {
            VertexKind::InfiniteLight { .. } => true,
            VertexKind::Light { .. }
            | VertexKind::Camera
            | VertexKind::Surface { .. }
            | VertexKind::Medium(_) => false,
        }
    }

    /// A light vertex whose position or direction is a Dirac (point, spot, goniometric,
    /// ideal directional): no path can hit it.
    pub fn is_delta_light(&self, lights: &LightSet) -> bool {
        match self.kind {
            VertexKind::Light { index } | VertexKind::InfiniteLight { index: Some(index) } => {
                lights.light(index).is_delta()
            }
            VertexKind::InfiniteLight { index: None }
            | VertexKind::Camera
            | VertexKind::Surface { .. }
            | VertexKind::Medium(_) => false,
        }
    }

    /// Can a deterministic connection reach this vertex? (Not a Dirac scatterer, not a
    /// light at infinity of Dirac direction.)
    pub fn is_connectible(&self, lights: &LightSet, surfaces: &[SurfaceScatter]) -> bool {
        match self.kind {
            VertexKind::Medium(_) | VertexKind::Camera => true,
            VertexKind::Light { index } => !lights.light(index).is_delta_direction(),
            VertexKind::InfiniteLight { .. } => false,
            VertexKind::Surface { scatter, .. } => !surfaces[scatter as usize].bsdf.is_specular(),
        }
    }

    /// True for vertices that scatter (surfaces and media).
    pub fn scatters(&self) -> bool {
        match self.kind {
            VertexKind::Surface { .. } | VertexKind::Medium(_) => true,
            VertexKind::Camera | VertexKind::Light { .. } | VertexKind::InfiniteLight { .. } => {
                false
            }
        }
    }

    /// f_s from this vertex towards `next` (surfaces: f·|cos θ_shading|, with the shading
    /// normal correction of the adjoint for importance transport, Veach 1997 §5.3.2; media:
    /// the phase function). Zero for cameras and lights (their terms are in β).
    pub fn f(
        &self,
        surfaces: &[SurfaceScatter],
        next: &BdptVertex,
        mode: TransportMode,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::splat(0.0);
        let w = next.p - self.p;
        if w.length_squared() == 0.0 {
            return zero;
        }
        let wi = w.normalize();
        match &self.kind {
            VertexKind::Surface { scatter, .. } => {
                let scatter = &surfaces[*scatter as usize];
                let v = scatter.scatter_vertex();
                let Some(eval) = v.eval(wi, mode) else {
                    return zero;
                };
                eval.f_cos * shading_normal_correction(&scatter.si, scatter.wo, wi, mode)
            }
            VertexKind::Medium(m) => SampledSpectrum::splat(m.phase.eval(m.wo, wi)),
            VertexKind::Camera | VertexKind::Light { .. } | VertexKind::InfiniteLight { .. } => {
                zero
            }
        }
    }

    /// Converts a solid-angle density at this vertex of sampling the direction to `next`
    /// into an area density at `next` (pbrt-v3 `Vertex::ConvertDensity`).
    pub fn convert_density(&self, pdf: f32, next: &BdptVertex) -> f32 {
        if next.is_infinite_light() {
            return pdf;
        }
        let w = next.p - self.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        convert_with(pdf, d2, w / d2.sqrt(), next)
    }

    /// Area density with which this vertex's subpath samples `next` given `prev` (pbrt-v3
    /// `Vertex::Pdf`): the camera's directional density, a BSDF's or phase function's, or a
    /// light's emission density.
    pub fn pdf(
        &self,
        scene: &RenderScene,
        surfaces: &[SurfaceScatter],
        prev: Option<&BdptVertex>,
        next: &BdptVertex,
        mode: TransportMode,
    ) -> f32 {
        let w = next.p - self.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let wn = w * (1.0 / d2.sqrt());
        let pdf = match &self.kind {
            VertexKind::Light { .. } | VertexKind::InfiniteLight { .. } => {
                return self.pdf_light(scene, next);
            }
            VertexKind::Camera => scene
                .camera
                .pdf_we(&Ray::infinite(self.p, wn))
                .map_or(0.0, |(_, pdf_dir)| pdf_dir),
            VertexKind::Surface { scatter, .. } => {
                let Some(prev) = prev else {
                    return 0.0;
                };
                // Measured from `prev`, which may belong to the other subpath: the vertex
                // as if it had been reached from there.
                let arriving = self.p - prev.p;
                if arriving.length_squared() == 0.0 {
                    return 0.0;
                }
                surfaces[*scatter as usize]
                    .seen_from(-arriving.normalize())
                    .pdf_toward(wn, mode)
            }
            VertexKind::Medium(m) => match prev {
                Some(prev) if prev.p != self.p => m.phase.pdf((prev.p - self.p).normalize(), wn),
                Some(_) | None => 0.0,
            },
        };
        if next.is_infinite_light() {
            pdf
        } else {
            convert_with(pdf, d2, wn, next)
        }
    }

    /// Density with which this light vertex emits towards `v`, per unit area at `v` (per
    /// unit area of the scene disk for infinite lights; pbrt-v3 `Vertex::PdfLight`).
    pub fn pdf_light(&self, scene: &RenderScene, v: &BdptVertex) -> f32 {
        let w = v.p - self.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let w = w / d2.sqrt();
        let sphere = scene.lights.scene_sphere();
        let mut pdf = match self.kind {
            VertexKind::InfiniteLight { .. } => {
                1.0 / (std::f32::consts::PI * sphere.radius_m * sphere.radius_m)
            }
            VertexKind::Light { index } => {
                let (_, pdf_dir) =
                    scene
                        .lights
                        .light(index)
                        .pdf_le(sphere, self.p, self.n_geometric, w);
                pdf_dir / d2
            }
            VertexKind::Surface { emitter, .. } if emitter != NO_LIGHT => {
                let (_, pdf_dir) =
                    scene
                        .lights
                        .light(emitter)
                        .pdf_le(sphere, self.p, self.n_geometric, w);
                pdf_dir / d2
            }
            VertexKind::Surface { .. } | VertexKind::Camera | VertexKind::Medium(_) => 0.0,
        };
        if v.is_on_surface() {
            pdf *= v.n_geometric.dot(w).abs();
        }
        pdf
    }

    /// Density of this light vertex as the origin of a light subpath (light choice ×
    /// position density; for infinite lights the directional density of all of them
    /// towards `v`; pbrt-v3 `Vertex::PdfLightOrigin`).
    pub fn pdf_light_origin(&self, scene: &RenderScene, v: &BdptVertex) -> f32 {
        let w = v.p - self.p;
        if w.length_squared() == 0.0 {
            return 0.0;
        }
        let w = w.normalize();
        let lights = &scene.lights;
        let sphere = lights.scene_sphere();
        match self.kind {
            VertexKind::InfiniteLight { .. } => infinite_light_density(lights, w),
            VertexKind::Light { index } => {
                let (pdf_pos, _) = lights
                    .light(index)
                    .pdf_le(sphere, self.p, self.n_geometric, w);
                lights.pmf(index) * pdf_pos
            }
            VertexKind::Surface { emitter, .. } if emitter != NO_LIGHT => {
                let (pdf_pos, _) =
                    lights
                        .light(emitter)
                        .pdf_le(sphere, self.p, self.n_geometric, w);
                lights.pmf(emitter) * pdf_pos
            }
            VertexKind::Surface { .. } | VertexKind::Camera | VertexKind::Medium(_) => 0.0,
        }
    }

    /// Radiance this light vertex (an emitter hit, or the infinite lights of an escaped
    /// ray) sends towards `v`.
    pub fn le(
        &self,
        scene: &RenderScene,
        surfaces: &[SurfaceScatter],
        v: &BdptVertex,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::splat(0.0);
        let w = v.p - self.p;
        if w.length_squared() == 0.0 {
            return zero;
        }
        let w = w.normalize();
        let lights = &scene.lights;
        match &self.kind {
            VertexKind::InfiniteLight { .. } => {
                // The escaped ray travelled along −w.
                let mut le = zero;
                for &l in lights.infinite_lights() {
                    le += lights.light(l).infinite_radiance(-w, wavelengths);
                }
                le
            }
            VertexKind::Surface { scatter, emitter } if *emitter != NO_LIGHT => {
                let hit = LightHit {
                    p: self.p,
                    n: self.n_geometric,
                    uv: surfaces[*scatter as usize].si.uv,
                    distance_m: w.length(),
                };
                lights
                    .light(*emitter)
                    .emitted_radiance(&hit, w, wavelengths)
            }
            VertexKind::Surface { .. }
            | VertexKind::Light { .. }
            | VertexKind::Camera
            | VertexKind::Medium(_) => zero,
        }
    }

    /// The reference point for light sampling at this vertex.
    pub fn light_context(&self) -> LightSampleContext {
        LightSampleContext {
            p: self.p,
            n: self.n_geometric,
        }
    }
}

/// A solid-angle density along unit `w` over squared distance `d2` as an area density at
/// `next` (pbrt-v3 `ConvertDensity`'s arithmetic).
#[inline(always)]
fn convert_with(pdf: f32, d2: f32, w: Vec3A, next: &BdptVertex) -> f32 {
    let mut pdf = pdf / d2;
    if next.is_on_surface() {
        pdf *= next.n_geometric.dot(w).abs();
    }
    pdf
}

/// Σ over the infinite lights of pmf(l) · pdf_li(−w): the density with which a light
/// subpath leaves the infinite lights along the travel direction `w` (pbrt-v3
/// `InfiniteLightDensity`).
pub fn infinite_light_density(lights: &LightSet, w: Vec3A) -> f32 {
    let ctx = LightSampleContext {
        p: Vec3A::ZERO,
        n: Vec3A::ZERO,
    };
    lights
        .infinite_lights()
        .iter()
        .map(|&l| lights.pmf(l) * lights.light(l).pdf_li(&ctx, -w, None))
        .sum()
}

/// The adjoint BSDF's correction for shading normals (Veach 1997 §5.3.2, eq. 5.19; pbrt-v3
/// `CorrectShadingNormal`): |ωo·ns| |ωi·ng| / (|ωo·ng| |ωi·ns|) for importance transport,
/// 1 for radiance.
#[inline]
pub fn shading_normal_correction(
    si: &SurfaceInteraction,
    wo: Vec3A,
    wi: Vec3A,
    mode: TransportMode,
) -> f32 {
    match mode {
        TransportMode::Radiance => 1.0,
        TransportMode::Importance => {
            let num = wo.dot(si.n_shading).abs() * wi.dot(si.n_geometric).abs();
            let denom = wo.dot(si.n_geometric).abs() * wi.dot(si.n_shading).abs();
            if denom == 0.0 {
                0.0
            } else {
                num / denom
            }
        }
    }
}
