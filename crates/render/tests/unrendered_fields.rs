//! Nothing parsed is silently dropped: what the scene reader accepts but render does not do
//! yet fails `RenderScene::build` with the file and the JSON path (scene_build::fields).

use prism_render::RenderScene;

/// `RenderScene::build`'s error for the scene `json`, read as `scene.json`.
fn build_error(json: &str) -> String {
    let description = prism_scene::parse_scene_str(json, "scene.json").unwrap();
    match RenderScene::build(&description, Some(glam::UVec2::new(4, 4))) {
        Ok(_) => panic!("built a scene that should be refused: {json}"),
        Err(e) => e.to_string(),
    }
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
