//! OBJ and PLY loading (ASCII, binary little and big endian) and clear errors on malformed
//! files: the message names the file, the place and what was expected.

use std::path::PathBuf;

use glam::{Vec2, Vec3A};
use prism_geometry::{load_obj, load_ply, TriangleMesh};

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("prism-geometry-mesh-loading")
        .join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const QUAD_POS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.5, 0.5, 1.0],
];
const QUAD_UV: [[f32; 2]; 5] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];

/// A PLY with 5 vertices (x y z nx ny nz u v as float) and a quad + a triangle.
fn ply_bytes(format: &str, big_endian: bool, truncate: usize, bad_index: bool) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment test\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    let faces: [&[i32]; 2] = [&[0, 1, 2, 3], &[0, 1, if bad_index { 9 } else { 4 }]];
    if format == "ascii" {
        for (p, uv) in QUAD_POS.iter().zip(QUAD_UV) {
            out.extend(format!("{} {} {} 0 0 1 {} {}\n", p[0], p[1], p[2], uv[0], uv[1]).bytes());
        }
        for f in faces {
            let idx: Vec<String> = f.iter().map(|i| i.to_string()).collect();
            out.extend(format!("{} {}\n", f.len(), idx.join(" ")).bytes());
        }
    } else {
        let f32b = |x: f32| {
            if big_endian {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        let i32b = |x: i32| {
            if big_endian {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        for (p, uv) in QUAD_POS.iter().zip(QUAD_UV) {
            for x in [p[0], p[1], p[2], 0.0, 0.0, 1.0, uv[0], uv[1]] {
                out.extend(f32b(x));
            }
        }
        for f in faces {
            out.push(f.len() as u8);
            for &i in f {
                out.extend(i32b(i));
            }
        }
    }
    out.truncate(out.len() - truncate);
    out
}

fn check_quad_mesh(m: &TriangleMesh) {
    assert_eq!(m.positions.len(), 5);
    assert_eq!(m.positions[2], Vec3A::new(1.0, 1.0, 0.0));
    // Quad fan-triangulated into two triangles, plus the triangle.
    assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    assert_eq!(m.normals.as_ref().unwrap()[4], Vec3A::Z);
    assert_eq!(m.uvs.as_ref().unwrap()[4], Vec2::new(0.5, 0.5));
}

#[test]
fn ply_ascii_binary_little_and_big_endian_load_the_same_mesh() {
    let d = dir("ply_ok");
    for (name, format, be) in [
        ("ascii.ply", "ascii", false),
        ("le.ply", "binary_little_endian", false),
        ("be.ply", "binary_big_endian", true),
    ] {
        let path = d.join(name);
        std::fs::write(&path, ply_bytes(format, be, 0, false)).unwrap();
        let mesh = load_ply(&path).unwrap_or_else(|e| panic!("{e}"));
        check_quad_mesh(&mesh);
    }
}

#[test]
fn ply_errors_name_the_file_and_the_problem() {
    let d = dir("ply_bad");
    let truncated = d.join("truncated.ply");
    std::fs::write(
        &truncated,
        ply_bytes("binary_little_endian", false, 7, false),
    )
    .unwrap();
    let e = load_ply(&truncated).unwrap_err().to_string();
    assert!(e.contains("truncated.ply"), "{e}");
    assert!(e.contains("truncated"), "{e}");

    let bad = d.join("bad_index.ply");
    std::fs::write(&bad, ply_bytes("binary_big_endian", true, 0, true)).unwrap();
    let e = load_ply(&bad).unwrap_err().to_string();
    assert!(
        e.contains("bad_index.ply")
            && e.contains("face 1 refers to vertex 9")
            && e.contains("5 vertices"),
        "{e}"
    );

    let ascii_bad = d.join("ascii_bad.ply");
    let text = String::from_utf8(ply_bytes("ascii", false, 0, false))
        .unwrap()
        .replace("0.5 0.5 1 0 0 1", "0.5 zz 1 0 0 1");
    std::fs::write(&ascii_bad, text).unwrap();
    let e = load_ply(&ascii_bad).unwrap_err();
    assert_eq!(e.line, Some(20), "{e}");
    let e = e.to_string();
    assert!(
        e.contains("ascii_bad.ply:20:") && e.contains("`0.5 zz 1 0 0 1") && e.contains("column"),
        "{e}"
    );
    // No Debug output of the parser's internals.
    for internal in ["ParseError", "LineCol", "Custom {", "kind:"] {
        assert!(!e.contains(internal), "{internal}: {e}");
    }
    let e = load_ply(&d).unwrap_err().to_string();
    assert!(e.contains("is a directory"), "{e}");

    let missing = d.join("does_not_exist.ply");
    let e = load_ply(&missing).unwrap_err().to_string();
    assert!(
        e.contains("does_not_exist.ply") && e.contains("cannot open"),
        "{e}"
    );
}

const OBJ: &str = "# two objects, two materials
mtllib two.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
o floor
usemtl red
f 1/1/1 2/2/1 3/3/1 4/4/1
o lid
usemtl blue
f 1/1/1 3/3/1 4/4/1
";

const MTL: &str = "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n";

#[test]
fn obj_with_two_objects_and_two_materials() {
    let d = dir("obj_ok");
    std::fs::write(d.join("two.mtl"), MTL).unwrap();
    let path = d.join("two.obj");
    std::fs::write(&path, OBJ).unwrap();
    let m = load_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.triangle_count(), 3);
    assert_eq!(m.object_names, vec!["floor".to_string(), "lid".to_string()]);
    assert_eq!(m.object_ids, vec![0, 0, 1]);
    let names: Vec<&str> = m
        .material_ids
        .iter()
        .map(|&i| m.material_names[i as usize].as_str())
        .collect();
    assert_eq!(names, vec!["red", "red", "blue"]);
    assert!(m.normals.as_ref().unwrap().iter().all(|&n| n == Vec3A::Z));
    // uvs follow the positions (single index).
    let uvs = m.uvs.as_ref().unwrap();
    for (p, uv) in m.positions.iter().zip(uvs) {
        assert_eq!(Vec2::new(p.x, p.y), *uv);
    }
}

#[test]
fn obj_errors_name_the_file_line_and_expectation() {
    let d = dir("obj_bad");
    std::fs::write(d.join("two.mtl"), MTL).unwrap();
    let nonnumeric = d.join("nonnumeric.obj");
    std::fs::write(&nonnumeric, OBJ.replace("v 1 1 0", "v 1 one 0")).unwrap();
    let e = load_obj(&nonnumeric).unwrap_err();
    assert_eq!(e.line, Some(5), "{e}");
    let s = e.to_string();
    assert!(
        s.starts_with(&format!("{}:5:", nonnumeric.display())),
        "{s}"
    );
    assert!(
        s.contains("expected 3 numbers") && s.contains("v 1 one 0"),
        "{s}"
    );

    let bad_face = d.join("bad_face.obj");
    std::fs::write(
        &bad_face,
        OBJ.replace("f 1/1/1 3/3/1 4/4/1", "f 1/1/1 3/3/1 7/4/1"),
    )
    .unwrap();
    let e = load_obj(&bad_face).unwrap_err();
    let s = e.to_string();
    assert_eq!(e.line, Some(17), "{s}");
    assert!(
        s.contains("bad_face.obj")
            && s.contains("vertex index 7 is out of range")
            && s.contains("4 vertices are defined"),
        "{s}"
    );

    // Files without faces are errors, not empty meshes: empty, plain text, points only.
    for (name, text) in [
        ("empty.obj", ""),
        ("notes.obj", "this is not a mesh\njust text\n"),
        ("points.obj", "v 0 0 0\nv 1 0 0\n"),
    ] {
        let path = d.join(name);
        std::fs::write(&path, text).unwrap();
        let s = load_obj(&path).unwrap_err().to_string();
        assert!(s.contains(name) && s.contains("no faces"), "{s}");
    }
    let nan = d.join("nan.obj");
    std::fs::write(&nan, "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let s = load_obj(&nan).unwrap_err().to_string();
    assert!(s.contains("(NaN, 0, 0)") && !s.contains("Vec3A"), "{s}");
    let s = load_obj(&d).unwrap_err().to_string();
    assert!(s.contains("is a directory"), "{s}");

    let unknown_mtl = d.join("unknown_mtl.obj");
    std::fs::write(&unknown_mtl, OBJ.replace("usemtl blue", "usemtl green")).unwrap();
    let s = load_obj(&unknown_mtl).unwrap_err().to_string();
    assert!(
        s.contains("unknown_mtl.obj:16:") && s.contains("'green'") && s.contains("red, blue"),
        "{s}"
    );
}

/// A binary PLY as other writers emit it: double positions, a colour and a per-vertex list
/// the mesh does not use, an element between vertex and face, ushort list counts and uint
/// indices. The decoder reads over what it does not use.
fn ply_binary_mixed(big_endian: bool, face_count_type: &str, index_type: &str) -> Vec<u8> {
    let format = if big_endian {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\nelement vertex 5\nproperty double x\nproperty uchar red\n\
         property double y\nproperty double z\nproperty list uchar float weights\n\
         property short s\nproperty short t\nelement edge 1\nproperty int vertex1\n\
         property int vertex2\nelement face 2\nproperty uchar flags\n\
         property list {face_count_type} {index_type} vertex_indices\nend_header\n"
    )
    .into_bytes();
    macro_rules! put {
        ($x:expr) => {
            if big_endian {
                out.extend($x.to_be_bytes())
            } else {
                out.extend($x.to_le_bytes())
            }
        };
    }
    for (p, uv) in QUAD_POS.iter().zip(QUAD_UV) {
        put!(p[0] as f64);
        put!(200u8);
        put!(p[1] as f64);
        put!(p[2] as f64);
        put!(2u8);
        put!(0.25f32);
        put!(0.75f32);
        put!(uv[0] as i16);
        put!(uv[1] as i16);
    }
    put!(0i32);
    put!(1i32);
    let faces: [&[u32]; 2] = [&[0, 1, 2, 3], &[0, 1, 4]];
    for f in faces {
        put!(7u8);
        match face_count_type {
            "char" => put!(if f.len() == 3 { -1i8 } else { f.len() as i8 }),
            _ => put!(f.len() as u16),
        }
        for &i in f {
            match index_type {
                "float" => put!(i as f32),
                _ => put!(i),
            }
        }
    }
    out
}

#[test]
fn binary_ply_reads_over_the_properties_and_elements_it_does_not_use() {
    let d = dir("ply_mixed");
    for be in [false, true] {
        let path = d.join(format!("mixed-{be}.ply"));
        std::fs::write(&path, ply_binary_mixed(be, "ushort", "uint")).unwrap();
        let m = load_ply(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.positions[4], Vec3A::new(0.5, 0.5, 1.0));
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
        assert!(m.normals.is_none());
        // s, t are integers here: uv (1, 1) at vertex 2, (0, 0) at vertex 4 (0.5 truncated).
        let uvs = m.uvs.as_ref().unwrap();
        assert_eq!(uvs[2], Vec2::new(1.0, 1.0));
        assert_eq!(uvs[4], Vec2::ZERO);
    }
}

#[test]
fn binary_ply_errors_name_the_element_and_what_was_expected() {
    let d = dir("ply_mixed_bad");
    let negative = d.join("negative-length.ply");
    std::fs::write(&negative, ply_binary_mixed(false, "char", "uint")).unwrap();
    let e = load_ply(&negative).unwrap_err().to_string();
    assert!(
        e.contains("negative-length.ply")
            && e.contains("element 'face' 1")
            && e.contains("length -1"),
        "{e}"
    );
    let float_indices = d.join("float-indices.ply");
    std::fs::write(&float_indices, ply_binary_mixed(false, "ushort", "float")).unwrap();
    let e = load_ply(&float_indices).unwrap_err().to_string();
    assert!(e.contains("integer list"), "{e}");

    // A position declared as a list, and a file cut inside the face element.
    let mut list_x = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
        property list uchar float x\nproperty float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for p in &QUAD_POS[..3] {
        list_x.push(1);
        for c in p {
            list_x.extend(c.to_le_bytes());
        }
    }
    list_x.push(3);
    for i in 0..3i32 {
        list_x.extend(i.to_le_bytes());
    }
    let list_path = d.join("list-x.ply");
    std::fs::write(&list_path, list_x).unwrap();
    let e = load_ply(&list_path).unwrap_err().to_string();
    assert!(e.contains("numeric scalars"), "{e}");
    let cut = d.join("cut.ply");
    std::fs::write(&cut, ply_bytes("binary_big_endian", true, 3, false)).unwrap();
    let e = load_ply(&cut).unwrap_err().to_string();
    assert!(
        e.contains("cut.ply") && e.contains("element 'face' 1 of 2") && e.contains("truncated"),
        "{e}"
    );
}
