//! Durations of virtual time as the command line and the debugger take
//! them (`500ms`, `10s`, `5m`).

/// Parses `500ms`, `10s`, `5m`, `1h`, `2.5` (seconds) into nanoseconds.
pub fn parse_duration(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 1e6)
    } else if let Some(n) = t.strip_suffix("us") {
        (n, 1e3)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1e9)
    } else if let Some(n) = t.strip_suffix('m') {
        (n, 60e9)
    } else if let Some(n) = t.strip_suffix('h') {
        (n, 3600e9)
    } else {
        (t, 1e9)
    };
    let v: f64 = number.trim().parse().map_err(|_| format!("'{text}' is not a duration (use e.g. 500ms, 10s, 5m, 1h)"))?;
    if !(v >= 0.0 && v.is_finite()) {
        return Err(format!("'{text}' is not a duration: a finite time forward"));
    }
    // Refused, not capped: 2^64 ns is the end of virtual time
    // (docs/behaviour.md rule 84).
    let ns = v * scale;
    if ns >= u64::MAX as f64 {
        return Err(format!("'{text}' is too long: virtual time ends after {:.0} s (about 584 years)", u64::MAX as f64 * 1e-9));
    }
    Ok(ns as u64)
}

#[cfg(test)]
mod tests {
    use super::parse_duration;

    #[test]
    fn durations_out_of_range_are_refused_not_capped() {
        assert_eq!(parse_duration("1.5s"), Ok(1_500_000_000));
        assert_eq!(parse_duration("500ms"), Ok(500_000_000));
        assert_eq!(parse_duration("1e10"), Ok(10_000_000_000_000_000_000));
        for long in ["18446744074s", "1e12", "1e300h"] {
            assert!(parse_duration(long).unwrap_err().contains("is too long"), "{long}");
        }
        for bad in ["-1s", "nan", "inf", "-inf"] {
            assert!(parse_duration(bad).unwrap_err().contains("is not a duration"), "{bad}");
        }
    }
}
