//! Transform steps compose in the order written: `[A, B]` maps p to B·A·p.

mod common;

use common::Dir;
use glam::{DMat4, DVec3};
use prism_scene::Transform;

fn transform_of(dir: &Dir, steps: &str) -> Transform {
    let s = dir
        .load(&format!(
            r#"{{"shapes": [{{"type": "sphere", "transform": {steps}}}]}}"#
        ))
        .unwrap();
    s.shapes[0].transform
}

fn assert_matrix_eq(a: DMat4, b: DMat4) {
    assert!(a.abs_diff_eq(b, 1e-12), "{a} != {b}");
}

#[test]
fn steps_apply_in_the_order_written() {
    let dir = Dir::new("order");
    let rotate = r#"{"rotate": {"axis": [0, 0, 1], "angle_deg": 90}}"#;
    let translate = r#"{"translate": [1, 0, 0]}"#;
    let t_then_r = transform_of(&dir, &format!("[{translate}, {rotate}]"));
    let r_then_t = transform_of(&dir, &format!("[{rotate}, {translate}]"));

    let t = DMat4::from_translation(DVec3::X);
    let r = DMat4::from_rotation_z(std::f64::consts::FRAC_PI_2);
    assert_matrix_eq(t_then_r.matrix, r * t);
    assert_matrix_eq(r_then_t.matrix, t * r);
    assert!(!t_then_r.matrix.abs_diff_eq(r_then_t.matrix, 1e-6));

    // The origin: moved to +X then turned to +Y; or turned (stays) then moved to +X.
    let o = t_then_r.transform_point(DVec3::ZERO);
    assert!(o.abs_diff_eq(DVec3::Y, 1e-12), "{o}");
    let o = r_then_t.transform_point(DVec3::ZERO);
    assert!(o.abs_diff_eq(DVec3::X, 1e-12), "{o}");

    // The inverse undoes it.
    assert_matrix_eq(t_then_r.matrix * t_then_r.inverse, DMat4::IDENTITY);
}

#[test]
fn scale_matrix_and_three_step_composition() {
    let dir = Dir::new("three");
    let composed = transform_of(
        &dir,
        r#"[{"scale": [2, 3, 4]},
            {"matrix": [[1, 0, 0, 5], [0, 1, 0, 6], [0, 0, 1, 7], [0, 0, 0, 1]]},
            {"rotate": {"axis": [0, 2, 0], "angle_deg": 180}}]"#,
    );
    let s = DMat4::from_scale(DVec3::new(2.0, 3.0, 4.0));
    let m = DMat4::from_translation(DVec3::new(5.0, 6.0, 7.0));
    let r = DMat4::from_rotation_y(std::f64::consts::PI);
    assert_matrix_eq(composed.matrix, r * m * s);
    assert_matrix_eq(composed.inverse, (r * m * s).inverse());
    // A single step may be given without the list.
    let single = transform_of(&dir, r#"{"scale": 2}"#);
    assert_matrix_eq(single.matrix, DMat4::from_scale(DVec3::splat(2.0)));
}

#[test]
fn look_at_puts_the_eye_at_the_origin_and_minus_z_towards_the_target() {
    let eye = DVec3::new(1.0, 2.0, 3.0);
    let target = DVec3::new(1.0, 2.0, -7.0);
    let t = Transform::look_at(eye, target, DVec3::Y).unwrap();
    assert!(t.transform_point(DVec3::ZERO).abs_diff_eq(eye, 1e-12));
    assert!(t.transform_vector(-DVec3::Z).abs_diff_eq(-DVec3::Z, 1e-12));
    assert!(t.transform_vector(DVec3::Y).abs_diff_eq(DVec3::Y, 1e-12));

    // Looking along +X from the origin: local −Z → +X, local +X (right) → +Z.
    let t = Transform::look_at(DVec3::ZERO, DVec3::new(4.0, 0.0, 0.0), DVec3::Y).unwrap();
    assert!(t.transform_vector(-DVec3::Z).abs_diff_eq(DVec3::X, 1e-12));
    assert!(t.transform_vector(DVec3::X).abs_diff_eq(DVec3::Z, 1e-12));
    assert!(t.transform_vector(DVec3::Y).abs_diff_eq(DVec3::Y, 1e-12));

    // A tilted up vector is made orthogonal; a parallel one is refused.
    let t = Transform::look_at(DVec3::ZERO, -DVec3::Z, DVec3::new(0.0, 1.0, 1.0)).unwrap();
    assert!(t.transform_vector(DVec3::Y).abs_diff_eq(DVec3::Y, 1e-12));
    assert!(Transform::look_at(DVec3::ZERO, DVec3::Y, DVec3::Y).is_none());
    assert!(Transform::look_at(DVec3::ONE, DVec3::ONE, DVec3::Y).is_none());

    // Through the file, with the default up.
    let dir = Dir::new("look-at");
    let s = dir
        .load(r#"{"camera": {"transform": {"look_at": {"eye": [0, 0, 0], "target": [4, 0, 0]}}}}"#)
        .unwrap();
    assert!(s
        .camera
        .transform
        .transform_vector(-DVec3::Z)
        .abs_diff_eq(DVec3::X, 1e-12));
}

#[test]
fn singular_matrices_are_refused() {
    let dir = Dir::new("singular");
    let e = dir
        .load(r#"{"shapes": [{"type": "sphere", "transform": {"matrix": [[1, 0, 0, 0], [0, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}}]}"#)
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}:1:56: shapes[0].transform.matrix: the transform is not invertible",
            dir.0.join("scene.json").display()
        )
    );
}
