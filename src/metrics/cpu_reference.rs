//! A stricter reference for image error: the light model evaluated in `f64` on the CPU at a
//! stratified set of pixels of any scene, found by casting each pixel's ray through a
//! [`SceneRaycaster`].
//!
//! Each sample is an interval per channel: the encoded light model at the pixel centre and at
//! [`snapping_reach`] from it in ±x and ±y. GPUs snap vertices to a sub-pixel grid (1/256 pixel
//! on common hardware and llvmpipe, 1/16 on SwiftShader: `GL_SUBPIXEL_BITS`), so the point a
//! fragment is shaded at may be that far from the exact centre; across a hard spot edge the
//! interval is wide, elsewhere it is a point. Pixels the
//! reference cannot speak for are skipped and counted: triangle edges and silhouettes (the GPU
//! may shade the neighbour), textured surfaces (filtering is not reproduced), surfaces behind
//! or on a transparent one (blended), and the background.

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::scene::raycast::{pixel_ray, Hit, SceneRaycaster};
use crate::scene::shading::{self, Surface};
use crate::scene::{Camera, Projection, Scene};

/// How far from the pixel centre the light model is also evaluated, in pixels, for a context
/// reporting `subpixel_bits` (`Caps::subpixel_bits`): twice its vertex snapping step (8 bits:
/// 1/128 pixel). Values outside the specification's 4 and a sane 16 are clamped, so a driver
/// reporting nonsense gets the widest interval the specification allows.
pub fn snapping_reach(subpixel_bits: i32) -> f64 {
    2.0 * (-(subpixel_bits.clamp(4, 16) as f64)).exp2()
}

/// How the image stores linear radiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// sRGB transfer function of the value clamped to [0, 1] (the default render).
    Srgb,
    /// The value clamped to [0, 1] (`RenderOptions::linear`).
    Linear,
}

impl Encoding {
    /// The stored value of a linear channel, in 8-bit steps (0–255, not rounded).
    pub fn encode(self, linear: f64) -> f64 {
        let x = linear.clamp(0.0, 1.0);
        255.0
            * match self {
                Encoding::Srgb => shading::linear_to_srgb(x),
                Encoding::Linear => x,
            }
    }
}

/// The reference for one pixel: per channel, the range (0–255) the stored value may take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceSample {
    /// Column.
    pub x: u32,
    /// Row, 0 at the top.
    pub y: u32,
    /// Lowest encoded value per channel (RGB) over the sub-pixel points.
    pub lo: [f64; 3],
    /// Highest encoded value per channel (RGB) over the sub-pixel points.
    pub hi: [f64; 3],
}

/// The samples of one scene and view, and how many chosen pixels were skipped, by reason.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReferenceSet {
    /// Image width the samples were taken for.
    pub width: u32,
    /// Image height the samples were taken for.
    pub height: u32,
    /// Pixels with a reference value.
    pub samples: Vec<ReferenceSample>,
    /// Skipped: the sub-pixel rays hit different triangles or some missed (edge, silhouette).
    pub skipped_edge: usize,
    /// Skipped: another opaque surface lies within [`COPLANAR`](crate::scene::raycast::COPLANAR) of
    /// the one hit (coplanar or doubled faces, a ray exactly on a shared edge: the GPU's depth
    /// test may pick either).
    pub skipped_coplanar: usize,
    /// Skipped: the surface has a diffuse texture, vertex colours or glTF surface maps
    /// (normal, occlusion, emission).
    pub skipped_texture: usize,
    /// Skipped: a transparent surface lies in front of (or instead of) the opaque one.
    pub skipped_transparent: usize,
    /// Skipped: every sub-pixel ray misses all geometry within the view (background).
    pub missed: usize,
}

/// Error of an image against a [`ReferenceSet`], in 8-bit steps.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct CpuError {
    /// Number of samples compared.
    pub samples: usize,
    /// Largest distance of a stored channel from its interval.
    pub max_abs: f64,
    /// Root mean square of that distance over samples × 3 channels.
    pub rmse: f64,
    /// Pixel (x, y) of the largest error.
    pub worst: (u32, u32),
}

/// Chooses `count` pixels (at most) on a stratified grid over the whole image and evaluates
/// the light model there. Deterministic. The scene must validate.
/// `subpixel` is [`snapping_reach`] of the context the image comes from.
pub fn reference_samples(
    scene: &Scene,
    width: u32,
    height: u32,
    count: usize,
    encoding: Encoding,
    subpixel: f64,
) -> ReferenceSet {
    let raycaster = SceneRaycaster::new(scene);
    reference_samples_with(&raycaster, scene, width, height, count, encoding, subpixel)
}

/// [`reference_samples`] with a ray caster already built for `scene`'s geometry (to reuse it
/// across light sets or cameras).
pub fn reference_samples_with(
    raycaster: &SceneRaycaster,
    scene: &Scene,
    width: u32,
    height: u32,
    count: usize,
    encoding: Encoding,
    subpixel: f64,
) -> ReferenceSet {
    let outcomes: Vec<Outcome> = sample_pixels(width, height, count)
        .into_par_iter()
        .map(|(x, y)| {
            evaluate(
                raycaster,
                scene,
                (width, height),
                (x, y),
                encoding,
                subpixel,
            )
        })
        .collect();
    let mut set = ReferenceSet {
        width,
        height,
        ..ReferenceSet::default()
    };
    for outcome in outcomes {
        match outcome {
            Outcome::Sample(s) => set.samples.push(s),
            Outcome::Edge => set.skipped_edge += 1,
            Outcome::Coplanar => set.skipped_coplanar += 1,
            Outcome::Texture => set.skipped_texture += 1,
            Outcome::Transparent => set.skipped_transparent += 1,
            Outcome::Missed => set.missed += 1,
        }
    }
    set
}

/// Compares an image with the reference: per channel, the distance of the stored value from
/// the sample's interval (0 inside it). Panics if the image is not the size the set was
/// taken for (a caller bug).
pub fn compare(image: &image::RgbaImage, set: &ReferenceSet) -> CpuError {
    assert_eq!(
        image.dimensions(),
        (set.width, set.height),
        "image and reference differ in size"
    );
    let (mut max_abs, mut worst, mut sq) = (0.0f64, (0, 0), 0.0);
    for s in &set.samples {
        let px = image.get_pixel(s.x, s.y);
        for c in 0..3 {
            let v = px[c] as f64;
            let err = (s.lo[c] - v).max(v - s.hi[c]).max(0.0);
            sq += err * err;
            if err > max_abs {
                (max_abs, worst) = (err, (s.x, s.y));
            }
        }
    }
    let n = set.samples.len();
    CpuError {
        samples: n,
        max_abs,
        rmse: if n == 0 {
            0.0
        } else {
            (sq / (3 * n) as f64).sqrt()
        },
        worst,
    }
}

/// What one chosen pixel turned out to be.
enum Outcome {
    Sample(ReferenceSample),
    Edge,
    Coplanar,
    Texture,
    Transparent,
    Missed,
}

/// What one sub-pixel ray sees.
enum RaySees {
    Nothing,
    Transparent,
    /// An opaque surface with another just behind it.
    Ambiguous,
    Opaque(Hit),
}

/// At most `count` distinct pixels: `rows` evenly spaced rows of evenly spaced columns, rows
/// chosen so the cells are roughly square; every pixel when `count` covers the image.
fn sample_pixels(width: u32, height: u32, count: usize) -> Vec<(u32, u32)> {
    let (w, h) = (width as usize, height as usize);
    if count == 0 {
        return Vec::new();
    }
    if count >= w * h {
        return (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .collect();
    }
    let rows =
        ((count as f64 * h as f64 / w as f64).sqrt().round() as usize).clamp(1, h.min(count));
    let mut pixels = Vec::with_capacity(count);
    for r in 0..rows {
        // Spread `count` over the rows as evenly as integers allow.
        let in_row = (r + 1) * count / rows - r * count / rows;
        let y = ((r as f64 + 0.5) * h as f64 / rows as f64) as u32;
        let start = pixels.len();
        for i in 0..in_row {
            let x = ((i as f64 + 0.5) * w as f64 / in_row as f64) as u32;
            pixels.push((x.min(width - 1), y.min(height - 1)));
        }
        // Only a row asked for more pixels than it has can repeat one (adjacent, as x grows).
        let mut row = pixels.split_off(start);
        row.dedup();
        pixels.extend(row);
    }
    pixels
}

/// Casts the five sub-pixel rays of pixel (x, y) and classifies or evaluates it.
fn evaluate(
    raycaster: &SceneRaycaster,
    scene: &Scene,
    (width, height): (u32, u32),
    (x, y): (u32, u32),
    encoding: Encoding,
    subpixel: f64,
) -> Outcome {
    let d = subpixel;
    let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
    let is_opaque = |o: usize| !scene.materials[scene.objects[o].material].is_transparent();
    let sees: Vec<RaySees> = [(0.0, 0.0), (d, 0.0), (-d, 0.0), (0.0, d), (0.0, -d)]
        .iter()
        .map(|(dx, dy)| {
            let (origin, dir) = pixel_ray(&scene.camera, width, height, cx + dx, cy + dy);
            let t_far = far_plane_t(&scene.camera, origin, dir);
            let r = raycaster.first_opaque_hit(origin, dir, t_far, is_opaque);
            match (r.hit, r.transparent_t, r.runner_up_t) {
                (_, Some(_), _) => RaySees::Transparent,
                (Some(_), None, Some(_)) => RaySees::Ambiguous,
                (Some(h), None, None) => RaySees::Opaque(h),
                (None, None, _) => RaySees::Nothing,
            }
        })
        .collect();
    if sees.iter().all(|s| matches!(s, RaySees::Nothing)) {
        return Outcome::Missed;
    }
    if sees.iter().any(|s| matches!(s, RaySees::Transparent)) {
        return Outcome::Transparent;
    }
    if sees.iter().any(|s| matches!(s, RaySees::Ambiguous)) {
        return Outcome::Coplanar;
    }
    let hits: Vec<Hit> = sees
        .into_iter()
        .filter_map(|s| match s {
            RaySees::Opaque(h) => Some(h),
            _ => None,
        })
        .collect();
    let same = |h: &Hit| (h.object, h.triangle) == (hits[0].object, hits[0].triangle);
    if hits.len() < 5 || !hits.iter().all(same) {
        return Outcome::Edge;
    }
    let material = &scene.materials[scene.objects[hits[0].object].material];
    // Textures, vertex colours and the glTF surface inputs vary across a triangle or add
    // terms this light-model reference does not evaluate: skipped like textures.
    let object = &scene.objects[hits[0].object];
    let maps = &material.maps;
    if material.diffuse_texture.is_some()
        || !object.mesh.colors.is_empty()
        || maps.emits()
        || maps.normal.is_some()
        || maps.occlusion.is_some()
        || maps.metallic_roughness.is_some()
    {
        return Outcome::Texture;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for h in &hits {
        let v = view_direction(&scene.camera, h.position);
        let normal = shading::seen_side(h.normal, h.face, v);
        let surface = Surface::of(material, h.position, normal, material.diffuse.as_dvec3());
        let c = shading::shade(&surface, v, &scene.lights, scene.ambient)
            + shading::shade_directional(&surface, v, &scene.directional_lights);
        for ch in 0..3 {
            let e = encoding.encode(c[ch]);
            (lo[ch], hi[ch]) = (lo[ch].min(e), hi[ch].max(e));
        }
    }
    Outcome::Sample(ReferenceSample { x, y, lo, hi })
}

/// Unit direction from a surface point to the eye: towards the camera for perspective, the
/// reversed view axis for orthographic (parallel rays), as the shaders use.
fn view_direction(camera: &Camera, p: DVec3) -> DVec3 {
    match camera.projection {
        Projection::Perspective { .. } => (camera.position - p).normalize(),
        Projection::Orthographic { .. } => (camera.position - camera.target).normalize(),
    }
}

/// Ray parameter at which a ray (unit `dir`) crosses the far plane: geometry beyond it is
/// clipped on the GPU, so it is background here too.
fn far_plane_t(camera: &Camera, origin: DVec3, dir: DVec3) -> f64 {
    let far = camera.near_far().1;
    let forward = (camera.target - camera.position).normalize();
    let along = dir.dot(forward);
    if far.is_infinite() || along <= 0.0 {
        return f64::INFINITY;
    }
    (far - (origin - camera.position).dot(forward)) / along
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::{DMat4, DVec4, Vec3};

    use super::*;
    use crate::scene::meshbuild::MeshBuilder;
    use crate::scene::{builtin, Light, Material, Object, Texture};

    const W: u32 = 97;
    const H: u32 = 61;

    /// The `plane` built-in with two point lights and a hard-edged spot.
    fn lit_plane() -> Scene {
        let mut scene = builtin::build("plane", None).unwrap();
        scene.lights = vec![
            Light::point(
                DVec3::new(-1.0, 0.5, 1.0),
                4.0,
                Vec3::new(1.0, 0.8, 0.6),
                2.0,
            ),
            Light::point(
                DVec3::new(1.5, -1.0, 0.6),
                3.0,
                Vec3::new(0.3, 0.6, 1.0),
                3.0,
            ),
            Light::spot(
                DVec3::new(0.5, 0.5, 2.0),
                6.0,
                Vec3::ONE,
                1.5,
                crate::scene::Cone {
                    direction: DVec3::new(0.0, -0.2, -1.0),
                    inner_deg: 12.0,
                    outer_deg: 12.0,
                },
            ),
        ];
        scene.validate().unwrap();
        scene
    }

    /// The linear colour the plane z = 0 (facing +Z, the built-in's material) shows at window
    /// position (px, py): ray–plane intersection worked out without the ray caster.
    fn plane_point(scene: &Scene, px: f64, py: f64) -> DVec3 {
        let cam = &scene.camera;
        let inv_vp = (cam.projection_matrix(W as f64 / H as f64) * cam.view_matrix()).inverse();
        let ndc = (2.0 * px / W as f64 - 1.0, 1.0 - 2.0 * py / H as f64);
        let unproject = |z: f64| {
            let p = inv_vp * DVec4::new(ndc.0, ndc.1, z, 1.0);
            p.truncate() / p.w
        };
        let (a, b) = (unproject(-1.0), unproject(1.0));
        let p = a + (b - a) * (-a.z / (b - a).z);
        let m = &scene.materials[0];
        let surface = Surface::of(m, p, DVec3::Z, m.diffuse.as_dvec3());
        let v = view_direction(cam, p);
        shading::shade(&surface, v, &scene.lights, scene.ambient)
            + shading::shade_directional(&surface, v, &scene.directional_lights)
    }

    fn check_against_plane(scene: &Scene, encoding: Encoding) {
        let count = 500;
        let set = reference_samples(scene, W, H, count, encoding, snapping_reach(8));
        // The quad's diagonal is the only edge; the plane fills the view.
        assert_eq!(
            set.samples.len() + set.skipped_edge + set.skipped_coplanar,
            count
        );
        assert!(set.samples.len() > count * 9 / 10, "{set:?}");
        for s in &set.samples {
            let (cx, cy) = (s.x as f64 + 0.5, s.y as f64 + 0.5);
            let d = snapping_reach(8);
            for ch in 0..3 {
                let values = [(0.0, 0.0), (d, 0.0), (-d, 0.0), (0.0, d), (0.0, -d)]
                    .map(|(dx, dy)| encoding.encode(plane_point(scene, cx + dx, cy + dy)[ch]));
                let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                assert!((s.lo[ch] - lo).abs() < 1e-7, "{s:?} channel {ch}: {lo}");
                assert!((s.hi[ch] - hi).abs() < 1e-7, "{s:?} channel {ch}: {hi}");
            }
        }
        // The lights reach part of the view only: both lit and ambient-only pixels are there.
        let reds: Vec<f64> = set.samples.iter().map(|s| s.hi[0]).collect();
        let ambient = encoding.encode(scene.ambient.x as f64 * scene.materials[0].diffuse.x as f64);
        let lit = reds.iter().filter(|&&r| r > 100.0).count();
        let dark = reds.iter().filter(|&&r| (r - ambient).abs() < 1e-9).count();
        assert!(lit > 20 && dark > 20, "{lit} lit, {dark} ambient only");
    }

    #[test]
    fn plane_samples_match_the_light_model_at_the_analytic_point() {
        let mut scene = lit_plane();
        check_against_plane(&scene, Encoding::Srgb);
        scene.camera.projection = Projection::Orthographic {
            height: 6.0,
            near: 0.1,
            far: 50.0,
        };
        check_against_plane(&scene, Encoding::Linear);
    }

    #[test]
    fn compare_measures_the_distance_from_the_interval() {
        let sample = |x, y, lo: [f64; 3], hi: [f64; 3]| ReferenceSample { x, y, lo, hi };
        let set = ReferenceSet {
            width: 4,
            height: 3,
            samples: vec![
                sample(0, 0, [10.0, 20.0, 30.0], [10.0, 20.0, 30.0]),
                sample(3, 1, [99.6, 0.0, 254.2], [101.2, 0.4, 255.0]),
                sample(2, 2, [200.0, 201.0, 202.0], [200.0, 201.0, 202.0]),
            ],
            ..ReferenceSet::default()
        };
        let mut image = image::RgbaImage::from_pixel(4, 3, image::Rgba([7, 7, 7, 255]));
        for s in &set.samples {
            let mid = |c: usize| ((s.lo[c] + s.hi[c]) * 0.5).round() as u8;
            image.put_pixel(s.x, s.y, image::Rgba([mid(0), mid(1), mid(2), 255]));
        }
        let e = compare(&image, &set);
        assert_eq!((e.samples, e.max_abs, e.rmse), (3, 0.0, 0.0));
        image.get_pixel_mut(2, 2)[1] += 5;
        let e = compare(&image, &set);
        assert_eq!((e.max_abs, e.worst), (5.0, (2, 2)));
        assert!((e.rmse - (25.0f64 / 9.0).sqrt()).abs() < 1e-12);

        // A rendered-like image from a real set: 8-bit rounding only.
        let set = reference_samples(&lit_plane(), W, H, 300, Encoding::Srgb, snapping_reach(8));
        let mut image = image::RgbaImage::new(W, H);
        for s in &set.samples {
            let mid = |c: usize| ((s.lo[c] + s.hi[c]) * 0.5).round() as u8;
            image.put_pixel(s.x, s.y, image::Rgba([mid(0), mid(1), mid(2), 255]));
        }
        let e = compare(&image, &set);
        assert_eq!(e.samples, set.samples.len());
        assert!(e.max_abs <= 0.5 && e.rmse <= 0.5, "{e:?}");
    }

    #[test]
    fn textured_surfaces_are_skipped() {
        let texture = Arc::new(Texture::new(
            "grey",
            image::RgbaImage::from_pixel(1, 1, image::Rgba([0, 128, 128, 255])),
        ));
        let map = Some(crate::scene::surface_maps::MapTexture {
            texture: texture.clone(),
            transform: crate::scene::surface_maps::TextureTransform::IDENTITY,
        });
        // Each texture a material may have: the reference evaluates none of them.
        type SetTexture<'a> = &'a dyn Fn(&mut Material);
        let with: [(&str, SetTexture); 5] = [
            ("base colour", &|m| {
                m.diffuse_texture = Some(texture.clone())
            }),
            ("normal", &|m| m.maps.normal = map.clone()),
            ("occlusion", &|m| m.maps.occlusion = map.clone()),
            ("emissive", &|m| {
                m.maps.emissive = Vec3::ONE;
                m.maps.emissive_texture = map.clone();
            }),
            ("metallic-roughness", &|m| {
                m.model = crate::scene::MaterialModel::MetallicRoughness;
                m.maps.metallic_roughness = map.clone();
            }),
        ];
        for (what, set_texture) in with {
            let mut scene = lit_plane();
            set_texture(&mut scene.materials[0]);
            scene.validate().unwrap();
            let set = reference_samples(&scene, W, H, 200, Encoding::Srgb, snapping_reach(8));
            assert!(
                set.samples.is_empty(),
                "{what}: {} samples",
                set.samples.len()
            );
            assert_eq!(
                set.skipped_texture + set.skipped_edge + set.skipped_coplanar,
                200
            );
            assert!(set.skipped_texture > 150, "{what}");
        }
    }

    #[test]
    fn surfaces_behind_transparent_ones_are_skipped() {
        let mut scene = lit_plane();
        let glass = scene.add_material(Material {
            alpha: 0.5,
            ..Material::flat("glass", Vec3::ONE)
        });
        // A pane in front of the middle of the plane, and one behind it (which hides nothing).
        for z in [1.0f32, -1.0] {
            let mut pane = MeshBuilder::new();
            let s = if z > 0.0 { 1.0 } else { 20.0 };
            pane.quad(
                Vec3::new(-s, -s, z),
                Vec3::new(s, -s, z),
                Vec3::new(s, s, z),
                Vec3::new(-s, s, z),
            );
            scene.objects.push(Object {
                mesh: Arc::new(pane.build().unwrap()),
                material: glass,
                transform: DMat4::IDENTITY,
            });
        }
        let count = 400;
        let set = reference_samples(&scene, W, H, count, Encoding::Srgb, snapping_reach(8));
        assert_eq!(
            set.samples.len() + set.skipped_edge + set.skipped_coplanar + set.skipped_transparent,
            count
        );
        // Where the centre ray crosses z = 1 well inside the pane, the pixel is skipped.
        let crosses_pane = |x: u32, y: u32, margin: f64| {
            let (o, d) = pixel_ray(&scene.camera, W, H, x as f64 + 0.5, y as f64 + 0.5);
            let p = o + d * ((1.0 - o.z) / d.z);
            p.x.abs().max(p.y.abs()) < 1.0 - margin
        };
        let inside = sample_pixels(W, H, count)
            .into_iter()
            .filter(|&(x, y)| crosses_pane(x, y, 0.05))
            .count();
        assert!(inside > 20 && set.skipped_transparent >= inside, "{set:?}");
        assert!(set.samples.iter().all(|s| !crosses_pane(s.x, s.y, -0.05)));
    }

    #[test]
    fn background_and_far_clipped_pixels_count_as_missed() {
        let mut scene = lit_plane();
        // A view much larger than the 16 × 16 quad.
        scene.camera.projection = Projection::Orthographic {
            height: 40.0,
            near: 0.1,
            far: 50.0,
        };
        let set = reference_samples(&scene, W, H, 300, Encoding::Linear, snapping_reach(8));
        assert!(set.missed > 150 && !set.samples.is_empty(), "{set:?}");
        assert_eq!(
            set.samples.len() + set.skipped_edge + set.skipped_coplanar + set.missed,
            300
        );
        // The far plane in front of the quad: everything is clipped.
        scene.camera.projection = Projection::Perspective {
            fov_y_deg: 60.0,
            near: 0.1,
            far: 4.5,
        };
        let set = reference_samples(&scene, W, H, 300, Encoding::Linear, snapping_reach(8));
        assert_eq!(set.missed, 300);
    }

    #[test]
    fn sample_pixels_cover_the_image_deterministically() {
        let pixels = sample_pixels(W, H, 1000);
        assert_eq!(pixels, sample_pixels(W, H, 1000));
        assert_eq!(pixels.len(), 1000);
        let mut sorted = pixels.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 1000);
        let (xs, ys): (Vec<u32>, Vec<u32>) = pixels.iter().copied().unzip();
        assert!(xs.iter().all(|&x| x < W) && ys.iter().all(|&y| y < H));
        // From edge to edge: no cell wider than about sqrt(W·H / count) ≈ 2.4 pixels.
        assert!(*xs.iter().min().unwrap() <= 2 && *xs.iter().max().unwrap() >= W - 3);
        assert!(*ys.iter().min().unwrap() <= 2 && *ys.iter().max().unwrap() >= H - 3);
        assert_eq!(sample_pixels(5, 4, 100).len(), 20);
        assert_eq!(sample_pixels(1000, 2, 7).len(), 7);
    }
}
