//! The viewer's colours in one place: the part palette ("Colour by part"), the joint axis rods
//! and the true parts' ghost, with the sRGB text the page's legend shows. The part palette keeps
//! clear of the axis colours (CIE76 ΔE ≥ 30, tested) so a part never reads as an axis.

/// Part colours when colouring by part, as sRGB bytes (what the page shows; the renderer takes
/// them linear). Part 0, the base, is light grey; the others lean on the Okabe–Ito set, leaving
/// out its orange and blue, which the axes use.
const PALETTE_SRGB: [[u8; 3]; 8] = [
    [0xc0, 0xc0, 0xc0], // grey: the base
    [0x00, 0x9e, 0x73], // bluish green
    [0xcc, 0x79, 0xa7], // reddish purple
    [0xf0, 0xe4, 0x42], // yellow
    [0x6a, 0x3d, 0x9a], // purple
    [0x00, 0xcc, 0xcc], // cyan
    [0xe3, 0x1a, 0x1c], // red
    [0x7f, 0x7f, 0x00], // olive
];

/// Axis rod colours (linear RGB): revolute orange, prismatic blue.
pub const REVOLUTE_ROD: [f32; 3] = [1.0, 0.45, 0.0];
/// See [`REVOLUTE_ROD`].
pub const PRISMATIC_ROD: [f32; 3] = [0.0, 0.35, 1.0];
/// The true axes' colour, when the truth is known: near black, apart from the fitted ones.
pub const TRUTH_ROD: [f32; 3] = [0.05, 0.05, 0.05];
/// The true parts' colour (linear), drawn as a see-through ghost over the fitted twin: dark like
/// the true axes, so "dark = true" holds across the viewer.
pub const TRUTH_PART: [f32; 3] = [0.02, 0.02, 0.03];

/// Linear → sRGB transfer (the renderer's `srgb_encode`) of one channel.
fn encode(linear: f32) -> f32 {
    let x = linear.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB → linear of one channel byte.
pub(super) fn decode(byte: u8) -> f32 {
    let s = byte as f32 / 255.0;
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// The number of distinct part colours; part `k` has colour `k % PALETTE_LEN`.
pub const PALETTE_LEN: usize = PALETTE_SRGB.len();

/// Part `k`'s colour (linear RGB, what the renderer takes).
pub fn part_colour(k: usize) -> [f32; 3] {
    PALETTE_SRGB[k % PALETTE_LEN].map(decode)
}

/// Part `k`'s colour as CSS text (`#rrggbb`): what a part facing the camera looks like.
pub fn part_css(k: usize) -> String {
    let [r, g, b] = PALETTE_SRGB[k % PALETTE_LEN];
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// A linear colour as CSS text (`#rrggbb`, sRGB-encoded as the renderer writes it).
pub fn css(linear: [f32; 3]) -> String {
    let [r, g, b] = linear.map(|c| (encode(c) * 255.0).round() as u8);
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// CIE L*a*b* (D65) of a linear sRGB colour.
pub fn lab(linear: [f32; 3]) -> [f32; 3] {
    let [r, g, b] = linear;
    let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.950_47;
    let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.088_83;
    let f = |t: f32| {
        if t > 216.0 / 24389.0 {
            t.cbrt()
        } else {
            (24389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(x), f(y), f(z));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIE76 colour difference ΔE of two linear colours (about 2.3 is just noticeable; 30 and up
/// reads as a different colour name).
pub fn delta_e(a: [f32; 3], b: [f32; 3]) -> f32 {
    let (a, b) = (lab(a), lab(b));
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_part_colour_is_far_from_every_axis_colour() {
        for k in 0..PALETTE_LEN {
            for (name, axis) in [
                ("hinge", REVOLUTE_ROD),
                ("slide", PRISMATIC_ROD),
                ("truth", TRUTH_ROD),
            ] {
                let d = delta_e(part_colour(k), axis);
                assert!(d >= 30.0, "part {k} is ΔE {d:.1} from the {name} axis");
            }
        }
    }

    #[test]
    fn part_colours_differ_from_each_other_and_the_ghost() {
        for a in 0..PALETTE_LEN {
            for b in a + 1..PALETTE_LEN {
                let d = delta_e(part_colour(a), part_colour(b));
                assert!(d >= 25.0, "parts {a} and {b} are only ΔE {d:.1} apart");
            }
            let d = delta_e(part_colour(a), TRUTH_PART);
            assert!(
                d >= 30.0,
                "part {a} is ΔE {d:.1} from the true parts' ghost"
            );
        }
    }

    #[test]
    fn css_text_round_trips_the_palette() {
        assert_eq!(part_css(0), "#c0c0c0");
        assert_eq!(part_css(PALETTE_LEN + 1), part_css(1));
        for k in 0..PALETTE_LEN {
            assert_eq!(css(part_colour(k)), part_css(k), "part {k}");
        }
        // Lab's reference points: white is L 100, black L 0, both grey (a = b = 0).
        let w = lab([1.0; 3]);
        assert!(
            (w[0] - 100.0).abs() < 0.1 && w[1].abs() < 0.1 && w[2].abs() < 0.1,
            "{w:?}"
        );
        assert!(lab([0.0; 3])[0].abs() < 1e-3);
    }
}
