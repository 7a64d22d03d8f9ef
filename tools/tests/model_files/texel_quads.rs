//! The picture the sampler tests read (`gltf_samplers`, `obj_map_options`): four quads tiling
//! a `W` × `H` view, each textured from one 2 × 2 image over coordinates from −1 to 2, and
//! the test's own reading of which texel each pixel shows.

use manylight::sampling::Wrap;

pub const W: u32 = 192;
pub const H: u32 = 108;

/// The image's texels, row by row from the top: red, green / blue, white.
pub const TEXELS: [[u8; 3]; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]];

/// The 2 × 2 image of [`TEXELS`].
pub fn image() -> image::RgbaImage {
    image::RgbaImage::from_fn(2, 2, |x, y| {
        let [r, g, b] = TEXELS[(2 * y + x) as usize];
        image::Rgba([r, g, b, 255])
    })
}

/// Half the view's width (its height is 2): the quads tile the whole view.
pub fn half_width() -> f64 {
    W as f64 / H as f64
}

/// The quad's corners in the view (x0, y0, x1, y1), quads numbered left to right, then top to
/// bottom.
pub fn quad_corners(q: usize) -> (f64, f64, f64, f64) {
    let a = half_width();
    let x0 = if q.is_multiple_of(2) { -a } else { 0.0 };
    let y1 = if q < 2 { 1.0 } else { 0.0 };
    (x0, y1 - 1.0, x0 + a, y1)
}

/// The quad pixel (x, y) lies in and its coordinates there, from −1 at the quad's left and top
/// to 2 at its right and bottom; `None` within a pixel of a quad's border (left to rounding).
pub fn quad_and_uv(x: u32, y: u32) -> Option<(usize, f64, f64)> {
    let (half_w, half_h) = (W as f64 / 2.0, H as f64 / 2.0);
    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
    if px % half_w < 1.0 || py % half_h < 1.0 {
        return None;
    }
    let (fx, fy) = (px / half_w, py / half_h);
    let q = (fx >= 1.0) as usize + 2 * (fy >= 1.0) as usize;
    Some((q, -1.0 + 3.0 * fx.fract(), -1.0 + 3.0 * fy.fract()))
}

/// Coordinate `u` wrapped into [0, 1] as `mode` says (glTF §5.26, GL's wrap modes), and its
/// distance in texels of the 2-texel image from the nearest place where the texel read
/// changes: the middle, and with `Repeat` the image's ends too (where the next copy starts;
/// clamping and mirroring read the same texel on both sides).
pub fn wrapped(u: f64, mode: Wrap) -> (f64, f64) {
    let w = match mode {
        Wrap::Repeat => u - u.floor(),
        Wrap::ClampToEdge => u.clamp(0.0, 1.0),
        Wrap::MirroredRepeat => {
            let t = u.rem_euclid(2.0);
            if t > 1.0 {
                2.0 - t
            } else {
                t
            }
        }
    };
    let middle = (w - 0.5).abs() * 2.0;
    let edge = match mode {
        Wrap::Repeat => middle.min(w.min(1.0 - w) * 2.0),
        _ => middle,
    };
    (w, edge)
}

/// The texel (its place in [`TEXELS`]) at wrapped coordinates `u` across and `t` down.
pub fn texel_at(u: f64, t: f64) -> usize {
    let column = ((u * 2.0).floor() as usize).min(1);
    let row = ((t * 2.0).floor() as usize).min(1);
    2 * row + column
}
