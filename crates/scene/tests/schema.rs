//! `prism_scene::schema::rows()` is what the parsers check: for every row, a scene with an
//! unknown key in an object of that kind is refused at that key, with exactly the row's keys
//! as the expected ones. A row without a scene here fails the test, so a new kind of object
//! gets one.

use prism_scene::parse_scene_str;
use prism_scene::schema::{key_paths, rows};

/// A scene with an object of the row's kind, `$` where the unknown key goes.
fn scene_with(pattern: &str) -> Option<String> {
    let tagged = |section: &str, kind: &str| -> String {
        match section {
            "camera" | "integrator" => format!(r#"{{"{section}": {{"type": "{kind}", $}}}}"#),
            "film.filter" => format!(r#"{{"film": {{"filter": {{"type": "{kind}", $}}}}}}"#),
            "media" | "materials" => {
                format!(r#"{{"{section}": {{"x": {{"type": "{kind}", $}}}}}}"#)
            }
            "textures" => format!(r#"{{"textures": {{"t": {{"type": "{kind}", $}}}}}}"#),
            _ => format!(r#"{{"{section}": [{{"type": "{kind}", $}}]}}"#),
        }
    };
    let (section, kind) = match pattern.split_once('<') {
        Some((section, rest)) if rest.ends_with('>') => (
            section.trim_end_matches(".*").trim_end_matches("[]"),
            &rest[..rest.len() - 1],
        ),
        _ => ("", ""),
    };
    let section = match section {
        "@texture" => "textures",
        s => s,
    };
    Some(match pattern {
        "" => "{$}".into(),
        "film" => r#"{"film": {$}}"#.into(),
        "meshes.*" => r#"{"meshes": {"m": {$}}}"#.into(),
        "tiles.*" => r#"{"tiles": {"t": {$}}}"#.into(),
        "@sun" => r#"{"lights": [{"type": "cie_sky", "sky_type": 1,
                    "zenith_luminance_cd_m2": 1, "sun": {$}}]}"#
            .into(),
        "materials.*<lafortune>.lobes[]" => {
            r#"{"materials": {"x": {"type": "lafortune", "lobes": [{$}]}}}"#.into()
        }
        "@ior" => r#"{"materials": {"x": {"type": "dielectric", "ior": {$}}}}"#.into(),
        "@ior.sellmeier" => {
            r#"{"materials": {"x": {"type": "dielectric", "ior": {"sellmeier": {$}}}}}"#.into()
        }
        "@ior.cauchy" => {
            r#"{"materials": {"x": {"type": "dielectric", "ior": {"cauchy": {$}}}}}"#.into()
        }
        "@spectrum" => r#"{"spectra": {"s": {$}}}"#.into(),
        // Re-radiation entries have no `type`: the form is told by `bfc` or `absorption`.
        "reradiation.*<bfc>" => r#"{"reradiation": {"r": {"bfc": "r.bfc", $}}}"#.into(),
        "reradiation.*<dye>" => r#"{"reradiation": {"r": {"absorption": "a.csv", $}}}"#.into(),
        "media.*.fluorescence" => r#"{"media": {"m": {"fluorescence": {$}}}}"#.into(),
        "@phase<isotropic>" | "@phase<rayleigh>" | "@phase<hg>" | "@phase<tabulated>" => {
            format!(r#"{{"media": {{"m": {{"phase": {{"type": "{kind}", $}}}}}}}}"#)
        }
        "@texture_ref" => r#"{"materials": {"x": {"type": "lambert",
                              "reflectance": {"texture": "t", $}}}}"#
            .into(),
        "@transform" => r#"{"camera": {"transform": {$}}}"#.into(),
        "@transform.rotate" => r#"{"camera": {"transform": {"rotate": {$}}}}"#.into(),
        "@transform.look_at" => r#"{"camera": {"transform": {"look_at": {$}}}}"#.into(),
        _ if !kind.is_empty() => match section {
            "camera" | "film.filter" | "integrator" | "media" | "shapes" | "lights"
            | "materials" | "sensors" | "textures" => tagged(section, kind),
            _ => return None,
        },
        _ => return None,
    })
}

#[test]
fn every_row_is_the_key_list_its_parser_checks() {
    const UNKNOWN: &str = "zzz_not_a_key";
    let mut failures = Vec::new();
    for row in rows() {
        let Some(template) = scene_with(row.pattern) else {
            failures.push(format!("`{}`: no scene in scene_with", row.pattern));
            continue;
        };
        let json = template.replace('$', &format!(r#""{UNKNOWN}": 1"#));
        let keys: Vec<String> = row.keys().map(|k| format!("`{k}`")).collect();
        let expected = format!(
            "unknown field `{UNKNOWN}`, expected one of {}",
            keys.join(", ")
        );
        match parse_scene_str(&json, "scene.json") {
            Ok(_) => failures.push(format!("`{}`: accepted {json}", row.pattern)),
            Err(e) => {
                let at_key = e.path.to_string().ends_with(UNKNOWN);
                if !at_key || !e.message.starts_with(&expected) {
                    failures.push(format!("`{}`: {e}", row.pattern));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn key_paths_name_the_object_kind_and_the_key() {
    let paths = key_paths();
    for p in [
        "camera",
        "media",
        "shapes[]<sphere>.interior_medium",
        "shapes[]<mesh>.exterior_medium",
        "media.*<homogeneous>.sigma_s_per_m",
        "camera<thin_lens>.focus_distance_m",
        "@transform.look_at.eye",
    ] {
        assert!(paths.iter().any(|k| k == p), "no key path `{p}`");
    }
    let mut sorted = paths.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!(sorted.len(), paths.len(), "a key path twice");
}
