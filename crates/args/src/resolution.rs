//! `--resolution WIDTHxHEIGHT`.

use glam::UVec2;

/// `WIDTHxHEIGHT` (or `X`), both sides whole numbers ≥ 1.
pub fn parse_resolution(s: &str) -> Result<UVec2, String> {
    let parse = |t: &str| t.trim().parse::<u32>().ok().filter(|&v| v >= 1);
    match s.split_once(['x', 'X']) {
        Some((w, h)) => match (parse(w), parse(h)) {
            (Some(w), Some(h)) => Ok(UVec2::new(w, h)),
            _ => Err(format!(
                "`{s}`: expected WIDTHxHEIGHT with both ≥ 1, e.g. 64x48"
            )),
        },
        None => Err(format!("`{s}`: expected WIDTHxHEIGHT, e.g. 64x48")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_refuse_with_the_text() {
        assert_eq!(parse_resolution("64x48"), Ok(UVec2::new(64, 48)));
        assert_eq!(parse_resolution(" 8 X 4 "), Ok(UVec2::new(8, 4)));
        for bad in ["64", "0x4", "4x", "x", "4x-1", "99999999999x1"] {
            assert!(parse_resolution(bad).unwrap_err().contains(bad), "{bad}");
        }
    }
}
