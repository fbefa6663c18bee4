//! Prints the closed furnace's radiosity error against error_bound_rel (docs/radiosity.md).
use std::sync::atomic::{AtomicU32, Ordering};

use glam::Vec3A;
use prism_radiosity::{
    ElementShape, InputPatch, NoDirectLight, Radiosity, RadiositySettings, Unoccluded,
};
fn square(p0: Vec3A, e1: Vec3A, e2: Vec3A, rho: f32) -> InputPatch {
    // Each square is a surface of its own.
    static NEXT_SURFACE: AtomicU32 = AtomicU32::new(0);
    InputPatch {
        shape: ElementShape::Parallelogram { p0, e1, e2 },
        reflectance: vec![rho],
        emission: vec![1.0],
        surface: NEXT_SURFACE.fetch_add(1, Ordering::Relaxed),
        directional: None,
    }
}
fn main() {
    let (o, x, y, z) = (Vec3A::ZERO, Vec3A::X, Vec3A::Y, Vec3A::Z);
    for rho in [0.5f32, 0.8] {
        let patches = vec![
            square(o, x, y, rho),
            square(z, y, x, rho),
            square(o, z, x, rho),
            square(y, x, z, rho),
            square(o, y, z, rho),
            square(x, z, y, rho),
        ];
        for eps in [0.016f32, 0.004, 0.001, 0.00025] {
            let s = RadiositySettings {
                error_bound_rel: eps,
                ..Default::default()
            };
            let mut sol = Radiosity::new(&patches, 1, s).unwrap();
            let mut st = None;
            for _ in 0..3 {
                st = Some(sol.iterate(&Unoccluded, &NoDirectLight).unwrap());
            }
            let expected = 1.0 / (1.0 - rho);
            let mut worst = 0.0f32;
            for i in 0..64 {
                for j in 0..64 {
                    let b = sol.radiosity_at(
                        0,
                        patches[0]
                            .shape
                            .point((i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 64.0),
                    )[0];
                    worst = worst.max((b / expected - 1.0).abs());
                }
            }
            let mean = sol.total_power()[0] / 6.0 / expected - 1.0;
            let st = st.unwrap();
            println!("rho {rho} eps {eps}: mean {mean:+.5} worst {worst:.4} elements {} links {} refine {:.3}s", st.elements, st.links, st.refine_s);
        }
    }
}
