//! The papers' error colours (Cheng et al. 2007 §IV-D): blue, green, yellow and red at 0, ⅓, ⅔
//! and 1 of the scale, linear in between, red beyond.

/// The colour of `t` = error / scale (`t ≥ 1` and non-finite values are red).
pub fn error_color(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 4] = [
        [0.0, 0.0, 255.0],
        [0.0, 255.0, 0.0],
        [255.0, 255.0, 0.0],
        [255.0, 0.0, 0.0],
    ];
    let x = if t.is_finite() {
        t.clamp(0.0, 1.0) * 3.0
    } else {
        3.0
    };
    let i = (x.floor() as usize).min(2);
    let f = x - i as f64;
    std::array::from_fn(|k| (STOPS[i][k] + f * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stops_and_clamping() {
        assert_eq!(error_color(0.0), [0, 0, 255]);
        assert_eq!(error_color(1.0 / 3.0), [0, 255, 0]);
        assert_eq!(error_color(2.0 / 3.0), [255, 255, 0]);
        assert_eq!(error_color(1.0), [255, 0, 0]);
        assert_eq!(error_color(7.0), [255, 0, 0]);
        assert_eq!(error_color(f64::NAN), [255, 0, 0]);
        assert_eq!(error_color(-1.0), [0, 0, 255]);
        assert_eq!(error_color(1.0 / 6.0), [0, 128, 128]);
    }
}
