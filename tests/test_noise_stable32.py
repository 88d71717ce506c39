"""Allan family against published reference results: the Stable32 runs and the NBS14
test suite that allantools' own test suite ships (tests/data/stable32/SOURCE.md), and
allantools itself.

atomnav returns variances; Stable32 and the NBS14 tables print deviations, so ``dev``
(the square root of ``var``) is compared. Rule for a printed value: it must equal
atomnav's deviation rounded to the printed digits, i.e. |dev/printed − 1| ≤ half a unit
of the last printed digit relative to the printed value. Against allantools (``oadev``,
``mdev``, ``ohdev``) the relative difference must be ≤ 1e-8. Stable32's ``#`` column
(the number of terms) must equal atomnav's ``n_terms``.
"""

import gzip
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest

from atomnav.noise import allan

allantools = pytest.importorskip("allantools")

DATA = Path(__file__).parent / "data" / "stable32"
PEERS = {"allan": "oadev", "modified": "mdev", "hadamard": "ohdev"}
PEER_RTOL = 1e-8


def _series(name: str) -> np.ndarray:
    """One number a line, '#' comments; ``.gz`` read transparently."""
    path = DATA / name
    with (gzip.open(path, "rt") if path.suffix == ".gz" else path.open()) as f:
        return np.array([float(line) for line in f if line.strip() and not line.startswith("#")])


def _phase_dat():
    return _series("PHASE.DAT"), "phase", 1.0


def _ocxo():
    # Stable32's header for these runs (file "ocxo_frequency.003": Average = 1.881550e-13,
    # Maximum = 2.905756e-10) is the fractional frequency (f − f̄)/f̄ of the counter
    # readings up to a constant 1.9e-13 that no deviation sees; dividing by the nominal
    # 10 MHz instead would scale every deviation by 1 + 1.3e-8.
    f = _series("ocxo_frequency.txt.gz")
    return (f - f.mean()) / f.mean(), "rate", 1.0


def _pink():
    # the Stable32 runs of the all-τ files used a data interval of 42 s (their Tau column)
    return _series("pink_frequency.txt.gz"), "rate", 42.0


def _pink_unit_interval():
    return _series("pink_frequency.txt.gz"), "rate", 1.0


def _stable32(name: str):
    """Rows (AF, n, printed deviation) of a Stable32 result table."""
    rows = []
    for line in (DATA / name).read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            af, _tau, n, _alpha, _lo, dev, _hi = line.split()
            rows.append((int(af), int(n), dev))
    return rows


def _half_unit(printed: str) -> float:
    """Half a unit of the last printed digit, relative to the printed value."""
    d = Decimal(printed)
    return float(Decimal(5).scaleb(d.as_tuple().exponent - 1) / abs(d))


def _check_printed(dev, printed, labels, what):
    """Every ``dev`` rounds to its ``printed`` value."""
    dev = np.asarray(dev, dtype=float)
    ref = np.array([float(p) for p in printed])
    rel = np.abs(dev / ref - 1)
    tol = np.array([_half_unit(p) for p in printed])
    bad = np.nonzero(rel > tol)[0]
    assert bad.size == 0, "; ".join(
        f"{what} at {labels[i]}: atomnav {dev[i]:.8e}, published {printed[i]}, relative error {rel[i]:.2e} > {tol[i]:.2e}" for i in bad[:5]
    )


def _check_peer(data, data_type, tau0, kind, m, dev, what):
    taus, devs, _, _ = getattr(allantools, PEERS[kind])(
        data, rate=1.0 / tau0, data_type="phase" if data_type == "phase" else "freq", taus=np.asarray(m, dtype=float) * tau0
    )
    np.testing.assert_allclose(taus, np.asarray(m) * tau0, rtol=1e-12, err_msg=what)
    np.testing.assert_allclose(dev, devs, rtol=PEER_RTOL, atol=0, err_msg=f"{what} vs allantools.{PEERS[kind]}")


OCXO_RATIO_RUN = (
    "Stable32's octave run of the OCXO (file 'ocxo_frequency.001', header Maximum = Minimum = "
    "Average = 1.000000e+00, i.e. the ratio f/10 MHz) differs from its all-τ run of the same "
    "record (file '.003', which atomnav matches at every τ, including these) by up to 1.8e-3 "
    "(AF = 1: 7.6143e-11 against 7.6106e-11): the input of that run, not the estimator; "
    "allantools' own test accepts these rows only at 2e-3"
)

# (data set loader, kind, Stable32 result file); every row of each file is checked
STABLE32 = [
    (_phase_dat, "allan", "phasedat_oadev_octave.txt"),
    (_phase_dat, "allan", "phasedat_oadev_all.txt"),
    (_phase_dat, "modified", "phasedat_mdev_octave.txt"),
    (_phase_dat, "modified", "phasedat_mdev_all.txt"),
    (_phase_dat, "hadamard", "phasedat_ohdev_octave.txt"),
    (_phase_dat, "hadamard", "phasedat_ohdev_all.txt"),
    (_ocxo, "allan", "ocxo_oadev_all.txt"),
    (_ocxo, "modified", "ocxo_mdev_all.txt"),
    (_ocxo, "hadamard", "ocxo_ohdev_all.txt"),
    (_ocxo, "allan", "ocxo_oadev_octave.txt"),
    (_ocxo, "modified", "ocxo_mdev_octave.txt"),
    (_ocxo, "hadamard", "ocxo_ohdev_octave.txt"),
    (_pink_unit_interval, "allan", "pink_oadev_octave.txt"),
    (_pink, "allan", "pink_oadev_all.txt"),
    (_pink, "modified", "pink_mdev_all.txt"),
    (_pink, "hadamard", "pink_ohdev_all.txt"),
]
DISAGREE = {f"ocxo_{PEERS[kind]}_octave.txt": OCXO_RATIO_RUN for kind in PEERS}
# single rows atomnav does not round to, (file, AF): reason
DISAGREE_ROWS = {
    ("ocxo_mdev_all.txt", 1994): (
        "atomnav's MDEV 6.99265006e-12 lies 7.9e-9 (relative) above the midpoint 6.99265e-12 "
        "between 6.9926e-12 (printed) and 6.9927e-12; allantools.mdev gives the same value to "
        "1e-13, so the estimator agrees and the difference is below the precision of the "
        "fractional-frequency file Stable32 read (rounding it to 6 significant digits moves "
        "this row to 6.9926496e-12)"
    ),
}


def _run(loader, kind, result):
    data, data_type, tau0 = loader()
    rows = _stable32(result)
    m = [r[0] for r in rows]
    table = allan.allan_variance(data, tau0, m=m, kind=kind, data_type=data_type)
    return data, data_type, tau0, rows, m, table


@pytest.mark.parametrize(
    ("loader", "kind", "result"),
    [pytest.param(*c, marks=pytest.mark.xfail(strict=True, reason=DISAGREE[c[2]])) if c[2] in DISAGREE else c for c in STABLE32],
)
def test_agrees_with_stable32(loader, kind, result):
    _, _, _, rows, m, table = _run(loader, kind, result)
    assert table["m"].tolist() == m
    assert table["n_terms"].tolist() == [r[1] for r in rows], f"{result}: number of terms"
    keep = [i for i, a in enumerate(m) if (result, a) not in DISAGREE_ROWS]
    _check_printed(table["dev"].to_numpy()[keep], [rows[i][2] for i in keep], [f"AF = {m[i]}" for i in keep], result)


@pytest.mark.parametrize(
    ("loader", "kind", "result", "af"),
    [
        pytest.param(loader, kind, result, af, marks=pytest.mark.xfail(strict=True, reason=DISAGREE_ROWS[(result, af)]))
        for loader, kind, result in STABLE32
        for f, af in DISAGREE_ROWS
        if f == result
    ],
)
def test_stable32_rows_atomnav_does_not_round_to(loader, kind, result, af):
    data, data_type, tau0 = loader()
    (printed,) = [r[2] for r in _stable32(result) if r[0] == af]
    table = allan.allan_variance(data, tau0, m=[af], kind=kind, data_type=data_type)
    _check_printed(table["dev"], [printed], [f"AF = {af}"], result)


@pytest.mark.parametrize(("loader", "kind", "result"), STABLE32)
def test_agrees_with_allantools_on_stable32_data(loader, kind, result):
    data, data_type, tau0, _, m, table = _run(loader, kind, result)
    _check_peer(data, data_type, tau0, kind, m, table["dev"].to_numpy(), result)


# NBS14 10-point set and its deviations at τ = 1, 2 s (Riley, NIST SP 1065 (2008),
# Table 31; as transcribed in allantools, tests/nbs14/test_nbs14_10point.py)
NBS14_PHASE = [0.00000, 103.11111, 123.22222, 157.33333, 166.44444, 48.55555, -96.33333, -2.22222, 111.88889, 0.00000]
NBS14_FREQ = [892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0]
NBS14_10 = {"allan": ["91.22945", "85.95287"], "modified": ["91.22945", "74.78849"], "hadamard": ["70.80607", "85.61487"]}

# NBS14 1000-point set (the 16807 · n mod 2³¹ − 1 generator seeded with 1234567890) and
# its deviations at τ = 1, 10, 100 s (Riley, NIST SP 1065 (2008), §12; as transcribed in
# allantools, tests/nbs14/test_nbs14_1000point.py)
NBS14_1000 = {
    "allan": ["2.922319e-01", "9.159953e-02", "3.241343e-02"],
    "modified": ["2.922319e-01", "6.172376e-02", "2.170921e-02"],
    "hadamard": ["2.943883e-01", "9.581083e-02", "3.237638e-02"],
}


def _nbs14_1000_freq() -> np.ndarray:
    n = [1234567890]
    for _ in range(999):
        n.append(16807 * n[-1] % 2147483647)
    assert n[1:4] == [395529916, 1209410747, 633705974]  # the first three printed in the handbook
    return np.array(n, dtype=float) / 2147483647


def _nbs14_cases():
    freq_1000 = _nbs14_1000_freq()
    phase_1000 = np.concatenate([[0.0], np.cumsum(freq_1000)])
    for kind in PEERS:
        yield pytest.param(np.array(NBS14_PHASE), "phase", [1, 2], NBS14_10[kind], kind, id=f"nbs14_10-phase-{kind}")
        yield pytest.param(np.array(NBS14_FREQ), "rate", [1, 2], NBS14_10[kind], kind, id=f"nbs14_10-freq-{kind}")
        yield pytest.param(phase_1000, "phase", [1, 10, 100], NBS14_1000[kind], kind, id=f"nbs14_1000-phase-{kind}")
        yield pytest.param(freq_1000, "rate", [1, 10, 100], NBS14_1000[kind], kind, id=f"nbs14_1000-freq-{kind}")


@pytest.mark.parametrize(("data", "data_type", "m", "published", "kind"), list(_nbs14_cases()))
def test_agrees_with_nbs14_tables(data, data_type, m, published, kind):
    table = allan.allan_variance(data, 1.0, m=m, kind=kind, data_type=data_type)
    _check_printed(table["dev"], published, [f"τ = {t} s" for t in m], f"NBS14 {kind} ({data_type})")
    _check_peer(data, data_type, 1.0, kind, m, table["dev"].to_numpy(), f"NBS14 {kind} ({data_type})")


def test_half_unit_rule():
    # the rule itself: 2.9223e-01 covers [0.292225, 0.292235]
    assert _half_unit("2.9223e-01") == pytest.approx(0.5e-5 / 0.29223, rel=1e-12)
    assert _half_unit("91.22945") == pytest.approx(0.5e-5 / 91.22945, rel=1e-12)
    _check_printed([0.2922349], ["2.9223e-01"], ["x"], "rule")
    with pytest.raises(AssertionError):
        _check_printed([0.2922351], ["2.9223e-01"], ["x"], "rule")
