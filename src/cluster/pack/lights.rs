//! Texel layouts of the light data texture, shared by every method.
//!
//! All data textures are [`DATA_TEXTURE_WIDTH`] texels wide (a power of two, so texel
//! addresses `i % W`, `i / W` and the ES 2.0 coordinates `(x + 0.5) / W` are exact in float
//! arithmetic) and as many rows high as needed. Light `i` occupies texels
//! `i·T … i·T + T−1` where `T` = [`LightLayout::texels_per_light`] (also a power of two, so a
//! light never straddles a row). A frame without spot lights reads no spot texels, and its
//! records leave them out: half the bytes.
//!
//! ```text
//! Float32 (RGBA32F, 16 bytes a texel; ES 3.0, or ES 2.0 with OES_texture_float)
//!   t0: pos.x   pos.y   pos.z   radius        view-space position (metres)
//!   t1: rad.r   rad.g   rad.b   spot_scale    radiance = colour × intensity
//!   or, for variants without fragment highp (FP16_LIGHTS):
//!   t1: rad.r/k² rad.g/k² rad.b/k² k          radiance in fp16 range: k = 2^e, e ≥ 0 the
//!                                             least with max(rad)/k² ≤ 1, rad at most 2³⁰
//!   spots only:
//!   t2: dir.x   dir.y   dir.z   spot_offset   unit view-space spot axis (reversed, with
//!                                             scale and offset, past 90° inside:
//!                                             [`shader_spot_terms`])
//!   t3: spot_scale  -  -  -                   (FP16_LIGHTS, where t1.w holds k)
//!   → 2 texels (32 bytes) a light, 4 (64 bytes) with spots
//!
//! Rgba8 (RGBA8, 4 bytes a texel; ES 2.0 without OES_texture_float). Lossy:
//!   t0: x.hi x.lo y.hi y.lo      16-bit fixed point over [−pos_range, +pos_range]
//!   t1: z.hi z.lo r.hi r.lo      radius 16-bit over [0, radius_range]
//!   t2: R    G    B    E         shared-exponent radiance: c = m/255 · 2^(E−128)
//!   spots only:
//!   t3: dx.hi dx.lo dy.hi dy.lo  axis 16-bit snorm
//!   t4: dz.hi dz.lo  omni  -     omni: 255 for a point light, 0 for a spot, 128 for a
//!                                spot past 90° inside, turned round (axis reversed)
//!   t5: so.hi so.lo si.hi si.lo  sin(α/2) of the outer and inner half-angles, 16-bit unorm
//!                                (cos(α/2) for a cone turned round)
//!   → 4 texels (16 bytes) a light (t3 unused), 8 (32 bytes) with spots (t6, t7 unused)
//! ```
//!
//! The spot terms are `t = clamp(spot_offset − spot_scale·(1 − cos), 0, 1)` (see
//! [`crate::scene::Light::spot_scale_offset`]); the Rgba8 layout stores the half-angles' sines
//! (cosines for a cone turned round) instead and the shader rebuilds scale and offset with
//! arithmetic alone (`scale` reaches 10⁴
//! for hard-edged cones; rebuilding it from angles needed `sin`, whose precision GLSL ES leaves
//! to the implementation: SwiftShader's moved hard cone edges by up to 55/255).

use glam::Vec3;

use crate::cluster::headroom::zeroed_with_room;
use crate::cluster::view_light::GpuLight;
use crate::scene::light::{
    half_cosine, half_sine, spot_terms_from_half_cosines, spot_terms_from_half_sines,
};

/// Width in texels of every data texture (a power of two ≤ 1024: exact under mediump math).
pub const DATA_TEXTURE_WIDTH: u32 = 1024;

/// How light records are stored in the light texture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LightEncoding {
    /// RGBA32F, exact.
    #[default]
    Float32,
    /// RGBA8 fixed point and shared exponent, lossy (the error is measured, not hidden).
    Rgba8,
}

impl LightEncoding {
    /// Bytes per texel.
    pub const fn bytes_per_texel(self) -> usize {
        match self {
            LightEncoding::Float32 => 16,
            LightEncoding::Rgba8 => 4,
        }
    }
}

/// How a frame's light records are laid out: their encoding, and what the shader variant
/// reading them needs (spot terms; radiance in fp16 range where fragments lack highp).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LightLayout {
    /// The records' encoding.
    pub encoding: LightEncoding,
    /// The records hold spot terms (the variant has spots).
    pub spots: bool,
    /// Float32 records hold radiance in fp16 range (the variant lacks fragment highp).
    pub fp16: bool,
}

impl LightLayout {
    /// Most texels a light record takes, whatever the frame: RGBA8 with spot terms.
    pub const MOST_TEXELS_PER_LIGHT: u32 = LightLayout {
        encoding: LightEncoding::Rgba8,
        spots: true,
        fp16: false,
    }
    .texels_per_light();

    /// Texels per light record: a power of two dividing the data textures' width, 1024.
    pub const fn texels_per_light(self) -> u32 {
        match (self.encoding, self.spots) {
            (LightEncoding::Float32, false) => 2,
            (LightEncoding::Float32, true) => 4,
            (LightEncoding::Rgba8, false) => 4,
            (LightEncoding::Rgba8, true) => 8,
        }
    }

    /// Bytes per light record.
    pub const fn bytes_per_light(self) -> usize {
        self.texels_per_light() as usize * self.encoding.bytes_per_texel()
    }
}

/// A light texture ready to upload.
#[derive(Clone, Debug)]
pub struct PackedLights {
    /// Layout of the records.
    pub layout: LightLayout,
    /// Number of lights.
    pub count: usize,
    /// Texture width in texels ([`DATA_TEXTURE_WIDTH`]).
    pub width: u32,
    /// Rows the records take (at least 1): the texture's height.
    pub height: u32,
    /// The records' texels, row-major (f32 little-endian for Float32): `count` records, the
    /// last row only as far as they reach.
    pub bytes: Vec<u8>,
    /// Rgba8 only: positions are fixed point over `[−pos_range, pos_range]`.
    pub pos_range: f32,
    /// Rgba8 only: radii are fixed point over `[0, radius_range]`.
    pub radius_range: f32,
    /// Rgba8 only: lights whose position or radius step at this frame's ranges passes a tenth
    /// of their radius (one far or huge light widens the ranges for all): they light the wrong
    /// place, or nothing.
    pub coarse: usize,
    /// The coarse lights were warned of (once for these records, frame after frame).
    warned_coarse: bool,
}

impl Default for PackedLights {
    /// [`PackedLights::empty`] for float records.
    fn default() -> Self {
        PackedLights::empty(LightLayout::default())
    }
}

impl PackedLights {
    /// No lights, and no bytes yet: a buffer for [`pack_lights_into`] to fill frame after frame.
    pub fn empty(layout: LightLayout) -> PackedLights {
        PackedLights {
            layout,
            count: 0,
            width: DATA_TEXTURE_WIDTH,
            height: 0,
            bytes: Vec::new(),
            pos_range: 0.0,
            radius_range: 0.0,
            coarse: 0,
            warned_coarse: false,
        }
    }
}

/// Packs lights into texels.
pub fn pack_lights(lights: &[GpuLight], layout: LightLayout) -> PackedLights {
    let mut packed = PackedLights::empty(layout);
    pack_lights_into(lights, layout, &mut packed);
    packed
}

/// [`pack_lights`] into `packed`, reusing its bytes: once they have grown to a frame's size,
/// packing allocates nothing.
pub fn pack_lights_into(lights: &[GpuLight], layout: LightLayout, packed: &mut PackedLights) {
    let (encoding, record) = (layout.encoding, layout.bytes_per_light());
    let width = DATA_TEXTURE_WIDTH as usize;
    let height = (lights.len() * layout.texels_per_light() as usize)
        .div_ceil(width)
        .max(1);
    let bytes = &mut packed.bytes;
    zeroed_with_room(bytes, lights.len() * record);
    let pos_range = lights
        .iter()
        .map(|l| l.position.abs().max_element())
        .fold(1e-6f32, f32::max);
    let radius_range = lights.iter().map(|l| l.radius).fold(1e-6f32, f32::max);
    // Fixed-point steps: positions over 2·pos_range, radii over radius_range, in 65 535 steps.
    let step = (2.0 * pos_range).max(radius_range) / 65535.0;
    // How far a decoded centre may lie from the light's: a whole position step on each axis
    // (half a step rounding here, up to one more from the shader's constants rounded to fp16).
    // Without fragment highp, fp16 also rounds the decoded centre itself, as it rounds a float
    // record's: that moves a light's faint edge, not the gross rounding this guards against.
    let centre_error = 3f32.sqrt() * 2.0 * pos_range / 65535.0;
    let mut coarse = 0;
    for (i, l) in lights.iter().enumerate() {
        match encoding {
            LightEncoding::Float32 => {
                let (direction, spot_scale, spot_offset) = shader_spot_terms(l);
                let (radiance, w) = if layout.fp16 {
                    fp16_radiance(l.radiance)
                } else {
                    (l.radiance, spot_scale)
                };
                let rec: [f32; 16] = [
                    l.position.x,
                    l.position.y,
                    l.position.z,
                    l.radius, //
                    radiance.x,
                    radiance.y,
                    radiance.z,
                    w, //
                    direction.x,
                    direction.y,
                    direction.z,
                    spot_offset, //
                    spot_scale,
                    0.0,
                    0.0,
                    0.0,
                ];
                let floats = record / 4;
                bytes[i * record..(i + 1) * record]
                    .copy_from_slice(bytemuck::cast_slice(&rec[..floats]));
            }
            LightEncoding::Rgba8 => {
                // A light of radius 0 (forward's darkened unseen ones) lights nothing anyway.
                coarse += usize::from(l.radius > 0.0 && step > 0.1 * l.radius);
                let p = |v: f32| unorm16(v / pos_range * 0.5 + 0.5);
                let s = |v: f32| unorm16(v * 0.5 + 0.5);
                let words = [
                    p(l.position.x),
                    p(l.position.y),
                    p(l.position.z),
                    // Rounded down and less the centre's error, so the sphere a record
                    // lights lies inside the one the light was culled with: a radius rounded
                    // up would light pixels of cells whose lists leave the light out.
                    unorm16_down((l.radius - centre_error).max(0.0) / radius_range),
                ];
                let rec = &mut bytes[i * record..(i + 1) * record];
                for (k, w) in words.iter().enumerate() {
                    rec[k * 2..k * 2 + 2].copy_from_slice(&w.to_be_bytes());
                }
                rec[8..12].copy_from_slice(&rgbe(l.radiance));
                if !layout.spots {
                    continue;
                }
                // A cone past 90° inside comes turned round as in the float records: its axis
                // reversed and its angles' half cosines, precise near 180° where their sines
                // are not (t4.z 128).
                let (axis, scale, _) = shader_spot_terms(l);
                for (k, w) in [s(axis.x), s(axis.y), s(axis.z)].iter().enumerate() {
                    rec[12 + k * 2..14 + k * 2].copy_from_slice(&w.to_be_bytes());
                }
                let omni = l.cone_deg.1 >= 180.0;
                let back = scale < 0.0;
                rec[18] = if omni {
                    255
                } else if back {
                    128
                } else {
                    0
                };
                for (k, deg) in [l.cone_deg.0, l.cone_deg.1].into_iter().enumerate() {
                    let half = if back { half_cosine } else { half_sine }(deg as f64) as f32;
                    rec[20 + 2 * k..22 + 2 * k].copy_from_slice(&unorm16(half).to_be_bytes());
                }
            }
        }
    }
    packed.layout = layout;
    packed.count = lights.len();
    packed.width = DATA_TEXTURE_WIDTH;
    packed.height = height as u32;
    packed.pos_range = pos_range;
    packed.radius_range = radius_range;
    packed.coarse = coarse;
    if coarse > 0 && !packed.warned_coarse {
        packed.warned_coarse = true;
        log::warn!(
            "RGBA8 light data (no float textures): {coarse} of {} lights are smaller than ten \
             steps of this frame's fixed point (positions within ±{pos_range:.3e}, radii up to \
             {radius_range:.3e}, set by the farthest and the largest light) and light the wrong \
             place or nothing; keep lights of one scale near the camera, or use a context with \
             float textures (said once)",
            lights.len()
        );
    }
}

/// A spot's axis, scale and offset as the shaders read them from a float record or a deferred
/// instance. A cone whose inner angle is past 90° comes turned round: axis `−a`, scale `−s`,
/// offset `o − 2s`, so `t = o' − s'·|L + a'|²/2` measures `1 + cos θ` from the back axis,
/// where its edge lies. The same `t`, but small terms where fp16 holds them: from the front,
/// a 170–180° cone's offset was 131.6, fp16 steps of 1/16 there, and the fade came out
/// 86/255 wrong without fragment highp.
pub(crate) fn shader_spot_terms(l: &GpuLight) -> (Vec3, f32, f32) {
    let (scale, offset) = (l.spot_scale, l.spot_offset);
    // 1 − cos(inner) = (offset − 1) / scale: past 1, the inner angle is past 90°.
    if scale > 0.0 && offset - 1.0 > scale {
        let back = (f64::from(offset) - 2.0 * f64::from(scale)) as f32;
        (-l.direction, -scale, back)
    } else {
        (l.direction, scale, offset)
    }
}

/// Decodes light `i` exactly as the shader does (used to test round trips and to measure the
/// Rgba8 error).
pub fn unpack_light(packed: &PackedLights, i: usize) -> GpuLight {
    let layout = packed.layout;
    let record = layout.bytes_per_light();
    let rec = &packed.bytes[i * record..(i + 1) * record];
    // What a record without spot terms stands for: a point light (Light::spot_scale_offset).
    let point = |position: Vec3, radius: f32, radiance: Vec3| GpuLight {
        position,
        radius,
        cull_radius: radius,
        radiance,
        spot_scale: 0.0,
        direction: Vec3::ZERO,
        spot_offset: 1.0,
        cone_deg: (180.0, 180.0),
    };
    match layout.encoding {
        LightEncoding::Float32 => {
            let f: &[f32] = bytemuck::cast_slice(rec);
            // Powers of two: k² scales the fp16 form back exactly.
            let k2 = if layout.fp16 { f[7] * f[7] } else { 1.0 };
            let mut light = point(
                Vec3::new(f[0], f[1], f[2]),
                f[3],
                Vec3::new(f[4], f[5], f[6]) * k2,
            );
            if layout.spots {
                light.spot_scale = if layout.fp16 { f[12] } else { f[7] };
                light.direction = Vec3::new(f[8], f[9], f[10]);
                light.spot_offset = f[11];
                light.cone_deg = (f32::NAN, f32::NAN);
            }
            light
        }
        LightEncoding::Rgba8 => {
            let w = |k: usize| u16::from_be_bytes([rec[k], rec[k + 1]]) as f32 / 65535.0;
            let pos = |k: usize| (w(k) * 2.0 - 1.0) * packed.pos_range;
            let snorm = |k: usize| w(k) * 2.0 - 1.0;
            let e = rec[11] as i32 - 128;
            let radiance =
                Vec3::new(rec[8] as f32, rec[9] as f32, rec[10] as f32) / 255.0 * 2f32.powi(e);
            let mut light = point(
                Vec3::new(pos(0), pos(2), pos(4)),
                w(6) * packed.radius_range,
                radiance,
            );
            if layout.spots {
                light.direction = Vec3::new(snorm(12), snorm(14), snorm(16)).normalize_or_zero();
                // 255 in t4.z: a point light among spots; 128: a cone turned round.
                if rec[18] != 255 {
                    let (outer, inner) = (w(20) as f64, w(22) as f64);
                    let ((scale, offset), angle): (_, fn(f64) -> f64) = if rec[18] == 128 {
                        (spot_terms_from_half_cosines(outer, inner), f64::acos)
                    } else {
                        (spot_terms_from_half_sines(outer, inner), f64::asin)
                    };
                    let degrees = |half: f64| 2.0 * angle(half).to_degrees() as f32;
                    light.spot_scale = scale as f32;
                    light.spot_offset = offset as f32;
                    light.cone_deg = (degrees(outer), degrees(inner));
                }
            }
            light
        }
    }
}

/// Brightest radiance channel the fp16 form holds: `k` is then at most 2¹⁵, within fp16's
/// 65 504 (a `k` of 2¹⁶ and up read as infinity, lighting every pixel the light reaches at the
/// shader's cap). Radiance past it is taken as it, its channels scaled alike.
pub const FP16_MAX_RADIANCE: f32 = (1u32 << 30) as f32;

/// Radiance in a range fp16 holds, for devices without fragment highp: `(c / k², k)` with
/// `k = 2^e`, `e ≥ 0` the least with `max(c) / k² ≤ 1`, `c` first scaled down to at most
/// [`FP16_MAX_RADIANCE`]. The shader multiplies `k²` back into the falloff, which is small
/// wherever the light is not saturating the pixel anyway (see `glsl/light_model.glsl`).
pub fn fp16_radiance(c: Vec3) -> (Vec3, f32) {
    let c = scaled_alike_within(c, FP16_MAX_RADIANCE);
    let m = c.max_element();
    let e = if m > 1.0 {
        // At most 15 (k = 2¹⁵) however the scaling above rounded.
        ((m.log2() * 0.5).ceil() as i32).min(15)
    } else {
        0
    };
    let k = 2f32.powi(e);
    (c / (k * k), k)
}

fn unorm16(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// [`unorm16`] rounded towards zero.
fn unorm16_down(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * 65535.0).floor() as u16
}

/// Brightest radiance channel an RGBA8 record holds: a mantissa of 255/255 at the largest
/// exponent, 2¹²⁷. Radiance past it is taken as it, its channels scaled alike, as in
/// [`fp16_radiance`].
const RGBE_MAX_RADIANCE: f32 = 1.7014118e38;

/// `c` scaled down, its channels alike, so that none passes `most` (clamped alone, the
/// brightest channel would lose more than the others: a hue shift).
pub(crate) fn scaled_alike_within(c: Vec3, most: f32) -> Vec3 {
    let brightest = c.max_element();
    if brightest > most {
        c * (most / brightest)
    } else {
        c
    }
}

/// Shared-exponent RGB: the largest channel keeps 8 bits of mantissa.
fn rgbe(c: Vec3) -> [u8; 4] {
    let m = c.max_element();
    if m.is_nan() || m < 1e-30 {
        return [0, 0, 0, 0];
    }
    let c = scaled_alike_within(c, RGBE_MAX_RADIANCE);
    let m = c.max_element();
    // 2^e > m, so every mantissa is ≤ 255.
    let e = (m.log2().floor() as i32 + 1).clamp(-128, 127);
    let scale = 2f32.powi(-e) * 255.0;
    let q = |v: f32| (v * scale).round().clamp(0.0, 255.0) as u8;
    [q(c.x), q(c.y), q(c.z), (e + 128) as u8]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Light;
    use glam::DVec3;

    fn sample_lights() -> Vec<GpuLight> {
        let view =
            glam::dcamera::rh::view::look_at_mat4(DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO, DVec3::Y);
        (0..300)
            .map(|i| {
                let f = i as f64;
                let p = DVec3::new((f * 0.37).sin() * 20.0, (f * 0.11).cos() * 5.0, -(f * 0.05));
                let light = if i % 3 == 0 {
                    Light::spot(
                        p,
                        (2.0 + (f % 7.0)) as f32,
                        Vec3::new(1.0, 0.5, 0.25),
                        (1.0 + f) as f32,
                        crate::scene::Cone {
                            direction: DVec3::new(0.2, -1.0, 0.1),
                            // Every other spot wider than a hemisphere (turned round).
                            inner_deg: 10.0 + f % 20.0 + if i % 2 == 0 { 120.0 } else { 0.0 },
                            outer_deg: 30.0 + f % 40.0 + if i % 2 == 0 { 110.0 } else { 0.0 },
                        },
                    )
                } else {
                    Light::point(
                        p,
                        (0.5 + (f % 11.0)) as f32,
                        Vec3::new(0.2, 0.9, 0.4),
                        (0.01 + f * 0.1) as f32,
                    )
                };
                GpuLight::from_light(&light, &view)
            })
            .collect()
    }

    /// Records with spot terms in `encoding`, radiance as fragments with highp read it.
    fn with_spots(encoding: LightEncoding) -> LightLayout {
        LightLayout {
            encoding,
            spots: true,
            fp16: false,
        }
    }

    #[test]
    fn float32_round_trips_exactly_in_every_layout() {
        let lights = sample_lights();
        for (spots, fp16) in [(true, false), (true, true), (false, false), (false, true)] {
            let layout = LightLayout {
                encoding: LightEncoding::Float32,
                spots,
                fp16,
            };
            let packed = pack_lights(&lights, layout);
            let texels = if spots { 4 } else { 2 };
            assert_eq!(packed.width, DATA_TEXTURE_WIDTH);
            // 300 records over 1 024-texel rows, the last row's rest left out.
            assert_eq!(packed.height, if spots { 2 } else { 1 });
            assert_eq!(packed.bytes.len(), 300 * texels * 16);
            for (i, l) in lights.iter().enumerate() {
                let u = unpack_light(&packed, i);
                assert_eq!(
                    (u.position, u.radius, u.radiance),
                    (l.position, l.radius, l.radiance),
                    "light {i}, {layout:?}"
                );
                // Without spots a record is a point light's, whatever the light was.
                let spot = |l: &GpuLight| (l.direction, l.spot_scale, l.spot_offset);
                let expected = if spots {
                    shader_spot_terms(l)
                } else {
                    (Vec3::ZERO, 0.0, 1.0)
                };
                assert_eq!(spot(&u), expected, "light {i}, {layout:?}");
            }
        }
    }

    #[test]
    fn fp16_radiance_fits_fp16_and_scales_back_exactly() {
        let lights = sample_lights();
        for spots in [true, false] {
            let layout = LightLayout {
                encoding: LightEncoding::Float32,
                spots,
                fp16: true,
            };
            let packed = pack_lights(&lights, layout);
            let record = layout.bytes_per_light();
            for (i, l) in lights.iter().enumerate() {
                let f: &[f32] = bytemuck::cast_slice(&packed.bytes[i * record..(i + 1) * record]);
                let (scaled, k) = (Vec3::new(f[4], f[5], f[6]), f[7]);
                assert!(scaled.max_element() <= 1.0 && k >= 1.0 && k.log2().fract() == 0.0);
                // Powers of two scale exactly.
                assert_eq!(scaled * (k * k), l.radiance, "light {i}");
            }
        }
        for (c, k) in [
            (0.5, 1.0),
            (1.0, 1.0),
            (1.01, 2.0),
            (4.0, 2.0),
            (1e6, 1024.0),
            (1e9, 2f32.powi(15)),
            // Past 2³⁰, taken as 2³⁰: k stays within fp16 (2¹⁶ and up read as infinity).
            (1e10, 2f32.powi(15)),
            (f32::MAX, 2f32.powi(15)),
        ] {
            let (scaled, root) = fp16_radiance(Vec3::splat(c));
            assert_eq!(root, k, "radiance {c}");
            assert!(
                scaled.x <= 1.0 && (c <= 1.0 || scaled.x > 0.25),
                "radiance {c}"
            );
            assert!(root <= 65504.0, "radiance {c}: k past fp16");
        }
    }

    /// One huge light widens the radius range for all: the others' radii round to nothing,
    /// and the records say how many (the renderer warns of them).
    #[test]
    fn rgba8_counts_the_lights_its_ranges_cannot_hold() {
        let lights = sample_lights();
        assert_eq!(
            pack_lights(&lights, with_spots(LightEncoding::Rgba8)).coarse,
            0
        );
        assert_eq!(
            pack_lights(&lights, with_spots(LightEncoding::Float32)).coarse,
            0
        );
        let mut with_huge = lights.clone();
        with_huge[0].radius = 1e6;
        let packed = pack_lights(&with_huge, with_spots(LightEncoding::Rgba8));
        assert_eq!(packed.coarse, lights.len() - 1);
        // What a record keeps of a radius lies within it, however coarse the steps.
        for (i, light) in with_huge.iter().enumerate() {
            let decoded = unpack_light(&packed, i);
            let reach = (decoded.position - light.position).length() + decoded.radius;
            assert!(
                reach <= light.radius,
                "light {i}: {reach} past {}",
                light.radius
            );
        }
        let small = unpack_light(&packed, 1);
        assert!(small.radius < 0.5 * lights[1].radius, "{}", small.radius);
    }

    #[test]
    fn rgba8_error_stays_within_its_quantisation_bounds() {
        let lights = sample_lights();
        let packed = pack_lights(&lights, with_spots(LightEncoding::Rgba8));
        let pos_step = 2.0 * packed.pos_range / 65535.0;
        for (i, l) in lights.iter().enumerate() {
            let u = unpack_light(&packed, i);
            assert!(
                (u.position - l.position).abs().max_element() <= pos_step * 0.51,
                "light {i}"
            );
            // Rounded down, less the centre's error: the decoded sphere lies in the light's.
            let radius_step = packed.radius_range / 65535.0;
            let centre_error = 3f32.sqrt() * pos_step;
            assert!(u.radius <= l.radius && u.radius >= l.radius - radius_step - centre_error);
            let reach = (u.position - l.position).length() + u.radius;
            assert!(
                reach <= l.radius,
                "light {i}: reaches {reach}, radius {}",
                l.radius
            );
            // Shared exponent: a step is 2^e / 255 with 2^e <= 2·max, so half a step is at most
            // max / 255 (reached when max is a power of two); 1e-4 covers f32 rounding.
            let tol = l.radiance.max_element() / 255.0 * (1.0 + 1e-4);
            assert!(
                (u.radiance - l.radiance).abs().max_element() <= tol,
                "light {i}: {:?} vs {:?}",
                u.radiance,
                l.radiance
            );
            if l.spot_scale != 0.0 {
                // As the float records give the shaders: turned round past 90° inside.
                let (axis, scale, _) = shader_spot_terms(l);
                assert!((u.direction - axis).length() < 1e-4, "light {i}");
                assert_eq!(u.spot_scale < 0.0, scale < 0.0, "light {i}");
                assert!((u.cone_deg.0 - l.cone_deg.0).abs() < 0.002, "light {i}");
                assert!((u.cone_deg.1 - l.cone_deg.1).abs() < 0.002, "light {i}");
            }
        }
    }

    /// Without spots an RGBA8 record is its first four texels (t3 unused): the same
    /// position, radius and radiance as with spots, at half the bytes.
    #[test]
    fn rgba8_points_keep_the_first_texels_at_half_the_bytes() {
        let lights = sample_lights();
        let full = pack_lights(&lights, with_spots(LightEncoding::Rgba8));
        let points = LightLayout {
            spots: false,
            ..with_spots(LightEncoding::Rgba8)
        };
        let half = pack_lights(&lights, points);
        assert_eq!(half.bytes.len() * 2, full.bytes.len());
        for i in 0..lights.len() {
            let (a, b) = (unpack_light(&full, i), unpack_light(&half, i));
            assert_eq!(
                (a.position, a.radius, a.radiance),
                (b.position, b.radius, b.radiance)
            );
            assert_eq!(
                (b.spot_scale, b.spot_offset, b.direction),
                (0.0, 1.0, Vec3::ZERO)
            );
            assert_eq!(
                full.bytes[i * 32..i * 32 + 12],
                half.bytes[i * 16..i * 16 + 12]
            );
        }
    }

    #[test]
    fn rgbe_handles_zero_and_extremes() {
        assert_eq!(rgbe(Vec3::ZERO), [0, 0, 0, 0]);
        let big = rgbe(Vec3::splat(1e6));
        assert!(big[0] > 127 && big[3] > 128);
        let tiny = rgbe(Vec3::splat(1e-6));
        assert!(tiny[0] > 127 && tiny[3] < 128);
        // Past the largest exponent the channels are scaled alike, keeping the hue (red alone
        // was clipped: 3e38 × (1, 0.5, 0.25) read as (1.7e38, 1.5e38, 0.75e38)).
        assert_eq!(RGBE_MAX_RADIANCE, 2f32.powi(127));
        for brightest in [RGBE_MAX_RADIANCE, 3e38, f32::MAX] {
            let [r, g, b, e] = rgbe(Vec3::new(1.0, 0.5, 0.25) * brightest);
            assert_eq!((r, e), (255, 255), "{brightest}");
            assert!(
                g.abs_diff(128) <= 1 && b.abs_diff(64) <= 1,
                "{brightest}: {g} {b}"
            );
        }
    }
}
