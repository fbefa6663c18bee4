//! `prism tonemap`'s values: `--exposure EV|auto` and `--param KEY=VALUE`.

use std::collections::BTreeMap;

/// Every `--param KEY=VALUE` (a finite number) by key; the last of a repeated key wins.
pub fn parse_params(raw: &[String]) -> Result<BTreeMap<String, f64>, String> {
    let mut params = BTreeMap::new();
    for item in raw {
        let (key, value) = item
            .split_once('=')
            .ok_or_else(|| format!("--param {item}: expected KEY=VALUE, e.g. --param key=0.18"))?;
        let number: f64 = value
            .trim()
            .parse()
            .map_err(|_| format!("--param {item}: expected a number after `=`, found `{value}`"))?;
        if !number.is_finite() {
            return Err(format!("--param {item}: expected a finite number"));
        }
        params.insert(key.trim().to_string(), number);
    }
    Ok(params)
}

/// `--exposure EV|auto` → (EV, auto).
pub fn parse_exposure(raw: &str) -> Result<(f64, bool), String> {
    if raw.trim().eq_ignore_ascii_case("auto") {
        return Ok((0.0, true));
    }
    match raw.trim().parse::<f64>() {
        Ok(ev) if ev.is_finite() => Ok((ev, false)),
        _ => Err(format!(
            "--exposure {raw}: expected a finite number of stops (e.g. -2.5) or `auto`"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_parse_and_refuse_with_the_text() {
        assert_eq!(parse_exposure("auto"), Ok((0.0, true)));
        assert_eq!(parse_exposure("-2.5"), Ok((-2.5, false)));
        assert!(parse_exposure("inf").unwrap_err().contains("inf"));
        let params = parse_params(&["key=0.18".into(), " white = 4 ".into()]).unwrap();
        assert_eq!(params["key"], 0.18);
        assert_eq!(params["white"], 4.0);
        for bad in ["key", "key=x", "key=NaN"] {
            assert!(
                parse_params(&[bad.into()]).unwrap_err().contains(bad),
                "{bad}"
            );
        }
    }
}
