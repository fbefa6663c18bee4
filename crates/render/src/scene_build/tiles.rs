//! `tiled` materials → periodic tiles placed on their carrier shapes (virtual ray tracing,
//! prism-geometry `tiling`).
//!
//! A tile's OBJ is loaded once, its `usemtl` names are mapped to scene materials (every
//! name used must be mapped and every mapped name used), and it must continue across its
//! period (no open seams). A carrier is a rectangle, or a mesh of parallelogram quads, each
//! holding a whole number of periods along each edge, so that its corners are tile corners
//! (Mostefaoui et al., Fig. 4a); every quad becomes one geometry instance. The tile
//! is placed in metres: x along the quad's first edge, y along the second, z along its
//! normal, whatever the shape's transform scales.

use glam::{DMat4, DVec3, DVec4};
use prism_geometry::{open_seam_edges, GeometryBuilder, MeshId, Tiling, TriangleMesh, NO_MATERIAL};
use prism_scene::{MaterialKind, SceneDescription};

use crate::tile_pyramid::{PyramidOptions, TilePyramid, TiledSurface};

/// Two periods agree with an edge when they differ by at most this fraction of a period.
const WHOLE_PERIODS_TOLERANCE: f64 = 1e-3;

/// The tile a shape's material repeats, if the material is `tiled`.
pub(crate) fn tile_of(scene: &SceneDescription, material: Option<usize>) -> Option<usize> {
    match scene.materials.get(material?)?.kind {
        MaterialKind::Tiled { tile, .. } => Some(tile),
        MaterialKind::Lambert { .. }
        | MaterialKind::Conductor { .. }
        | MaterialKind::Dielectric { .. }
        | MaterialKind::TwoSided { .. }
        | MaterialKind::Mask { .. }
        | MaterialKind::NormalMap { .. }
        | MaterialKind::BumpMap { .. }
        | MaterialKind::ThinDielectric { .. }
        | MaterialKind::Mix { .. }
        | MaterialKind::Library(_)
        | MaterialKind::Fluorescent { .. }
        | MaterialKind::Interface => None,
    }
}

/// The tiles' meshes, each loaded and checked the first time a carrier uses it.
#[derive(Default)]
pub(crate) struct TileMeshes {
    loaded: Vec<Option<MeshId>>,
    /// A loaded tile has vertex normals.
    pub vertex_normals: bool,
}

impl TileMeshes {
    /// The mesh of tile `tile`, added to `builder` once; errors name what is wrong with the
    /// tile (the caller adds the place `tiles.<name>`).
    pub fn mesh(
        &mut self,
        scene: &SceneDescription,
        tile: usize,
        builder: &mut GeometryBuilder,
    ) -> Result<MeshId, String> {
        if self.loaded.len() < scene.tiles.len() {
            self.loaded.resize(scene.tiles.len(), None);
        }
        if let Some(id) = self.loaded[tile] {
            return Ok(id);
        }
        let t = &scene.tiles[tile];
        let mut mesh = prism_geometry::load_obj(&t.mesh).map_err(|e| e.to_string())?;
        mesh.validate()
            .map_err(|e| format!("{}: {e}", t.mesh.display()))?;
        let period = [t.period_m[0] as f32, t.period_m[1] as f32];
        let seams = open_seam_edges(&mesh, period);
        if seams > 0 {
            return Err(format!(
                "{}: {seams} boundary edge{} on the period planes (x = 0 or {} m, y = 0 or {} m) \
                 find no partner on the opposite plane: the tile does not continue across its \
                 period, so repeating it leaves open seams (a rim that lies exactly on a period \
                 plane counts as a seam: move it inside the period)",
                t.mesh.display(),
                if seams == 1 { "" } else { "s" },
                t.period_m[0],
                t.period_m[1],
            ));
        }
        // usemtl name → scene material, for every face.
        let mut scene_material = Vec::with_capacity(mesh.material_names.len());
        for name in &mesh.material_names {
            scene_material.push(t.materials.iter().find(|(n, _)| n == name).map(|(_, m)| *m));
        }
        let used: Vec<bool> = (0..mesh.material_names.len())
            .map(|k| mesh.material_ids.contains(&(k as u32)))
            .collect();
        if let Some(k) =
            (0..mesh.material_names.len()).find(|&k| used[k] && scene_material[k].is_none())
        {
            return Err(format!(
                "the OBJ's faces use `usemtl {}`, which `materials` does not map to a scene \
                 material",
                mesh.material_names[k]
            ));
        }
        if let Some((name, _)) = t.materials.iter().find(|(n, _)| {
            !mesh
                .material_names
                .iter()
                .zip(&used)
                .any(|(m, u)| *u && m == n)
        }) {
            return Err(format!(
                "`materials` maps `{name}`, which no face of {} uses (its usemtl names: {})",
                t.mesh.display(),
                mesh.material_names.join(", ")
            ));
        }
        let unassigned = mesh
            .material_ids
            .iter()
            .filter(|&&m| m == NO_MATERIAL)
            .count();
        if unassigned > 0 {
            return Err(format!(
                "{unassigned} face{} of {} come before any `usemtl`: every face of a tile needs \
                 a material",
                if unassigned == 1 { "" } else { "s" },
                t.mesh.display()
            ));
        }
        for m in &mut mesh.material_ids {
            *m = scene_material[*m as usize].expect("checked above") as u32;
        }
        self.vertex_normals |= mesh.normals.is_some();
        let id = builder.add_mesh(mesh);
        self.loaded[tile] = Some(id);
        Ok(id)
    }
}

/// A quadrilateral carrier in its shape's object space: a parallelogram with a corner, its
/// two edges (tile x along the first, y along the second) and its unit normal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CarrierQuad {
    pub corner: DVec3,
    pub edges: [DVec3; 2],
    pub normal: DVec3,
}

impl CarrierQuad {
    /// A `rectangle` shape of `size_m`: centred, in the local x–y plane, normal +z.
    pub fn rectangle(size_m: [f64; 2]) -> Self {
        Self {
            corner: DVec3::new(-0.5 * size_m[0], -0.5 * size_m[1], 0.0),
            edges: [
                DVec3::new(size_m[0], 0.0, 0.0),
                DVec3::new(0.0, size_m[1], 0.0),
            ],
            normal: DVec3::Z,
        }
    }

    /// The quadrilaterals of a carrier mesh: consecutive triangle pairs (a, b, c), (a, c, d)
    /// — an OBJ quad face as it is fan-triangulated — that form parallelograms (corner a,
    /// edges b − a and d − a). Anything else is an error naming the triangle.
    pub fn of_mesh(mesh: &TriangleMesh) -> Result<Vec<Self>, String> {
        let n = mesh.triangle_count();
        if n % 2 == 1 {
            return Err(format!(
                "a `tiled` carrier mesh must be made of quadrilateral faces (parallelograms, \
                 two triangles each), but it has {n} triangles"
            ));
        }
        let p = |k: u32| mesh.positions[k as usize].as_dvec3();
        (0..n / 2)
            .map(|q| {
                let [a, b, c] = mesh.indices[2 * q];
                let [a2, c2, d] = mesh.indices[2 * q + 1];
                let not_quad = |why: &str| {
                    format!(
                        "triangles {} and {} {why}: a `tiled` carrier mesh must be made of \
                         quadrilateral faces (OBJ `f` lines of four vertices), each a \
                         parallelogram whose corners are tile corners",
                        2 * q,
                        2 * q + 1
                    )
                };
                if a2 != a || c2 != c {
                    return Err(not_quad("are not the two halves of one quadrilateral face"));
                }
                let (u, v) = (p(b) - p(a), p(d) - p(a));
                let gap = (p(a) + p(c) - p(b) - p(d)).length();
                if gap > 1e-4 * u.length().max(v.length()) {
                    return Err(not_quad(&format!(
                        "form a quadrilateral that is not a parallelogram (a + c − b − d is \
                         {gap:.3e} m long)"
                    )));
                }
                let normal = u.cross(v).normalize();
                if !normal.is_finite() {
                    return Err(not_quad("form a degenerate quadrilateral"));
                }
                Ok(Self {
                    corner: p(a),
                    edges: [u, v],
                    normal,
                })
            })
            .collect()
    }

    /// The tiling of this quad placed by `shape_to_world`, and the matrix that takes the
    /// tile's space (metres, period in x–y, height along z) to the world.
    pub fn tiling(
        &self,
        shape_to_world: &DMat4,
        period_m: [f64; 2],
        mesh: MeshId,
    ) -> Result<(Tiling, DMat4), String> {
        let corner = shape_to_world.transform_point3(self.corner);
        let edges = self.edges.map(|e| shape_to_world.transform_vector3(e));
        let mut cells = [0u32; 2];
        let mut axes = [DVec3::ZERO; 2];
        for k in 0..2 {
            let length = edges[k].length();
            let periods = length / period_m[k];
            let whole = periods.round();
            if whole < 1.0 || (periods - whole).abs() > WHOLE_PERIODS_TOLERANCE {
                return Err(format!(
                    "a `tiled` carrier must hold a whole number of tile periods along each \
                     edge, so that its corners are tile corners: its {} edge is {length} m, \
                     {periods:.4} periods of {} m",
                    ["first (x)", "second (y)"][k],
                    period_m[k]
                ));
            }
            if whole > f64::from(u32::MAX) {
                return Err(format!("{whole} periods along one edge are too many"));
            }
            cells[k] = whole as u32;
            // One tile period along the edge (the edge's length divided exactly).
            axes[k] = edges[k] / (whole * period_m[k]);
        }
        // The carrier's normal as the renderer shades it (the normal matrix of the shape's
        // transform), unit length: tile heights stay in metres.
        let normal = shape_to_world
            .inverse()
            .transpose()
            .transform_vector3(self.normal)
            .normalize();
        if !normal.is_finite() || axes.iter().any(|a| !a.is_finite()) {
            return Err("the carrier is degenerate under its transform".into());
        }
        let tile_to_world = DMat4::from_cols(
            axes[0].extend(0.0),
            axes[1].extend(0.0),
            normal.extend(0.0),
            DVec4::new(corner.x, corner.y, corner.z, 1.0),
        );
        Ok((
            Tiling {
                mesh,
                period_m: [period_m[0] as f32, period_m[1] as f32],
                cells,
            },
            tile_to_world,
        ))
    }
}

/// Per material id, the surface `radiosity` holds a `tiled` material by, where a shape uses
/// it (`None` for every other material): the top level of the tile's pyramid
/// ([`radiosity_surface`] with 1 level). The solution asks for finer levels where its
/// elements get smaller than a period.
pub(crate) fn radiosity_surfaces(
    scene: &SceneDescription,
    geometry: &prism_geometry::Geometry,
) -> Result<Vec<Option<TiledSurface>>, String> {
    (0..=scene.materials.len())
        .map(|m| radiosity_surface(scene, geometry, m, 1))
        .collect()
}

/// The surface `radiosity` holds `tiled` material `material` by, with a pyramid of `levels`
/// levels, at most the material's own `levels`, and the slab of its tile. `None` for
/// another material, or one no shape uses. 16 samples per bin pair reach each cell of the pyramid's finest level
/// (64 at least, 1 024 at most: beyond level 3 the finest cells get fewer, down to the one
/// sample per cell and band group the simulation needs).
pub(crate) fn radiosity_surface(
    scene: &SceneDescription,
    geometry: &prism_geometry::Geometry,
    material: usize,
    levels: u32,
) -> Result<Option<TiledSurface>, String> {
    let Some(MaterialKind::Tiled {
        tile,
        levels: most,
        self_shadowing,
        interreflection,
    }) = scene.materials.get(material).map(|m| &m.kind).cloned()
    else {
        return Ok(None);
    };
    let slab = geometry
        .instances()
        .iter()
        .find_map(|inst| match inst.shape {
            prism_geometry::Shape::Tiled(t) if inst.material == Some(material as u32) => {
                let (lo, hi) = geometry.mesh(t.mesh).bounds();
                Some((lo.z, hi.z))
            }
            _ => None,
        });
    let Some(slab) = slab else {
        return Ok(None);
    };
    let levels = levels.clamp(1, most.max(1));
    let finest_cells = 1u32 << (2 * (levels - 1));
    let options = PyramidOptions {
        levels,
        samples_per_bin_pair: (16 * finest_cells).clamp(64, 1024).max(4 * finest_cells),
        self_shadowing,
        interreflection,
        ..PyramidOptions::default()
    };
    let pyramid = TilePyramid::simulate(scene, tile, &options)
        .map_err(|e| format!("the pyramid of tile `{}`: {e}", scene.tiles[tile].name))?;
    Ok(Some(pyramid.tiled_surface(slab)))
}
