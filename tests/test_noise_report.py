"""Baselines, the model-B pipeline against spec §4b.5, and the paper's claims over seeds
(spec §4b.4–5)."""

import numpy as np
import pytest

from atomnav.noise import allan, arma, baselines, filters, report, synth


@pytest.fixture(scope="module")
def cmp105():
    return report.compare(synth.model_b())


def test_model_b_pipeline_matches_spec_table(cmp105):
    f = cmp105.fit
    np.testing.assert_allclose([f.ar[0], f.ar[1], f.ma[0], f.sigma2], [0.0089, 0.0106, -0.9905, 0.016102], atol=6e-5)
    assert f.dw == pytest.approx(1.998, abs=1e-3)
    want = {
        "raw": (0.12752, 0.07652, 0.01504, 0.01088),
        "fixed KF": (0.09794, 0.06916, 0.01025, 0.02322),
        "adaptive KF (literal)": (0.09824, 0.06929, 0.01029, 0.02315),
        "adaptive KF (differenced)": (0.08132, 0.06341, 0.00707, 0.02818),
        "Sage-Husa": (0.11836, 0.07459, 0.01371, 0.01551),
        "LPF": (0.05763, 0.05572, 0.0, 0.02139),
        "WD": (0.03174, 0.03173, 0.0, 0.0),
    }
    t = cmp105.table
    for name, vals in want.items():
        np.testing.assert_allclose(t.loc[name, ["bs1_dph", "bs3_dph", "ss_dpsh", "ls_dph"]].to_numpy(float), vals, atol=1e-5, err_msg=name)
    assert t.loc["adaptive KF (differenced)", "ir_bs1_pct"] == pytest.approx(36.2, abs=0.1)
    assert t.loc["adaptive KF (differenced)", "ir_ss_pct"] == pytest.approx(53.0, abs=0.1)


def test_claims_reported_plainly(cmp105):
    c = cmp105.claims.set_index("claim")["holds"]
    assert c["adaptive KF better than fixed KF on bs1_dph"] and c["adaptive KF better than fixed KF on ss_dpsh"]
    # Not reproduced with the paper's stated settings (spec §4c): WD and LPF smooth more.
    assert not c["adaptive KF at least as good as WD on ss_dpsh"] and not c["adaptive KF better than LPF on bs1_dph"]
    assert not c["adaptive KF improves ls_dph over raw"]


def test_paper_tables_and_ratios():
    p = report.paper_tables()
    ir = allan.improvement_ratio(p.loc["raw", "bs_dph"], p.loc[["fixed KF", "adaptive KF"], "bs_dph"], absolute=True)
    np.testing.assert_allclose(ir, [7.96, 28.20], atol=0.01)
    assert np.isnan(p.loc["LPF", "bs_dph"]) and p.loc["WD", "bs_table4_misprint"] == 0.6970


def _kf_metrics(seed):
    w = synth.model_b(seed=seed)
    f = arma.fit_arma(w, (2, 1))
    m = filters.ArimaStateSpace.from_arma(f.ar, f.ma, f.sigma2)
    out = {"raw": w, "fixed": filters.kalman(w, m, record=False).omega_hat, "adaptive": filters.kalman(w, m, adaptive=True, record=False).omega_hat}
    return {k: (allan.bias(x), allan.bias_stability(x, 1), allan.bias_stability(x, 3), allan.ss_deg_per_sqrt_hour(allan.fit_allan(x, 52.0))) for k, x in out.items()}


def _adaptive_beats_fixed(seeds):
    wins = 0
    for s in seeds:
        r = _kf_metrics(s)
        for k in ("fixed", "adaptive"):
            assert abs(r[k][0] - r["raw"][0]) <= 0.001, (s, k, r[k][0] - r["raw"][0])
        wins += all(r["adaptive"][i] < r["fixed"][i] < r["raw"][i] for i in (1, 2, 3))
    return wins


def test_adaptive_beats_fixed_reduced():
    # Default run: seeds 1000–1002 of the 100-seed test below; all must win.
    assert _adaptive_beats_fixed(range(1000, 1003)) == 3


@pytest.mark.slow
def test_adaptive_beats_fixed_100_seeds():
    # Acceptance: ≥ 95 of 100 seeds (spec §4b.5 finds 100/100); bias kept within 0.001 °/h.
    assert _adaptive_beats_fixed(range(1000, 1100)) >= 95


def test_lowpass_response_at_cutoff():
    # Zero-phase Butterworth applies |H|² twice: amplitude 1/2 at f_c, ≈ 1 far below.
    tau0, fc = 52.0, 0.002
    t = np.arange(20000) * tau0
    for f, gain in [(fc, 0.5), (fc / 20, 1.0)]:
        y = baselines.butterworth_lowpass(np.sin(2 * np.pi * f * t), tau0, fc=fc)
        mid = slice(5000, 15000)
        amp = np.sqrt(2 * np.mean(y[mid] ** 2))
        assert amp == pytest.approx(gain, rel=2e-3), f
    z = baselines.butterworth_lowpass(np.ones(50) * 3.0, tau0, zero_phase=False)
    np.testing.assert_allclose(z, 3.0, rtol=1e-12)


def test_wavelet_removes_white_noise_keeps_smooth_signal():
    rng = np.random.default_rng(0)
    n = 4096
    noise = rng.normal(size=n)
    # Details are thresholded away; the kept level-5 approximation carries 2⁻⁵ of the
    # white-noise power (orthogonal transform).
    assert np.std(baselines.wavelet_denoise(noise)) == pytest.approx(2**-2.5, rel=0.1)
    smooth = np.sin(2 * np.pi * np.arange(n) / 2048)
    out = baselines.wavelet_denoise(smooth + 0.1 * noise)
    assert out.size == n and np.sqrt(np.mean((out - smooth) ** 2)) < 0.03


def test_baselines_keep_bias():
    w = synth.model_b()
    for y in (baselines.butterworth_lowpass(w, 52.0), baselines.wavelet_denoise(w)):
        assert abs(y.mean() - w.mean()) <= 0.001


@pytest.mark.slow
def test_reproduce_section_quick(tmp_path):
    from atomnav import reproduce

    t = reproduce.run(tmp_path, only=["noise_niu2025"], quick=True)
    assert (t["verdict"] != "FAIL").all()
    assert (tmp_path / "noise_niu2025_allan.png").exists() and (tmp_path / "noise_niu2025_psd.png").exists()
    assert (t["verdict"] == "not reproduced").any() and (t.loc[t["verdict"] == "not reproduced", "note"] != "").all()
