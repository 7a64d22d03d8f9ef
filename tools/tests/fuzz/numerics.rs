//! Generators for numbers that used to give a silently wrong picture: object transforms near 0
//! and near 10¹², vertex normals of no use (zero, huge, NaN), spot axes of any length and
//! large light ranges, on ES 3.0, ES 2.0 and without fragment highp. A light 1 m in front of
//! the plane's centre must light the centre of a finite frame, or the frame is refused naming
//! what is at fault.

use std::cell::RefCell;
use std::sync::Arc;

use glam::{DMat4, DVec3, Vec3};
use manylight::metrics::cpu_reference::Encoding;
use manylight::scene::{self, Camera, Light, Mesh, Scene};
use manylight::{EsVersion, RenderOptions};
use proptest::prelude::*;

use crate::common::Gpu;

/// A device kind of the fuzz: ES 3.0, ES 2.0, ES 2.0 without fragment highp.
#[derive(Clone, Copy, Debug)]
pub enum Device {
    Es3,
    Es2,
    NoFragmentHighp,
}

pub fn device() -> impl Strategy<Value = Device> {
    prop::sample::select(vec![Device::Es3, Device::Es2, Device::NoFragmentHighp])
}

/// A scale factor: mostly ordinary, often 0 or tiny (flat objects), sometimes huge.
pub fn scale_factor() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => 0.25f64..4.0,
        2 => prop::sample::select(vec![0.0, 1e-300, 1e-20, 1e-7]),
        1 => prop::sample::select(vec![1e3, 1e6, 1e9]),
    ]
}

/// A coordinate: near the origin, or near the documented ±10¹² limit.
pub fn placement() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -10.0f64..10.0,
        2 => prop::sample::select(vec![1e6, -1e7, 1e9, -1e11, 1e12 - 10.0, -1e12]),
    ]
}

/// A vertex normal along the plane's own (of any length), or one of no use. (A tilted one
/// under a huge scale along the normal turns edge-on to the view, where whether it is lit is
/// the sign of a rounding error.)
pub fn normal() -> impl Strategy<Value = Vec3> {
    prop::sample::select(vec![
        Vec3::Z,
        Vec3::new(0.0, 0.0, 3e30),
        Vec3::new(0.0, 0.0, 1e-30),
        Vec3::ZERO,
        Vec3::NAN,
        Vec3::new(0.0, 0.0, f32::INFINITY),
    ])
}

/// A light radius, up to far past fp16's 65 504.
pub fn radius() -> impl Strategy<Value = f32> {
    prop_oneof![
        2 => 3.0f32..20.0,
        3 => prop::sample::select(vec![6e3f32, 6e4, 1e5, 1e6, 1e12, f32::MAX]),
    ]
}

/// A spot axis length (or none: a point light).
pub fn axis_length() -> impl Strategy<Value = Option<f64>> {
    prop::option::weighted(
        0.4,
        prop::sample::select(vec![1.0, 1e-200, 1e-30, 1e155, 1e300]),
    )
}

/// What one case builds.
#[derive(Clone, Debug)]
pub struct Case {
    pub device: Device,
    /// Per-axis scale of the plane (its normal is z).
    pub scale: [f64; 3],
    /// Where the plane's centre is.
    pub at: [f64; 3],
    pub normals: [Vec3; 4],
    pub radius: f32,
    pub axis: Option<f64>,
}

pub fn case() -> impl Strategy<Value = Case> {
    (
        device(),
        (scale_factor(), scale_factor(), scale_factor()),
        (placement(), placement(), placement()),
        [normal(), normal(), normal(), normal()],
        radius(),
        axis_length(),
    )
        .prop_map(
            |(device, (sx, sy, sz), (x, y, z), normals, radius, axis)| Case {
                device,
                // The plane must cover the view's centre: its own axes are at least 1.
                scale: [sx.max(1.0), sy.max(1.0), sz],
                at: [x, y, z],
                normals,
                radius,
                axis,
            },
        )
}

/// The case's scene: the plane placed, the camera 5 m in front of its centre, one light 1 m
/// in front (a spot aims at the centre).
pub fn scene_of(case: &Case) -> Scene {
    let mut s = scene::builtin::build("plane", None).unwrap();
    let at = DVec3::from(case.at);
    let quad = &s.objects[0].mesh;
    let mesh = Mesh::new(
        quad.positions.clone(),
        case.normals.to_vec(),
        quad.uvs.clone(),
        quad.indices.clone(),
    )
    .unwrap();
    s.objects[0].mesh = Arc::new(mesh);
    s.objects[0].transform =
        DMat4::from_translation(at) * DMat4::from_scale(DVec3::from(case.scale));
    s.camera = Camera::perspective(at + DVec3::Z * 5.0, at, 60.0, 0.1, 50.0);
    s.ambient = Vec3::ZERO;
    let position = at + DVec3::new(0.2, 0.1, 1.0);
    s.lights = vec![match case.axis {
        None => Light::point(position, case.radius, Vec3::ONE, 2.0),
        Some(length) => Light::spot(
            position,
            case.radius,
            Vec3::ONE,
            2.0,
            manylight::Cone {
                direction: DVec3::new(-0.2, -0.1, -1.0) * length,
                inner_deg: 30.0,
                outer_deg: 60.0,
            },
        ),
    }];
    s
}

thread_local! {
    /// One renderer per device kind and test thread, made when first needed; a new context
    /// becomes current, so a different kind replaces the one held.
    static GPU: RefCell<Option<(String, Gpu)>> = const { RefCell::new(None) };
}

/// Renders the case's scene (16 × 9, half float) with forward: a finite frame whose centre the
/// light reaches, and whose pixels the f64 light model gives, or an error naming the object,
/// camera or light.
pub fn check(case: &Case) {
    let s = scene_of(case);
    if let Err(e) = s.validate() {
        let message = e.to_string();
        assert!(
            message.contains("lights[0]") || message.contains("camera"),
            "{message}"
        );
        return;
    }
    GPU.with(|cell| {
        let mut cell = cell.borrow_mut();
        let kind = format!("{:?}", case.device);
        if cell.as_ref().is_none_or(|(k, _)| *k != kind) {
            *cell = None;
            let (es, no_fragment_highp) = match case.device {
                Device::Es3 => (EsVersion::Es3, false),
                Device::Es2 => (EsVersion::Es2, false),
                Device::NoFragmentHighp => (EsVersion::Es2, true),
            };
            let restrictions = manylight::gl::Restrictions {
                no_fragment_highp,
                ..Default::default()
            };
            *cell = Some((kind, Gpu::restricted(es, &restrictions)));
        }
        let gpu = &mut cell.as_mut().unwrap().1;
        gpu.r().set_method_named("forward").unwrap();
        match gpu
            .r()
            .render_offscreen_hdr(&s, 16, 9, &RenderOptions::default())
        {
            Ok((pixels, _)) => {
                assert!(
                    pixels.iter().flatten().all(|v| v.is_finite()),
                    "NaN or Inf in the frame of {case:?}"
                );
                let centre = pixels[4 * 16 + 8];
                assert!(
                    centre[0] > 0.0,
                    "the light does not reach the centre: {case:?}"
                );
                // And what it lights is what the f64 light model says, within the documented
                // bounds (docs/precision.md): 2/255 with fragment highp; without it, fp16
                // positions put a light off by up to 21/255 on a few pixels.
                let linear = RenderOptions {
                    linear: true,
                    ..RenderOptions::default()
                };
                let (img, _) = gpu.r().render_offscreen(&s, 16, 9, &linear).unwrap();
                let (err, at, samples) =
                    crate::common::max_oracle_error(&img, &s, Encoding::Linear, gpu.r().caps());
                let bound = match case.device {
                    Device::NoFragmentHighp => 21.0,
                    Device::Es3 | Device::Es2 => 2.0,
                };
                assert!(
                    samples > 0 && err <= bound,
                    "{err:.1}/255 from the light model at {at:?} ({samples} samples): {case:?}"
                );
            }
            Err(manylight::Error::Limit(reason)) => assert!(
                ["objects[0]", "camera."].iter().any(|f| reason.contains(f)),
                "a limit naming nothing: {reason}"
            ),
            Err(e) => {
                let message = e.to_string();
                assert!(
                    ["objects[0]", "camera.", "lights[0]"]
                        .iter()
                        .any(|f| message.contains(f)),
                    "an error naming nothing: {message}"
                );
            }
        }
    });
}
