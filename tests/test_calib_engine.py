"""The calibration engine, independent of any physics: a toy family with known truth, the signal operators
against direct implementations, the statistics against closed forms."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from swiftfin.calibration import effects as op
from swiftfin.calibration.engine import (Calibrator, Context, Effect, Family, Param, acf, block_test,
                                effective_sample_fraction, effective_sample_size, get_family, heldout_f_test,
                                ljung_box)

# ------------------------------------------------------------------------------------------------ toy family
# y = a x + effects + white noise; the base model has one fitted coefficient a (like a drive's mass).


def toy_effects():
    return (
        Effect(name="offset", meaning="constant", fingerprint="constant residual",
               linear=(Param("offset", "-", -10, 10),), fingerprint_axis="position",
               columns_fn=lambda ctx, nl: np.ones(ctx.n)),
        Effect(name="lag", meaning="first-order lag of the input", fingerprint="phase lag",
               linear=(Param("gain", "-", 0.5, 5.0),),
               nonlinear=(Param("tau_s", "s", 1e-3, 1.0, scale="log", grid=20),),
               columns_fn=lambda ctx, nl: op.first_order(ctx.t, ctx.signals["input"], nl["tau_s"])
               - ctx.signals["input"]),
        Effect(name="cubic", meaning="hardening", fingerprint="x^3",
               linear=(Param("k3", "-", -100, 100),), fingerprint_axis="position",
               columns_fn=lambda ctx, nl: ctx.signals["input"] ** 3),
    )


def toy_context(seed=0, n=6000, lag=None, cubic=0.0, offset=0.0, extra=None, noise=0.01, a=2.0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.01
    ph = rng.uniform(0, 2 * np.pi, 3)
    x = 0.8 * np.sin(0.7 * t + ph[0]) + 0.4 * np.sin(2.3 * t + ph[1]) + 0.2 * np.sin(6.1 * t + ph[2])
    xs = x if lag is None else op.first_order(t, x, lag)
    y = a * xs + cubic * x**3 + offset + rng.normal(0, noise, n)
    if extra is not None:
        y = y + extra(t, x)
    v = np.gradient(x, t)
    return Context(t, y, np.zeros(n), x[:, None], {"input": x, "velocity": v, "position": x}, "toy")


TOY = Family(name="toy", description="toy", columns=(), target="y", target_unit="-", base_terms=("a x",),
             effects=toy_effects(), load=lambda *a, **k: None, base_coef_names=("a",))


def names(cal):
    return [e.name for e in cal.added_effects_]


def test_no_effect_adds_nothing():
    cal = Calibrator(TOY).fit(toy_context(1))
    assert names(cal) == []
    assert cal.final_["residual_white"] and not cal.unexplained_structure_
    assert cal.baseline_["coef_final"]["a"]["value"] == pytest.approx(2.0, abs=3 * cal.baseline_["coef_final"]["a"]["std"] + 1e-9)
    assert cal.baseline_["rmse_holdout"] == pytest.approx(0.01, rel=0.1)


def test_lag_found_and_recovered_within_uncertainty():
    cal = Calibrator(TOY).fit(toy_context(2, lag=0.05))
    assert names(cal) == ["lag"]
    fe = cal.added_effects_[0]
    assert abs(fe.values["tau_s"] - 0.05) < 3 * fe.stds["tau_s"] + 1e-12
    # y = a lag(x) = a x + a (lag(x) - x): the gain equals the base coefficient
    assert abs(fe.values["gain"] - 2.0) < 3 * fe.stds["gain"]
    assert fe.rmse_holdout_after == pytest.approx(0.01, rel=0.1)
    assert fe.confidence == "high"


def test_two_effects_both_found():
    cal = Calibrator(TOY).fit(toy_context(3, cubic=0.3, offset=0.05))
    assert sorted(names(cal)) == ["cubic", "offset"]
    vals = {k: (v, fe.stds[k]) for fe in cal.added_effects_ for k, v in fe.values.items()}
    assert abs(vals["k3"][0] - 0.3) < 3 * vals["k3"][1]
    assert abs(vals["offset"][0] - 0.05) < 3 * vals["offset"][1]
    assert not cal.unexplained_structure_


def test_structure_outside_library_flagged():
    """A periodic term in position no candidate can express: nothing claimed with confidence, structure flagged."""
    cal = Calibrator(TOY).fit(toy_context(4, extra=lambda t, x: 0.05 * np.sin(25 * x)))
    assert cal.unexplained_structure_
    assert all(fe.confidence == "low" for fe in cal.added_effects_), names(cal)


def test_uncertainty_coverage():
    """Over 20 seeds the 2-sigma interval of tau covers the truth about 95 % of the time (>= 16 of 20)."""
    hits = 0
    for seed in range(20):
        cal = Calibrator(TOY, candidates=["lag"]).fit(toy_context(100 + seed, n=3000, lag=0.08, noise=0.02))
        fe = cal.added_effects_[0]
        hits += abs(fe.values["tau_s"] - 0.08) < 2 * fe.stds["tau_s"]
    assert hits >= 16, hits


def test_holdout_blocks_contiguous_not_random():
    ctx = toy_context(5, n=10000)
    cal = Calibrator(TOY, holdout_fraction=0.3, n_blocks=10)
    mask = cal._holdout_mask(ctx)
    assert mask.mean() == pytest.approx(0.3, abs=0.01)
    runs = np.flatnonzero(np.diff(mask.astype(int)) != 0)
    assert len(runs) == 6                       # three separate contiguous blocks, none at the ends
    assert not mask[:1000].any() and not mask[-1000:].any()


def test_separate_holdout_run():
    tr, ho = toy_context(6, lag=0.05), toy_context(7, lag=0.05)
    cal = Calibrator(TOY).fit(tr, ho)
    assert names(cal) == ["lag"]
    assert cal.n_holdout_ == ho.n and cal.n_train_ == tr.n
    assert "separate run" in cal.report_dict()["holdout"]


def test_report_dict_fields():
    cal = Calibrator(TOY).fit(toy_context(8, cubic=0.3))
    rep = cal.report_dict()
    for key in ("family", "n_samples", "baseline", "added_effects", "final", "unexplained_structure", "units"):
        assert key in rep
    assert set(rep["baseline"]) >= {"terms", "rmse_train", "rmse_holdout"}
    e = rep["added_effects"][0]
    assert set(e) >= {"name", "params", "rmse_holdout_before", "rmse_holdout_after", "evidence"}
    assert set(e["params"]["k3"]) == {"value", "std", "unit"}
    assert set(rep["final"]) >= {"rmse_train", "rmse_holdout", "residual_white"}


def test_get_family():
    assert get_family("joint").name == "joint"
    with pytest.raises(KeyError, match="known:"):
        get_family("nope")


# ------------------------------------------------------------------------------------------------ operators


def naive_play(x, h):
    y = np.empty_like(x)
    y[0] = x[0]
    for k in range(1, x.size):
        y[k] = min(max(y[k - 1], x[k] - h), x[k] + h)
    return y


def test_play_matches_definition():
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.normal(0, 1, 3000))
    x[500:520] = x[499]                     # flat stretch
    for h in (0.0, 0.5, 3.0, 50.0):
        assert np.allclose(op.play(x, h), naive_play(x, h), atol=1e-12)


def test_second_order_matches_lsim():
    t = np.arange(0, 2, 1e-3)
    x = np.sin(2 * np.pi * 3 * t) + 0.5 * np.sin(2 * np.pi * 11 * t)
    t1, t2 = 2e-3, 1e-4
    _, ref, _ = signal.lsim(([1.0], [t2, t1, 1.0]), x, t, X0=None)
    y = op.second_order(t, x, t1, t2)
    # lsim starts at rest at 0 and x[0] = 0: same initial condition
    assert np.max(np.abs(y - ref)) < 2e-3 * np.max(np.abs(x))
    # steady state of a step = the input (unit DC gain), and equilibrium start
    step = np.ones(100)
    assert np.allclose(op.second_order(t[:100], step, t1, t2), 1.0)


def test_delay_and_travel():
    t = np.arange(0, 1, 1e-3)
    x = 3.0 * t
    assert np.allclose(op.delay(t, x, 0.0125)[20:], 3.0 * (t[20:] - 0.0125))
    assert op.travel(np.array([0.0, 1.0, -1.0, 0.5]))[-1] == pytest.approx(4.5)


def test_threshold_crossings_and_ramps():
    t = np.arange(0, 1, 0.01)
    a = np.where(t < 0.505, 0.0, 10.0) * np.sin(2 * np.pi * t)   # one entry around t = 0.505 (a < 0 there)
    a = np.sin(2 * np.pi * t) * 10
    times, signs = op.threshold_crossings(t, a, 5.0)
    # |10 sin(2 pi t)| = 5 at t = 1/12 and 7/12 (rising), interpolated between samples
    assert np.allclose(times, [1 / 12, 7 / 12], atol=2e-3)
    assert list(signs) == [1.0, -1.0]
    r = op.ramped_steps(t, times, signs, 0.1)
    assert r[0] == 0 and r[-1] == 0 and r[50] == pytest.approx(1.0)
    assert 0 < r[12] < 1


# ------------------------------------------------------------------------------------------------ statistics


def test_ljung_box_and_neff():
    rng = np.random.default_rng(1)
    w = rng.normal(size=20000)
    q, p = ljung_box(w, 20)
    assert p > 1e-3 and q == pytest.approx(20, abs=4 * math.sqrt(40))
    ar = signal.lfilter([1.0], [1.0, -0.5], w)
    assert ljung_box(ar, 20)[1] < 1e-12
    assert acf(ar, 3)[1] == pytest.approx(0.5, abs=0.03)
    # n_eff / n of AR(1) with rho = 0.5 is (1 - rho) / (1 + rho) = 1/3 (sum truncated: slightly above)
    assert effective_sample_fraction(ar) == pytest.approx(1 / 3, rel=0.15)
    assert effective_sample_fraction(w) == pytest.approx(1.0, abs=0.05)


def test_heldout_f_test():
    rng = np.random.default_rng(2)
    e = rng.normal(size=5000)
    assert heldout_f_test(e, e, 1) == 1.0
    assert heldout_f_test(1.2 * e, e, 1) < 1e-12
    assert heldout_f_test(1.0005 * e, e, 1) > 0.01


def test_heldout_f_test_per_series_is_order_free():
    """n_eff is summed over series, each from its own autocorrelation: the closed form for AR(1),
    n (1 - rho) / (1 + rho), for the correlated series, n for the white ones; stacking order changes nothing."""
    rng = np.random.default_rng(0)
    n, rho = 600, 0.95
    white1, white2 = rng.normal(size=n), rng.normal(size=n)
    ar = signal.lfilter([1.0], [1.0, -rho], rng.normal(size=n))
    ar /= ar.std()
    groups = np.repeat([0, 1, 2], n)
    fwd, rev = np.r_[white1, ar, white2], np.r_[white2, ar, white1]
    expected = 2 * n + n * (1 - rho) / (1 + rho)
    assert effective_sample_size(fwd, groups) == pytest.approx(expected, rel=0.05)
    assert effective_sample_size(fwd, groups) == pytest.approx(effective_sample_size(rev, groups), rel=1e-12)
    p_f = heldout_f_test(1.05 * fwd, fwd, 1, groups)
    p_r = heldout_f_test(1.05 * rev, rev, 1, groups)
    assert p_f == pytest.approx(p_r, rel=1e-9)
    assert block_test(1.05 * fwd, fwd, 40, groups) == pytest.approx(block_test(1.05 * rev, rev, 40, groups), rel=1e-9)
    # the F statistic by hand: ((1.05^2 - 1) SSE / 1) / (SSE / n_eff) on (1, n_eff)
    from scipy import stats
    ne = effective_sample_size(fwd, groups)
    assert p_f == pytest.approx(stats.f.sf((1.05**2 - 1) * ne, 1, ne), rel=1e-9)


def test_criterion_is_the_familys_unless_overridden():
    strict = Family(name="toy2", description="toy", columns=(), target="y", target_unit="-", base_terms=("a x",),
                    effects=toy_effects(), load=lambda *a, **k: None, base_coef_names=("a",),
                    alpha=0.2, min_relative_drop=0.5)
    assert (Calibrator(strict).alpha, Calibrator(strict).min_relative_drop) == (0.2, 0.5)
    assert (Calibrator(TOY).alpha, Calibrator(TOY).min_relative_drop) == (1e-3, 0.10)
    assert Calibrator(strict, alpha=0.01, min_relative_drop=0.0).alpha == 0.01
    # a 50 % margin refuses a cubic term that lowers the held-out error by 24 %; the default 10 % takes it
    ctx = toy_context(4, cubic=0.05, noise=0.02)
    assert names(Calibrator(TOY).fit(ctx)) == ["cubic"]
    assert names(Calibrator(strict).fit(ctx)) == []
    with pytest.raises(ValueError, match="alpha"):
        Calibrator(TOY, alpha=1.0)
    with pytest.raises(ValueError, match="min_relative_drop"):
        Calibrator(TOY, min_relative_drop=-0.1)


def test_forced_effects_skip_selection():
    cal = Calibrator(TOY, forced_effects=("offset",)).fit(toy_context(5, lag=0.05))
    assert names(cal) == ["offset"]                    # fitted although useless; the lag is not looked for
    with pytest.raises(KeyError):
        Calibrator(TOY, forced_effects=("nonsense",))
