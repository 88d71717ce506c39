//! The named trajectories of the source papers, built from profiles.

use super::motion::{euler_chain, AxisRotation, Motion};
use super::profile::{Profile, StepShape, Term};
use crate::error::{check_positive, invalid, Result};
use crate::math::Vec3;
use std::f64::consts::PI;

fn zero3() -> [Profile; 3] {
    [Profile::zero(), Profile::zero(), Profile::zero()]
}

/// A period (s) whose angular frequency 2π/period is finite: a subnormal period is not.
fn check_period(field: &str, period: f64) -> Result<()> {
    check_positive(field, period)?;
    if (2.0 * PI / period).is_finite() {
        Ok(())
    } else {
        Err(invalid(field, format!("{period:e} s is too short: its angular frequency 2π/period is not finite")))
    }
}

fn sine(amp: f64, period: f64) -> Term {
    Term::Sine { amp, period, phase: 0.0 }
}

/// Sinusoidal motion about `origin`: NED displacement amplitude (m) and period (s) per
/// axis, and roll/pitch/yaw oscillations (rad, s) about `heading`.
// invariant: fixed-size 3-vectors indexed by i < 3.
#[allow(clippy::indexing_slicing)]
pub fn sinusoidal(origin: Vec3, duration: f64, amp_ned: Vec3, period_ned: Vec3, amp_euler: Vec3, period_euler: Vec3, heading: f64) -> Result<Motion> {
    for i in 0..3 {
        check_period("period_ned", period_ned[i])?;
        check_period("period_euler", period_euler[i])?;
    }
    let disp = [0, 1, 2].map(|i| Profile::zero().with(sine(amp_ned[i], period_ned[i])));
    let att = [0, 1, 2].map(|i| Profile::zero().with(sine(amp_euler[i], period_euler[i])));
    let [roll, pitch, yaw] = att;
    Ok(Motion {
        name: "sinusoidal".into(),
        origin,
        duration,
        speed: Profile::zero(),
        course: Profile::zero(),
        displacement: disp,
        attitude: euler_chain(roll, pitch, yaw.with(Term::Linear { c: heading, r: 0.0 })),
    })
}

/// Raised-cosine pulse of height `amp`: ramp up over `ramp` s at `start`, hold `hold` s,
/// ramp down over `ramp` s.
fn pulse(p: Profile, start: f64, ramp: f64, hold: f64, amp: f64, shape: StepShape) -> Profile {
    p.with(Term::Step { start, duration: ramp, delta: amp, shape, integrated: false })
        .with(Term::Step { start: start + ramp + hold, duration: ramp, delta: -amp, shape, integrated: false })
}

/// Hexapod tilt sequence (Tennstedt et al. 2021 §5.3; docs/departures.md#hexapod-scenario): 10 s
/// static, then roll performs [+a, −a, +a/2, −a/2] three times (each: 1 s raised-cosine
/// ramp, 5 s hold, 1 s ramp back, 5 s at 0; 48 s per block); pitch the same delayed by
/// `pitch_delay` s; static until 170 s. `max_tilt` = 0.0654 rad (3.75°) by default, below
/// [`HEXAPOD_MAX_TILT`] in magnitude.
pub fn hexapod(origin: Vec3, max_tilt: f64, pitch_delay: f64, heading: f64) -> Result<Motion> {
    if !(max_tilt.is_finite() && max_tilt.abs() < HEXAPOD_MAX_TILT) {
        return Err(invalid("max_tilt", format!("must be finite and below {HEXAPOD_MAX_TILT} rad, got {max_tilt}")));
    }
    crate::error::check_finite("pitch_delay", &[pitch_delay, heading], 1)?;
    let block = [max_tilt, -max_tilt, 0.5 * max_tilt, -0.5 * max_tilt];
    let tilts = |delay: f64| {
        let mut p = Profile::zero();
        for rep in 0..3 {
            for (j, a) in block.iter().enumerate() {
                let start = 10.0 + delay + 48.0 * rep as f64 + 12.0 * j as f64;
                p = pulse(p, start, 1.0, 5.0, *a, StepShape::RaisedCosine);
            }
        }
        p
    };
    Ok(Motion {
        name: "hexapod".into(),
        origin,
        duration: 170.0,
        speed: Profile::zero(),
        course: Profile::zero(),
        displacement: zero3(),
        attitude: euler_chain(tilts(0.0), tilts(pitch_delay), Profile::constant(heading)),
    })
}

/// Largest hexapod tilt magnitude (rad) accepted by [`hexapod`]: the platform's small-angle
/// tilt sequence (Tennstedt et al. 2021 §5.3 uses 3.75°), well inside the Euler-chain's regular range.
pub const HEXAPOD_MAX_TILT: f64 = 0.5;

/// Straight drive at constant `speed` (m/s) with sinusoidal yaw rate
/// ω_z = `yaw_rate_amp`·sin(2πt/`period`) (Tennstedt et al. 2023 Fig. 7: 1 m/s, 0.05 rad/s, 50 s).
/// The velocity follows the heading (no side slip).
pub fn drive_with_yaw(origin: Vec3, speed: f64, yaw_rate_amp: f64, period: f64, duration: f64, heading: f64) -> Result<Motion> {
    check_period("period", period)?;
    // ψ = ψ₀ + A·P/(2π)·(1 − cos(2πt/P))
    let k = yaw_rate_amp * period / (2.0 * PI);
    let yaw = Profile::constant(heading + k).with(Term::Sine { amp: -k, period, phase: PI / 2.0 });
    Ok(Motion {
        name: "drive_with_yaw".into(),
        origin,
        duration,
        speed: Profile::constant(speed),
        course: yaw.clone(),
        displacement: zero3(),
        attitude: euler_chain(Profile::zero(), Profile::zero(), yaw),
    })
}

/// Level slalom (docs/departures.md#scenario-values): north = `speed`·t,
/// east = `amp`·sin(2πt/`period`), heading = atan2(ė, ṅ). Defaults 5 m/s, 2 m, 10 s, 60 s.
pub fn slalom(origin: Vec3, speed: f64, amp: f64, period: f64, duration: f64) -> Result<Motion> {
    check_positive("speed", speed)?;
    check_period("period", period)?;
    let slope = amp * 2.0 * PI / period / speed; // ė/ṅ amplitude
    if !slope.is_finite() {
        let field = if (2.0 * PI / period / speed).is_finite() { "amp" } else { "speed" };
        return Err(invalid(field, format!("amp={amp:e} m, period={period:e} s and speed={speed:e} m/s give a path slope that is not finite")));
    }
    Ok(Motion {
        name: "slalom".into(),
        origin,
        duration,
        speed: Profile::zero(),
        course: Profile::zero(),
        displacement: [
            Profile::zero().with(Term::Linear { c: 0.0, r: speed }),
            Profile::zero().with(sine(amp, period)),
            Profile::zero(),
        ],
        attitude: euler_chain(Profile::zero(), Profile::zero(), Profile::zero().with(Term::ArctanSine { amp: slope, period, phase: PI / 2.0 })),
    })
}

/// Car-like profile after Tennstedt et al. 2023 Fig. 9 (docs/departures.md#scenario-values), 40 s:
/// [0,5) static; [5,12) along-track acceleration 1 m/s²; [12,19) sliding right turn, yaw
/// rate up to +0.15 rad/s with the course unchanged and the acceleration kept;
/// [19,30) left turn −0.2 rad/s with 0.5 m/s² (course follows yaw, so a_y = vω_z);
/// spike at 26 s (Gaussian σ = 0.05 s: +3 m/s² along and across track, +0.3 rad/s roll and
/// pitch rate, vertical vibration ×3); [30,40] 0.8 m/s², 0.02 rad/s, all vibration ×2 in
/// 33–35 s. Vibration: 4.3, 9.7, 15.1 Hz sines of 0.05 m/s² (as NED displacement) and
/// 0.005 rad/s (as Euler-angle oscillation), envelope 0 while static and 1 after (1 s
/// raised-cosine ramps). Interpretations of the paper's body-frame wording are stated above.
pub fn car(origin: Vec3, heading: f64, vibration: bool) -> Motion {
    let rc = StepShape::RaisedCosine;
    let step = |p: Profile, start: f64, delta: f64, integrated: bool| p.with(Term::Step { start, duration: 1.0, delta, shape: rc, integrated });
    // along-track acceleration a_x(t) integrated once: the speed
    let mut speed = Profile::zero();
    for (t, d) in [(5.0, 1.0), (19.0, -0.5), (30.0, 0.3)] {
        speed = step(speed, t, d, true);
    }
    speed = speed.with(Term::Gaussian { t0: 26.0, sigma: 0.05, amp: 3.0, integrated: true });
    // yaw rate integrated once: the yaw angle; the course only turns from 19 s on
    let mut yaw = Profile::constant(heading);
    for (t, d) in [(12.0, 0.15), (18.0, -0.15), (19.0, -0.2), (30.0, 0.22)] {
        yaw = step(yaw, t, d, true);
    }
    let mut course = Profile::constant(heading);
    for (t, d) in [(19.0, -0.2), (30.0, 0.22)] {
        course = step(course, t, d, true);
    }
    // lateral spike a_y = v·ċ: course rate pulse of 3 m/s² divided by the speed at 26 s
    let v26 = speed.eval(26.0).v;
    course = course.with(Term::Gaussian { t0: 26.0, sigma: 0.05, amp: 3.0 / v26, integrated: true });
    let spike_rate = |p: Profile| p.with(Term::Gaussian { t0: 26.0, sigma: 0.05, amp: 0.3, integrated: true });
    let (mut roll, mut pitch) = (spike_rate(Profile::zero()), spike_rate(Profile::zero()));
    let mut disp = zero3();
    if vibration {
        let env = |z: bool| {
            let mut e = step(Profile::zero(), 4.0, 1.0, false);
            e = pulse(e, 32.5, 0.5, 2.0, 1.0, rc); // ×2 in 33–35 s
            if z {
                e = pulse(e, 25.5, 0.25, 0.5, 2.0, rc); // ×3 around the spike
            }
            e
        };
        let vib = |amp_of: &dyn Fn(f64) -> f64, z: bool, phase0: f64| {
            let mut carrier = Profile::zero();
            for (i, f) in [4.3, 9.7, 15.1].iter().enumerate() {
                carrier = carrier.with(Term::Sine { amp: amp_of(*f), period: 1.0 / f, phase: phase0 + i as f64 });
            }
            Profile::zero().with(Term::Product(Box::new(env(z)), Box::new(carrier)))
        };
        let lin = |f: f64| 0.05 / (2.0 * PI * f).powi(2); // displacement of a 0.05 m/s² sine
        let ang = |f: f64| 0.005 / (2.0 * PI * f); // angle of a 0.005 rad/s sine
        disp = [vib(&lin, false, 0.0), vib(&lin, false, 0.7), vib(&lin, true, 1.4)];
        roll.0.extend(vib(&ang, false, 2.1).0);
        pitch.0.extend(vib(&ang, false, 2.8).0);
        yaw.0.extend(vib(&ang, false, 3.5).0);
    }
    Motion { name: "car".into(), origin, duration: 40.0, speed, course, displacement: disp, attitude: euler_chain(roll, pitch, yaw) }
}

/// Level stop-and-go drive along the constant course `heading` (rad): at rest for `stop`
/// s, then `cycles` times: speed up to `speed` (m/s) over a raised-cosine ramp of `ramp`
/// s, cruise `cruise` s, slow to rest over `ramp` s, stand `stop` s. The body pitches with
/// the longitudinal acceleration a (squat and dive on the suspension): a raised-cosine
/// pulse over each ramp peaking at `squat`·a_max (rad per m/s², a_max = π·speed/(2·ramp)),
/// nose up while speeding up. While moving the body also rolls in a 12 Hz oscillation of
/// angular-rate amplitude `vibration` (rad/s) times speed/`speed` (road vibration: an IMU
/// cannot tell a smooth cruise from rest).
#[allow(clippy::too_many_arguments)]
pub fn stop_and_go(origin: Vec3, heading: f64, speed: f64, ramp: f64, cruise: f64, stop: f64, cycles: usize, squat: f64, vibration: f64) -> Result<Motion> {
    check_positive("speed", speed)?;
    check_positive("ramp", ramp)?;
    check_positive("stop", stop)?;
    crate::error::check_count("cycles", cycles, 1, 10_000)?;
    for (field, x) in [("cruise", cruise), ("squat", squat), ("vibration", vibration)] {
        if !(x.is_finite() && x >= 0.0) {
            return Err(invalid(field, format!("must be finite and >= 0, got {x}")));
        }
    }
    crate::error::check_finite("heading", &[heading], 1)?;
    let rc = StepShape::RaisedCosine;
    let period = 2.0 * ramp + cruise + stop;
    let starts = (0..cycles).map(|k| stop + k as f64 * period);
    // the speed profile with height 1: the vibration's envelope
    let envelope = starts.clone().fold(Profile::zero(), |p, s| pulse(p, s, ramp, cruise, 1.0, rc));
    let speed_profile = starts.clone().fold(Profile::zero(), |p, s| pulse(p, s, ramp, cruise, speed, rc));
    let tilt = squat * PI * speed / (2.0 * ramp);
    let pitch = starts.fold(Profile::zero(), |p, s| pulse(pulse(p, s, ramp / 2.0, 0.0, tilt, rc), s + ramp + cruise, ramp / 2.0, 0.0, -tilt, rc));
    let f = 12.0;
    let carrier = Profile::zero().with(sine(vibration / (2.0 * PI * f), 1.0 / f));
    let roll = Profile::zero().with(Term::Product(Box::new(envelope), Box::new(carrier)));
    Ok(Motion {
        name: "stop_and_go".into(),
        origin,
        duration: stop + cycles as f64 * period,
        speed: speed_profile,
        course: Profile::constant(heading),
        displacement: zero3(),
        attitude: euler_chain(roll, pitch, Profile::constant(heading)),
    })
}

/// Two-axis rotary stand (as in Vasilyuk et al. 2024) in NED/FRD:
/// C_nb = R_y(tilt) R_z(turntable) — tilt about the East axis, turntable about body z.
/// `states` are (tilt, turntable) in rad; the stand holds each state and moves to the
/// next at `move_starts[j]` (s) over `move_duration` s with the quintic profile
/// 10x³ − 15x⁴ + 6x⁵.
// invariant: states is non-empty and has move_starts.len() + 1 entries (checked
// above), so j + 1 < states.len(); windows(2) yields pairs.
#[allow(clippy::indexing_slicing)]
pub fn rotary_stand(origin: Vec3, states: &[(f64, f64)], move_starts: &[f64], move_duration: f64, duration: f64) -> Result<Motion> {
    if states.is_empty() {
        return Err(invalid("states", "at least one stand state is needed"));
    }
    if move_starts.len() != states.len() - 1 {
        return Err(invalid("move_starts", format!("expected {} start times (one per move), got {}", states.len() - 1, move_starts.len())));
    }
    check_positive("move_duration", move_duration)?;
    for (j, w) in move_starts.windows(2).enumerate() {
        if w[1] < w[0] + move_duration {
            return Err(invalid("move_starts", format!("move {} at {} s starts before move {} ends", j + 1, w[1], j)));
        }
    }
    let axis_profile = |pick: fn(&(f64, f64)) -> f64| {
        let mut p = Profile::constant(pick(&states[0]));
        for (j, start) in move_starts.iter().enumerate() {
            let delta = pick(&states[j + 1]) - pick(&states[j]);
            p = p.with(Term::Step { start: *start, duration: move_duration, delta, shape: StepShape::Quintic, integrated: false });
        }
        p
    };
    Ok(Motion {
        name: "rotary_stand".into(),
        origin,
        duration,
        speed: Profile::zero(),
        course: Profile::zero(),
        displacement: zero3(),
        attitude: vec![
            AxisRotation { axis: Vec3::y(), angle: axis_profile(|s| s.0) },
            AxisRotation { axis: Vec3::z(), angle: axis_profile(|s| s.1) },
        ],
    })
}

/// The stand schedule after Vasilyuk et al. 2024: 13 (tilt, turntable) states in degrees, 73 camera
/// epochs t_n = 0.5023 + 21.0007(n − 1) s, each later state held for 6 epochs, move j
/// starting 4 s after epoch 6j − 5 and lasting 12 s.
pub fn vasilyuk2024_stand(origin: Vec3) -> Result<Motion> {
    const STATES_DEG: [(f64, f64); 13] = [
        (0.0, 50.0), (0.0, 170.0), (0.0, 90.0), (15.0, 90.0), (15.0, 245.0), (15.0, 297.0), (0.0, 297.0),
        (0.0, 240.0), (-7.0, 240.0), (-7.0, 110.0), (-7.0, 60.0), (0.0, 60.0), (0.0, 150.0),
    ];
    let epoch = |n: usize| 0.5023 + 21.0007 * (n as f64 - 1.0);
    let states: Vec<(f64, f64)> = STATES_DEG.iter().map(|(a, b)| (a.to_radians(), b.to_radians())).collect();
    let starts: Vec<f64> = (1..=12).map(|j| epoch(6 * j - 5) + 4.0).collect();
    rotary_stand(origin, &states, &starts, 12.0, epoch(73) + 0.5)
}
