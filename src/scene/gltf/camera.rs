//! glTF cameras → the renderer's look-at [`Camera`]: the node's world origin is the eye, its
//! world −Z the view direction, its world +Y the up direction (scale ignored, as glTF says).
//! Perspective: `yfov` (radians) → `fov_y_deg`, `znear`, `zfar` (absent: an infinite far
//! plane, which the renderer supports). Orthographic: `ymag` is half the view's height →
//! `height = 2 · ymag`. `aspectRatio` and `xmag` are not used: the viewport decides the
//! aspect, as it does for every camera of the renderer.

use glam::{DMat4, DVec3};
use gltf::camera::Projection as GltfProjection;

use crate::scene::camera::{MIN_FOV_Y_DEG, MIN_ORTHO_HEIGHT};
use crate::scene::{Camera, Projection, Short};

/// Converts `camera` of `document` on a node with world transform `world`; `field` names it
/// in errors.
pub(super) fn convert(
    document: &gltf::Document,
    camera: &gltf::Camera,
    world: &DMat4,
    field: &str,
) -> Result<Camera, String> {
    // The crate's `projection()` assumes the object its `type` names is there.
    if let Some(json) = document.as_json().cameras.get(camera.index()) {
        use gltf::json::camera::Type;
        use gltf::json::validation::Checked;
        let present = match json.type_ {
            Checked::Valid(Type::Perspective) => json.perspective.is_some(),
            Checked::Valid(Type::Orthographic) => json.orthographic.is_some(),
            Checked::Invalid => false,
        };
        if !present {
            return Err(format!(
                "{field}: its `type` names a projection the camera does not define"
            ));
        }
    }
    let position = world.transform_point3(DVec3::ZERO);
    let forward = crate::scene::direction::unit(world.transform_vector3(DVec3::NEG_Z));
    let up = crate::scene::direction::unit(world.transform_vector3(DVec3::Y));
    let (Some(forward), Some(up)) = (forward, up) else {
        return Err(format!(
            "{field}: the node's transform has no direction (zero scale)"
        ));
    };
    // Any look-at distance gives the same view; one proportionate to the position keeps the
    // direction exact in f64 far from the origin.
    let distance = (position.abs().max_element() * 1e-3).max(1.0);
    check_projection(&camera.projection(), camera.index()).map_err(|e| format!("{field}: {e}"))?;
    let projection = match camera.projection() {
        GltfProjection::Perspective(p) => Projection::Perspective {
            fov_y_deg: f64::from(p.yfov()).to_degrees(),
            near: f64::from(p.znear()),
            far: p.zfar().map_or(f64::INFINITY, f64::from),
        },
        GltfProjection::Orthographic(o) => Projection::Orthographic {
            height: 2.0 * f64::from(o.ymag()).abs(),
            near: f64::from(o.znear()),
            far: f64::from(o.zfar()),
        },
    };
    let camera = Camera {
        position,
        target: position + forward * distance,
        up,
        projection,
    };
    camera.validate().map_err(|e| format!("{field}: {e}"))?;
    Ok(camera)
}

/// What reading a glTF number as f32 (as the loader does) made of `v`, where it is not what the
/// file says: 0 from a tiny magnitude, infinite from a huge one.
fn as_f32_reads(v: f64) -> String {
    if v == 0.0 {
        format!(
            " (read as f32: magnitudes below {:e} read as 0)",
            f32::from_bits(1)
        )
    } else if v.is_infinite() {
        format!(
            " (read as f32: magnitudes past {:.1e} read as infinite)",
            f32::MAX
        )
    } else {
        String::new()
    }
}

/// The projection's values the renderer cannot take, named as the file writes them
/// (`cameras[i].perspective.yfov` in radians, not the converted `camera.fov_y_deg`).
fn check_projection(projection: &GltfProjection, index: usize) -> Result<(), String> {
    let bad = |name: &str, why: String| Err(format!("`cameras[{index}].{name}` {why}"));
    let (kind, znear, zfar) = match projection {
        GltfProjection::Perspective(p) => {
            let (min, yfov) = (MIN_FOV_Y_DEG.to_radians(), f64::from(p.yfov()));
            if !(min..std::f64::consts::PI).contains(&yfov) {
                return bad(
                    "perspective.yfov",
                    format!(
                        "must be in [{min:e}, π) radians, got {yfov:?}{}",
                        as_f32_reads(yfov)
                    ),
                );
            }
            let znear = f64::from(p.znear());
            if !(znear > 0.0 && znear.is_finite()) {
                return bad(
                    "perspective.znear",
                    format!(
                        "must be finite and > 0, got {znear:?}{}",
                        as_f32_reads(znear)
                    ),
                );
            }
            ("perspective", znear, p.zfar().map(f64::from))
        }
        GltfProjection::Orthographic(o) => {
            let ymag = f64::from(o.ymag()).abs();
            if !(2.0 * ymag >= MIN_ORTHO_HEIGHT && ymag.is_finite()) {
                return bad(
                    "orthographic.ymag",
                    format!(
                        "must be finite with a magnitude of at least {:e}, got {}",
                        MIN_ORTHO_HEIGHT / 2.0,
                        Short(o.ymag())
                    ),
                );
            }
            let znear = f64::from(o.znear());
            if !(znear >= 0.0 && znear.is_finite()) {
                return bad(
                    "orthographic.znear",
                    format!("must be finite and >= 0, got {znear:?}"),
                );
            }
            ("orthographic", znear, Some(f64::from(o.zfar())))
        }
    };
    match zfar {
        Some(zfar) if !(zfar > znear && zfar.is_finite()) => bad(
            &format!("{kind}.zfar"),
            format!("must be finite and > znear ({znear:?}), got {zfar:?}"),
        ),
        _ => Ok(()),
    }
}
