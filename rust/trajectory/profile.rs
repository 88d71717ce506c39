//! Smooth scalar time profiles with exact first and second derivatives: the building
//! blocks of every motion model. A `Profile` is a sum of `Term`s.

use std::f64::consts::PI;

/// Value and first two time derivatives of a profile at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Eval {
    pub v: f64,
    pub d1: f64,
    pub d2: f64,
}

impl std::ops::Add for Eval {
    type Output = Eval;
    fn add(self, o: Eval) -> Eval {
        Eval { v: self.v + o.v, d1: self.d1 + o.d1, d2: self.d2 + o.d2 }
    }
}

/// Shape of a smooth 0→1 transition over u ∈ [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum StepShape {
    /// Raised cosine (1 − cos πu)/2.
    RaisedCosine,
    /// Quintic 10u³ − 15u⁴ + 6u⁵ (zero rate and acceleration at both ends; the stand of Vasilyuk et al. 2024).
    Quintic,
}

impl StepShape {
    /// (s, s', s'') w.r.t. u, and ∫₀^u s.
    fn eval(self, u: f64) -> (f64, f64, f64, f64) {
        match self {
            StepShape::RaisedCosine => {
                let (s, c) = (PI * u).sin_cos();
                (0.5 * (1.0 - c), 0.5 * PI * s, 0.5 * PI * PI * c, 0.5 * u - s / (2.0 * PI))
            }
            StepShape::Quintic => {
                let (u2, u3) = (u * u, u * u * u);
                (
                    10.0 * u3 - 15.0 * u3 * u + 6.0 * u3 * u2,
                    30.0 * u2 - 60.0 * u3 + 30.0 * u2 * u2,
                    60.0 * u - 180.0 * u2 + 120.0 * u3,
                    2.5 * u2 * u2 - 3.0 * u3 * u2 + u3 * u3,
                )
            }
        }
    }
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Term {
    /// c + r·t.
    Linear { c: f64, r: f64 },
    /// amp·sin(2πt/period + phase).
    Sine { amp: f64, period: f64, phase: f64 },
    /// A smooth step of height `delta` starting at `start`, lasting `duration`.
    /// With `integrated`, the term is the time integral of that step instead
    /// (e.g. the speed produced by an acceleration step).
    Step { start: f64, duration: f64, delta: f64, shape: StepShape, integrated: bool },
    /// Gaussian pulse amp·exp(−(t−t0)²/(2σ²)); with `integrated`, its time integral
    /// amp·σ√(2π)·Φ((t−t0)/σ).
    Gaussian { t0: f64, sigma: f64, amp: f64, integrated: bool },
    /// atan(amp·sin(2πt/period + phase)): the heading of a sinusoidal slalom.
    ArctanSine { amp: f64, period: f64, phase: f64 },
    /// envelope(t) · carrier(t): vibration whose amplitude follows a profile.
    Product(Box<Profile>, Box<Profile>),
}

impl Term {
    pub fn eval(&self, t: f64) -> Eval {
        match self {
            Term::Linear { c, r } => Eval { v: c + r * t, d1: *r, d2: 0.0 },
            Term::Sine { amp, period, phase } => {
                let w = 2.0 * PI / period;
                let (s, c) = (w * t + phase).sin_cos();
                Eval { v: amp * s, d1: amp * w * c, d2: -amp * w * w * s }
            }
            Term::Step { start, duration, delta, shape, integrated } => {
                let u = ((t - start) / duration).clamp(0.0, 1.0);
                let (s, s1, s2, si) = shape.eval(u);
                let inside = t > *start && t < start + duration;
                let (d1, d2) = if inside { (s1 / duration, s2 / (duration * duration)) } else { (0.0, 0.0) };
                if *integrated {
                    // ∫ step = duration·∫₀^u s du, then linear growth after the step ends
                    let after = (t - start - duration).max(0.0);
                    Eval { v: delta * (duration * si + after), d1: delta * s, d2: delta * d1 }
                } else {
                    Eval { v: delta * s, d1: delta * d1, d2: delta * d2 }
                }
            }
            Term::Gaussian { t0, sigma, amp, integrated } => {
                let x = (t - t0) / sigma;
                let g = amp * (-0.5 * x * x).exp();
                if *integrated {
                    let cdf = 0.5 * (1.0 + libm::erf(x / std::f64::consts::SQRT_2));
                    Eval { v: amp * sigma * (2.0 * PI).sqrt() * cdf, d1: g, d2: -g * x / sigma }
                } else {
                    Eval { v: g, d1: -g * x / sigma, d2: g * (x * x - 1.0) / (sigma * sigma) }
                }
            }
            Term::ArctanSine { amp, period, phase } => {
                let w = 2.0 * PI / period;
                let (s, c) = (w * t + phase).sin_cos();
                let (u, u1, u2) = (amp * s, amp * w * c, -amp * w * w * s);
                let q = 1.0 + u * u;
                Eval { v: u.atan(), d1: u1 / q, d2: (u2 * q - 2.0 * u * u1 * u1) / (q * q) }
            }
            Term::Product(a, b) => {
                let (a, b) = (a.eval(t), b.eval(t));
                Eval { v: a.v * b.v, d1: a.d1 * b.v + a.v * b.d1, d2: a.d2 * b.v + 2.0 * a.d1 * b.d1 + a.v * b.d2 }
            }
        }
    }
}

/// A sum of terms; the empty profile is identically zero.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Profile(pub Vec<Term>);

impl Profile {
    pub fn zero() -> Self {
        Profile(Vec::new())
    }
    pub fn constant(c: f64) -> Self {
        Profile(vec![Term::Linear { c, r: 0.0 }])
    }
    pub fn with(mut self, term: Term) -> Self {
        self.0.push(term);
        self
    }
    pub fn eval(&self, t: f64) -> Eval {
        self.0.iter().fold(Eval::default(), |acc, term| acc + term.eval(t))
    }
    /// The value of a profile made only of constant terms, or None when it varies.
    pub fn constant_value(&self) -> Option<f64> {
        self.0.iter().try_fold(0.0, |sum, term| match term {
            Term::Linear { c, r } if *r == 0.0 => Some(sum + c),
            _ => None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(p: &Profile, t: f64) {
        let h = 1e-5;
        let e = p.eval(t);
        let d1 = (p.eval(t + h).v - p.eval(t - h).v) / (2.0 * h);
        let d2 = (p.eval(t + h).d1 - p.eval(t - h).d1) / (2.0 * h);
        assert!((e.d1 - d1).abs() < 1e-6 * (1.0 + d1.abs()), "d1 {} vs {}", e.d1, d1);
        assert!((e.d2 - d2).abs() < 1e-5 * (1.0 + d2.abs()), "d2 {} vs {}", e.d2, d2);
    }

    #[test]
    fn derivatives_are_consistent() {
        let env = Profile::zero().with(Term::Step { start: 1.0, duration: 2.0, delta: 0.7, shape: StepShape::RaisedCosine, integrated: false });
        let p = Profile::constant(0.3)
            .with(Term::Sine { amp: 0.2, period: 7.0, phase: 0.4 })
            .with(Term::Step { start: 0.5, duration: 1.5, delta: 2.0, shape: StepShape::Quintic, integrated: true })
            .with(Term::Step { start: 0.5, duration: 1.5, delta: -1.0, shape: StepShape::RaisedCosine, integrated: true })
            .with(Term::Gaussian { t0: 1.3, sigma: 0.2, amp: 3.0, integrated: true })
            .with(Term::Gaussian { t0: 1.1, sigma: 0.3, amp: 1.0, integrated: false })
            .with(Term::ArctanSine { amp: 0.25, period: 3.0, phase: 0.5 })
            .with(Term::Product(Box::new(env), Box::new(Profile::zero().with(Term::Sine { amp: 1.0, period: 0.25, phase: 0.0 }))));
        for &t in &[0.2, 0.9, 1.31, 1.77, 2.6, 4.0] {
            check_derivatives(&p, t);
        }
    }

    #[test]
    fn integrated_step_is_the_integral() {
        for shape in [StepShape::RaisedCosine, StepShape::Quintic] {
            let s = Term::Step { start: 1.0, duration: 2.0, delta: 1.5, shape, integrated: false };
            let i = Term::Step { start: 1.0, duration: 2.0, delta: 1.5, shape, integrated: true };
            // trapezoid with a fine step: integral of the step from 0 to 4 s
            let n = 400_000;
            let h = 4.0 / n as f64;
            let trap: f64 = (0..n).map(|k| 0.5 * h * (s.eval(k as f64 * h).v + s.eval((k + 1) as f64 * h).v)).sum();
            assert!((i.eval(4.0).v - trap).abs() < 1e-9, "{shape:?}");
        }
    }
}
