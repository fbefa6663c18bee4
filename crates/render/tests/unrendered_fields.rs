//! Nothing parsed is silently dropped: what the scene reader accepts but render does not do
//! yet fails `RenderScene::build` with the file and the JSON path (scene_build::fields).

use prism_render::RenderScene;

const FOG: &str = r#""media": {"fog": {"type": "homogeneous", "sigma_a_per_m": 0.01,
                                        "sigma_s_per_m": 0.1, "g": 0.2}}"#;

/// `RenderScene::build`'s error for the scene `json`, read as `scene.json`.
fn build_error(json: &str) -> String {
    let description = prism_scene::parse_scene_str(json, "scene.json").unwrap();
    match RenderScene::build(&description, Some(glam::UVec2::new(4, 4))) {
        Ok(_) => panic!("built a scene that should be refused: {json}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_fog_medium_is_refused_where_it_is_defined() {
    let json = format!(r#"{{{FOG}, "shapes": [{{"type": "rectangle"}}]}}"#);
    assert_eq!(
        build_error(&json),
        "scene.json: media.fog: participating media are not rendered yet"
    );
    // Names that are not plain keys are written as the reader writes them.
    let json = r#"{"media": {"thick fog": {"sigma_s_per_m": 1}}}"#;
    assert_eq!(
        build_error(json),
        "scene.json: media[\"thick fog\"]: participating media are not rendered yet"
    );
}

#[test]
fn a_shape_in_a_medium_is_refused_at_the_shape() {
    let shapes = |medium: &str| {
        format!(
            r#"{{{FOG}, "shapes": [{{"type": "rectangle"}}, {{"type": "cuboid"}}, {{"type": "disk"}},
                {{"type": "sphere", "radius_m": 0.5, {medium}: "fog"}}]}}"#
        )
    };
    assert_eq!(
        build_error(&shapes(r#""interior_medium""#)),
        "scene.json: shapes[3].interior_medium: participating media are not rendered yet"
    );
    assert_eq!(
        build_error(&shapes(r#""exterior_medium""#)),
        "scene.json: shapes[3].exterior_medium: participating media are not rendered yet"
    );
}

/// The format has no camera (or world) medium: the reader refuses the key, so a camera in
/// fog cannot be written and then dropped.
#[test]
fn a_camera_medium_is_not_a_key_of_the_format() {
    let json = format!(r#"{{{FOG}, "camera": {{"type": "pinhole", "medium": "fog"}}}}"#);
    let e = prism_scene::parse_scene_str(&json, "scene.json").unwrap_err();
    assert_eq!(e.path.to_string(), "camera.medium");
    assert!(e.message.starts_with("unknown field `medium`"), "{e}");
}

#[test]
fn the_position_aov_is_refused_and_the_written_ones_are_not() {
    let json = r#"{"film": {"aovs": ["depth", "position"]}, "shapes": [{"type": "rectangle"}]}"#;
    assert_eq!(
        build_error(json),
        "scene.json: film.aovs[1]: the `position` AOV is not written yet (EXR outputs hold \
         depth, normal and albedo)"
    );
    let json =
        r#"{"film": {"aovs": ["depth", "normal", "albedo"]}, "shapes": [{"type": "rectangle"}]}"#;
    let description = prism_scene::parse_scene_str(json, "scene.json").unwrap();
    let scene = RenderScene::build(&description, Some(glam::UVec2::new(4, 4)))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.resolution, glam::UVec2::new(4, 4));
    assert_eq!(description.film.aovs.len(), 3);
}
