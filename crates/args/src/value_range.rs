//! `--false-colour-range MIN:MAX`: a range of finite numbers.

/// `MIN:MAX` of the false-colour ramp.
pub fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let parse = |t: &str| t.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    match s.split_once(':') {
        Some((a, b)) => match (parse(a), parse(b)) {
            (Some(a), Some(b)) if b > a => Ok((a, b)),
            _ => Err(format!(
                "`{s}`: expected MIN:MAX with MIN < MAX, e.g. 0:500"
            )),
        },
        None => Err(format!("`{s}`: expected MIN:MAX, e.g. 0:500")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_refuse_with_the_text() {
        assert_eq!(parse_range("0:500"), Ok((0.0, 500.0)));
        for bad in ["500", "5:1", "1:1", "a:2", "0:inf", "NaN:1"] {
            assert!(parse_range(bad).unwrap_err().contains(bad), "{bad}");
        }
    }
}
