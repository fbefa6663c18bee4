//! Whole-number options (`--seed`, `--checkpoints`, `--spectral-bins`, `--spp`, …) parsed
//! with messages in the project's words: clap's own parser answers "not in 0..=4294967295".

/// A whole number from 0 to `u32::MAX`.
pub fn parse_u32(text: &str) -> Result<u32, String> {
    parse(text)
        .and_then(|n| u32::try_from(n).map_err(|_| format!("`{text}`: at most {} here", u32::MAX)))
}

/// A whole number from 0 to `u64::MAX`.
pub fn parse_u64(text: &str) -> Result<u64, String> {
    parse(text)
}

fn parse(text: &str) -> Result<u64, String> {
    let t = text.trim();
    if t.starts_with('-') {
        return Err(format!("`{text}`: expected a whole number ≥ 0"));
    }
    t.parse::<u64>().map_err(|e| match e.kind() {
        std::num::IntErrorKind::PosOverflow => {
            format!("`{text}`: at most {} here", u64::MAX)
        }
        _ => format!("`{text}`: expected a whole number, e.g. 16"),
    })
}

/// `--spp N`: a whole number from 1 to 2³² − 1, said in those words.
pub fn parse_spp(s: &str) -> Result<u32, String> {
    let t = s.trim();
    let digits = !t.is_empty() && t.chars().all(|c| c.is_ascii_digit());
    match t.parse::<u64>() {
        Ok(0) => Err(format!("`{s}`: expected at least 1 sample per pixel")),
        Ok(n) if n <= u64::from(u32::MAX) => Ok(n as u32),
        // Too large for u32, or for u64: still digits.
        Ok(_) | Err(_) if digits => Err(format!("`{s}`: at most {} samples per pixel", u32::MAX)),
        Ok(_) | Err(_) => Err(format!(
            "`{s}`: expected a whole number of samples per pixel, e.g. 64"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_refused_in_words() {
        assert_eq!(parse_u32("16"), Ok(16));
        assert_eq!(parse_u64(" 7 "), Ok(7));
        assert!(parse_u32("99999999999")
            .unwrap_err()
            .contains("at most 4294967295"));
        assert!(parse_u64("99999999999999999999")
            .unwrap_err()
            .contains("at most"));
        assert!(parse_u32("-3").unwrap_err().contains("≥ 0"));
        assert!(parse_u32("1.5").unwrap_err().contains("whole number"));
        assert_eq!(parse_spp("64"), Ok(64));
        assert!(parse_spp("0").unwrap_err().contains("at least 1"));
        assert!(parse_spp("99999999999").unwrap_err().contains("at most"));
        assert!(parse_spp("6.5").unwrap_err().contains("`6.5`"));
    }
}
