//! How long each frame of a dynamic run's GIF shows: its real time to the next frame, or that
//! times a stated slow-down when real time is too fast for a GIF.

use crate::Real;

/// The shortest frame a GIF viewer honours, hundredths of a second (browsers show shorter
/// delays at 1/10 s).
pub const MIN_DELAY: u16 = 2;

/// The delays of frames shown at the strictly increasing `times` (s) and the slow-down used:
/// frame `i` shows for `s (t_{i+1} − t_i)` (in hundredths of a second, rounded, at least
/// [`MIN_DELAY`]), `s` the smallest power of ten (1, 10, 100, …) that makes the shortest
/// interval last [`MIN_DELAY`]; the last frame holds `last` hundredths. `None` when fewer than
/// two times are given or they do not rise (the caller keeps its fixed delays).
pub fn timed_delays(times: &[Real], last: u16) -> Option<(Vec<u16>, Real)> {
    if times.len() < 2
        || !times.iter().all(|t| t.is_finite())
        || times.windows(2).any(|w| w[1] <= w[0])
    {
        return None;
    }
    let shortest = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(Real::INFINITY, Real::min);
    let mut slowdown: Real = 1.0;
    while 100.0 * slowdown * shortest < Real::from(MIN_DELAY) - 0.5 && slowdown < 1e12 {
        slowdown *= 10.0;
    }
    let mut delays: Vec<u16> = times
        .windows(2)
        .map(|w| {
            (100.0 * slowdown * (w[1] - w[0]))
                .round()
                .clamp(Real::from(MIN_DELAY), Real::from(u16::MAX)) as u16
        })
        .collect();
    delays.push(last);
    Some((delays, slowdown))
}

/// How a frame's title states the pace of the GIF it is in, for the `slowdown` that
/// [`timed_delays`] returned: `"real time"` at 1, else `"shown 100× slower"` (the factor as a
/// whole number, thousands grouped by commas: `"shown 10,000× slower"`).
pub fn pace_label(slowdown: Real) -> String {
    if slowdown <= 1.0 {
        return "real time".to_string();
    }
    let digits = format!("{:.0}", slowdown.round());
    let mut grouped = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            grouped.push(',');
        }
        grouped.push(c);
    }
    format!("shown {grouped}× slower")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_time_when_a_gif_can_show_it_else_a_power_of_ten_slower() {
        // 0.02 s apart: real time, 2 hundredths each.
        let (d, s) = timed_delays(&[0.0, 0.02, 0.04, 0.1], 200).unwrap();
        assert_eq!((d, s), (vec![2, 2, 6, 200], 1.0));
        // 1 ms apart: 100× slower, 0.1 s per frame.
        let (d, s) = timed_delays(&[0.0, 1e-3, 2e-3], 200).unwrap();
        assert_eq!((d, s), (vec![10, 10, 200], 100.0));
        // 5 µs apart: 1e4 × slower, 5 hundredths (1e3 × would give 0.5).
        let (d, s) = timed_delays(&[0.0, 5e-6], 200).unwrap();
        assert_eq!((d, s), (vec![5, 200], 1e4));
        assert!(timed_delays(&[0.0], 200).is_none());
        assert!(timed_delays(&[0.0, 0.0], 200).is_none());
    }

    #[test]
    fn the_pace_is_stated_in_words_with_the_factor_grouped() {
        assert_eq!(pace_label(1.0), "real time");
        assert_eq!(pace_label(10.0), "shown 10× slower");
        assert_eq!(pace_label(100.0), "shown 100× slower");
        assert_eq!(pace_label(1e3), "shown 1,000× slower");
        assert_eq!(pace_label(1e4), "shown 10,000× slower");
        assert_eq!(pace_label(1e6), "shown 1,000,000× slower");
        // The factor timed_delays picks for frames 1 ms apart, in words.
        let (_, s) = timed_delays(&[0.0, 1e-3, 2e-3], 200).unwrap();
        assert_eq!(pace_label(s), "shown 100× slower");
    }
}
