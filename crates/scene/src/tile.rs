//! The `tiles` section: periodic texture tiles modelled as geometry (an OBJ over one period)
//! that `tiled` materials repeat over their carrier surfaces (virtual ray tracing).

use std::path::PathBuf;

use crate::reader::{Result, V};
use crate::schema::schema;
use crate::shape::named_index;

/// One periodic tile.
#[derive(Debug, Clone, PartialEq)]
pub struct Tile {
    /// Its key in `tiles`.
    pub name: String,
    /// The OBJ file, resolved against the scene file's folder and checked to exist. Its
    /// period lies in its x–y plane, `[0, period_x] × [0, period_y]`; z is the height above
    /// the carrier surface.
    pub mesh: PathBuf,
    /// Period along the tile's x and y, metres.
    pub period_m: [f64; 2],
    /// The OBJ's `usemtl` names and the scene material (index into `materials`) each
    /// becomes, in file order.
    pub materials: Vec<(String, usize)>,
}

/// The names in `tiles`, in file order (materials refer to tiles before the tiles, which
/// refer to materials, are parsed).
pub(crate) fn tile_names<'a>(v: &V<'a>) -> Result<Vec<&'a str>> {
    Ok(v.map()?.into_iter().map(|(name, _)| name).collect())
}

/// Parses `tiles`; `materials` are the scene's material names and `tiled[i]` whether
/// material `i` is itself `tiled` (which a tile's faces cannot be).
pub(crate) fn parse_tiles(v: &V, materials: &[&str], tiled: &[bool]) -> Result<Vec<Tile>> {
    let mut tiles = Vec::new();
    for (name, entry) in v.map()? {
        let o = entry.object(schema!("tiles.*"))?;
        let mesh = o
            .req("mesh", "the tile's OBJ file (one period)")?
            .asset("tile mesh", &["obj"])?;
        let period = o.req("period_m", "the period [x, y] in metres")?;
        let period_m: [f64; 2] = period.numbers()?;
        if let Some(bad) = period_m.iter().find(|p| **p <= 0.0) {
            return Err(period.err(format!("expected two periods > 0 m, found {bad}")));
        }
        let map = o.req(
            "materials",
            "an object mapping each `usemtl` name of the OBJ to a scene material",
        )?;
        let mut mapped = Vec::new();
        for (usemtl, target) in map.map()? {
            let m = named_index(&target, "material", "materials", materials)?;
            if tiled[m] {
                return Err(target.err(format!(
                    "material `{}` is `tiled`: a tile's faces need a surface material",
                    materials[m]
                )));
            }
            mapped.push((usemtl.to_string(), m));
        }
        tiles.push(Tile {
            name: name.to_string(),
            mesh,
            period_m,
            materials: mapped,
        });
    }
    Ok(tiles)
}
