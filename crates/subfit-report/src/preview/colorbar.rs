//! The colour bar of [`super::render`]: a vertical [`crate::error_color`] ramp on the right of
//! the image, ticked at 0, ⅓, ⅔ and 1 of the scale, labelled in a 5×7 bitmap font.

use super::{ColorBar, Image, PreviewOptions};
use crate::error_color;

/// Where the bar goes, in pixels.
pub(crate) struct BarLayout {
    /// Width reserved on the right of the image.
    pub width: u32,
    scale: u32,
    bar_x: u32,
    bar_w: u32,
    top: u32,
    bar_h: u32,
    labels: [String; 4],
}

/// Glyph cell: 5×7 dots plus one column of spacing, times the font scale.
const GLYPH_W: u32 = 5;
const GLYPH_H: u32 = 7;
const ADVANCE: u32 = GLYPH_W + 1;

/// Sizes the bar for the image: font scale `max(1, height / 300)`, bar 70 % of the height.
pub(crate) fn layout(bar: &ColorBar, options: &PreviewOptions) -> BarLayout {
    let (w, h) = (options.width, options.height);
    let scale = (h / 300).max(1);
    let labels: [String; 4] = std::array::from_fn(|i| {
        format!("{}{}", format_value(bar.max * i as f64 / 3.0), bar.suffix)
    });
    let chars = labels.iter().map(|l| l.chars().count()).max().unwrap_or(1) as u32;
    let margin = 4 * scale + 4;
    let bar_w = (h / 30).max(8);
    let gap = 3 * scale + 2;
    let width = (margin + bar_w + gap + chars * ADVANCE * scale + margin).min(w / 2);
    let bar_h = (h * 7 / 10).clamp(1, h);
    BarLayout {
        width,
        scale,
        bar_x: w - width + margin,
        bar_w,
        top: (h - bar_h) / 2,
        bar_h,
        labels,
    }
}

/// Draws the ramp (red at the top), its border, ticks and labels.
pub(crate) fn draw(image: &mut Image, l: &BarLayout) {
    const INK: [u8; 3] = [40, 40, 40];
    for y in 0..l.bar_h {
        let t = 1.0 - f64::from(y) / f64::from((l.bar_h - 1).max(1));
        let c = error_color(t);
        for x in 0..l.bar_w {
            put(image, l.bar_x + x, l.top + y, c);
        }
    }
    let (x0, x1, y0, y1) = (l.bar_x, l.bar_x + l.bar_w - 1, l.top, l.top + l.bar_h - 1);
    for x in x0..=x1 {
        put(image, x, y0, INK);
        put(image, x, y1, INK);
    }
    for y in y0..=y1 {
        put(image, x0, y, INK);
        put(image, x1, y, INK);
    }
    for (i, label) in l.labels.iter().enumerate() {
        let y = y1 - (f64::from(l.bar_h - 1) * i as f64 / 3.0).round() as u32;
        for x in x1..x1 + 2 * l.scale + 1 {
            put(image, x, y, INK);
        }
        let tx = x1 + 3 * l.scale + 2;
        let ty = y.saturating_sub(GLYPH_H * l.scale / 2);
        text(image, tx, ty, label, l.scale, INK);
    }
}

/// A compact label: `0`, up to three significant digits for `1e-2 ≤ |v| < 1e4`, else
/// scientific (`1.2e-5`).
fn format_value(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_nan() { "-".into() } else { "0".into() };
    }
    let a = v.abs();
    if (1e-2..1e4).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.1e}")
    }
}

fn put(image: &mut Image, x: u32, y: u32, c: [u8; 3]) {
    if x < image.width && y < image.height {
        let i = 3 * (y as usize * image.width as usize + x as usize);
        image.rgb[i..i + 3].copy_from_slice(&c);
    }
}

/// Draws `s` with its top-left corner at `(x, y)`, each dot `scale × scale` pixels.
fn text(image: &mut Image, x: u32, y: u32, s: &str, scale: u32, c: [u8; 3]) {
    for (n, ch) in s.chars().enumerate() {
        let gx = x + n as u32 * ADVANCE * scale;
        for (row, bits) in glyph(ch).iter().enumerate() {
            for col in 0..GLYPH_W {
                if bits >> (GLYPH_W - 1 - col) & 1 == 1 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            put(image, gx + col * scale + dx, y + row as u32 * scale + dy, c);
                        }
                    }
                }
            }
        }
    }
}

/// 5×7 glyphs, one byte per row, the low five bits left to right.
fn glyph(c: char) -> [u8; 7] {
    match c {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C],
        '-' => [0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00],
        '+' => [0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00],
        'e' => [0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        _ => [0; 7],
    }
}

#[cfg(test)]
mod tests {
    use super::format_value;

    #[test]
    fn labels_are_compact() {
        assert_eq!(format_value(0.0), "0");
        assert_eq!(format_value(0.5), "0.5");
        assert_eq!(format_value(1.0 / 3.0), "0.333");
        assert_eq!(format_value(12.0), "12");
        assert_eq!(format_value(0.001), "1.0e-3");
        assert_eq!(format_value(2e5), "2.0e5");
    }
}
