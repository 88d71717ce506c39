//! Allan family: overlapping Allan, modified Allan and overlapping Hadamard variance of
//! rate or phase (angle) data, batch and streaming; equivalent degrees of freedom; the
//! five-term IEEE Std 952 fit (Niu et al. 2025 Eqs. 19–21; docs/departures.md#allan-fit).
//!
//! Everything works on phase x (the integral of the rate): rate data y become
//! x₀ = 0, x_{i+1} = x_i + (y_i − ȳ) in units of rate·τ₀, so that all three statistics
//! are O(N) per τ with no prefix-sum cancellation (NIST SP 1065 Eqs. 11, 15, 18):
//!   AVAR(mτ₀)  = Σ_{i<Np−2m} (x_{i+2m} − 2x_{i+m} + x_i)² / (2 m² τ₀² (Np−2m)),
//!   MVAR(mτ₀)  = Σ_{j<Np−3m+1} (Σ_{i=j}^{j+m−1} x_{i+2m} − 2x_{i+m} + x_i)² / (2 m⁴ τ₀² (Np−3m+1)),
//!   HVAR(mτ₀)  = Σ_{i<Np−3m} (x_{i+3m} − 3x_{i+2m} + 3x_{i+m} − x_i)² / (6 m² τ₀² (Np−3m)),
//! with Np phase points. τ₀ cancels for rate data (x in rate·τ₀ units).

use crate::error::{check_finite, check_positive, invalid, invalid_at, NavError, Result};
use crate::noise::nnls::nnls;
use crate::options::Choice;
use nalgebra::{DMatrix, DVector};

/// Which variance of the Allan family.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Overlapping Allan variance.
    Allan,
    /// Modified Allan variance.
    Modified,
    /// Overlapping Hadamard variance.
    Hadamard,
}

impl Choice for Kind {
    const PARAMETER: &'static str = "kind";
    const CHOICES: &'static [(&'static str, Self)] = &[("allan", Kind::Allan), ("modified", Kind::Modified), ("hadamard", Kind::Hadamard)];
}

impl Kind {
    /// Phase points one term of the sum reaches beyond its first (m ≥ 1): 2m (Allan),
    /// 3m − 1 (modified), 3m (Hadamard); a term uses the rate samples of that span.
    fn span(self, m: usize) -> usize {
        match self {
            Kind::Allan => m.saturating_mul(2),
            Kind::Modified => m.saturating_mul(3).saturating_sub(1),
            Kind::Hadamard => m.saturating_mul(3),
        }
    }

    /// Number of terms in the sum at averaging factor m ≥ 1 with `np` phase points.
    pub fn terms(self, np: usize, m: usize) -> usize {
        np.saturating_sub(self.span(m))
    }

    /// The error for a factor `m` (index `i` of the caller's list) that has only `terms`
    /// terms: names `m` and the number of consecutive samples that give `MIN_TERMS`.
    fn too_few_terms(self, data_type: DataType, m: usize, i: usize, terms: usize) -> NavError {
        let need = self.span(m).saturating_add(MIN_TERMS) - usize::from(data_type == DataType::Rate);
        invalid_at(
            "m",
            i,
            format!(
                "averaging factor {m} at index {i} has {terms} terms (< {MIN_TERMS}): τ is too large for the record; {need} consecutive samples without a gap give {MIN_TERMS} terms (about twice τ for the Allan variance, three times for modified/Hadamard)"
            ),
        )
    }
}

/// Whether the input series is a rate (frequency) or its integral (phase, angle).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataType {
    Rate,
    Phase,
}

impl Choice for DataType {
    const PARAMETER: &'static str = "data_type";
    const CHOICES: &'static [(&'static str, Self)] = &[("rate", DataType::Rate), ("phase", DataType::Phase)];
}

/// Averaging factors m (τ = mτ₀).
#[derive(Debug, Clone, PartialEq)]
pub enum TauSet {
    /// 1, 2, 4, 8, …
    Octave,
    /// 1, 2, 4, 10, 20, 40, … (as Stable32 and allantools "decade").
    Decade,
    /// Every m.
    All,
    /// User-given factors; each must leave at least two terms.
    List(Vec<usize>),
}

/// A generated set of averaging factors, chosen by name (`m="octave"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TauGrid {
    Octave,
    Decade,
    All,
}

impl Choice for TauGrid {
    const PARAMETER: &'static str = "m";
    const CHOICES: &'static [(&'static str, Self)] = &[("octave", TauGrid::Octave), ("decade", TauGrid::Decade), ("all", TauGrid::All)];
}

impl From<TauGrid> for TauSet {
    fn from(g: TauGrid) -> TauSet {
        match g {
            TauGrid::Octave => TauSet::Octave,
            TauGrid::Decade => TauSet::Decade,
            TauGrid::All => TauSet::All,
        }
    }
}

/// One statistic at each averaging factor.
#[derive(Debug, Clone, PartialEq)]
pub struct AllanResult {
    pub m: Vec<usize>,
    /// τ = mτ₀ (s).
    pub tau: Vec<f64>,
    /// Variance in (rate unit)².
    pub var: Vec<f64>,
    /// Number of terms in each sum.
    pub n: Vec<usize>,
    /// Number of NaN (missing) rate samples left out.
    pub missing: usize,
}

/// Minimum number of terms for a variance to be reported (as allantools).
pub const MIN_TERMS: usize = 2;

/// Resolve a τ set into the averaging factors that leave at least `MIN_TERMS` terms in
/// a record of gap-free stretches of `np` phase points each. A user list with a factor
/// that is too large is an error naming its index; a named set of which no factor has
/// enough terms is an error naming `data`.
pub fn resolve_m(set: &TauSet, kind: Kind, data_type: DataType, np: &[usize]) -> Result<Vec<usize>> {
    let longest = np.iter().max().map_or(0, |p| p - usize::from(data_type == DataType::Rate));
    resolve_factors(
        set,
        |m| np.iter().map(|&p| kind.terms(p, m)).sum::<usize>(),
        |m, i, terms| kind.too_few_terms(data_type, m, i, terms),
        &format!("the stretches between NaN samples are too short (at most {longest} samples)"),
    )
}

/// The averaging factors of `set` that leave at least `MIN_TERMS` terms, `terms(m)`
/// counting them: a user factor with fewer is the error `too_few(m, index, terms)`, a
/// named set without any factor the error naming `data` with `why`. Ascending, no repeats.
pub(crate) fn resolve_factors(set: &TauSet, terms: impl Fn(usize) -> usize, too_few: impl Fn(usize, usize, usize) -> NavError, why: &str) -> Result<Vec<usize>> {
    let ok = |m: usize| m >= 1 && terms(m) >= MIN_TERMS;
    let gen = |f: &dyn Fn(usize) -> usize| -> Result<Vec<usize>> {
        let ms: Vec<usize> = (0..).map(f).take_while(|&m| ok(m)).collect();
        match ms.is_empty() {
            true => Err(invalid("data", format!("no averaging factor has {MIN_TERMS} terms: {why}"))),
            false => Ok(ms),
        }
    };
    match set {
        TauSet::Octave => gen(&|k| 1usize << k),
        TauSet::All => gen(&|k| k + 1),
        TauSet::Decade => gen(&|k| {
            let mantissa = match k % 3 {
                0 => 1,
                1 => 2,
                _ => 4,
            };
            u32::try_from(k / 3).ok().and_then(|e| 10usize.checked_pow(e)).and_then(|p| p.checked_mul(mantissa)).unwrap_or(usize::MAX)
        }),
        TauSet::List(ms) => {
            if ms.is_empty() {
                return Err(invalid("m", "no averaging factors given"));
            }
            for (i, &m) in ms.iter().enumerate() {
                if m == 0 {
                    return Err(invalid_at("m", i, format!("averaging factor 0 at index {i}; τ must be ≥ τ₀")));
                }
                if !ok(m) {
                    return Err(too_few(m, i, terms(m)));
                }
            }
            let mut v = ms.clone();
            v.sort_unstable();
            v.dedup();
            Ok(v)
        }
    }
}

/// Fixed number of parts that long loops are split into: results are combined in part
/// order, so they do not depend on how many threads the machine has.
const PARTS: usize = 8;

/// `f(p)` for p in 0..PARTS, on up to PARTS threads when `work` (element operations)
/// is large enough to pay for them; results in part order.
fn par_parts<T: Send>(work: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = if work < 1 << 22 { 1 } else { std::thread::available_parallelism().map_or(1, |n| n.get()).min(PARTS) };
    if threads == 1 {
        return (0..PARTS).map(f).collect();
    }
    let f = &f;
    let mut out: Vec<(usize, T)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads).map(|t| s.spawn(move || (t..PARTS).step_by(threads).map(|p| (p, f(p))).collect::<Vec<_>>())).collect();
        // a worker fails only by a panic of `f` itself: passed on unchanged
        handles.into_iter().flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
    });
    out.sort_by_key(|(p, _)| *p);
    out.into_iter().map(|(_, v)| v).collect()
}

/// Σ f(v) with eight independent accumulators (vectorisable).
fn lane_sum(v: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    let mut acc = [0.0f64; 8];
    let mut chunks = v.chunks_exact(8);
    for c in &mut chunks {
        for (a, &x) in acc.iter_mut().zip(c) {
            *a += f(x);
        }
    }
    chunks.remainder().iter().map(|&x| f(x)).sum::<f64>() + acc.iter().sum::<f64>()
}

/// Phase points from rate data: x₀ = 0, x_{i+1} = x_i + (y_i − ȳ) (units rate·τ₀).
/// Removing the mean does not change any of the three variances and avoids cancellation.
/// Two passes over PARTS contiguous parts: part sums, then each part's running sum.
fn rate_to_phase(y: &[f64]) -> Vec<f64> {
    let n = y.len();
    // a constant series (a stuck or quantised sensor) has phase 0 about its mean, and so
    // every variance exactly 0 (the rounded part sums would leave ~1e-31)
    if y.split_first().is_some_and(|(&y0, rest)| rest.iter().all(|&v| v == y0)) {
        return vec![0.0; n + 1];
    }
    let len = n.div_ceil(PARTS);
    let part = |p: usize| y.get((p * len).min(n)..((p + 1) * len).min(n)).unwrap_or_default();
    let sums = par_parts(n, |p| lane_sum(part(p), |v| v));
    let mean = sums.iter().sum::<f64>() / n as f64;
    let mut x = vec![0.0; n + 1];
    let mut start = 0.0;
    let mut starts = Vec::with_capacity(PARTS);
    for (p, s) in sums.iter().enumerate() {
        starts.push(start);
        start += s - part(p).len() as f64 * mean;
    }
    let mut outs: Vec<&mut [f64]> = x.get_mut(1..).unwrap_or_default().chunks_mut(len.max(1)).collect();
    outs.resize_with(PARTS, || &mut []);
    let outs: Vec<std::sync::Mutex<&mut [f64]>> = outs.into_iter().map(std::sync::Mutex::new).collect();
    par_parts(n, |p| {
        // one part per worker: the lock is never contended, nor poisoned (nothing below panics)
        let (Some(Ok(mut out)), Some(&start)) = (outs.get(p).map(|o| o.lock()), starts.get(p)) else { return };
        let mut acc = start;
        for (o, v) in out.iter_mut().zip(part(p)) {
            acc += v - mean;
            *o = acc;
        }
    });
    x
}

/// Σ_i (Σ_k c_k s_k[i])² over the common length of the K slices, with eight
/// independent accumulators over fixed-size blocks so the loop vectorises.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // index i runs across the K slices
// invariant: K ≥ 1 slices of one common length (difference_sums cuts each to end − i0), so
// every index below n = s[0].len() is in range and each block is exactly L long.
#[allow(clippy::indexing_slicing, clippy::expect_used)]
fn sum_sq_impl<const K: usize>(s: [&[f64]; K], c: [f64; K]) -> f64 {
    const L: usize = 8;
    let n = s[0].len();
    let mut acc = [0.0f64; L];
    let blocks = n / L;
    for blk in 0..blocks {
        let b: [&[f64; L]; K] = std::array::from_fn(|k| s[k][blk * L..blk * L + L].try_into().expect("block of L"));
        for l in 0..L {
            let mut v = 0.0;
            for k in 0..K {
                v += c[k] * b[k][l];
            }
            acc[l] += v * v;
        }
    }
    for i in blocks * L..n {
        let v: f64 = (0..K).map(|k| c[k] * s[k][i]).sum();
        acc[0] += v * v;
    }
    acc.iter().sum()
}

/// The same loop compiled for AVX2 (four f64 lanes), chosen at run time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sum_sq_avx2<const K: usize>(s: [&[f64]; K], c: [f64; K]) -> f64 {
    sum_sq_impl(s, c)
}

pub(crate) fn sum_sq<const K: usize>(s: [&[f64]; K], c: [f64; K]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { sum_sq_avx2(s, c) };
    }
    sum_sq_impl(s, c)
}

/// Σ_i (Σ_k c_k x_{i+km})² for every m in `ms` (ascending), i < Np − (K−1)m: the Allan
/// (K = 3) and Hadamard (K = 4) sums. The index range is cut into blocks of `BLOCK`
/// terms and each block is visited once for all m, so the windows x_{i+km} of
/// neighbouring octave factors (2m_k = m_{k+1}) are read from cache rather than memory.
/// The range is split into `PARTS` fixed parts (see [`par_parts`]).
// invariant: variance passes only the m with x.len() − (K−1)m ≥ 1 term, and end ≤ terms(m),
// so x[i0 + km .. end + km] ends at most at x.len().
#[allow(clippy::indexing_slicing)]
fn difference_sums<const K: usize>(x: &[f64], ms: &[usize], c: [f64; K]) -> Vec<f64> {
    const BLOCK: usize = 2048;
    let terms = |m: usize| x.len() - (K - 1) * m;
    let Some(&m0) = ms.first() else { return Vec::new() };
    let total = terms(m0);
    let part_len = total.div_ceil(PARTS).div_ceil(BLOCK) * BLOCK;
    let parts = par_parts(total * ms.len(), |p| {
        let mut sums = vec![0.0; ms.len()];
        let (start, stop) = ((p * part_len).min(total), ((p + 1) * part_len).min(total));
        let mut i0 = start;
        while i0 < stop {
            for (j, &m) in ms.iter().enumerate() {
                let end = (i0 + BLOCK).min(stop).min(terms(m));
                if end > i0 {
                    sums[j] += sum_sq(std::array::from_fn(|k| &x[i0 + k * m..end + k * m]), c);
                }
            }
            i0 += BLOCK;
        }
        sums
    });
    (0..ms.len()).map(|j| parts.iter().map(|p| p[j]).sum()).collect()
}

/// Σ_j v_j², v_j = Σ_{i=j}^{j+m−1} (x_{i+2m} − 2x_{i+m} + x_i), updated by
/// v_{j+1} = v_j + x_{j+3m} − 3x_{j+2m} + 3x_{j+m} − x_j (NIST SP 1065 Eq. 15).
// invariant: variance passes only the m with x.len() + 1 − 3m ≥ 1 term, so i + 2m and
// j + 3m stay below x.len().
#[allow(clippy::indexing_slicing)]
fn modified_sum(x: &[f64], m: usize) -> f64 {
    let mut v: f64 = (0..m).map(|i| x[i + 2 * m] - 2.0 * x[i + m] + x[i]).sum();
    let mut s = v * v;
    for j in 0..x.len() + 1 - 3 * m - 1 {
        v += x[j + 3 * m] - 3.0 * x[j + 2 * m] + 3.0 * x[j + m] - x[j];
        s += v * v;
    }
    s
}

/// Divisor that turns a sum into the variance: 2m²·n (Allan), 2m⁴·n (modified), 6m²·n (Hadamard).
fn divisor(kind: Kind, m: usize, n: usize) -> f64 {
    let (m, n) = (m as f64, n as f64);
    match kind {
        Kind::Allan => 2.0 * m * m * n,
        Kind::Modified => 2.0 * m.powi(4) * n,
        Kind::Hadamard => 6.0 * m * m * n,
    }
}

/// Checks the series and returns its number of NaN (missing) samples: allowed in rate
/// data only; ±inf is invalid everywhere.
fn check_series(data: &[f64], data_type: DataType, tau0: f64) -> Result<usize> {
    check_positive("tau0", tau0)?;
    // v·0 is NaN exactly for NaN/±inf: one vectorised pass, the indexed search only on failure.
    let missing = match lane_sum(data, |v| v * 0.0).is_nan() {
        true => check_missing("data", data, data_type)?,
        false => 0,
    };
    let min = if data_type == DataType::Rate { 3 } else { 4 };
    if data.len() - missing < min {
        let what = if missing > 0 { " non-NaN" } else { "" };
        return Err(invalid("data", format!("series of {}{what} samples is too short; at least {min} are needed for one Allan point", data.len() - missing)));
    }
    Ok(missing)
}

/// The number of NaN samples of a rate series (missing samples); ±inf, or NaN in phase
/// data, is invalid input naming `field` and its first index.
fn check_missing(field: &str, data: &[f64], data_type: DataType) -> Result<usize> {
    let phase = data_type == DataType::Phase;
    if let Some((i, v)) = data.iter().enumerate().find(|(_, v)| v.is_infinite() || (phase && v.is_nan())) {
        let why = if v.is_nan() { " (a missing sample is a NaN of rate data; a phase record's gap leaves the phase across it unknown)" } else { "" };
        return Err(invalid_at(field, i, format!("non-finite value {v} at index {i}{why}")));
    }
    Ok(data.iter().filter(|v| v.is_nan()).count())
}

/// Batch Allan-family variance of rate data (any unit) or phase data (angle; the
/// variance is then in angle/s²) sampled every `tau0` seconds.
///
/// A NaN rate sample is missing (a gap is marked, not filled: Riley, NIST SP 1065, "Gaps,
/// jumps, and outliers"; the rule of allantools' gap-resistant `gradev`, which applies it
/// to phase points): every term whose span of rate
/// samples ([`Kind::span`]: 2m for the Allan, 3m − 1 for the modified, 3m for the
/// Hadamard variance) holds a NaN is left out, and the variance is the mean of the other
/// terms. This is the terms of each gap-free stretch pooled, so the record is cut at its
/// NaN samples and each stretch is summed as a record of its own; leading and trailing
/// NaN are trimmed as allantools' `frequency2phase` does. A constant series gives 0.
pub fn variance(data: &[f64], tau0: f64, data_type: DataType, kind: Kind, set: &TauSet) -> Result<AllanResult> {
    let missing = check_series(data, data_type, tau0)?;
    let stretches: Vec<&[f64]> = match missing {
        0 => vec![data],
        _ => data.split(|v| v.is_nan()).filter(|s| !s.is_empty()).collect(),
    };
    // a rate stretch of L samples is L + 1 phase points
    let np: Vec<usize> = stretches.iter().map(|y| y.len() + usize::from(data_type == DataType::Rate)).collect();
    let scale = if data_type == DataType::Phase { 1.0 / (tau0 * tau0) } else { 1.0 };
    let ms = resolve_m(set, kind, data_type, &np)?;
    let mut sums = vec![0.0; ms.len()];
    for y in stretches {
        let x = match data_type {
            DataType::Rate => std::borrow::Cow::Owned(rate_to_phase(y)),
            DataType::Phase => std::borrow::Cow::Borrowed(y),
        };
        // ms ascending: the factors with a term in this stretch are a prefix of it
        let here: Vec<usize> = ms.iter().copied().take_while(|&m| kind.terms(x.len(), m) >= 1).collect();
        let part = match kind {
            Kind::Allan => difference_sums(&x, &here, [1.0, -2.0, 1.0]),
            Kind::Hadamard => difference_sums(&x, &here, [-1.0, 3.0, -3.0, 1.0]),
            Kind::Modified => here.iter().map(|&m| modified_sum(&x, m)).collect(),
        };
        sums.iter_mut().zip(part).for_each(|(s, p)| *s += p);
    }
    let n: Vec<usize> = ms.iter().map(|&m| np.iter().map(|&p| kind.terms(p, m)).sum()).collect();
    let res = AllanResult {
        tau: ms.iter().map(|&m| m as f64 * tau0).collect(),
        var: sums.iter().zip(&ms).zip(&n).map(|((s, &m), &nj)| s * scale / divisor(kind, m, nj)).collect(),
        m: ms,
        n,
        missing,
    };
    check_overflow(&res)?;
    Ok(res)
}

/// Time variance σ²_x(τ) = τ²/3 · MVAR(τ) (NIST SP 1065 §5.2.6): the modified Allan
/// variance of [`variance`] scaled, in (phase unit)² for phase data and (rate unit · s)²
/// for rate data; the terms, gaps and τ set are those of the modified Allan variance.
pub fn time_variance(data: &[f64], tau0: f64, data_type: DataType, set: &TauSet) -> Result<AllanResult> {
    let mut res = variance(data, tau0, data_type, Kind::Modified, set)?;
    res.var.iter_mut().zip(&res.tau).for_each(|(v, t)| *v *= t * t / 3.0);
    check_overflow(&res)?;
    Ok(res)
}

/// Streaming accumulation of all three variances at fixed averaging factors, for
/// records that do not fit in memory. Memory is a ring of 3·max(m)+1 phase points.
/// Rate data are integrated about their first sample instead of their mean (unknown in
/// advance); the variances do not depend on that offset. A NaN rate sample is missing,
/// as in [`variance`]: it ends the current gap-free stretch, whose terms are kept, and
/// the next sample starts a new one, so the stream equals the batch on the same record.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct AllanStream {
    /// The factors as given (errors name an index of this list).
    given: Vec<usize>,
    /// The factors sorted, without repeats.
    ms: Vec<usize>,
    tau0: f64,
    #[serde(with = "crate::options::by_name")]
    data_type: DataType,
    ring: Vec<f64>,
    mask: usize,
    /// Phase points of the current gap-free stretch.
    np: usize,
    /// Running phase (rate data) and the rate offset.
    phase: f64,
    offset: Option<f64>,
    sum_a: Vec<f64>,
    sum_m: Vec<f64>,
    sum_h: Vec<f64>,
    v: Vec<f64>,
    /// Terms of the finished stretches per factor: (Allan, modified, Hadamard).
    done: Vec<[usize; 3]>,
    /// NaN (missing) rate samples seen.
    missing: usize,
}

/// The slot of `kind` in [`AllanStream`]'s per-kind arrays.
fn slot(kind: Kind) -> usize {
    match kind {
        Kind::Allan => 0,
        Kind::Modified => 1,
        Kind::Hadamard => 2,
    }
}

const KINDS: [Kind; 3] = [Kind::Allan, Kind::Modified, Kind::Hadamard];

impl AllanStream {
    /// A stream at the averaging factors `ms` (each ≥ 1; the ring of 3·max(m)+1 phase
    /// points must fit in memory: `OutOfMemory` names its size otherwise).
    pub fn new(ms: &[usize], tau0: f64, data_type: DataType) -> Result<AllanStream> {
        check_positive("tau0", tau0)?;
        if let Some(i) = ms.iter().position(|&m| m == 0) {
            return Err(invalid_at("m", i, format!("averaging factor 0 at index {i}")));
        }
        let (i, &m_max) = ms.iter().enumerate().max_by_key(|(_, m)| **m).ok_or_else(|| invalid("m", "no averaging factors given"))?;
        let cap = m_max
            .checked_mul(3)
            .and_then(|n| n.checked_add(1))
            .and_then(usize::checked_next_power_of_two)
            .ok_or_else(|| invalid_at("m", i, format!("averaging factor {m_max} at index {i} needs a ring of 3m+1 phase points, more than any address space holds")))?;
        // reserved, not touched: the pages fill as the stream runs
        let mut ring = Vec::new();
        ring.try_reserve_exact(cap).map_err(|_| NavError::OutOfMemory { field: "m".into(), bytes: cap as u128 * 8 })?;
        let given = ms.to_vec();
        let mut ms = ms.to_vec();
        ms.sort_unstable();
        ms.dedup();
        let k = ms.len();
        Ok(AllanStream {
            given,
            ms,
            tau0,
            data_type,
            ring,
            mask: cap - 1,
            np: 0,
            phase: 0.0,
            offset: None,
            sum_a: vec![0.0; k],
            sum_m: vec![0.0; k],
            sum_h: vec![0.0; k],
            v: vec![0.0; k],
            done: vec![[0; 3]; k],
            missing: 0,
        })
    }

    // invariant: ring indices are masked by mask = ring capacity − 1 once the ring is
    // full and below n = ring.len() before; sum_a, sum_m, sum_h and v have one entry per m.
    #[allow(clippy::indexing_slicing)]
    fn push_phase(&mut self, x: f64) {
        let n = self.np;
        if self.ring.len() > self.mask {
            self.ring[n & self.mask] = x;
        } else {
            self.ring.push(x); // first pass: n == ring.len() == n & mask
        }
        let r = |i: usize| self.ring[i & self.mask];
        for (j, &m) in self.ms.iter().enumerate() {
            if n < 2 * m {
                break;
            }
            let s2 = x - 2.0 * r(n - m) + r(n - 2 * m);
            self.sum_a[j] += s2 * s2;
            if n >= 3 * m {
                let h = s2 - (r(n - m) - 2.0 * r(n - 2 * m) + r(n - 3 * m));
                self.sum_h[j] += h * h;
                self.v[j] += h;
                self.sum_m[j] += self.v[j] * self.v[j];
            } else {
                self.v[j] += s2;
                if n == 3 * m - 1 {
                    self.sum_m[j] += self.v[j] * self.v[j];
                }
            }
        }
        self.np += 1;
    }

    /// Close the current gap-free stretch: its terms are counted, its phase forgotten.
    fn end_stretch(&mut self) {
        for (d, &m) in self.done.iter_mut().zip(&self.ms) {
            d.iter_mut().zip(KINDS).for_each(|(t, kind)| *t += kind.terms(self.np, m));
        }
        (self.np, self.phase) = (0, 0.0);
        self.ring.clear();
        self.v.fill(0.0);
    }

    /// Feed the next chunk of samples (rate or phase, as constructed; NaN marks a missing
    /// rate sample). Samples so large that the sums overflow the f64 range are an error.
    pub fn update(&mut self, chunk: &[f64]) -> Result<()> {
        if lane_sum(chunk, |v| v * 0.0).is_nan() {
            check_missing("chunk", chunk, self.data_type)?;
        }
        for &y in chunk {
            match self.data_type {
                DataType::Phase => self.push_phase(y),
                DataType::Rate if y.is_nan() => {
                    self.missing += 1;
                    if self.np > 0 {
                        self.end_stretch();
                    }
                }
                DataType::Rate => {
                    let off = *self.offset.get_or_insert(y);
                    if self.np == 0 {
                        self.push_phase(0.0);
                    }
                    self.phase += y - off;
                    self.push_phase(self.phase);
                }
            }
        }
        if !self.sum_a.iter().chain(&self.sum_m).chain(&self.sum_h).all(|s| s.is_finite()) {
            return Err(invalid("chunk", "the sums overflow the floating-point range: the samples are too large (rescale them)"));
        }
        Ok(())
    }

    /// Terms so far at factor `ms[j]` of `kind`.
    fn terms(&self, kind: Kind, j: usize, m: usize) -> usize {
        self.done.get(j).and_then(|d| d.get(slot(kind))).copied().unwrap_or_default() + kind.terms(self.np, m)
    }

    /// The variances so far, at every factor, as [`variance`] gives them for the same
    /// samples: a factor with fewer than `MIN_TERMS` terms yet is an error naming `m`, its
    /// index in the list given and the number of samples it needs.
    pub fn result(&self, kind: Kind) -> Result<AllanResult> {
        let terms = |m: usize| self.ms.iter().position(|&v| v == m).map_or(0, |j| self.terms(kind, j, m));
        if let Some((i, &m)) = self.given.iter().enumerate().find(|(_, &m)| terms(m) < MIN_TERMS) {
            return Err(kind.too_few_terms(self.data_type, m, i, terms(m)));
        }
        let scale = if self.data_type == DataType::Phase { 1.0 / (self.tau0 * self.tau0) } else { 1.0 };
        let sums = match kind {
            Kind::Allan => &self.sum_a,
            Kind::Modified => &self.sum_m,
            Kind::Hadamard => &self.sum_h,
        };
        let n: Vec<usize> = self.ms.iter().enumerate().map(|(j, &m)| self.terms(kind, j, m)).collect();
        Ok(AllanResult {
            tau: self.ms.iter().map(|&m| m as f64 * self.tau0).collect(),
            var: sums.iter().zip(&self.ms).zip(&n).map(|((s, &m), &nj)| s * scale / divisor(kind, m, nj)).collect(),
            m: self.ms.clone(),
            n,
            missing: self.missing,
        })
    }
}

/// τ and variances of a finite record can still overflow the f64 range (samples near 1e300).
fn check_overflow(res: &AllanResult) -> Result<()> {
    match res.tau.iter().chain(&res.var).find(|v| !v.is_finite()) {
        Some(v) => Err(invalid("data", format!("a variance or τ overflows the floating-point range ({v}): rescale the data or tau0"))),
        None => Ok(()),
    }
}

/// Power-law noise type for the equivalent degrees of freedom (α of S_y(f) ∝ f^α).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseType {
    WhitePm,
    FlickerPm,
    WhiteFm,
    FlickerFm,
    RandomWalkFm,
}

impl Choice for NoiseType {
    const PARAMETER: &'static str = "noise";
    const CHOICES: &'static [(&'static str, Self)] = &[
        ("white_pm", NoiseType::WhitePm),
        ("flicker_pm", NoiseType::FlickerPm),
        ("white_fm", NoiseType::WhiteFm),
        ("flicker_fm", NoiseType::FlickerFm),
        ("random_walk_fm", NoiseType::RandomWalkFm),
    ];
}

impl NoiseType {
    /// Exponent α of the rate spectrum S_y(f) ∝ f^α: 2 (white PM), 1 (flicker PM),
    /// 0 (white FM), −1 (flicker FM), −2 (random-walk FM).
    pub fn alpha(self) -> i32 {
        match self {
            NoiseType::WhitePm => 2,
            NoiseType::FlickerPm => 1,
            NoiseType::WhiteFm => 0,
            NoiseType::FlickerFm => -1,
            NoiseType::RandomWalkFm => -2,
        }
    }
}

impl Kind {
    /// Order d of the phase difference: 2 (Allan, modified Allan) or 3 (Hadamard).
    pub fn order(self) -> u32 {
        match self {
            Kind::Hadamard => 3,
            Kind::Allan | Kind::Modified => 2,
        }
    }
}

/// Equivalent degrees of freedom of `kind` at each averaging factor of `m` for a record
/// of `np` phase points (docs/departures.md#allan-edf):
/// - Allan: Howe's approximations, [`edf_overlapping_allan`];
/// - modified Allan and Hadamard: for white PM, white FM and random-walk FM at
///   (d+1)m ≤ 100 the exact EDF of the sampled estimator, [`edf_sampled`]; otherwise
///   Greenhall & Riley 2003, [`edf_greenhall`].
pub fn edf(kind: Kind, noise: NoiseType, np: usize, m: &[usize]) -> Result<Vec<f64>> {
    if let Some((i, mi)) = m.iter().enumerate().find(|(_, &mj)| mj == 0 || kind.terms(np, mj) == 0) {
        return Err(invalid_at("m", i, format!("averaging factor {mi} at index {i} leaves no term of the sum for {np} phase points (a term spans {} points)", kind.span(*mi).saturating_add(1))));
    }
    Ok(m.iter()
        .map(|&mj| match kind {
            Kind::Allan => edf_overlapping_allan(noise, np, mj),
            _ if noise != NoiseType::FlickerPm && noise != NoiseType::FlickerFm && (f64::from(kind.order()) + 1.0) * mj as f64 <= J_MAX => edf_sampled(kind, noise, np, mj),
            _ => edf_greenhall(kind, noise, np, mj),
        })
        .collect())
}

/// Equivalent degrees of freedom of the overlapping Allan variance with `np` phase
/// points at factor m, by Howe's approximations (NIST SP 1065 Table 12; Stable32).
/// For white FM: (3(Np−1)/(2m) − 2(Np−2)/Np)·4m²/(4m²+5).
pub fn edf_overlapping_allan(noise: NoiseType, np: usize, m: usize) -> f64 {
    let (n, m) = (np as f64, m as f64);
    let edf = match noise {
        NoiseType::WhitePm => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
        NoiseType::FlickerPm => (((n - 1.0) / (2.0 * m)).ln() * ((2.0 * m + 1.0) * (n - 1.0) / 4.0).ln()).sqrt().exp(),
        NoiseType::WhiteFm => (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * 4.0 * m * m / (4.0 * m * m + 5.0),
        NoiseType::FlickerFm => {
            if m == 1.0 {
                2.0 * (n - 2.0) / (2.3 * n - 4.9)
            } else {
                5.0 * n * n / (4.0 * m * (n + 3.0 * m))
            }
        }
        NoiseType::RandomWalkFm => (n - 2.0) / m * ((n - 1.0).powi(2) - 3.0 * m * (n - 1.0) + 4.0 * m * m) / (n - 3.0).powi(2),
    };
    edf.max(1.0)
}

/// Greenhall & Riley 2003 J_max: longest sum evaluated term by term.
const J_MAX: f64 = 100.0;

/// C(2d, d−k) for k = 0…d (d = 2 or 3): the autocorrelation of the d-th difference.
fn binomial_2d(d: u32) -> &'static [f64] {
    if d == 2 {
        &[6.0, 4.0, 1.0]
    } else {
        &[20.0, 15.0, 6.0, 1.0]
    }
}

/// Generalised autocovariance of the continuous power-law process w (Greenhall & Riley
/// 2003 Eq. 7), α ∈ [−2, 2]; the overall sign and scale cancel in the EDF.
fn gr_sw(t: f64, alpha: i32) -> f64 {
    match alpha {
        2 => -t.abs(),
        1 if t == 0.0 => 0.0,
        1 => t * t * t.abs().ln(),
        0 => t.abs().powi(3),
        -1 if t == 0.0 => 0.0,
        -1 => t.powi(4) * t.abs().ln(),
        _ => t.abs().powi(5),
    }
}

/// Phase autocovariance behind filter factor F (Greenhall & Riley 2003 Eq. 8); `None`
/// is F = ∞ (the phase sampled without a filter, α ≤ 0).
fn gr_sx(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    match f {
        None => gr_sw(t, alpha + 2),
        Some(f) => f * f * (2.0 * gr_sw(t, alpha) - gr_sw(t - 1.0 / f, alpha) - gr_sw(t + 1.0 / f, alpha)),
    }
}

/// Autocovariance of the d-th difference of the phase at lag t (in τ; Eq. 9).
fn gr_sz(t: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let mut acc = 0.0;
    for (k, c) in binomial_2d(d).iter().enumerate() {
        let (sign, k) = (if k % 2 == 0 { 1.0 } else { -1.0 }, k as f64);
        acc = if k == 0.0 { c * gr_sx(t, f, alpha) } else { acc + sign * c * gr_sx(t - k, f, alpha) + sign * c * gr_sx(t + k, f, alpha) };
    }
    acc
}

/// Greenhall & Riley 2003 Eq. 10: M·sz(0)²/EDF from J lags of stride 1/S.
fn gr_basic_sum(j: f64, m_terms: f64, s: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let first = gr_sz(0.0, f, alpha, d).powi(2);
    let second = (1.0 - j / m_terms) * gr_sz(j / s, f, alpha, d).powi(2);
    let mut third = 0.0;
    let mut jj = 1.0;
    while jj < j {
        third += 2.0 * (1.0 - jj / m_terms) * gr_sz(jj / s, f, alpha, d).powi(2);
        jj += 1.0;
    }
    first + second + third
}

/// Greenhall & Riley 2003 Table 1 (modified variances, many lags): (a₀, a₁), d = 2, 3.
fn gr_table1(alpha: i32, d: u32) -> (f64, f64) {
    match (alpha, d) {
        (2, 2) => (7.0 / 9.0, 0.5),
        (2, _) => (22.0 / 25.0, 2.0 / 3.0),
        (1, 2) => (0.997, 0.616),
        (1, _) => (1.141, 0.843),
        (0, 2) => (1.033, 0.607),
        (0, _) => (1.184, 0.848),
        (-1, 2) => (1.048, 0.534),
        (-1, _) => (1.180, 0.816),
        (_, 2) => (1.302, 0.535),
        _ => (1.175, 0.777),
    }
}

/// Greenhall & Riley 2003 Table 2 (unmodified variances, many lags), α ≤ 1: (a₀, a₁).
fn gr_table2(alpha: i32, d: u32) -> (f64, f64) {
    match (alpha, d) {
        (1, 2) => (790.0, 410.0),
        (1, _) => (9950.0, 6520.0),
        (0, 2) => (2.0 / 3.0, 1.0 / 3.0),
        (0, _) => (7.0 / 9.0, 0.5),
        (-1, 2) => (0.852, 0.375),
        (-1, _) => (0.997, 0.617),
        (_, 2) => (1.079, 0.368),
        _ => (1.033, 0.607),
    }
}

/// Equivalent degrees of freedom of the overlapping estimator `kind` (stride τ₀) on
/// continuous-time power-law noise, by C. A. Greenhall and W. J. Riley, "Uncertainty of
/// stability variances based on finite differences", PTTI 2003, §3.4–3.6 (the algorithm
/// of Stable32 and allantools' `edf_greenhall`): filter factor F = 1 (modified) or m,
/// stride factor S = m, d = 2 (Allan, modified Allan) or 3 (Hadamard), M terms,
/// J = min(M, (d+1)S), J_max = 100, r = M/S. For white PM (α = 2, unmodified) the
/// closed form of their case 4, (1 + 2 Σ_{k<min(⌈r⌉, d+1)} (1 − k/r) C(2d,d−k)²/C(2d,d)²)/M,
/// which is exact. `np` phase points, factor `m` with at least one term.
pub fn edf_greenhall(kind: Kind, noise: NoiseType, np: usize, m: usize) -> f64 {
    let (alpha, d) = (noise.alpha(), kind.order());
    let (n, m, df) = (np as f64, m as f64, f64::from(d));
    let modified = kind == Kind::Modified;
    let s = m;
    let l = if modified { m } else { 1.0 } + m * df;
    let m_terms = 1.0 + (s * (n - l) / m).floor();
    let j = m_terms.min((df + 1.0) * s);
    let r = m_terms / s;
    let inv = if modified {
        let sz0 = gr_sz(0.0, Some(1.0), alpha, d).powi(2);
        if j <= J_MAX {
            gr_basic_sum(j, m_terms, s, Some(1.0), alpha, d) / (sz0 * m_terms)
        } else if r > df + 1.0 {
            let (a0, a1) = gr_table1(alpha, d);
            (a0 - a1 / r) / r
        } else {
            gr_basic_sum(J_MAX, J_MAX, J_MAX / r, Some(1.0), alpha, d) / (sz0 * J_MAX)
        }
    } else if alpha <= 0 {
        if j <= J_MAX {
            let f = if m * (df + 1.0) <= J_MAX { Some(m) } else { None };
            gr_basic_sum(j, m_terms, s, f, alpha, d) / (gr_sz(0.0, f, alpha, d).powi(2) * m_terms)
        } else if r > df + 1.0 {
            let (a0, a1) = gr_table2(alpha, d);
            (a0 - a1 / r) / r
        } else {
            gr_basic_sum(J_MAX, J_MAX, J_MAX / r, None, alpha, d) / (gr_sz(0.0, None, alpha, d).powi(2) * J_MAX)
        }
    } else if alpha == 1 {
        // Table 3: the log-m normalisation of flicker PM
        let (b0, b1) = if d == 2 { (15.23, 12.0) } else { (47.8, 40.0) };
        let b = (b0 + b1 * m.ln()).powi(2);
        if j <= J_MAX {
            gr_basic_sum(j, m_terms, s, Some(m), 1, d) / (gr_sz(0.0, Some(m), 1, d).powi(2) * m_terms)
        } else if r > df + 1.0 {
            let (a0, a1) = gr_table2(alpha, d);
            (a0 - a1 / r) / (b * r)
        } else {
            gr_basic_sum(J_MAX, J_MAX, J_MAX / r, Some(J_MAX / r), 1, d) / (b * J_MAX)
        }
    } else {
        let c = binomial_2d(d);
        let c0 = c.first().copied().unwrap_or(1.0);
        let lags = c.iter().enumerate().skip(1).take_while(|(k, _)| (*k as f64) < r.ceil());
        (1.0 + 2.0 * lags.map(|(k, ck)| (1.0 - k as f64 / r) * ck * ck).sum::<f64>() / (c0 * c0)) / m_terms
    };
    1.0 / inv
}

/// Exact equivalent degrees of freedom 2E[V]²/Var[V] of the estimator `kind` at factor
/// `m` on sampled Gaussian noise whose d-th phase differences have finite memory: white PM
/// (iid phase), white FM (iid rate) and random-walk FM (rate a random walk of iid steps).
/// With z_i = Σ_k h_k x_{i+k} the M terms of the sum (h the weights of `kind`) and ρ
/// their autocorrelation, 1/EDF = Σ_{|l|<M} (1 − |l|/M) ρ(l)²/M: Greenhall & Riley
/// 2003 Eq. 10 summed over every lag, from the autocovariance of the samples rather
/// than of a continuous-time model (which misstates the EDF at small m). The phase
/// generalised autocovariance at integer lag k is δ_k, −|k| and |k|³ − |k|. Cost O(m²).
pub fn edf_sampled(kind: Kind, noise: NoiseType, np: usize, m: usize) -> f64 {
    let diff: &[f64] = if kind.order() == 2 { &[1.0, -2.0, 1.0] } else { &[1.0, -3.0, 3.0, -1.0] };
    let mut h = vec![0.0; kind.span(m) + 1];
    for i in 0..if kind == Kind::Modified { m } else { 1 } {
        for (k, c) in diff.iter().enumerate() {
            if let Some(v) = h.get_mut(i + k * m) {
                *v += c;
            }
        }
    }
    // autocorrelation of the weights, R(q) = Σ_i h_i h_{i+q}
    let rh: Vec<f64> = (0..h.len()).map(|q| h.iter().zip(h.iter().skip(q)).map(|(a, b)| a * b).sum()).collect();
    let s = |k: usize| -> f64 {
        let k = k as f64;
        match noise {
            NoiseType::WhitePm => f64::from(u8::from(k == 0.0)),
            NoiseType::WhiteFm => -k,
            _ => k * k * k - k,
        }
    };
    // autocovariance of the terms at lag l: Σ_q R(|q|) s(|l + q|)
    let gamma: Vec<f64> = (0..h.len())
        .map(|l| rh.iter().enumerate().map(|(q, r)| if q == 0 { r * s(l) } else { r * (s(l + q) + s(l.abs_diff(q))) }).sum())
        .collect();
    let m_terms = kind.terms(np, m) as f64;
    let g0 = gamma.first().copied().unwrap_or(1.0);
    let tail: f64 = gamma.iter().enumerate().skip(1).filter(|(l, _)| (*l as f64) < m_terms).map(|(l, g)| 2.0 * (1.0 - l as f64 / m_terms) * (g / g0).powi(2)).sum();
    m_terms / (1.0 + tail)
}

/// Result of the five-term fit σ²(τ) = Σ_{k=−2}^{2} A_k τ^k (Niu et al. 2025 Eq. 19).
#[derive(Debug, Clone, PartialEq)]
pub struct AllanFit {
    /// A₋₂, A₋₁, A₀, A₁, A₂ in (rate)²·s^k.
    pub coeffs: [f64; 5],
    /// Quantisation Q_q = √(A₋₂/3) (rate·s).
    pub quantization: f64,
    /// Angle random walk N = √A₋₁ (rate·√s); also the paper's SS (Eq. 20).
    pub arw: f64,
    /// Bias instability B = √(π A₀ / (2 ln 2)) (rate); also the paper's LS (Eq. 21).
    pub bias_instability: f64,
    /// Rate random walk K = √(3 A₁) (rate/√s).
    pub rrw: f64,
    /// Rate ramp R = √(2 A₂) (rate/s).
    pub ramp: f64,
    /// Number of Allan points used.
    pub points: usize,
}

impl AllanFit {
    /// The derived noise parameters by name (the fields after `coeffs`).
    pub fn parameters(&self) -> [(&'static str, f64); 5] {
        [("quantization", self.quantization), ("arw", self.arw), ("bias_instability", self.bias_instability), ("rrw", self.rrw), ("ramp", self.ramp)]
    }
}

/// Weighted non-negative least-squares fit of the five-term model to AVAR points (docs/departures.md#allan-fit):
/// weights 1/σ_j², σ_j = AVAR_j/√max(1, ⌊N/m_j⌋ − 1), columns normalised, Lawson–Hanson.
/// `terms` selects which of A₋₂…A₂ are free (the others are 0); only points with
/// `tau_min ≤ τ ≤ tau_max` and positive variance are used. `n_samples` is the record length.
pub fn fit(res: &AllanResult, n_samples: usize, terms: [bool; 5], tau_min: f64, tau_max: f64) -> Result<AllanFit> {
    let k = res.m.len();
    if res.tau.len() != k || res.var.len() != k {
        return Err(invalid("var", format!("m, tau and var must have equal lengths ({k}, {}, {})", res.tau.len(), res.var.len())));
    }
    if let Some(i) = res.m.iter().position(|&m| m == 0) {
        return Err(invalid_at("m", i, format!("averaging factor 0 at index {i}")));
    }
    check_finite("tau", &res.tau, 1)?;
    check_finite("var", &res.var, 1)?;
    // (τ_j, AVAR_j, σ_j) of the points used
    let sigma = |var: f64, m: usize| var / (((n_samples / m) as f64 - 1.0).max(1.0)).sqrt();
    let pts: Vec<(f64, f64, f64)> = (res.tau.iter().zip(&res.var).zip(&res.m))
        .filter(|((&t, &v), _)| t >= tau_min && t <= tau_max && v > 0.0)
        .map(|((&t, &v), &m)| (t, v, sigma(v, m)))
        .collect();
    let cols: Vec<i32> = (-2..=2).zip(terms).filter(|(_, on)| *on).map(|(k, _)| k).collect();
    if cols.is_empty() {
        return Err(invalid("terms", "no term selected"));
    }
    if pts.len() < cols.len() {
        return Err(invalid(
            "tau_min/tau_max",
            format!("{} Allan points with positive variance in [{tau_min}, {tau_max}] s; the fit needs at least {}", pts.len(), cols.len()),
        ));
    }
    let rows = pts.len();
    // column-major: one column per selected power of τ
    let mut a = DMatrix::from_iterator(rows, cols.len(), cols.iter().flat_map(|&k| pts.iter().map(move |&(t, _, s)| t.powi(k) / s)));
    let b = DVector::from_iterator(rows, pts.iter().map(|&(_, v, s)| v / s));
    let norms: Vec<f64> = (0..cols.len()).map(|c| a.column(c).norm()).collect();
    for (c, nrm) in norms.iter().enumerate() {
        a.column_mut(c).unscale_mut(*nrm);
    }
    let z = nnls(&a, &b)?;
    let mut coeffs = [0.0; 5];
    for ((&k, zc), nrm) in cols.iter().zip(z.iter()).zip(&norms) {
        if let Some(slot) = usize::try_from(k + 2).ok().and_then(|i| coeffs.get_mut(i)) {
            *slot = zc / nrm;
        }
    }
    if !coeffs.iter().all(|c| c.is_finite()) {
        return Err(NavError::Numerical("the Allan fit overflows the floating-point range (rescale the variances)".into()));
    }
    Ok(AllanFit {
        coeffs,
        quantization: (coeffs[0] / 3.0).sqrt(),
        arw: coeffs[1].sqrt(),
        bias_instability: (coeffs[2] * std::f64::consts::PI / (2.0 * std::f64::consts::LN_2)).sqrt(),
        rrw: (3.0 * coeffs[3]).sqrt(),
        ramp: (2.0 * coeffs[4]).sqrt(),
        points: rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn avar(y: &[f64], set: TauSet) -> AllanResult {
        variance(y, 1.0, DataType::Rate, Kind::Allan, &set).unwrap()
    }

    #[test]
    fn ramp_gives_m_squared_over_two() {
        // exact case: ω_k = k, N = 32 → σ²(m) = m²/2.
        let y: Vec<f64> = (0..32).map(|k| k as f64).collect();
        let r = avar(&y, TauSet::Octave);
        assert_eq!(r.m, vec![1, 2, 4, 8]);
        for (m, v) in r.m.iter().zip(&r.var) {
            assert!((v - (*m as f64).powi(2) / 2.0).abs() < 1e-12, "m={m} v={v}");
        }
    }

    #[test]
    fn alternating_sign() {
        // exact case: ±1, N = 16 → 2, 0, 2/9, 0 at m = 1…4.
        let y: Vec<f64> = (0..16).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let r = avar(&y, TauSet::List(vec![1, 2, 3, 4]));
        for (v, e) in r.var.iter().zip([2.0, 0.0, 2.0 / 9.0, 0.0]) {
            assert!((v - e).abs() < 1e-12);
        }
    }

    #[test]
    fn streaming_equals_batch_for_all_kinds() {
        let y: Vec<f64> = (0..1000).map(|k| ((k * 7919) % 1013) as f64 * 0.01 + (k as f64 * 0.1).sin()).collect();
        let ms = resolve_m(&TauSet::Octave, Kind::Hadamard, DataType::Rate, &[y.len() + 1]).unwrap();
        let mut s = AllanStream::new(&ms, 2.0, DataType::Rate).unwrap();
        for c in y.chunks(77) {
            s.update(c).unwrap();
        }
        for kind in [Kind::Allan, Kind::Modified, Kind::Hadamard] {
            let b = variance(&y, 2.0, DataType::Rate, kind, &TauSet::List(ms.clone())).unwrap();
            let st = s.result(kind).unwrap();
            assert_eq!(b.m, st.m);
            for (u, v) in b.var.iter().zip(&st.var) {
                assert!((u - v).abs() <= 1e-10 * u.abs(), "{kind:?}: {u} vs {v}");
            }
        }
    }

    /// NaN rate samples: the batch pools the gap-free stretches (each summed as its own
    /// record), the stream fed in any chunks gives the same, and a constant series gives 0.
    #[test]
    fn gaps_pool_the_stretches_in_batch_and_stream() {
        let mut y: Vec<f64> = (0..600).map(|k| ((k * 7919) % 1013) as f64 * 0.01 + (k as f64 * 0.3).sin()).collect();
        for i in [0, 1, 40, 41, 42, 300, 599] {
            y[i] = f64::NAN;
        }
        let ms = vec![1, 2, 8, 20];
        let mut s = AllanStream::new(&ms, 0.5, DataType::Rate).unwrap();
        for c in y.chunks(41) {
            s.update(c).unwrap();
        }
        let stretches: Vec<&[f64]> = y.split(|v| v.is_nan()).filter(|s| !s.is_empty()).collect();
        for kind in [Kind::Allan, Kind::Modified, Kind::Hadamard] {
            let b = variance(&y, 0.5, DataType::Rate, kind, &TauSet::List(ms.clone())).unwrap();
            assert_eq!(b.missing, 7);
            let (mut sum, mut n) = (vec![0.0; ms.len()], vec![0; ms.len()]);
            for part in &stretches {
                for (j, &m) in ms.iter().enumerate() {
                    let t = kind.terms(part.len() + 1, m);
                    if t >= MIN_TERMS {
                        let r = variance(part, 0.5, DataType::Rate, kind, &TauSet::List(vec![m])).unwrap();
                        sum[j] += r.var[0] * t as f64;
                    }
                    n[j] += t;
                }
            }
            assert_eq!(b.n, n, "{kind:?}");
            let st = s.result(kind).unwrap();
            assert_eq!((&st.n, st.missing), (&b.n, 7));
            for j in 0..ms.len() {
                // stretches with a single term are in b but not in the per-stretch sum
                if stretches.iter().all(|p| kind.terms(p.len() + 1, ms[j]) != 1) {
                    assert!((b.var[j] - sum[j] / n[j] as f64).abs() <= 1e-12 * b.var[j], "{kind:?} m = {}", ms[j]);
                }
                assert!((b.var[j] - st.var[j]).abs() <= 1e-10 * b.var[j], "{kind:?}: {} vs {}", b.var[j], st.var[j]);
            }
            let c = variance(&[2.5; 50], 1.0, DataType::Rate, kind, &TauSet::Octave).unwrap();
            assert!(c.var.iter().all(|&v| v == 0.0), "{kind:?}: {:?}", c.var);
        }
    }

    /// A factor without MIN_TERMS terms yet is the same error from the stream as from the
    /// batch, naming m at its index in the list given.
    #[test]
    fn stream_and_batch_reject_the_same_factor() {
        let y = [1.0, 3.0, 2.0, 5.0, 4.0];
        let mut s = AllanStream::new(&[4, 1, 2], 1.0, DataType::Rate).unwrap();
        s.update(&y).unwrap();
        let want = variance(&y, 1.0, DataType::Rate, Kind::Allan, &TauSet::List(vec![4, 1, 2])).unwrap_err();
        assert_eq!(s.result(Kind::Allan).unwrap_err(), want);
        assert!(matches!(&want, NavError::InvalidInput { field, index: Some(0), reason } if field == "m" && reason.contains("9 consecutive samples")), "{want}");
    }

    #[test]
    fn tau_too_large_is_rejected() {
        let y: Vec<f64> = (0..100).map(|k| (k as f64).sin()).collect();
        let e = variance(&y, 1.0, DataType::Rate, Kind::Allan, &TauSet::List(vec![1, 60])).unwrap_err();
        assert!(e.to_string().contains("index 1"), "{e}");
    }

    #[test]
    fn fit_recovers_exact_power_law() {
        // A noiseless AVAR curve built from known coefficients is fitted back exactly.
        let coeffs = [0.0, 2.0, 0.5, 1e-3, 0.0];
        let m: Vec<usize> = (0..12).map(|k| 1 << k).collect();
        let tau: Vec<f64> = m.iter().map(|&m| m as f64).collect();
        let var = tau.iter().map(|t| (0..5).map(|k| coeffs[k] * t.powi(k as i32 - 2)).sum()).collect();
        let r = AllanResult { m, tau, var, n: vec![10; 12], missing: 0 };
        let f = fit(&r, 100_000, [true; 5], 0.0, f64::INFINITY).unwrap();
        for k in 0..5 {
            assert!((f.coeffs[k] - coeffs[k]).abs() < 1e-9 * (1.0 + coeffs[k]), "{k}: {:?}", f.coeffs);
        }
    }

    #[test]
    fn sizes_from_input_are_checked() {
        let y: Vec<f64> = (0..64).map(|k| ((k * 37 % 11) as f64).sin()).collect();
        let field = |e: NavError| match e {
            NavError::InvalidInput { field, .. } | NavError::OutOfMemory { field, .. } => field,
            NavError::Numerical(m) => m,
        };
        assert_eq!(field(variance(&y, 1.0, DataType::Rate, Kind::Allan, &TauSet::List(vec![])).unwrap_err()), "m");
        for kind in [Kind::Allan, Kind::Modified, Kind::Hadamard] {
            assert_eq!(field(variance(&y, 1.0, DataType::Rate, kind, &TauSet::List(vec![1 << 63, 1])).unwrap_err()), "m");
        }
        assert_eq!(field(AllanStream::new(&[], 1.0, DataType::Rate).unwrap_err()), "m");
        assert_eq!(field(AllanStream::new(&[4, 1 << 62], 1.0, DataType::Rate).unwrap_err()), "m");
        assert_eq!(field(AllanStream::new(&[usize::MAX / 4], 1.0, DataType::Rate).unwrap_err()), "m");
        assert_eq!(field(edf(Kind::Modified, NoiseType::WhiteFm, 64, &[1, 0]).unwrap_err()), "m");
        let r = AllanResult { m: vec![1, 0], tau: vec![1.0, 2.0], var: vec![1.0, 0.5], n: vec![0, 0], missing: 0 };
        assert_eq!(field(fit(&r, 100, [true; 5], 0.0, 10.0).unwrap_err()), "m");
        assert_eq!(field(fit(&AllanResult { m: vec![1], ..r }, 100, [true; 5], 0.0, 10.0).unwrap_err()), "var");
    }

    #[test]
    fn edf_picks_the_formula_of_the_kind() {
        let e = edf(Kind::Allan, NoiseType::WhiteFm, 1001, &[1, 10]).unwrap();
        assert_eq!(e, vec![edf_overlapping_allan(NoiseType::WhiteFm, 1001, 1), edf_overlapping_allan(NoiseType::WhiteFm, 1001, 10)]);
        // (d+1)m ≤ 100: exact sampled EDF; beyond, and for flicker noise, Greenhall & Riley
        assert_eq!(edf(Kind::Hadamard, NoiseType::WhiteFm, 1001, &[25, 26]).unwrap(), vec![edf_sampled(Kind::Hadamard, NoiseType::WhiteFm, 1001, 25), edf_greenhall(Kind::Hadamard, NoiseType::WhiteFm, 1001, 26)]);
        assert_eq!(edf(Kind::Modified, NoiseType::FlickerFm, 1001, &[2]).unwrap(), vec![edf_greenhall(Kind::Modified, NoiseType::FlickerFm, 1001, 2)]);
    }

    /// Two closed forms: at m = 1 the Allan terms of random-walk FM are its iid steps
    /// (EDF = M), and white PM (iid phase) gives Greenhall & Riley's exact case 4.
    #[test]
    fn sampled_edf_meets_closed_forms() {
        assert!((edf_sampled(Kind::Allan, NoiseType::RandomWalkFm, 500, 1) - 498.0).abs() < 1e-9);
        for (np, m) in [(40, 3), (30, 9), (1000, 7)] {
            let (a, b) = (edf_sampled(Kind::Hadamard, NoiseType::WhitePm, np, m), edf_greenhall(Kind::Hadamard, NoiseType::WhitePm, np, m));
            assert!((a / b - 1.0).abs() < 1e-12, "{np} {m}: {a} vs {b}");
        }
    }
}
