//! Triangle meshes the importer must write (pbrt's inline meshes, Mitsuba's serialized
//! meshes) as Wavefront OBJ text; numbers in Rust's shortest round-trip form, so the file
//! holds exactly the input's values.

use glam::DVec3;

/// OBJ text; `flip` reverses each triangle's winding.
pub fn obj_text(
    p: &[DVec3],
    n: Option<&[DVec3]>,
    uv: Option<&[f64]>,
    triangles: &[[usize; 3]],
    flip: bool,
) -> String {
    let mut s = String::from("# written by prism import\n");
    for v in p {
        s.push_str(&format!("v {} {} {}\n", v.x, v.y, v.z));
    }
    if let Some(n) = n {
        for v in n {
            s.push_str(&format!("vn {} {} {}\n", v.x, v.y, v.z));
        }
    }
    if let Some(uv) = uv {
        for c in uv.chunks(2) {
            s.push_str(&format!("vt {} {}\n", c[0], c[1]));
        }
    }
    for t in triangles {
        let t = if flip { [t[0], t[2], t[1]] } else { *t };
        let corner = |i: usize| match (uv.is_some(), n.is_some()) {
            (true, true) => format!("{0}/{0}/{0}", i + 1),
            (true, false) => format!("{0}/{0}", i + 1),
            (false, true) => format!("{0}//{0}", i + 1),
            (false, false) => format!("{}", i + 1),
        };
        s.push_str(&format!(
            "f {} {} {}\n",
            corner(t[0]),
            corner(t[1]),
            corner(t[2])
        ));
    }
    s
}
