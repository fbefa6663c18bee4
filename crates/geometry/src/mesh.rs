//! Indexed triangle meshes with optional per-vertex normals and uvs, per-face material and
//! object ids, and procedural constructors used by tests and benchmarks.

use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

/// Material id of a face the file gave no material; the scene assigns the instance's material.
pub const NO_MATERIAL: u32 = u32::MAX;

/// An indexed triangle mesh in object space (positions in metres).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3A>,
    /// Per-vertex shading normals (same length as `positions`), not necessarily unit length.
    pub normals: Option<Vec<Vec3A>>,
    /// Per-vertex texture coordinates (same length as `positions`).
    pub uvs: Option<Vec<Vec2>>,
    /// Vertex indices of each triangle, counter-clockwise seen from the front.
    pub indices: Vec<[u32; 3]>,
    /// Per-triangle index into `material_names`, or [`NO_MATERIAL`].
    pub material_ids: Vec<u32>,
    /// Per-triangle index into `object_names` (0 for single-object meshes).
    pub object_ids: Vec<u32>,
    pub material_names: Vec<String>,
    pub object_names: Vec<String>,
}

impl TriangleMesh {
    /// A single-object, single-material mesh; the caller guarantees valid indices
    /// (see [`TriangleMesh::validate`]).
    pub fn new(positions: Vec<Vec3A>, indices: Vec<[u32; 3]>) -> Self {
        let n = indices.len();
        Self {
            positions,
            normals: None,
            uvs: None,
            indices,
            material_ids: vec![NO_MATERIAL; n],
            object_ids: vec![0; n],
            material_names: Vec::new(),
            object_names: vec![String::new()],
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// Bounds (min, max) of the vertices the triangles use; inverted (∞, −∞) when there
    /// are none.
    pub fn bounds(&self) -> (Vec3A, Vec3A) {
        self.indices.iter().flatten().fold(
            (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
            |(lo, hi), &i| {
                let p = self.positions[i as usize];
                (lo.min(p), hi.max(p))
            },
        )
    }

    /// The three vertex positions of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3A; 3] {
        let [a, b, c] = self.indices[i];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Check internal consistency; returns what is wrong. Loaders call this so a broken file
    /// becomes an error, never a panic during rendering.
    pub fn validate(&self) -> Result<(), String> {
        let nv = self.positions.len();
        if self.indices.is_empty() {
            // An empty file, plain text or a point cloud would otherwise render as nothing.
            return Err(format!(
                "no faces ({nv} vertices); expected a triangle mesh (OBJ `f` lines, a PLY \
                 `face` element)"
            ));
        }
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            let p = self.positions[i];
            return Err(format!(
                "vertex {i} has a non-finite position ({}, {}, {}); expected finite numbers",
                p.x, p.y, p.z
            ));
        }
        if let Some(n) = &self.normals {
            if n.len() != nv {
                return Err(format!("{} normals for {nv} vertices", n.len()));
            }
        }
        if let Some(uv) = &self.uvs {
            if uv.len() != nv {
                return Err(format!("{} uvs for {nv} vertices", uv.len()));
            }
        }
        for (f, tri) in self.indices.iter().enumerate() {
            for &v in tri {
                if v as usize >= nv {
                    return Err(format!(
                        "triangle {f} refers to vertex {v}, but there are only {nv} vertices (indices start at 0)"
                    ));
                }
            }
        }
        let nt = self.indices.len();
        if self.material_ids.len() != nt || self.object_ids.len() != nt {
            return Err("per-triangle material/object id count differs from triangle count".into());
        }
        Ok(())
    }

    /// Axis-aligned box with half extents `half_extents_m`, centred on the origin, as 12
    /// triangles over 8 shared vertices (a closed mesh), outward-facing, flat shaded.
    pub fn cuboid(half_extents_m: Vec3A) -> Self {
        let h = half_extents_m;
        let positions = (0..8)
            .map(|i| {
                Vec3A::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect();
        // Each face as a quad (counter-clockwise from outside), split along one diagonal.
        let quads: [[u32; 4]; 6] = [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ];
        let indices = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Self::new(positions, indices)
    }

    /// A latitude/longitude sphere of radius `radius_m` with `rings ≥ 2` bands in θ and
    /// `segments ≥ 3` in φ, z as the polar axis, smooth unit normals `p/r` and uvs
    /// `(φ/2π, θ/π)` (the pbrt-v4 sphere parameterisation). The seam vertices are duplicated
    /// for uvs but bit-identical in position, so the mesh is watertight for
    /// [`crate::triangle`]'s test.
    pub fn uv_sphere(radius_m: f32, rings: u32, segments: u32) -> Self {
        let rings = rings.max(2);
        let segments = segments.max(3);
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut uvs = Vec::new();
        for i in 0..=rings {
            let theta = PI * i as f32 / rings as f32;
            let (st, ct) = if i == 0 {
                (0.0, 1.0)
            } else if i == rings {
                (0.0, -1.0)
            } else {
                theta.sin_cos()
            };
            for j in 0..=segments {
                let phi = 2.0 * PI * (j % segments) as f32 / segments as f32;
                let (sp, cp) = phi.sin_cos();
                let n = Vec3A::new(st * cp, st * sp, ct);
                positions.push(n * radius_m);
                normals.push(n);
                uvs.push(Vec2::new(
                    j as f32 / segments as f32,
                    i as f32 / rings as f32,
                ));
            }
        }
        let row = segments + 1;
        let mut indices = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let a = i * row + j;
                let b = a + row;
                // Outward orientation: (θ, φ) increasing is (down, counter-clockwise).
                if i != 0 {
                    indices.push([a, b, a + 1]);
                }
                if i != rings - 1 {
                    indices.push([a + 1, b, b + 1]);
                }
            }
        }
        let mut mesh = Self::new(positions, indices);
        mesh.normals = Some(normals);
        mesh.uvs = Some(uvs);
        mesh
    }

    /// Outward-facing icosphere of radius `radius_m`: an icosahedron subdivided
    /// `subdivisions` times with shared vertices (closed, 20·4ⁿ triangles), smooth normals.
    pub fn icosphere(radius_m: f32, subdivisions: u32) -> Self {
        let t = (1.0 + 5.0f32.sqrt()) / 2.0;
        let mut verts: Vec<Vec3A> = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ]
        .iter()
        .map(|&(x, y, z)| Vec3A::new(x, y, z).normalize())
        .collect();
        let mut faces: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions {
            let mut midpoints = std::collections::HashMap::new();
            let mut mid = |a: u32, b: u32, verts: &mut Vec<Vec3A>| -> u32 {
                let key = (a.min(b), a.max(b));
                *midpoints.entry(key).or_insert_with(|| {
                    verts.push(((verts[a as usize] + verts[b as usize]) * 0.5).normalize());
                    verts.len() as u32 - 1
                })
            };
            let mut next = Vec::with_capacity(faces.len() * 4);
            for &[a, b, c] in &faces {
                let ab = mid(a, b, &mut verts);
                let bc = mid(b, c, &mut verts);
                let ca = mid(c, a, &mut verts);
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            faces = next;
        }
        let positions = verts.iter().map(|&n| n * radius_m).collect();
        let mut mesh = Self::new(positions, faces);
        mesh.normals = Some(verts);
        mesh
    }

    /// Apply `f` to every position (and nothing else); used to displace procedural meshes.
    pub fn map_positions(&mut self, f: impl Fn(Vec3A) -> Vec3A) {
        for p in &mut self.positions {
            *p = f(*p);
        }
    }

    /// Append `other` (its material/object ids are offset past this mesh's names).
    pub fn append(&mut self, other: &TriangleMesh) {
        let v0 = self.positions.len() as u32;
        let m0 = self.material_names.len() as u32;
        let o0 = self.object_names.len() as u32;
        match (&mut self.normals, &other.normals) {
            (Some(a), Some(b)) => a.extend_from_slice(b),
            _ => self.normals = None,
        }
        match (&mut self.uvs, &other.uvs) {
            (Some(a), Some(b)) => a.extend_from_slice(b),
            _ => self.uvs = None,
        }
        self.positions.extend_from_slice(&other.positions);
        self.indices
            .extend(other.indices.iter().map(|t| t.map(|v| v + v0)));
        self.material_ids
            .extend(other.material_ids.iter().map(|m| m + m0));
        self.object_ids
            .extend(other.object_ids.iter().map(|o| o + o0));
        self.material_names
            .extend(other.material_names.iter().cloned());
        self.object_names.extend(other.object_names.iter().cloned());
    }
}
