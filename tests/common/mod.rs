//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use glam::{DVec3, DVec4};
use manylight::gl::HeadlessContext;
use manylight::scene::{shading, Projection, Scene};
use manylight::{EsVersion, RenderOptions, Renderer};

/// A headless context and a renderer on it (the context must outlive the renderer).
pub struct Gpu {
    pub renderer: Option<Renderer>,
    _ctx: HeadlessContext,
}

impl Gpu {
    pub fn new(es: EsVersion) -> Gpu {
        Gpu::restricted(es, &manylight::gl::Restrictions::default())
    }

    /// A renderer playing a weaker device (see `manylight::gl::Restrictions`).
    pub fn restricted(es: EsVersion, restrictions: &manylight::gl::Restrictions) -> Gpu {
        let ctx = HeadlessContext::new(es).unwrap_or_else(|e| {
            panic!("no headless {es} context ({e}); install libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri")
        });
        let renderer = Renderer::restricted(ctx.load_gl(), es, restrictions).expect("renderer");
        Gpu {
            renderer: Some(renderer),
            _ctx: ctx,
        }
    }

    pub fn r(&mut self) -> &mut Renderer {
        self.renderer.as_mut().unwrap()
    }

    pub fn render(
        &mut self,
        scene: &Scene,
        w: u32,
        h: u32,
        opts: &RenderOptions,
    ) -> image::RgbaImage {
        self.r()
            .render_offscreen(scene, w, h, opts)
            .expect("render")
            .0
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        if let Some(r) = self.renderer.take() {
            r.destroy();
        }
    }
}

/// `../shared/assets` or `$MANYLIGHT_ASSETS`, if present.
pub fn assets_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("MANYLIGHT_ASSETS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets"));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "SKIPPED: assets folder {} not found (set MANYLIGHT_ASSETS)",
            dir.display()
        );
        None
    }
}

/// CPU oracle for a scene whose only geometry is the plane z = 0 facing +Z (the `plane`
/// built-in, untransformed): the linear colour of pixel (x, y), top row first, or `None`
/// where the pixel ray misses the plane.
pub fn plane_pixel(scene: &Scene, w: u32, h: u32, x: u32, y: u32) -> Option<DVec3> {
    plane_point(scene, w, h, x as f64 + 0.5, y as f64 + 0.5)
}

/// [`plane_pixel`] at window position (`px`, `py`) in pixels from the top-left corner.
pub fn plane_point(scene: &Scene, w: u32, h: u32, px: f64, py: f64) -> Option<DVec3> {
    let cam = &scene.camera;
    let aspect = w as f64 / h as f64;
    let inv_vp = (cam.projection_matrix(aspect) * cam.view_matrix()).inverse();
    let ndc_x = 2.0 * px / w as f64 - 1.0;
    let ndc_y = 1.0 - 2.0 * py / h as f64;
    let unproject = |z: f64| {
        let p = inv_vp * DVec4::new(ndc_x, ndc_y, z, 1.0);
        p.truncate() / p.w
    };
    let (a, b) = (unproject(-1.0), unproject(1.0));
    let dir = b - a;
    if dir.z.abs() < 1e-12 {
        return None;
    }
    let t = -a.z / dir.z;
    if !(0.0..=1.0).contains(&t) {
        return None;
    }
    let p = a + dir * t;
    if p.x.abs() > 8.0 || p.y.abs() > 8.0 {
        return None;
    }
    let m = &scene.materials[scene.objects[0].material];
    let v = match cam.projection {
        Projection::Perspective { .. } => (cam.position - p).normalize(),
        Projection::Orthographic { .. } => (cam.position - cam.target).normalize(),
    };
    let surface = shading::Surface {
        position: p,
        normal: DVec3::Z,
        albedo: m.diffuse.as_dvec3(),
        specular: m.specular.as_dvec3(),
        exponent: m.shading_exponent() as f64,
    };
    Some(shading::shade(&surface, v, &scene.lights, scene.ambient))
}

/// How far from the pixel centre the oracle is also evaluated: GPUs snap vertices to a
/// sub-pixel grid (8 bits on common hardware, 1/256 pixel), so the point a fragment is shaded
/// at may be that far from the exact centre; twice that is the neighbourhood checked.
pub const ORACLE_SUBPIXEL: f64 = 1.0 / 128.0;

/// Largest per-channel difference (in 8-bit steps) between the image and the oracle over all
/// pixels the oracle covers, with the pixel where it happens; `encode` maps linear to stored.
///
/// The oracle is an interval: the light model at the pixel centre and at
/// [`ORACLE_SUBPIXEL`] from it in x and y, and the error is the distance from the interval.
/// Where the model is smooth, that is the plain difference; across a hard spot edge, where
/// a position that close already changes the value, it is what any GPU may rightly give.
pub fn max_oracle_error(
    img: &image::RgbaImage,
    scene: &Scene,
    encode: impl Fn(f64) -> f64,
) -> (f64, (u32, u32), usize) {
    let (w, h) = img.dimensions();
    let mut worst = (0.0f64, (0, 0));
    let mut covered = 0;
    let d = ORACLE_SUBPIXEL;
    for y in 0..h {
        for x in 0..w {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let samples: Vec<DVec3> = [(0.0, 0.0), (d, 0.0), (-d, 0.0), (0.0, d), (0.0, -d)]
                .iter()
                .filter_map(|(dx, dy)| plane_point(scene, w, h, cx + dx, cy + dy))
                .collect();
            if samples.len() < 5 {
                continue;
            }
            covered += 1;
            let px = img.get_pixel(x, y);
            for ch in 0..3 {
                let stored = |c: &DVec3| encode(c[ch]).clamp(0.0, 1.0) * 255.0;
                let lo = samples.iter().map(stored).fold(f64::INFINITY, f64::min);
                let hi = samples.iter().map(stored).fold(f64::NEG_INFINITY, f64::max);
                let v = px[ch] as f64;
                let err = (lo - v).max(v - hi).max(0.0);
                if err > worst.0 {
                    worst = (err, (x, y));
                }
            }
        }
    }
    (worst.0, worst.1, covered)
}
