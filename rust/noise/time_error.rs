//! Time interval error of a phase (time-error) record x_i sampled every τ₀: the maximum
//! time interval error MTIE(mτ₀) = max over windows of m + 1 consecutive samples of
//! (max − min) (ITU-T G.810 §B.3; NIST SP 1065 §5.2.14), and the rms time interval error
//! TIErms(mτ₀) = √(Σ_{i<N−m} (x_{i+m} − x_i)² / (N − m)) (NIST SP 1065 §5.2.15). Both are
//! in the unit of the phase. MTIE runs one pass per τ with monotonic deques of the
//! window's candidate maxima and minima: O(N) per τ, not O(N·m).

use crate::error::{check_finite, check_positive, invalid, invalid_at, Result};
use crate::noise::allan::{resolve_factors, sum_sq, TauSet, MIN_TERMS};
use std::collections::VecDeque;

/// MTIE and TIE rms at each averaging factor.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeErrorResult {
    pub m: Vec<usize>,
    /// τ = mτ₀ (s).
    pub tau: Vec<f64>,
    /// Maximum time interval error, phase unit.
    pub mtie: Vec<f64>,
    /// Rms time interval error, phase unit.
    pub tie_rms: Vec<f64>,
    /// Number of windows (and of differences x_{i+m} − x_i): N − m.
    pub n: Vec<usize>,
}

/// MTIE and TIE rms of the phase record `x` (finite, at least 3 samples) at the factors
/// of `set`, each leaving at least `MIN_TERMS` windows of m + 1 samples (m ≤ N − 2).
pub fn time_interval_error(x: &[f64], tau0: f64, set: &TauSet) -> Result<TimeErrorResult> {
    check_positive("tau0", tau0)?;
    check_finite("data", x, 1)?;
    let n = x.len();
    if n < MIN_TERMS + 1 {
        return Err(invalid("data", format!("series of {n} samples is too short; at least {} are needed for one time interval error", MIN_TERMS + 1)));
    }
    let ms = resolve_factors(
        set,
        |m| n.saturating_sub(m),
        |m, i, terms| invalid_at("m", i, format!("averaging factor {m} at index {i} leaves {terms} windows of m + 1 samples (< {MIN_TERMS}): m must be at most N − {MIN_TERMS} = {}", n - MIN_TERMS)),
        &format!("the record of {n} samples is too short"),
    )?;
    let tie_rms = ms
        .iter()
        .map(|&m| {
            let (a, b) = (x.get(..n - m).unwrap_or_default(), x.get(m..).unwrap_or_default());
            (sum_sq([a, b], [-1.0, 1.0]) / (n - m) as f64).sqrt()
        })
        .collect();
    let res = TimeErrorResult {
        tau: ms.iter().map(|&m| m as f64 * tau0).collect(),
        mtie: ms.iter().map(|&m| mtie(x, m)).collect(),
        tie_rms,
        n: ms.iter().map(|&m| n - m).collect(),
        m: ms,
    };
    match res.tau.iter().chain(&res.mtie).chain(&res.tie_rms).find(|v| !v.is_finite()) {
        Some(v) => Err(invalid("data", format!("a time interval error or τ overflows the floating-point range ({v}): rescale the data or tau0"))),
        None => Ok(res),
    }
}

/// max over i of (max − min of x_i … x_{i+m}), 0 for a record shorter than the window.
/// The deques hold (index, value) of the window's decreasing maxima and increasing minima;
/// each sample enters and leaves each deque once.
fn mtie(x: &[f64], m: usize) -> f64 {
    let mut hi: VecDeque<(usize, f64)> = VecDeque::new();
    let mut lo: VecDeque<(usize, f64)> = VecDeque::new();
    let mut best = 0.0f64;
    for (i, &v) in x.iter().enumerate() {
        while hi.back().is_some_and(|&(_, b)| b <= v) {
            hi.pop_back();
        }
        hi.push_back((i, v));
        while lo.back().is_some_and(|&(_, b)| b >= v) {
            lo.pop_back();
        }
        lo.push_back((i, v));
        let Some(start) = i.checked_sub(m) else { continue };
        while hi.front().is_some_and(|&(j, _)| j < start) {
            hi.pop_front();
        }
        while lo.front().is_some_and(|&(j, _)| j < start) {
            lo.pop_front();
        }
        if let (Some(&(_, a)), Some(&(_, b))) = (hi.front(), lo.front()) {
            best = best.max(a - b);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NavError;

    /// O(N·m) definition: every window of m + 1 samples scanned.
    fn mtie_brute(x: &[f64], m: usize) -> f64 {
        x.windows(m + 1).map(|w| w.iter().cloned().fold(f64::MIN, f64::max) - w.iter().cloned().fold(f64::MAX, f64::min)).fold(0.0, f64::max)
    }

    #[test]
    fn mtie_equals_brute_force() {
        // a random walk with ties (quantised steps) and a monotone stretch
        let mut x = Vec::new();
        let mut s: u64 = 12345;
        let mut v = 0.0;
        for k in 0..3000 {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            v += ((s >> 33) % 7) as f64 - 3.0;
            x.push(if (1000..1200).contains(&k) { k as f64 } else { v });
        }
        let r = time_interval_error(&x, 0.5, &TauSet::All).unwrap();
        assert_eq!(r.m.len(), x.len() - 2);
        for (j, &m) in r.m.iter().enumerate() {
            assert_eq!(r.mtie[j], mtie_brute(&x, m), "m = {m}");
            let tie: f64 = (0..x.len() - m).map(|i| (x[i + m] - x[i]).powi(2)).sum::<f64>() / (x.len() - m) as f64;
            assert!((r.tie_rms[j] - tie.sqrt()).abs() <= 1e-12 * tie.sqrt().max(1.0), "m = {m}");
            assert_eq!(r.n[j], x.len() - m);
            assert_eq!(r.tau[j], m as f64 * 0.5);
        }
    }

    #[test]
    fn bad_input_names_the_parameter() {
        let field = |e: NavError| match e {
            NavError::InvalidInput { field, .. } | NavError::OutOfMemory { field, .. } => field,
            NavError::Numerical(m) => m,
        };
        let x = [0.0, 1.0, 3.0, 2.0];
        assert_eq!(field(time_interval_error(&x, 0.0, &TauSet::Octave).unwrap_err()), "tau0");
        assert_eq!(field(time_interval_error(&[0.0, 1.0], 1.0, &TauSet::Octave).unwrap_err()), "data");
        assert_eq!(field(time_interval_error(&[0.0, f64::NAN, 1.0, 2.0], 1.0, &TauSet::Octave).unwrap_err()), "data");
        assert_eq!(field(time_interval_error(&x, 1.0, &TauSet::List(vec![1, 3])).unwrap_err()), "m");
        assert_eq!(field(time_interval_error(&x, 1.0, &TauSet::List(vec![0])).unwrap_err()), "m");
        assert_eq!(time_interval_error(&x, 1.0, &TauSet::Octave).unwrap().m, vec![1, 2]);
    }
}
