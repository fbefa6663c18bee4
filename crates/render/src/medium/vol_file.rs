//! Mitsuba's `.vol` grid files (Mitsuba 0.6 `gridvolume`, Mitsuba 3 `VolumeGrid`): the
//! density of a grid medium. Layout, little-endian:
//!
//! | bytes | content |
//! |---|---|
//! | 0–2 | `VOL` |
//! | 3 | version, 3 |
//! | 4–7 | encoding, i32: 1 = float32 (the only one read) |
//! | 8–19 | x, y, z resolution, i32 each |
//! | 20–23 | channels, i32: 1 (a scalar density) |
//! | 24–47 | bounding box, 6 × f32: xmin ymin zmin xmax ymax zmax |
//! | 48– | the voxels, f32, x fastest: index ((z·yres + y)·xres + x)·channels + c |
//!
//! A density is finite and ≥ 0, so NaN, infinite or negative voxels are errors naming the
//! voxel, never clamped: a broken file would otherwise render as a plausible medium.

use std::path::Path;

use glam::Vec3;

const MAGIC: &[u8; 3] = b"VOL";
const VERSION: u8 = 3;
const ENCODING_FLOAT32: i32 = 1;
const HEADER_BYTES: usize = 48;

/// A `.vol` file that cannot be read, with the file's name when there is one.
pub type VolError = crate::file_error::FileError;

/// A scalar voxel grid with the bounding box the file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct VolGrid {
    /// Voxels along x, y, z (each ≥ 1).
    pub resolution: [usize; 3],
    /// The file's box, m (min < max on every axis).
    pub bounds_min_m: Vec3,
    pub bounds_max_m: Vec3,
    /// Finite, ≥ 0, x fastest.
    pub values: Vec<f32>,
}

fn read_i32(bytes: &[u8], at: usize) -> i32 {
    i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
}

fn read_f32(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
}

impl VolGrid {
    /// The voxel at (x, y, z); each index below its resolution.
    #[inline]
    pub fn value(&self, x: usize, y: usize, z: usize) -> f32 {
        let [nx, ny, _] = self.resolution;
        self.values[(z * ny + y) * nx + x]
    }

    /// Parses a file's bytes (see the module docs for the layout and what is refused).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, VolError> {
        if bytes.len() < HEADER_BYTES {
            return Err(VolError::new(format!(
                "not a .vol file: {} bytes, shorter than the {HEADER_BYTES}-byte header",
                bytes.len()
            )));
        }
        if &bytes[0..3] != MAGIC {
            return Err(VolError::new(format!(
                "not a .vol file: starts with {:?}, expected \"VOL\"",
                String::from_utf8_lossy(&bytes[0..3])
            )));
        }
        if bytes[3] != VERSION {
            return Err(VolError::new(format!(
                "unsupported .vol version {}: only version {VERSION} is read",
                bytes[3]
            )));
        }
        let encoding = read_i32(bytes, 4);
        if encoding != ENCODING_FLOAT32 {
            return Err(VolError::new(format!(
                "unsupported .vol encoding {encoding}: only 1 (float32) is read"
            )));
        }
        let dims = [read_i32(bytes, 8), read_i32(bytes, 12), read_i32(bytes, 16)];
        if dims.iter().any(|&d| d < 1) {
            return Err(VolError::new(format!(
                "resolution {} × {} × {}: every axis needs at least one voxel",
                dims[0], dims[1], dims[2]
            )));
        }
        let channels = read_i32(bytes, 20);
        if channels != 1 {
            return Err(VolError::new(format!(
                "{channels} channels: a density grid has exactly 1"
            )));
        }
        let min = Vec3::new(
            read_f32(bytes, 24),
            read_f32(bytes, 28),
            read_f32(bytes, 32),
        );
        let max = Vec3::new(
            read_f32(bytes, 36),
            read_f32(bytes, 40),
            read_f32(bytes, 44),
        );
        if !(min.is_finite() && max.is_finite() && min.cmplt(max).all()) {
            return Err(VolError::new(format!(
                "empty or degenerate bounding box [{min}, {max}]: min < max is needed on every axis"
            )));
        }
        let resolution = dims.map(|d| d as usize);
        let expected = resolution
            .iter()
            .try_fold(4usize, |acc, &d| acc.checked_mul(d))
            .and_then(|data| data.checked_add(HEADER_BYTES));
        if expected != Some(bytes.len()) {
            let expected = expected.map_or("more than usize::MAX".to_string(), |e| e.to_string());
            return Err(VolError::new(format!(
                "size mismatch: a {} × {} × {} float32 grid is {expected} bytes, the file has {}",
                dims[0],
                dims[1],
                dims[2],
                bytes.len()
            )));
        }
        let values: Vec<f32> = bytes[HEADER_BYTES..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect();
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            let [nx, ny, _] = resolution;
            let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
            return Err(VolError::new(format!(
                "voxel (x {x}, y {y}, z {z}) is {}: a density is finite and ≥ 0",
                values[i]
            )));
        }
        Ok(Self {
            resolution,
            bounds_min_m: min,
            bounds_max_m: max,
            values,
        })
    }

    /// Reads a file; errors name it.
    pub fn read(path: &Path) -> Result<Self, VolError> {
        let bytes =
            std::fs::read(path).map_err(|e| VolError::new(format!("cannot read: {e}")).at(path))?;
        Self::from_bytes(&bytes).map_err(|e| e.at(path))
    }

    /// The file's bytes (version 3, float32, 1 channel).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_BYTES + 4 * self.values.len());
        out.extend_from_slice(MAGIC);
        out.push(VERSION);
        out.extend_from_slice(&ENCODING_FLOAT32.to_le_bytes());
        for d in self.resolution {
            out.extend_from_slice(&(d as i32).to_le_bytes());
        }
        out.extend_from_slice(&1i32.to_le_bytes());
        for v in self
            .bounds_min_m
            .to_array()
            .into_iter()
            .chain(self.bounds_max_m.to_array())
        {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in &self.values {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> VolGrid {
        VolGrid {
            resolution: [3, 2, 4],
            bounds_min_m: Vec3::new(-1.0, 0.0, -0.5),
            bounds_max_m: Vec3::new(1.0, 2.0, 0.5),
            values: (0..24).map(|i| i as f32 * 0.25).collect(),
        }
    }

    /// Writes `bytes` as `name` in a fresh folder and reads it back.
    fn read_written(name: &str, bytes: &[u8]) -> (tempfile::TempDir, Result<VolGrid, VolError>) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let result = VolGrid::read(&path);
        (dir, result)
    }

    /// The error of reading `bytes`, checked to name the file.
    fn error_of(bytes: &[u8]) -> String {
        let (_dir, result) = read_written("smoke.vol", bytes);
        let message = result.expect_err("the file is broken").to_string();
        assert!(message.contains("smoke.vol: "), "{message}");
        message
    }

    #[test]
    fn a_written_grid_reads_back_x_fastest() {
        let g = grid();
        let (_dir, read) = read_written("ok.vol", &g.to_bytes());
        let read = read.unwrap();
        assert_eq!(read, g);
        // ((z·yres + y)·xres + x): x = 2, y = 1, z = 3 → (3·2 + 1)·3 + 2 = 23.
        assert_eq!(read.value(2, 1, 3), 23.0 * 0.25);
        assert_eq!(read.value(1, 0, 0), 0.25);
        assert_eq!(read.value(0, 1, 0), 3.0 * 0.25);
        assert_eq!(read.value(0, 0, 1), 6.0 * 0.25);
    }

    #[test]
    fn a_hand_built_file_matches_the_layout() {
        // Hand-built header, independent of `to_bytes`: 1 × 1 × 2 grid.
        let mut b = b"VOL\x03".to_vec();
        for v in [1i32, 1, 1, 2, 1] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for v in [0.0f32, 0.0, 0.0, 1.0, 2.0, 3.0, 0.5, 7.0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        let g = VolGrid::from_bytes(&b).unwrap();
        assert_eq!(g.resolution, [1, 1, 2]);
        assert_eq!(g.bounds_max_m, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(g.values, vec![0.5, 7.0]);
    }

    #[test]
    fn bad_magic_is_refused() {
        let mut b = grid().to_bytes();
        b[0..3].copy_from_slice(b"VOX");
        let m = error_of(&b);
        assert!(
            m.contains("\"VOX\"") && m.contains("expected \"VOL\""),
            "{m}"
        );
        let m = error_of(b"VOL");
        assert!(
            m.contains("3 bytes, shorter than the 48-byte header"),
            "{m}"
        );
    }

    #[test]
    fn other_versions_are_refused() {
        let mut b = grid().to_bytes();
        b[3] = 2;
        let m = error_of(&b);
        assert!(m.contains("unsupported .vol version 2"), "{m}");
    }

    #[test]
    fn encodings_other_than_float32_are_refused() {
        let mut b = grid().to_bytes();
        b[4..8].copy_from_slice(&2i32.to_le_bytes());
        let m = error_of(&b);
        assert!(
            m.contains("unsupported .vol encoding 2") && m.contains("float32"),
            "{m}"
        );
    }

    #[test]
    fn more_than_one_channel_is_refused() {
        let mut b = grid().to_bytes();
        b[20..24].copy_from_slice(&3i32.to_le_bytes());
        let m = error_of(&b);
        assert!(m.contains("3 channels"), "{m}");
    }

    #[test]
    fn size_mismatch_gives_expected_and_actual_bytes() {
        let mut b = grid().to_bytes();
        b.truncate(b.len() - 4);
        let m = error_of(&b);
        assert!(
            m.contains("size mismatch") && m.contains("is 144 bytes, the file has 140"),
            "{m}"
        );
        let mut b = grid().to_bytes();
        b.extend_from_slice(&[0; 8]);
        let m = error_of(&b);
        assert!(m.contains("is 144 bytes, the file has 152"), "{m}");
    }

    #[test]
    fn zero_or_negative_resolution_is_refused() {
        let mut b = grid().to_bytes();
        b[12..16].copy_from_slice(&0i32.to_le_bytes());
        let m = error_of(&b);
        assert!(m.contains("3 × 0 × 4"), "{m}");
    }

    #[test]
    fn nan_infinite_and_negative_voxels_name_their_index() {
        for (bad, shown) in [(f32::NAN, "NaN"), (-0.5, "-0.5"), (f32::INFINITY, "inf")] {
            let mut g = grid();
            // x 1, y 0, z 2 → (2·2 + 0)·3 + 1 = 13.
            g.values[13] = bad;
            let m = error_of(&g.to_bytes());
            assert!(
                m.contains(&format!("voxel (x 1, y 0, z 2) is {shown}")),
                "{m}"
            );
        }
    }

    #[test]
    fn empty_or_degenerate_bounds_are_refused() {
        for (min, max) in [
            (Vec3::ZERO, Vec3::ZERO),
            (Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0)),
            (Vec3::ONE, Vec3::ZERO),
            (Vec3::ZERO, Vec3::new(1.0, f32::NAN, 1.0)),
        ] {
            let mut g = grid();
            g.bounds_min_m = min;
            g.bounds_max_m = max;
            let m = error_of(&g.to_bytes());
            assert!(m.contains("empty or degenerate bounding box"), "{m}");
        }
    }

    #[test]
    fn a_missing_file_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("absent.vol");
        let m = VolGrid::read(&path).unwrap_err().to_string();
        assert!(m.contains("absent.vol: cannot read"), "{m}");
    }
}
