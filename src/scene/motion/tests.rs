use glam::Vec3;

use super::*;

fn point() -> Light {
    Light::point(DVec3::new(1.0, 2.0, 3.0), 2.0, Vec3::ONE, 4.0)
}

fn spot() -> Light {
    Light::spot(
        DVec3::new(0.0, 5.0, 0.0),
        8.0,
        Vec3::ONE,
        2.0,
        crate::scene::Cone {
            direction: DVec3::NEG_Y,
            inner_deg: 10.0,
            outer_deg: 25.0,
        },
    )
}

fn every_motion() -> Motion {
    Motion {
        orbit: Some(Orbit {
            about: OrbitAbout::Radius(1.5),
            axis: DVec3::Y,
            period_s: 4.0,
            phase_deg: 70.0,
        }),
        bob: Some(Bob {
            amplitude: DVec3::new(0.0, 0.5, 0.0),
            period_s: 1.7,
            phase_deg: 30.0,
        }),
        wander: Some(Wander {
            radius: 2.0,
            period_s: 5.0,
            seed: 11,
        }),
        flicker: Some(Flicker {
            amount: 0.4,
            rate_hz: 6.0,
            seed: 3,
        }),
        sweep: Some(Sweep {
            axis: DVec3::X,
            angle_deg: 20.0,
            period_s: 3.0,
            phase_deg: 45.0,
        }),
    }
}

fn times() -> impl Iterator<Item = f64> {
    (0..2000).map(|i| i as f64 * 0.0137)
}

#[test]
fn every_motion_starts_at_the_rest_state() {
    let m = every_motion();
    for rest in [point(), spot()] {
        let at_zero = m.apply(&rest, 0.0);
        assert!((at_zero.position - rest.position).length() < 1e-12);
        assert_eq!(at_zero.intensity, rest.intensity);
        if let (LightKind::Spot { direction: a, .. }, LightKind::Spot { direction: b, .. }) =
            (at_zero.kind, rest.kind)
        {
            assert!((a - b).length() < 1e-12);
        }
    }
}

#[test]
fn motions_move_and_stay_within_their_bounds() {
    let rest = point();
    let only = |m: Motion| move |t: f64| m.apply(&rest, t);
    let wander = only(Motion {
        wander: every_motion().wander,
        ..Motion::default()
    });
    let bob = only(Motion {
        bob: every_motion().bob,
        ..Motion::default()
    });
    let flicker = only(Motion {
        flicker: every_motion().flicker,
        ..Motion::default()
    });
    let (mut wander_far, mut dimmest) = (0.0f64, f32::MAX);
    for t in times() {
        let d = (wander(t).position - rest.position).length();
        assert!(d <= 2.0 + 1e-9, "wander left its radius: {d} at t = {t}");
        wander_far = wander_far.max(d);
        let b = bob(t).position - rest.position;
        assert!(
            b.x == 0.0 && b.z == 0.0 && b.y.abs() <= 1.0 + 1e-12,
            "{b:?}"
        );
        let i = flicker(t).intensity;
        assert!(
            (rest.intensity * 0.6 - 1e-6..=rest.intensity).contains(&i),
            "{i}"
        );
        dimmest = dimmest.min(i);
    }
    // It really moves and flickers, not only stays in bounds.
    assert!(wander_far > 0.5, "wander reached only {wander_far}");
    assert!(
        dimmest < rest.intensity * 0.85,
        "flicker dipped only to {dimmest}"
    );
}

#[test]
fn orbits_are_circles_with_the_given_period() {
    let rest = point();
    let centre = DVec3::new(-1.0, 0.0, 0.5);
    let about_point = Motion {
        orbit: Some(Orbit {
            about: OrbitAbout::Point(centre),
            axis: DVec3::Y,
            period_s: 2.0,
            phase_deg: 0.0,
        }),
        ..Motion::default()
    };
    let radius = Motion {
        orbit: every_motion().orbit,
        ..Motion::default()
    };
    let horizontal = |v: DVec3| DVec3::new(v.x, 0.0, v.z).length();
    let start_r = horizontal(rest.position - centre);
    // The radius orbit's centre: on the far side of the rest position, 1.5 away.
    let phase = 70f64.to_radians();
    let (u, v) = DVec3::Y.any_orthonormal_pair();
    let circle_centre = rest.position - (u * phase.cos() + v * phase.sin()) * 1.5;
    for t in times() {
        let p = about_point.apply(&rest, t).position;
        assert!((horizontal(p - centre) - start_r).abs() < 1e-9);
        assert!((p.y - rest.position.y).abs() < 1e-9);
        let q = radius.apply(&rest, t).position;
        assert!(((q - circle_centre).length() - 1.5).abs() < 1e-9, "{q:?}");
    }
    let half_turn = about_point.apply(&rest, 1.0).position;
    assert!((half_turn - (2.0 * centre - rest.position).with_y(rest.position.y)).length() < 1e-9);
    let full_turn = about_point.apply(&rest, 2.0).position;
    assert!((full_turn - rest.position).length() < 1e-9);
}

#[test]
fn sweep_turns_the_cone_within_its_angle() {
    let rest = spot();
    let m = Motion {
        sweep: every_motion().sweep,
        ..Motion::default()
    };
    let mut widest = 0.0f64;
    for t in times() {
        let LightKind::Spot { direction, .. } = m.apply(&rest, t).kind else {
            unreachable!()
        };
        let off = direction.angle_between(DVec3::NEG_Y).to_degrees();
        assert!(off <= 40.0 + 1e-9, "{off}");
        assert!(direction.x.abs() < 1e-12, "turns about X only");
        widest = widest.max(off);
    }
    assert!(widest > 25.0, "{widest}");
}

#[test]
fn late_frames_stay_finite_and_periodic() {
    let m = every_motion();
    for t in [1e6, 1e9, 1e15, f64::MAX, f64::NAN, f64::INFINITY] {
        let l = m.apply(&spot(), t);
        l.validate("late").unwrap();
    }
    // A period-2 orbit one million turns on is where it started, to float precision of t.
    let orbit = Motion {
        orbit: Some(Orbit {
            about: OrbitAbout::Point(DVec3::ZERO),
            axis: DVec3::Y,
            period_s: 2.0,
            phase_deg: 0.0,
        }),
        ..Motion::default()
    };
    assert!((orbit.apply(&point(), 2e6).position - point().position).length() < 1e-6);
    // Short periods and a fast flicker at the largest times: `t/T` and `t·rate` overflowed,
    // posing the light at NaN and the flicker's NaN noise at intensity 0.
    let fast = Motion {
        orbit: Some(Orbit {
            period_s: 1e-3,
            ..every_motion().orbit.unwrap()
        }),
        bob: Some(Bob {
            period_s: 1e-3,
            ..every_motion().bob.unwrap()
        }),
        wander: Some(Wander {
            period_s: 1e-3,
            ..every_motion().wander.unwrap()
        }),
        flicker: Some(Flicker {
            rate_hz: 1e3,
            ..every_motion().flicker.unwrap()
        }),
        sweep: Some(Sweep {
            period_s: 1e-3,
            ..every_motion().sweep.unwrap()
        }),
    };
    for t in [1e300, f64::MAX, -f64::MAX] {
        let l = fast.apply(&spot(), t);
        l.validate("late").unwrap();
        assert!(l.position.is_finite(), "{t}: {:?}", l.position);
        // The deepest dip is 0.4 of the intensity.
        assert!(
            l.intensity >= 0.6 * spot().intensity - 1e-6,
            "{t}: {}",
            l.intensity
        );
    }
}

#[test]
fn validation_names_the_field() {
    let base = every_motion();
    let cases: Vec<(Motion, bool, &str)> = vec![
        (base, false, "m.sweep"),
        (
            Motion {
                bob: Some(Bob {
                    period_s: 0.0,
                    ..base.bob.unwrap()
                }),
                ..base
            },
            true,
            "m.bob.period_s",
        ),
        (
            Motion {
                wander: Some(Wander {
                    radius: f64::NAN,
                    ..base.wander.unwrap()
                }),
                ..base
            },
            true,
            "m.wander.radius",
        ),
        (
            Motion {
                flicker: Some(Flicker {
                    amount: 1.5,
                    ..base.flicker.unwrap()
                }),
                ..base
            },
            true,
            "m.flicker.amount",
        ),
        (
            Motion {
                flicker: Some(Flicker {
                    rate_hz: 0.0,
                    ..base.flicker.unwrap()
                }),
                ..base
            },
            true,
            "m.flicker.rate_hz",
        ),
        (
            Motion {
                orbit: Some(Orbit {
                    axis: DVec3::ZERO,
                    ..base.orbit.unwrap()
                }),
                ..base
            },
            true,
            "m.orbit.axis",
        ),
        (
            Motion {
                orbit: Some(Orbit {
                    about: OrbitAbout::Point(DVec3::splat(1e300)),
                    ..base.orbit.unwrap()
                }),
                ..base
            },
            true,
            "m.orbit.center",
        ),
        (
            Motion {
                sweep: Some(Sweep {
                    angle_deg: 200.0,
                    ..base.sweep.unwrap()
                }),
                ..base
            },
            true,
            "m.sweep.angle_deg",
        ),
        (
            Motion {
                bob: Some(Bob {
                    amplitude: DVec3::splat(f64::MAX),
                    ..base.bob.unwrap()
                }),
                ..base
            },
            true,
            "m.bob.amplitude",
        ),
    ];
    for (motion, is_spot, field) in cases {
        let err = motion.validate("m", is_spot).unwrap_err().to_string();
        assert!(err.contains(field), "expected {field} in: {err}");
    }
    base.validate("m", true).unwrap();
}

#[test]
fn varied_motions_differ_per_light_and_repeat_per_seed() {
    let m = every_motion();
    let a = m.varied(5, 0, true);
    assert_eq!(a, m.varied(5, 0, true));
    assert_ne!(a, m.varied(5, 1, true));
    assert_ne!(a, m.varied(6, 0, true));
    assert!(m.varied(5, 0, false).sweep.is_none());
    a.validate("varied", true).unwrap();
    // Still zero at t = 0 after the variation.
    let rest = spot();
    assert!((a.apply(&rest, 0.0).position - rest.position).length() < 1e-12);
}

/// A motion set in code that poses its light at NaN is named by the scene's check, not the
/// light it moved there.
#[test]
fn a_scene_names_a_bad_motion_before_the_light_it_posed() {
    let mut scene = crate::scene::Scene::empty();
    scene
        .lights
        .push(crate::scene::Light::point(DVec3::ZERO, 1.0, Vec3::ONE, 1.0));
    let orbit = Orbit {
        about: OrbitAbout::Point(DVec3::X),
        axis: DVec3::ZERO,
        period_s: 2.0,
        phase_deg: 0.0,
    };
    scene.animate_light(
        0,
        Motion {
            orbit: Some(orbit),
            ..Motion::default()
        },
    );
    scene.set_time(0.5);
    let err = scene.validate().unwrap_err().to_string();
    assert!(err.contains("lights[0].motion.orbit.axis"), "{err}");
}

/// A light valid at rest that its motion can carry past the lights' coordinate limit is
/// refused at once, naming the motion, not at the frame where it gets there (by a position
/// the file never wrote).
#[test]
fn a_motion_that_can_carry_a_light_out_of_range_is_named_at_once() {
    let orbit = Motion {
        orbit: Some(Orbit {
            about: OrbitAbout::Point(DVec3::ZERO),
            axis: DVec3::Y,
            period_s: 8.0,
            phase_deg: 0.0,
        }),
        ..Motion::default()
    };
    let bob = Motion {
        bob: Some(Bob {
            amplitude: DVec3::new(1e9, 0.0, 0.0),
            period_s: 4.0,
            phase_deg: 0.0,
        }),
        ..Motion::default()
    };
    let point =
        |x: f64, z: f64| crate::scene::Light::point(DVec3::new(x, 0.0, z), 1.0, Vec3::ONE, 1.0);
    let mut scene = crate::scene::Scene::empty();
    // About X, a light at (9e17, 9e17, 0) keeps x and goes round a circle of 9e17.
    let about_x = Motion {
        orbit: Some(Orbit {
            axis: DVec3::X,
            ..orbit.orbit.unwrap()
        }),
        ..orbit
    };
    let mut turning = DVec3::new(9e17, 9e17, 0.0);
    scene.lights = vec![point(6e17, 6e17), point(1e18 - 1e10, 0.0), point(9e17, 0.0)];
    scene.lights[2].position = turning;
    scene.animate_light(0, orbit);
    scene.animate_light(1, bob);
    scene.animate_light(2, about_x);
    scene.validate().unwrap();
    for i in 0..16 {
        scene.set_time(f64::from(i) * 0.5);
        turning = turning.abs().max(scene.lights[2].position.abs());
    }
    assert!(turning.max_element() <= 9e17 * (1.0 + 1e-12), "{turning}");
    for (light, motion) in [(point(9e17, 9e17), orbit), (point(1e18 - 5e8, 0.0), bob)] {
        let mut scene = crate::scene::Scene::empty();
        scene.lights = vec![point(0.0, 0.0), light];
        scene.animate_light(1, motion);
        let err = scene.validate().unwrap_err().to_string();
        assert!(
            err.contains("lights[1].motion") && err.contains("carry lights[1]"),
            "{err}"
        );
        // It does get there: at 45° (x = 1.27e18), or at the bob's crest.
        let far = (0..16).any(|i| {
            scene.set_time(f64::from(i) * 0.5);
            scene.lights[1].position.abs().max_element() > crate::scene::light::MAX_LIGHT_COORD
        });
        assert!(far, "{motion:?}");
    }
}

/// A motion set in code with an axis validation refuses (zero, NaN) poses the light without
/// that turn: finite, not NaN, and without the normalisations glam's assertions would stop at.
/// Validation still names the axis.
#[test]
fn an_axis_validation_refuses_turns_nothing_when_posed() {
    for axis in [DVec3::ZERO, DVec3::NAN] {
        let mut m = every_motion();
        m.orbit.as_mut().unwrap().axis = axis;
        m.sweep.as_mut().unwrap().axis = axis;
        let posed = m.apply(&spot(), 1.3);
        assert!(posed.position.is_finite(), "{axis:?}: {:?}", posed.position);
        let LightKind::Spot { direction, .. } = posed.kind else {
            panic!("not a spot");
        };
        assert_eq!(direction, DVec3::NEG_Y, "{axis:?}");
        let err = m
            .validate("lights[0].motion", true)
            .unwrap_err()
            .to_string();
        assert!(err.contains("axis"), "{err}");
    }
}

/// Any finite, non-zero axis is a direction, as a spot's is: one of length 1e200 or 1e-300
/// turns as the unit axis does. Squared for its length, 1e200 overflowed and was refused as
/// "not finite", and anything under 1e-12 as too short.
#[test]
fn an_axis_of_any_finite_length_turns_as_its_direction() {
    let posed_about = |axis: DVec3| {
        let mut m = every_motion();
        m.orbit.as_mut().unwrap().axis = axis;
        m.sweep.as_mut().unwrap().axis = axis;
        m.validate("m", true).map(|()| m.apply(&spot(), 1.3))
    };
    let unit = posed_about(DVec3::new(0.6, 0.8, 0.0)).unwrap();
    for scale in [1e200, 1e-13, 1e-300, f64::MAX / 2.0] {
        let posed = posed_about(DVec3::new(0.6, 0.8, 0.0) * scale).unwrap();
        assert!(
            posed.position.abs_diff_eq(unit.position, 1e-9),
            "{scale:e}: {posed:?} against {unit:?}"
        );
        let (LightKind::Spot { direction: d, .. }, LightKind::Spot { direction: u, .. }) =
            (posed.kind, unit.kind)
        else {
            panic!("not a spot");
        };
        assert!(d.abs_diff_eq(u, 1e-12), "{scale:e}: {d} against {u}");
    }
}

/// A spot's direction may have any finite length: a sweep turns it as its direction (turned
/// as it was, a direction past about 9·10³⁰⁷ overflowed to Inf and NaN at a later time, and
/// a recording failed part-way).
#[test]
fn a_sweep_turns_a_direction_of_any_finite_length() {
    let m = Motion {
        sweep: Some(Sweep {
            axis: DVec3::X,
            angle_deg: 180.0,
            period_s: 1.0,
            phase_deg: 0.0,
        }),
        ..Motion::default()
    };
    let mut rest = spot();
    let LightKind::Spot { direction, .. } = &mut rest.kind else {
        unreachable!()
    };
    *direction = DVec3::new(0.0, 1.6e308, -1e308);
    let along = crate::scene::direction::unit(*direction).unwrap();
    for t in [0.0, 0.1, 0.25, 0.6] {
        let LightKind::Spot { direction, .. } = m.apply(&rest, t).kind else {
            unreachable!()
        };
        assert!(direction.is_finite(), "t = {t}: {direction:?}");
        let unit_rest = spot_with(along);
        let LightKind::Spot {
            direction: want, ..
        } = m.apply(&unit_rest, t).kind
        else {
            unreachable!()
        };
        let turned = crate::scene::direction::unit(direction).unwrap();
        assert!(
            turned.abs_diff_eq(want, 1e-12),
            "t = {t}: {direction:?}, {want:?}"
        );
    }
}

/// [`spot`] pointing along `direction`.
fn spot_with(direction: DVec3) -> Light {
    let mut l = spot();
    if let LightKind::Spot { direction: d, .. } = &mut l.kind {
        *d = direction;
    }
    l
}

/// A phase past 2⁵³ degrees was added to the time's share of the turn before either was
/// reduced, which rounded the time away: the light stood still.
#[test]
fn a_huge_phase_keeps_the_motion_moving() {
    let bob = |phase_deg| Motion {
        bob: Some(Bob {
            amplitude: DVec3::Y,
            period_s: 2.0,
            phase_deg,
        }),
        ..Motion::default()
    };
    let rest = point();
    // 1e19 is 360 · 27 777 777 777 777 777 + 280 (exactly, in f64): the same motion as 280°.
    let (huge, plain) = (bob(1e19), bob(1e19f64.rem_euclid(360.0)));
    for t in [0.3, 0.5, 1.3] {
        let (a, b) = (
            huge.apply(&rest, t).position,
            plain.apply(&rest, t).position,
        );
        assert!(a.abs_diff_eq(b, 1e-12), "t = {t}: {a:?} against {b:?}");
        assert!((a - rest.position).length() > 1e-3, "t = {t}: still");
    }
}

/// A random set's lights each get a phase of their own, also where the phase written is huge
/// (added to 10¹⁹ degrees, each light's share rounded away: the set moved in lockstep).
#[test]
fn varied_phases_differ_whatever_the_phase_written() {
    let motion = Motion {
        bob: Some(Bob {
            amplitude: DVec3::Y,
            period_s: 2.0,
            phase_deg: 1e19,
        }),
        ..Motion::default()
    };
    let phases: Vec<f64> = (0..6)
        .map(|k| motion.varied(7, k, false).bob.unwrap().phase_deg)
        .collect();
    for (i, a) in phases.iter().enumerate() {
        assert!((0.0..720.0).contains(a), "{a}");
        assert!(phases[i + 1..].iter().all(|b| b != a), "{phases:?}");
    }
}
