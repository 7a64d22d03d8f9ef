//! How lights move: orbit, bob, wander, flicker and spot sweep, each a pure function of the
//! time `t` in seconds, so any frame can be rendered on its own (frame k of a sequence is the
//! same picture whether frames 0 … k − 1 were rendered before it or not).
//!
//! Every motion is a displacement that is **zero at `t = 0`**: the scene as written (or as
//! built) is its own first frame, so still renders, oracles and documented figures do not
//! change when a scene gains motion. Motions combine: position = rest + orbit + bob + wander,
//! the spot axis is swept, the intensity flickered.
//!
//! Periodic terms use `sin(2π·t/T + φ) − sin φ`: a swing of the given amplitude around a
//! centre offset by `−sin φ` times it, passing through the rest state at `t = 0`. Angles are
//! taken from the fractional part of `t/T`, so late frames (`t` of days) lose no precision.

use std::f64::consts::TAU;

use glam::{DQuat, DVec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::direction::unit;
use super::{Light, LightKind, SceneError};

/// Shortest period accepted, in seconds (a millisecond: faster is flicker noise at any
/// frame rate).
pub const MIN_PERIOD_S: f64 = 1e-3;
/// Longest period accepted, in seconds (about 30 years).
pub const MAX_PERIOD_S: f64 = 1e9;
/// Largest displacement a motion may add (orbit radius, bob amplitude, wander radius, an
/// orbit centre's coordinates); where the moving light may go is checked against the
/// lights' own limit (`MAX_LIGHT_COORD`) as well.
pub const MAX_DISPLACEMENT: f64 = 1e9;

/// Where an orbit goes round.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OrbitAbout {
    /// Rotates the rest position about the axis through this world point (a carousel: every
    /// light of a set on its own circle round the same axis).
    Point(DVec3),
    /// A circle of this radius through the rest position, in the plane normal to the axis
    /// (each light circles near where it was placed); the phase says where on the circle the
    /// rest position lies.
    Radius(f64),
}

/// Circular motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Centre point or circle radius.
    pub about: OrbitAbout,
    /// Rotation axis (right-handed; flip it to go the other way round). Non-zero.
    pub axis: DVec3,
    /// Seconds per turn.
    pub period_s: f64,
    /// Start angle on the circle, degrees ([`OrbitAbout::Radius`] only).
    pub phase_deg: f64,
}

/// Back-and-forth motion along a vector: `A·(sin(2π t/T + φ) − sin φ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bob {
    /// Amplitude vector `A`.
    pub amplitude: DVec3,
    /// Seconds per swing.
    pub period_s: f64,
    /// Phase φ in degrees.
    pub phase_deg: f64,
}

/// A smooth, seeded, never-repeating path that stays within `radius` of the rest position:
/// per axis a sum of three sines of seeded frequencies (around `1/period_s`) and phases.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wander {
    /// Largest distance from the rest position.
    pub radius: f64,
    /// Typical seconds per excursion.
    pub period_s: f64,
    /// Seed of the path (random sets give each light its own).
    pub seed: u64,
}

/// Intensity flicker: `intensity·(1 − amount·n(t))` with `n` a smooth seeded noise in
/// [0, 1], `n(0) = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flicker {
    /// Deepest dip, a fraction of the intensity in [0, 1].
    pub amount: f32,
    /// Typical dips per second.
    pub rate_hz: f64,
    /// Seed of the noise.
    pub seed: u64,
}

/// A spot light's axis swinging about an axis: rotation by `A·(sin(2π t/T + φ) − sin φ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// The axis the spot direction turns about. Non-zero.
    pub axis: DVec3,
    /// Swing amplitude `A` in degrees, within [0, 180].
    pub angle_deg: f64,
    /// Seconds per swing.
    pub period_s: f64,
    /// Phase φ in degrees.
    pub phase_deg: f64,
}

/// Any combination of motions of one light (all `None`: it stands still).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Circular motion.
    pub orbit: Option<Orbit>,
    /// Back-and-forth motion.
    pub bob: Option<Bob>,
    /// A wandering path.
    pub wander: Option<Wander>,
    /// Intensity flicker.
    pub flicker: Option<Flicker>,
    /// Spot axis sweep (spot lights only).
    pub sweep: Option<Sweep>,
}

/// Lights of a scene that move: a run of consecutive lights, their state at `t = 0`, and
/// how they move.
#[derive(Clone, Debug, PartialEq)]
pub struct LightTrack {
    /// Index into [`super::Scene::lights`] of the first light it moves.
    pub first: usize,
    /// The lights at `t = 0`, from `first` on.
    pub rest: Vec<Light>,
    /// Their motion.
    pub motion: Motion,
    /// `Some(seed)`: each light moves by its own variation of `motion` ([`Motion::varied`]),
    /// so a set does not move in lockstep; `None`: all exactly as `motion`.
    pub vary: Option<u64>,
    /// The variation number of its first light (0, unless [`super::Scene::remove_light`]
    /// split the track: the lights after a removed one keep their own variations).
    pub variation_start: usize,
}

impl LightTrack {
    /// The motion of the `k`-th light of the track.
    pub fn motion_of(&self, k: usize) -> Motion {
        match (self.vary, self.rest.get(k)) {
            (Some(seed), Some(rest)) => {
                let is_spot = matches!(rest.kind, LightKind::Spot { .. });
                self.motion
                    .varied(seed, self.variation_start.wrapping_add(k), is_spot)
            }
            _ => self.motion,
        }
    }

    /// Writes the track's lights at time `t` into `lights` (the slice starting at `first`).
    pub fn pose(&self, lights: &mut [Light], t: f64) {
        for (k, (light, rest)) in lights.iter_mut().zip(&self.rest).enumerate() {
            *light = self.motion_of(k).apply(rest, t);
        }
    }
}

/// Angle `2π·(t/T + φ/360)`, reduced to one turn before scaling so a large `t` keeps its
/// precision; `t` is reduced to one period first and `φ` to one turn (both exactly), so no
/// finite `t` overflows `t/T` and no large `φ` rounds the time's share of the turn away.
fn angle(t: f64, period_s: f64, phase_deg: f64) -> f64 {
    TAU * (t.rem_euclid(period_s) / period_s + phase_deg.rem_euclid(360.0) / 360.0).rem_euclid(1.0)
}

/// `sin(2π t/T + φ) − sin φ`: zero at `t = 0`, within [−2, 2].
fn swing(t: f64, period_s: f64, phase_deg: f64) -> f64 {
    angle(t, period_s, phase_deg).sin() - angle(0.0, period_s, phase_deg).sin()
}

/// Three partial frequencies (multiples of the base) and phases from a seed, for one axis or
/// the flicker noise.
fn partials(seed: u64, stream: u64) -> [(f64, f64); 3] {
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    // Spread over about an octave and a half, never equal, so the sum never repeats soon.
    [0.55, 1.0, 1.6].map(|base| {
        (
            base * rng.random_range(0.85..1.15),
            rng.random_range(0.0..360.0),
        )
    })
}

impl Motion {
    /// True when it moves nothing.
    pub fn is_still(&self) -> bool {
        *self == Motion::default()
    }

    /// The light at time `t` (seconds) given its state at `t = 0`. A non-finite `t` is taken
    /// as 0.
    pub fn apply(&self, rest: &Light, t: f64) -> Light {
        let t = if t.is_finite() { t } else { 0.0 };
        let mut light = *rest;
        // An axis validation refuses (zero, NaN) turns nothing here rather than make NaN
        // (or trip glam's assertions, where a dependency turns them on).
        if let Some((o, axis)) = self.orbit.as_ref().and_then(|o| Some((o, unit(o.axis)?))) {
            light.position += match o.about {
                OrbitAbout::Point(centre) => {
                    let turn = DQuat::from_axis_angle(axis, angle(t, o.period_s, 0.0));
                    centre + turn * (rest.position - centre) - rest.position
                }
                OrbitAbout::Radius(r) => {
                    let (u, v) = axis.any_orthonormal_pair();
                    let on_circle = |a: f64| (u * a.cos() + v * a.sin()) * r;
                    on_circle(angle(t, o.period_s, o.phase_deg))
                        - on_circle(angle(0.0, o.period_s, o.phase_deg))
                }
            };
        }
        if let Some(b) = &self.bob {
            light.position += b.amplitude * swing(t, b.period_s, b.phase_deg);
        }
        if let Some(w) = &self.wander {
            // Each axis: three sines of amplitude r/(6√3); each swing is within ±2 of its
            // amplitude, so an axis is within r/√3 and the offset within r.
            let a = w.radius / (6.0 * 3f64.sqrt());
            let axis_offset = |stream: u64| -> f64 {
                partials(w.seed, stream)
                    .iter()
                    .map(|&(f, phase)| a * swing(t, w.period_s / f, phase))
                    .sum()
            };
            light.position += DVec3::new(axis_offset(1), axis_offset(2), axis_offset(3));
        }
        if let Some(f) = &self.flicker {
            // n(t) = mean of (1 − cos)/2 terms: in [0, 1], 0 at t = 0.
            let noise: f64 = partials(f.seed, 4)
                .iter()
                .map(|&(freq, _)| (1.0 - angle(t, 1.0 / (f.rate_hz * freq), 0.0).cos()) / 6.0)
                .sum();
            light.intensity = rest.intensity * (1.0 - f.amount * noise as f32).max(0.0);
        }
        if let (Some(s), LightKind::Spot { direction, .. }) = (&self.sweep, &mut light.kind) {
            // The unit direction turned: a long one's products in the rotation overflowed
            // (a direction past about 9·10³⁰⁷ turned into Inf and NaN). Not turned, a light
            // keeps its rest direction as written (at t = 0, say).
            if let (Some(axis), Some(unit_direction)) = (unit(s.axis), unit(*direction)) {
                let angle = s.angle_deg.to_radians() * swing(t, s.period_s, s.phase_deg);
                if angle != 0.0 {
                    *direction = DQuat::from_axis_angle(axis, angle) * unit_direction;
                }
            }
        }
        light
    }

    /// A bound of the largest position coordinate (in magnitude) a light at rest at `rest`
    /// reaches at any time: an orbit about a point goes round a circle about its axis (whose
    /// coordinate `k` lies within `ρ·√(1 − a_k²)` of the circle's centre), one of a radius, a
    /// bob (`A·swing`, the swing within ±2) and a wander add at most `2r`, `2|A|` and `r`. (A
    /// varied motion has the same sizes: only its periods and phases differ.) Call it on a
    /// validated motion (its axis not zero).
    pub(crate) fn farthest_coordinate(&self, rest: DVec3) -> f64 {
        let mut base = rest.abs().max_element();
        let mut added = 0.0;
        if let Some(o) = &self.orbit {
            match o.about {
                OrbitAbout::Point(centre) => {
                    let axis = unit(o.axis).unwrap_or(DVec3::Y);
                    let v = rest - centre;
                    let along = v.dot(axis);
                    let rho = (v - axis * along).length();
                    let middle = centre + axis * along;
                    let reach = |k: usize| {
                        middle[k].abs() + rho * (1.0 - axis[k] * axis[k]).max(0.0).sqrt()
                    };
                    base = reach(0).max(reach(1)).max(reach(2));
                }
                OrbitAbout::Radius(r) => added += 2.0 * r.abs(),
            }
        }
        if let Some(b) = &self.bob {
            added += 2.0 * b.amplitude.abs().max_element();
        }
        if let Some(w) = &self.wander {
            added += w.radius.abs();
        }
        base + added
    }

    /// Checks every parameter; `field` is the path used in errors (`lights[3].motion`).
    /// `is_spot` says whether a sweep has a cone to move.
    pub fn validate(&self, field: &str, is_spot: bool) -> Result<(), SceneError> {
        let period = |value: f64, name: &str| check_period(value, field, name);
        if let Some(o) = &self.orbit {
            period(o.period_s, "orbit.period_s")?;
            check_axis(o.axis, field, "orbit.axis")?;
            check_finite(o.phase_deg, field, "orbit.phase_deg")?;
            match o.about {
                OrbitAbout::Point(c) => {
                    if !(c.is_finite() && c.abs().max_element() <= MAX_DISPLACEMENT) {
                        return Err(SceneError::invalid(
                            format!("{field}.orbit.center"),
                            format!(
                                "must be finite and within ±{MAX_DISPLACEMENT:e}, got {}",
                                super::short3(c)
                            ),
                        ));
                    }
                }
                OrbitAbout::Radius(r) => check_length(r, field, "orbit.radius")?,
            }
        }
        if let Some(b) = &self.bob {
            period(b.period_s, "bob.period_s")?;
            check_finite(b.phase_deg, field, "bob.phase_deg")?;
            if !(b.amplitude.is_finite() && b.amplitude.length() <= MAX_DISPLACEMENT) {
                return Err(SceneError::invalid(
                    format!("{field}.bob.amplitude"),
                    format!(
                        "must be finite and at most {MAX_DISPLACEMENT:e} long, got {}",
                        super::short3(b.amplitude)
                    ),
                ));
            }
        }
        if let Some(w) = &self.wander {
            period(w.period_s, "wander.period_s")?;
            check_length(w.radius, field, "wander.radius")?;
        }
        if let Some(f) = &self.flicker {
            if !(f.amount.is_finite() && (0.0..=1.0).contains(&f.amount)) {
                return Err(SceneError::invalid(
                    format!("{field}.flicker.amount"),
                    format!("must be in [0, 1], got {:?}", f.amount),
                ));
            }
            let (slowest, fastest) = (1.0 / MAX_PERIOD_S, 1.0 / MIN_PERIOD_S);
            if !(f.rate_hz.is_finite() && (slowest..=fastest).contains(&f.rate_hz)) {
                return Err(SceneError::invalid(
                    format!("{field}.flicker.rate_hz"),
                    format!(
                        "must be within [{slowest:e}, {fastest:e}] Hz, got {:?}",
                        f.rate_hz
                    ),
                ));
            }
        }
        if let Some(s) = &self.sweep {
            if !is_spot {
                return Err(SceneError::invalid(
                    format!("{field}.sweep"),
                    "only spot lights have an axis to sweep",
                ));
            }
            period(s.period_s, "sweep.period_s")?;
            check_axis(s.axis, field, "sweep.axis")?;
            check_finite(s.phase_deg, field, "sweep.phase_deg")?;
            if !(s.angle_deg.is_finite() && (0.0..=180.0).contains(&s.angle_deg)) {
                return Err(SceneError::invalid(
                    format!("{field}.sweep.angle_deg"),
                    format!("must be in [0, 180], got {:?}", s.angle_deg),
                ));
            }
        }
        Ok(())
    }

    /// This motion for light `index` of a random set: its own phases and seeds, and periods
    /// within ±25 % of the given ones, all from `seed`, so a set does not move in lockstep.
    /// Only spot lights keep a sweep.
    pub fn varied(&self, seed: u64, index: usize, is_spot: bool) -> Motion {
        let mut rng =
            Pcg64Mcg::seed_from_u64(seed ^ (index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
        let mut jitter = |period: f64| period * rng.random_range(0.75..1.25);
        let mut m = *self;
        if let Some(o) = &mut m.orbit {
            o.period_s = jitter(o.period_s);
        }
        if let Some(b) = &mut m.bob {
            b.period_s = jitter(b.period_s);
        }
        if let Some(w) = &mut m.wander {
            w.period_s = jitter(w.period_s);
        }
        if let Some(f) = &mut m.flicker {
            f.rate_hz = 1.0 / jitter(1.0 / f.rate_hz);
        }
        if let Some(s) = &mut m.sweep {
            s.period_s = jitter(s.period_s);
        }
        // Added to the phase reduced to one turn: added to a huge one, it rounded away.
        let mut phase = |written: f64| written.rem_euclid(360.0) + rng.random_range(0.0..360.0);
        if let Some(o) = &mut m.orbit {
            o.phase_deg = phase(o.phase_deg);
        }
        if let Some(b) = &mut m.bob {
            b.phase_deg = phase(b.phase_deg);
        }
        if let Some(s) = &mut m.sweep {
            s.phase_deg = phase(s.phase_deg);
        }
        let derived = rng.random::<u64>();
        if let Some(w) = &mut m.wander {
            w.seed ^= derived;
        }
        if let Some(f) = &mut m.flicker {
            f.seed ^= derived.rotate_left(17);
        }
        if !is_spot {
            m.sweep = None;
        }
        m
    }
}

// The checks take the field's path in two parts and join them only for an error: a scene is
// validated every frame, and a valid one must cost no allocation.

fn check_period(value: f64, field: &str, name: &str) -> Result<(), SceneError> {
    if value.is_finite() && (MIN_PERIOD_S..=MAX_PERIOD_S).contains(&value) {
        Ok(())
    } else {
        Err(SceneError::invalid(
            format!("{field}.{name}"),
            format!("must be within [{MIN_PERIOD_S:e}, {MAX_PERIOD_S:e}] seconds, got {value:?}"),
        ))
    }
}

fn check_axis(axis: DVec3, field: &str, name: &str) -> Result<(), SceneError> {
    match unit(axis) {
        Some(_) => Ok(()),
        None => Err(SceneError::invalid(
            format!("{field}.{name}"),
            format!(
                "must be a finite, non-zero direction, got {}",
                super::short3(axis)
            ),
        )),
    }
}

fn check_length(value: f64, field: &str, name: &str) -> Result<(), SceneError> {
    if value.is_finite() && (0.0..=MAX_DISPLACEMENT).contains(&value) {
        Ok(())
    } else {
        Err(SceneError::invalid(
            format!("{field}.{name}"),
            format!("must be within [0, {MAX_DISPLACEMENT:e}], got {value:?}"),
        ))
    }
}

fn check_finite(value: f64, field: &str, name: &str) -> Result<(), SceneError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(SceneError::invalid(
            format!("{field}.{name}"),
            format!("must be finite, got {value:?}"),
        ))
    }
}

#[cfg(test)]
mod tests;
