//! `--checkpoint-every`, `--progress-every`: durations as the command line spells them.

use std::time::Duration;

/// `Ns`, `Nm` or `Nh` (a whole number), at least one second.
pub fn parse_duration(s: &str) -> Result<Duration, String> {
    let t = s.trim();
    // The unit is the last character, which may be more than one byte (found by fuzzing:
    // a byte index inside `\u{feff}` panicked).
    let split = t.char_indices().last().map_or(0, |(i, _)| i);
    let (number, unit) = t.split_at(split);
    let seconds_per = match unit {
        "s" => 1,
        "m" => 60,
        "h" => 3600,
        _ => {
            return Err(format!(
                "`{s}`: expected a duration Ns, Nm or Nh (e.g. 60s, 5m, 1h)"
            ))
        }
    };
    let n: u64 = number
        .parse()
        .map_err(|_| format!("`{s}`: expected a whole number before `{unit}` (e.g. 60s)"))?;
    let seconds = n.saturating_mul(seconds_per);
    if seconds < 1 {
        return Err(format!("`{s}`: expected at least 1s"));
    }
    Ok(Duration::from_secs(seconds))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_take_s_m_h_and_at_least_a_second() {
        assert_eq!(parse_duration("60s"), Ok(Duration::from_secs(60)));
        assert_eq!(parse_duration("2m"), Ok(Duration::from_secs(120)));
        assert_eq!(parse_duration("1h"), Ok(Duration::from_secs(3600)));
        assert!(parse_duration("0s").unwrap_err().contains("at least 1s"));
        assert!(parse_duration("10").is_err());
        assert!(parse_duration("1.5m").is_err());
        assert!(parse_duration("57\u{feff}")
            .unwrap_err()
            .contains("57\u{feff}"));
        assert!(parse_duration("5é").is_err());
    }
}
