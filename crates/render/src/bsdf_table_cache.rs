//! The BSDF angular bandwidth tables (`bsdf_angular_table.rs`) kept across runs in a cache
//! directory (`--cache-dir`): a fixed-size binary file per table, named by a fingerprint of
//! what the table is built from, so a changed material is a new name, never a stale file.
//!
//! The fingerprint hashes (64-bit FNV-1a) the format version, the table's sizes, β, the
//! lobe's flags and closed form, and f·cos's luminance at the neutral hit and the table's
//! wavelengths for every incident cell against 8 × 8 outgoing directions (16 384 values,
//! a few ms even for a MERL table). The build reads the same BSDF at 64 × 64 outgoing
//! directions per incident cell, so two materials share a name only if they agree
//! bit for bit at all of those 16 384 pairs; any change of an analytic parameter or of
//! measured data changes every value's bits. A file that cannot be read back (truncated,
//! another version) is rebuilt and replaced.

use std::io::Write;
use std::path::{Path, PathBuf};

use prism_bandwidth::local_bandwidth::HAAR_BETA_CYCLES_PER_TEXEL;

use crate::bsdf::{Bxdf, TransportMode};
use crate::bsdf_angular_table::{
    cell_direction, with_tabulated_bsdf, MaterialAngularBandwidth, SLICE_TEXELS, TABLE_CELLS,
};
use crate::material::Material;
use crate::probe::reflectance_y;
use crate::stable_hash::Fnv1a64;
use prism_spectrum::XyzWeights;

/// Bumped whenever a table's construction or this file layout changes.
const FORMAT_VERSION: u32 = 1;
const MAGIC: &[u8; 8] = b"PRISMBAT";
/// Outgoing directions per axis of the fingerprint.
const FINGERPRINT_OUTGOING: usize = 8;

/// What `AngularTableCache::table` did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableCacheUse {
    /// Read from its file.
    Loaded,
    /// Built and written (no file yet, or one that could not be read back).
    Built,
    /// Lambert, Dirac or closed-form lobes: nothing to tabulate or keep.
    NotTabulated,
}

/// A directory of angular bandwidth tables.
#[derive(Clone, Debug)]
pub struct AngularTableCache {
    dir: PathBuf,
}

impl AngularTableCache {
    /// A cache in `dir` (which must exist and be writable).
    pub fn new(dir: PathBuf) -> Self {
        Self { dir }
    }

    /// `material`'s table from its file, else built and written there.
    pub fn table(
        &self,
        material: &Material,
    ) -> Result<(MaterialAngularBandwidth, TableCacheUse), String> {
        let Some(key) = fingerprint(material) else {
            return Ok((
                MaterialAngularBandwidth::build(material),
                TableCacheUse::NotTabulated,
            ));
        };
        let path = self.path_of(key);
        if let Some(table) = read_table(&path) {
            return Ok((
                MaterialAngularBandwidth::Table(table),
                TableCacheUse::Loaded,
            ));
        }
        let built = MaterialAngularBandwidth::build(material);
        if let MaterialAngularBandwidth::Table(values) = &built {
            write_table(&path, values)?;
        }
        Ok((built, TableCacheUse::Built))
    }

    /// The file a table of fingerprint `key` lives in.
    pub fn path_of(&self, key: u64) -> PathBuf {
        self.dir.join(format!("bsdf-angular-table-{key:016x}.bin"))
    }
}

/// The fingerprint of `material`'s table (module docs); `None` when `build` makes no table.
pub fn fingerprint(material: &Material) -> Option<u64> {
    with_tabulated_bsdf(material, |bsdf, wavelengths| {
        let mut hash = Fnv1a64::new();
        for word in [
            FORMAT_VERSION,
            TABLE_CELLS as u32,
            SLICE_TEXELS as u32,
            HAAR_BETA_CYCLES_PER_TEXEL.to_bits(),
            u32::from(bsdf.lobe.is_isotropic()),
            bsdf.lobe.angular_bandwidth_cycles_per_rad().to_bits(),
        ] {
            hash.write(&word.to_le_bytes());
        }
        let n = TABLE_CELLS;
        let m = FINGERPRINT_OUTGOING;
        let xyz = XyzWeights::new(wavelengths);
        for incident in 0..n * n {
            let wi = cell_direction(incident / n, incident % n, n);
            for outgoing in 0..m * m {
                let wo = cell_direction(outgoing / m, outgoing % m, m);
                let y = reflectance_y(bsdf.eval(wo, wi, TransportMode::Radiance), &xyz);
                hash.write(&y.to_bits().to_le_bytes());
            }
        }
        hash.finish()
    })
    .ok()
}

fn table_len() -> usize {
    TABLE_CELLS.pow(4)
}

/// The table in `path`, if it is one of this version and size with finite, non-negative
/// values.
fn read_table(path: &Path) -> Option<Vec<f32>> {
    let bytes = std::fs::read(path).ok()?;
    let header = MAGIC.len() + 8;
    if bytes.len() != header + 4 * table_len() || &bytes[..MAGIC.len()] != MAGIC {
        return None;
    }
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    if word(MAGIC.len()) != FORMAT_VERSION || word(MAGIC.len() + 4) != TABLE_CELLS as u32 {
        return None;
    }
    let values: Vec<f32> = bytes[header..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    values
        .iter()
        .all(|v| v.is_finite() && *v >= 0.0)
        .then_some(values)
}

/// Writes the table through a temporary sibling and a rename (`prism_image::io`'s atomic
/// write), so that a reader never sees half a file.
fn write_table(path: &Path, values: &[f32]) -> Result<(), String> {
    prism_image::io::write_stream_atomically(path, |file| {
        file.write_all(MAGIC)?;
        file.write_all(&FORMAT_VERSION.to_le_bytes())?;
        file.write_all(&(TABLE_CELLS as u32).to_le_bytes())?;
        for v in values {
            file.write_all(&v.to_le_bytes())?;
        }
        Ok(())
    })
    .map_err(|e| format!("BSDF table cache: cannot write ({e})"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_scene::parse_scene_str;

    use crate::scene_build::RenderScene;

    fn scene(json_material: &str) -> RenderScene {
        let json = format!(
            r#"{{"materials": {{"m": {json_material}}},
                "shapes": [{{"type": "sphere", "material": "m"}}]}}"#
        );
        RenderScene::build(&parse_scene_str(&json, "t.json").unwrap(), None).unwrap()
    }

    const GGX: &str = r#"{"type": "conductor", "metal": "Au", "roughness": 0.1}"#;

    #[test]
    fn a_table_is_built_once_then_read_back_and_a_changed_material_is_a_new_file() {
        let dir = tempfile::tempdir().unwrap();
        let cache = AngularTableCache::new(dir.path().to_path_buf());
        let ggx = scene(GGX);
        let (built, first) = cache.table(ggx.material(0)).unwrap();
        assert_eq!(first, TableCacheUse::Built);
        let (loaded, second) = cache.table(ggx.material(0)).unwrap();
        assert_eq!(second, TableCacheUse::Loaded);
        assert_eq!(built, loaded);
        assert_eq!(built, MaterialAngularBandwidth::build(ggx.material(0)));

        // A roughness one part in a thousand away is another table.
        let near = scene(&GGX.replace("0.1", "0.1001"));
        assert_ne!(fingerprint(ggx.material(0)), fingerprint(near.material(0)));
        assert_eq!(
            cache.table(near.material(0)).unwrap().1,
            TableCacheUse::Built
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);

        // Lambert needs no table and leaves no file.
        let lambert = scene(r#"{"type": "lambert", "reflectance": 0.5}"#);
        let (table, use_) = cache.table(lambert.material(0)).unwrap();
        assert_eq!(use_, TableCacheUse::NotTabulated);
        assert_eq!(table, MaterialAngularBandwidth::Constant(0.0));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn a_file_that_cannot_be_read_back_is_rebuilt_and_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let cache = AngularTableCache::new(dir.path().to_path_buf());
        let ggx = scene(GGX);
        let path = cache.path_of(fingerprint(ggx.material(0)).unwrap());
        let (built, _) = cache.table(ggx.material(0)).unwrap();
        let whole = std::fs::read(&path).unwrap();
        for broken in [whole[..whole.len() - 1].to_vec(), {
            let mut b = whole.clone();
            b[MAGIC.len()] ^= 1; // another version
            b
        }] {
            std::fs::write(&path, broken).unwrap();
            let (again, use_) = cache.table(ggx.material(0)).unwrap();
            assert_eq!((again, use_), (built.clone(), TableCacheUse::Built));
            assert_eq!(std::fs::read(&path).unwrap(), whole);
        }
    }
}
