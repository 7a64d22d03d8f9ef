//! Which proxy draws each of deferred's lights, and how its depth test bounds the surfaces it
//! shades.

use glam::DMat4;

use crate::cluster::view_light::GpuLight;
use crate::gl::state::{Cull, DepthTest};
use crate::scene::{Camera, Projection};

/// Proxies are drawn this much larger than the light radius: the 16 × 9 sphere's faces lie
/// inside the true sphere by up to 1 − cos(π/16)·cos(π/18) ≈ 3.4 %, and the rest is the
/// margin a depth test needs over the light's reach.
pub(super) const VOLUME_SCALE: f32 = 1.1;

/// A proxy drawn by its far side or bounded by its far end must end before this fraction of
/// the far plane's distance, or it takes the full-screen path (the far side must not be
/// clipped; the margin covers `f32` rounding of the projection).
const FAR_MARGIN: f32 = 0.999;

/// The largest proxy radius, in near-plane distances, drawn by its far side (or bounded by its
/// far end) in perspective; past it, the full-screen path. A tenth of where head lamps were
/// seen to lose light (docs/precision.md).
const FAR_SIDE_REACH: f32 = 2048.0;

/// Fewest pixels a proxy's radius spans where its light lies: a disc of a pixel's radius
/// holds a pixel centre wherever it lies (they are at most √2/2 apart from any point).
const MIN_PROXY_PX: f64 = 1.0;

/// Most pixels a proxy may span across, as scene triangles (`scene::triangle_reach`): a sphere
/// of about 2²⁷ pixels (a 10⁻⁵-high orthographic view) lost its light on every implementation
/// here, without an error. Past it, one in view takes the full-screen path (it covers much of
/// the frame anyway).
const MAX_PROXY_SPAN_PX: f64 = (1u64 << 24) as f64;

/// How a light's proxy is drawn and depth tested against the surfaces:
/// - wholly in front of the near plane: the sphere's near side, `LEQUAL` — where a surface
///   lies in front of the whole sphere the light cannot reach it and the pixel is skipped;
/// - reaching the near plane (the eye inside or beside it), whose near side would be clipped:
///   the far side, `GEQUAL` — surfaces behind the whole sphere are skipped;
/// - where the implementation loses triangles crossing the eye's plane
///   ([`Caps::loses_triangles_crossing_the_eye_plane`](crate::gl::Caps)) and the sphere
///   reaches behind the eye, or clips a shared edge into pieces that do not meet
///   ([`Caps::clips_shared_edges_apart`](crate::gl::Caps)) and the sphere crosses a side of
///   the view: a full-screen triangle at the depth of the light's far end, `GEQUAL` —
///   surfaces behind that plane are skipped;
/// - reaching the far plane too, depth too coarse there for any test, a far side the near
///   plane clips into faces too large to interpolate depth over, or a sphere spanning more
///   than [`MAX_PROXY_SPAN_PX`]: a full-screen triangle, untested.
///
/// Each is one-sided (no stencil). The far side everywhere would skip more in open scenes but
/// evaluate far more in enclosed ones (the conference room); the near side first avoids that
/// worst case. A depth bias (`Material::depth_bias`) moves the depth the tests read: where the
/// G-buffer holds a surface drawn toward the camera no light takes its near side, and where
/// it holds one drawn away the far side and the bound go untested ([`ProxyReach::depth_test`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Proxy {
    NearSide,
    FarSide,
    Bounded,
    FullScreen,
}

impl Proxy {
    /// Every proxy, in the order the light pass draws them (each has its instance stream).
    pub(super) const ALL: [Proxy; 4] = [
        Proxy::NearSide,
        Proxy::FarSide,
        Proxy::Bounded,
        Proxy::FullScreen,
    ];

    pub(super) fn cull(self) -> Cull {
        match self {
            Proxy::NearSide => Cull::Back,
            Proxy::FarSide => Cull::Front,
            Proxy::Bounded | Proxy::FullScreen => Cull::None,
        }
    }

    pub(super) fn depth_test(self) -> DepthTest {
        match self {
            Proxy::NearSide => DepthTest::LessEqual,
            Proxy::FarSide | Proxy::Bounded => DepthTest::GreaterEqual,
            Proxy::FullScreen => DepthTest::Off,
        }
    }

    /// Drawn as the full-screen triangle rather than the sphere.
    pub(super) fn full_screen(self) -> bool {
        matches!(self, Proxy::Bounded | Proxy::FullScreen)
    }
}

/// What decides a light's [`Proxy`]: the view's camera, depth range and projection, and the
/// implementation.
pub(super) struct ProxyReach<'a> {
    pub camera: &'a Camera,
    pub near: f32,
    pub far: f32,
    /// The projection the frame draws with.
    pub projection: DMat4,
    /// [`Caps::loses_triangles_crossing_the_eye_plane`](crate::gl::Caps).
    pub eye_plane_unreliable: bool,
    /// [`Caps::clips_shared_edges_apart`](crate::gl::Caps).
    pub sides_unreliable: bool,
    /// The frame's height in pixels.
    pub rows: u32,
    /// The G-buffer holds a surface drawn toward the camera, off its depth: a `LEQUAL` test
    /// of a near side in front of it would fail where the light reaches it.
    pub biased_toward: bool,
    /// The G-buffer holds a surface drawn away from the camera: a `GEQUAL` test of a far side
    /// or bound behind it would fail.
    pub biased_away: bool,
}

impl ProxyReach<'_> {
    /// The radius `light`'s proxy is drawn with: its reach, [`VOLUME_SCALE`] larger, and at
    /// least [`MIN_PROXY_PX`] pixels where the light lies, so that a light smaller than a pixel
    /// still covers the pixel centres it may light (SwiftShader, which snaps vertices to 1/16
    /// pixel, lost such lights at their own size).
    pub(super) fn radius(&self, light: &GpuLight) -> f32 {
        let reach = light.cull_radius * VOLUME_SCALE;
        let pixel = self.pixel_at(f64::from(-light.position.z));
        reach.max((MIN_PROXY_PX * pixel) as f32)
    }

    /// The height of a pixel at view depth `depth` (the near plane's where nearer; the same
    /// everywhere in orthographic).
    fn pixel_at(&self, depth: f64) -> f64 {
        let rows = f64::from(self.rows.max(1));
        let half_height = 1.0 / self.projection.y_axis.y;
        match self.camera.projection {
            Projection::Perspective { .. } => {
                2.0 * depth.max(f64::from(self.near)) * half_height / rows
            }
            Projection::Orthographic { .. } => 2.0 * half_height / rows,
        }
    }

    pub(super) fn proxy(&self, light: &GpuLight) -> Proxy {
        let radius = self.radius(light);
        let depth = -light.position.z;
        // A proxy's one-sided depth test needs depth steps well inside the light's reach
        // where it ends (a tiny near plane makes them wider; docs/precision.md).
        let coarse = self.camera.depth_step_at(f64::from(depth + radius), 24)
            > 0.1 * f64::from(light.cull_radius);
        let wide = self.too_wide(light, radius);
        let clipped_apart = self.sides_unreliable && self.crosses_a_side(light, radius);
        if !coarse
            && depth - radius >= 2.0 * self.near
            && !wide
            && !self.biased_toward
            && !clipped_apart
        {
            return Proxy::NearSide;
        }
        if coarse || depth + radius >= FAR_MARGIN * self.far || wide {
            return Proxy::FullScreen;
        }
        let perspective = matches!(self.camera.projection, Projection::Perspective { .. });
        // A far side around the eye is clipped at the near plane into faces reaching
        // `radius / near` half-viewports off screen, and so are the surfaces there: depth
        // interpolated across them is tens of steps off, too far for any depth test.
        if perspective && radius > FAR_SIDE_REACH * self.near {
            Proxy::FullScreen
        } else if perspective && self.eye_plane_unreliable && depth - radius < 0.0 {
            // A sphere reaching behind the eye has faces crossing its plane.
            Proxy::Bounded
        } else if clipped_apart {
            Proxy::Bounded
        } else {
            Proxy::FarSide
        }
    }

    /// How `proxy` is depth tested: its own test ([`Proxy::depth_test`]), or none where a
    /// surface drawn off its depth could fail it.
    pub(super) fn depth_test(&self, proxy: Proxy) -> DepthTest {
        let defeated = match proxy {
            Proxy::NearSide => self.biased_toward,
            Proxy::FarSide | Proxy::Bounded => self.biased_away,
            Proxy::FullScreen => false,
        };
        if defeated {
            DepthTest::Off
        } else {
            proxy.depth_test()
        }
    }

    /// For the view's two pairs of sides (left and right, bottom and top): how far `light`'s
    /// centre lies inside the nearer side, and the proxy's `radius`, both in that pair's own
    /// measure (the distance from a side plane `|v| = t · depth` in perspective, scaled).
    fn side_margins(&self, light: &GpuLight, radius: f32) -> [(f64, f64); 2] {
        let (c, r) = (light.position.as_dvec3(), f64::from(radius));
        let depth = -c.z;
        // The view's half extents: per unit of depth in perspective, in units orthographic.
        let (tx, ty) = (
            1.0 / self.projection.x_axis.x,
            1.0 / self.projection.y_axis.y,
        );
        let perspective = matches!(self.camera.projection, Projection::Perspective { .. });
        let inside_by = |v: f64, t: f64| {
            if perspective {
                (t * depth - v.abs(), r * (1.0 + t * t).sqrt())
            } else {
                (t - v.abs(), r)
            }
        };
        [inside_by(c.x, tx), inside_by(c.y, ty)]
    }

    /// Whether `light`'s proxy of `radius` lies wholly beside a side of the view (it covers no
    /// pixel).
    fn beside_the_view(&self, light: &GpuLight, radius: f32) -> bool {
        (self.side_margins(light, radius).iter()).any(|&(inside, r)| inside < -r)
    }

    /// Whether `light`'s proxy of `radius` crosses a side of the view (neither wholly inside
    /// the view's four sides nor wholly beside one of them).
    fn crosses_a_side(&self, light: &GpuLight, radius: f32) -> bool {
        let within = (self.side_margins(light, radius).iter()).all(|&(inside, r)| inside > r);
        !within && !self.beside_the_view(light, radius)
    }

    /// Whether `light`'s proxy of `radius` may be in view and spans more than
    /// [`MAX_PROXY_SPAN_PX`] where it comes nearest the eye (the near plane at most). One out
    /// of view covers no pixel however wide, and keeps its sphere (drawn full screen, it would
    /// be evaluated at every pixel). No trigonometry: the projection's scales give the view's
    /// extent.
    fn too_wide(&self, light: &GpuLight, radius: f32) -> bool {
        let (c, r) = (light.position.as_dvec3(), f64::from(radius));
        let depth = -c.z;
        let near = f64::from(self.near);
        if depth + r <= near {
            return false;
        }
        if self.beside_the_view(light, radius) {
            return false;
        }
        // The size of a pixel where the proxy comes nearest.
        2.0 * r > MAX_PROXY_SPAN_PX * self.pixel_at(depth - r)
    }

    /// The normalized device depth of a [`Proxy::Bounded`] light's far end (its proxy
    /// radius beyond its centre), rounded up to an `f32`: no surface the light reaches lies
    /// behind it.
    pub(super) fn bound_depth(&self, light: &GpuLight) -> f32 {
        let far_end = f64::from(light.position.z) - f64::from(light.cull_radius * VOLUME_SCALE);
        let clip = self.projection * glam::DVec4::new(0.0, 0.0, far_end, 1.0);
        let depth = (clip.z / clip.w).min(1.0);
        let rounded = depth as f32;
        if f64::from(rounded) < depth {
            rounded.next_up()
        } else {
            rounded
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Light;
    use glam::{DVec3, Vec3};

    fn camera(near: f64) -> Camera {
        Camera::perspective(DVec3::ZERO, DVec3::NEG_Z, 60.0, near, 100.0)
    }

    fn reach(camera: &Camera, eye_plane_unreliable: bool) -> ProxyReach<'_> {
        let (near, far) = camera.near_far();
        ProxyReach {
            camera,
            near: near as f32,
            far: far as f32,
            projection: camera.projection_matrix(16.0 / 9.0),
            eye_plane_unreliable,
            sides_unreliable: false,
            rows: 720,
            biased_toward: false,
            biased_away: false,
        }
    }

    /// A surface drawn toward the camera leaves no light its near side; one drawn away leaves
    /// the far side and the bound untested; both, the two.
    #[test]
    fn surfaces_drawn_off_their_depth_take_the_tests_they_cannot_fail() {
        let camera = camera(0.1);
        let ahead = light(DVec3::new(0.0, 0.0, -10.0), 2.0);
        let head_lamp = light(DVec3::ZERO, 2.0);
        for (toward, away) in [(false, false), (true, false), (false, true), (true, true)] {
            let r = ProxyReach {
                biased_toward: toward,
                biased_away: away,
                ..reach(&camera, true)
            };
            let tests = [&ahead, &head_lamp].map(|l| {
                let p = r.proxy(l);
                (p, r.depth_test(p))
            });
            let (near_side, far_side) = (
                (Proxy::NearSide, DepthTest::LessEqual),
                (Proxy::FarSide, DepthTest::GreaterEqual),
            );
            let untested = |p| (p, DepthTest::Off);
            let expected = match (toward, away) {
                (false, false) => [near_side, (Proxy::Bounded, DepthTest::GreaterEqual)],
                (true, false) => [far_side, (Proxy::Bounded, DepthTest::GreaterEqual)],
                (false, true) => [near_side, untested(Proxy::Bounded)],
                (true, true) => [untested(Proxy::FarSide), untested(Proxy::Bounded)],
            };
            assert_eq!(tests, expected, "toward {toward}, away {away}");
        }
    }

    fn light(at: DVec3, radius: f32) -> GpuLight {
        let l = Light::point(at, radius, Vec3::ONE, 1.0);
        GpuLight::from_light(&l, &glam::DMat4::IDENTITY)
    }

    /// Where shared edges are clipped apart, a sphere crossing a side of the view is bounded;
    /// one wholly inside or wholly beside the view keeps its near side, as everywhere else.
    #[test]
    fn a_sphere_crossing_the_views_side_is_bounded_only_where_clipping_splits_edges() {
        let camera = camera(0.1);
        // 60° vertical at 16:9: at depth 10 the view's half extents are 5.77 and 10.3.
        let cases = [
            (DVec3::new(0.0, 0.0, -10.0), Proxy::NearSide),
            (DVec3::new(0.0, 5.5, -10.0), Proxy::Bounded),
            (DVec3::new(-10.0, 0.0, -10.0), Proxy::Bounded),
            (DVec3::new(0.0, 9.0, -10.0), Proxy::NearSide),
        ];
        for (at, split_apart) in cases {
            let l = light(at, 1.0);
            assert_eq!(reach(&camera, true).proxy(&l), Proxy::NearSide, "{at}");
            let r = ProxyReach {
                sides_unreliable: true,
                ..reach(&camera, true)
            };
            assert_eq!(r.proxy(&l), split_apart, "{at}");
        }
    }

    #[test]
    fn a_sphere_behind_the_eye_is_bounded_only_where_its_faces_would_be_lost() {
        let camera = camera(0.1);
        let head_lamp = light(DVec3::ZERO, 2.0);
        // Reaching the near plane, but not behind the eye.
        let ahead = light(DVec3::new(0.0, 0.0, -2.15), 1.9);
        let far_away = light(DVec3::new(0.0, 0.0, -20.0), 2.0);
        for unreliable in [false, true] {
            let r = reach(&camera, unreliable);
            let bounded = if unreliable {
                Proxy::Bounded
            } else {
                Proxy::FarSide
            };
            assert_eq!(r.proxy(&head_lamp), bounded);
            assert_eq!(r.proxy(&ahead), Proxy::FarSide);
            assert_eq!(r.proxy(&far_away), Proxy::NearSide);
        }
        // Past FAR_SIDE_REACH near distances, full screen on every implementation.
        let huge = light(DVec3::ZERO, 0.1 * FAR_SIDE_REACH);
        assert_eq!(reach(&camera, true).proxy(&huge), Proxy::FullScreen);
        assert_eq!(reach(&camera, false).proxy(&huge), Proxy::FullScreen);
    }

    /// A sphere spanning more pixels than rasterizers keep (a 10⁻⁵-high orthographic view,
    /// a 10⁻³° lens) is drawn full screen; the same sphere in an ordinary view is not.
    #[test]
    fn a_sphere_wider_than_rasterizers_keep_is_drawn_full_screen() {
        let orthographic = |height| Camera {
            projection: Projection::Orthographic {
                height,
                near: 0.0,
                far: 100.0,
            },
            ..camera(0.1)
        };
        let narrow = Camera::perspective(DVec3::ZERO, DVec3::NEG_Z, 1e-3, 0.1, 100.0);
        // 11 units across from 4.5 away: 10⁸ pixels through the 10⁻³° lens at 720 rows.
        let ahead = light(DVec3::new(0.0, 0.0, -10.0), 5.0);
        let proxy = |camera: &Camera| reach(camera, false).proxy(&ahead);
        assert_eq!(proxy(&orthographic(1e-5)), Proxy::FullScreen);
        assert_eq!(proxy(&narrow), Proxy::FullScreen);
        assert_eq!(proxy(&orthographic(10.0)), Proxy::NearSide);
        assert_eq!(proxy(&camera(0.1)), Proxy::NearSide);
        // Beside the view or behind the eye it covers no pixel: not drawn full screen.
        for at in [DVec3::new(40.0, 0.0, -10.0), DVec3::new(0.0, 0.0, 10.0)] {
            let away = light(at, 5.0);
            assert_ne!(
                reach(&narrow, false).proxy(&away),
                Proxy::FullScreen,
                "{at}"
            );
            let tiny = orthographic(1e-5);
            assert_ne!(reach(&tiny, false).proxy(&away), Proxy::FullScreen, "{at}");
        }
    }

    #[test]
    fn the_bound_lies_behind_everything_the_light_reaches() {
        let camera = camera(0.01);
        let r = reach(&camera, true);
        for (z, radius) in [(0.0, 2.0), (-0.5, 3.0), (0.3, 1.0), (-1.0, 20.0)] {
            let l = light(DVec3::new(0.2, -0.1, z), radius);
            let bound = f64::from(r.bound_depth(&l));
            let reached = |depth: f64| {
                let clip = r.projection * glam::DVec4::new(0.0, 0.0, -depth, 1.0);
                clip.z / clip.w
            };
            let farthest = reached(-z + f64::from(radius));
            let proxy_end = reached(-z + f64::from(radius * VOLUME_SCALE));
            assert!(
                bound > farthest && bound >= proxy_end && bound < 1.0,
                "{z} {radius}: {bound}"
            );
        }
    }
}
