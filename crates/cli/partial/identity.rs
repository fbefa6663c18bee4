//! What a partial image is a part of: everything that changes the image (the scene's
//! content, spp, seed, resolution, integrator, sampler, sample plan, spectral bins, the
//! film's AOVs), and nothing that does not (`-o`, `--threads`, `--checkpoint-every`,
//! progress output). Each field is stored in the header, so a refusal names what changed;
//! their hash identifies the render in one value.

use std::path::Path;

use prism_scene::SceneDescription;

/// The header attribute of the hash; the fields are `prism:identity.<name>`.
pub const HASH_ATTRIBUTE: &str = "prism:identity";

/// The fields that decide the image (see the module docs), as text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderIdentity {
    pub fields: Vec<(&'static str, String)>,
}

/// 64-bit FNV-1a: a stable hash (std's `DefaultHasher` may change between Rust
/// releases, and parts of one render are made by different builds on a farm). It detects
/// edits, not adversaries.
pub fn fnv1a_64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The hash of the scene's content: the loaded description (meshes, spectra, textures and
/// every parameter, as read) without what does not change the image or comes from the
/// command line — the file's own path, `film.output`, `film.spp` and `film.seed` (their
/// effective values are fields of their own) — and with paths relative to the scene's
/// folder, so the same scene copied to another machine has the same hash.
pub fn scene_content_hash(description: &SceneDescription) -> u64 {
    let mut d = description.clone();
    let folder = description
        .file
        .parent()
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    d.file = Path::new("").to_path_buf();
    d.film.output = None;
    d.film.spp = 0;
    d.film.seed = 0;
    let mut text = format!("{d:?}");
    if !folder.is_empty() {
        text = text.replace(&folder, "<scene folder>");
    }
    fnv1a_64(text.as_bytes())
}

impl RenderIdentity {
    /// The hash of every field (names and values).
    pub fn hash(&self) -> String {
        let text: String = self
            .fields
            .iter()
            .map(|(k, v)| format!("{k}={v}\n"))
            .collect();
        format!("{:016x}", fnv1a_64(text.as_bytes()))
    }

    /// The fields as read back from a header (every attribute `prism:identity.<name>`).
    pub fn from_attributes(
        text: &std::collections::BTreeMap<String, String>,
    ) -> Vec<(String, String)> {
        let prefix = format!("{HASH_ATTRIBUTE}.");
        text.iter()
            .filter_map(|(k, v)| k.strip_prefix(&prefix).map(|n| (n.to_string(), v.clone())))
            .collect()
    }

    /// What differs from the fields of a header (`stored`): "name: stored in the file,
    /// this run's now" per field; empty when none does.
    pub fn differences(&self, stored: &[(String, String)]) -> Vec<String> {
        let own: Vec<(String, String)> = self
            .fields
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        field_differences(stored, &own, "in the file", "now")
    }
}

/// Field by field, what differs between two identities `a` and `b` (as read from headers),
/// each side named by its label: "spp: 512 in the file, 256 now".
pub fn field_differences(
    a: &[(String, String)],
    b: &[(String, String)],
    a_label: &str,
    b_label: &str,
) -> Vec<String> {
    let mut out = Vec::new();
    for (name, value) in b {
        match a.iter().find(|(k, _)| k == name) {
            Some((_, v)) if v == value => {}
            Some((_, v)) if name == "scene" => out.push(format!(
                "scene: its content changed (hash {v} {a_label}, {value} {b_label})"
            )),
            Some((_, v)) => out.push(format!("{name}: {v} {a_label}, {value} {b_label}")),
            None => out.push(format!("{name}: not recorded {a_label}")),
        }
    }
    for (name, _) in a {
        if !b.iter().any(|(k, _)| k == name) {
            out.push(format!("{name}: not recorded {b_label}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn identity(spp: &str) -> RenderIdentity {
        RenderIdentity {
            fields: vec![("scene", "00ff".into()), ("spp", spp.into())],
        }
    }

    #[test]
    fn differences_name_the_field_that_changed() {
        let a = identity("512");
        let stored: Vec<(String, String)> = a
            .fields
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        assert!(a.differences(&stored).is_empty());
        let b = identity("256");
        assert_eq!(
            b.differences(&stored),
            vec!["spp: 512 in the file, 256 now".to_string()]
        );
        assert_ne!(a.hash(), b.hash());
    }

    #[test]
    fn fnv_matches_its_reference_values() {
        // FNV-1a 64 test vectors (Fowler, Noll, Vo: the FNV reference page).
        assert_eq!(fnv1a_64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a_64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a_64(b"foobar"), 0x8594_4171_f739_67e8);
    }
}
