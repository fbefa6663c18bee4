//! The closed sets (BSDF lobes and materials, lights, cameras, integrators, phase
//! functions) are dispatched by exhaustive `match`, so a new variant that misses a method
//! fails to compile. A test cannot compile a missing arm; clippy's
//! `wildcard_enum_match_arm`, denied at the top of each dispatch module (and so in all of
//! its submodules), keeps `_ =>` arms over enums out. This test keeps the lint there.

const DISPATCH_MODULES: [&str; 6] = [
    "src/bsdf/mod.rs",
    "src/material/mod.rs",
    "src/light/mod.rs",
    "src/camera/mod.rs",
    "src/integrator/mod.rs",
    "src/medium/mod.rs",
];

#[test]
fn every_dispatch_module_denies_wildcard_arms_over_enums() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for module in DISPATCH_MODULES {
        let text = std::fs::read_to_string(root.join(module)).unwrap();
        // Inner attributes come before the first item: after the module docs only.
        let before_items: String = text
            .lines()
            .take_while(|l| {
                let l = l.trim_start();
                l.is_empty() || l.starts_with("//") || l.starts_with("#!")
            })
            .collect::<Vec<_>>()
            .join("\n");
        assert!(
            before_items.contains("#![deny(clippy::wildcard_enum_match_arm)]"),
            "{module}: the dispatch module must start with \
             #![deny(clippy::wildcard_enum_match_arm)]"
        );
    }
}
