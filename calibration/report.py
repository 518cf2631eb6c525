"""Fit reports: ``fit_report.json`` (machine-readable) and ``fit_report.md`` with PNG plots (human).

Plots (matplotlib, Agg backend, written next to the report):

* ``measured_vs_model.png``  measured, base model and final model on a held-out window, and the residual before
  and after the added effects;
* ``residual_vs_<effect>.png`` for each added effect: the residual *before* that effect was added against the
  effect's fingerprint axis (velocity, acceleration, position, travel or time), with its binned mean and the
  effect's fitted contribution on top: the picture that says why that effect was chosen;
* ``residual_spectrum.png``  spectra of the residual before and after over the shown series' whole record (Welch,
  from 4 / its span, below the slowest motion), and the held-out residual's autocorrelation.

Every number the markdown prints comes from :meth:`calibration.engine.Calibrator.report_dict` (the JSON).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from swiftfin.calibration.model import Context
from swiftfin.calibration.selection import Calibrator
from swiftfin.core.jsonable import jsonable


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _holdout_view(cal: Calibrator) -> tuple[Context, np.ndarray]:
    """The part holding held-out rows, and its holdout mask."""
    for p in cal._parts_full:
        if p.hold.any():
            return p.ctx, p.hold
    p = cal._parts_full[0]
    return p.ctx, np.ones(p.ctx.n, bool)


def noise_floor(cal: Calibrator) -> float:
    """What no model can remove from the held-out error [target unit]: the standard deviation of the final
    held-out residual's sample-to-sample differences over sqrt(2), which keeps white noise (sensor noise, the
    encoder's steps) and drops anything slower than a few samples; series and held-out blocks are not
    differenced across their joins."""
    ctx, hold = _holdout_view(cal)
    e = ctx.y - cal.predict(ctx)
    series = ctx.series if ctx.series is not None else np.zeros(ctx.n, int)
    ok = hold[1:] & hold[:-1] & (series[1:] == series[:-1])
    d = np.diff(e)[ok]
    return float(np.std(d) / np.sqrt(2.0)) if d.size > 2 else float("nan")


def _shown_rows(cal: Calibrator, ctx: Context, hold: np.ndarray) -> np.ndarray:
    """Held-out rows of the series the family wants shown (:attr:`Family.plot_rows_fn`, e.g. the body's tail
    tip); all held-out rows when the family does not choose or its series has none held out."""
    fn = cal.family.plot_rows_fn
    if fn is None:
        return hold
    mine = hold & np.asarray(fn(ctx), bool)
    return mine if mine.any() else hold


def _first_block(mask: np.ndarray, max_len: int) -> np.ndarray:
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return idx
    br = np.flatnonzero(np.diff(idx) != 1)
    end = br[0] + 1 if br.size else idx.size
    return idx[: min(end, max_len)]


def plot_measured_vs_model(cal: Calibrator, path: Path, window_s: float = 3.0) -> None:
    plt = _plt()
    ctx, hold = _holdout_view(cal)
    dt = float(np.median(np.diff(ctx.t)))
    rows = _first_block(_shown_rows(cal, ctx, hold), int(window_s / dt))
    fam = cal.family
    unit = cal.target_unit_
    base = cal.predict(ctx, 0)
    final = cal.predict(ctx)
    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True, layout="constrained")
    t = ctx.t[rows]
    ax[0].plot(t, ctx.y[rows], ".", ms=2, color="0.4", label="measured")
    ax[0].plot(t, base[rows], "-", lw=1, color="tab:red", label="base model")
    ax[0].plot(t, final[rows], "-", lw=1, color="tab:blue", label="final model")
    shown = ""
    if fam.plot_rows_fn is not None and ctx.series is not None and rows.size:
        shown = f", series {int(ctx.series[rows[0]])}"
    ax[0].set_ylabel(f"{fam.target} [{unit}]")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[0].set_title(f"{fam.name}: held-out data ({ctx.source}{shown})", fontsize=9)
    ax[1].plot(t, (ctx.y - base)[rows], lw=0.8, color="tab:red", label=f"residual, base (RMSE {cal.baseline_['rmse_holdout']:.3g})")
    ax[1].plot(t, (ctx.y - final)[rows], lw=0.8, color="tab:blue", label=f"residual, final (RMSE {cal.final_['rmse_holdout']:.3g})")
    ax[1].set_xlabel("time [s]")
    ax[1].set_ylabel(f"residual [{unit}]")
    ax[1].legend(loc="upper right", fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_fingerprint(cal: Calibrator, j: int, path: Path, max_points: int = 20000) -> None:
    """Residual before effect j against the effect's fingerprint axis, binned mean, fitted contribution."""
    plt = _plt()
    ctx, hold = _holdout_view(cal)
    eff, nl = cal.effects_[j]
    axis = eff.fingerprint_axis if eff.fingerprint_axis in ctx.signals or eff.fingerprint_axis == "time" else "velocity"
    x = ctx.t if axis == "time" and "time" not in ctx.signals else ctx.signals[axis]
    r_before = cal.residual(ctx, j)
    contrib = cal.predict(ctx, j + 1) - cal.predict(ctx, j)
    rows = np.flatnonzero(hold) if hold.any() else np.arange(ctx.n)
    if rows.size > max_points:
        rows = rows[:: int(math.ceil(rows.size / max_points))]
    fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
    ax.plot(x[rows], r_before[rows], ".", ms=1.5, alpha=0.35, color="0.45", label="residual before (held out)")
    order = np.argsort(x[rows])
    xs, rs, cs = x[rows][order], r_before[rows][order], contrib[rows][order]
    nb = 30
    edges = np.unique(np.quantile(xs, np.linspace(0, 1, nb + 1)))
    if edges.size > 2:
        b = np.clip(np.searchsorted(edges, xs, side="right") - 1, 0, edges.size - 2)
        cnt = np.maximum(np.bincount(b, minlength=edges.size - 1), 1)
        mid = 0.5 * (edges[1:] + edges[:-1])
        ax.plot(mid, np.bincount(b, rs, minlength=edges.size - 1) / cnt, "o-", ms=3, color="k", lw=1,
                label="binned mean of residual")
        ax.plot(mid, np.bincount(b, cs, minlength=edges.size - 1) / cnt, "s--", ms=3, color="tab:orange", lw=1,
                label=f"fitted {eff.name} (binned)")
    units = cal.report_units()
    ax.set_xlabel(f"{axis} [{units.get(axis, units.get('time', 's') if axis == 'time' else '-')}]")
    ax.set_ylabel(f"residual [{cal.target_unit_}]")
    ax.set_title(f"{eff.name}: {eff.fingerprint}", fontsize=8, wrap=True)
    ax.legend(fontsize=7, loc="best")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def residual_psd(t: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One-sided power spectral density of ``r`` over contiguous rows at times ``t`` [unit^2/Hz]: Welch's average
    of four-times-overlapping Hann segments a quarter of the rows long, so the first frequency above zero is
    4 / the span and the spectrum starts below the record's slowest motion (the bench command's 0.37-0.5 Hz over a
    40 s log, a tail beat over a few of its periods). The zero-frequency bin is dropped."""
    from scipy import signal
    t = np.asarray(t, float)
    r = np.asarray(r, float)
    dt = float(np.median(np.diff(t)))
    f, p = signal.welch(r - r.mean(), fs=1.0 / dt, nperseg=max(16, r.size // 4))
    return f[1:], p[1:]


def _series_rows(cal: Calibrator, ctx: Context, shown: np.ndarray) -> np.ndarray:
    """Every row (training and held-out) of the series the report shows, as one contiguous run."""
    idx = np.flatnonzero(shown)
    if ctx.series is None or idx.size == 0:
        return np.arange(ctx.n)
    return _first_block(ctx.series == ctx.series[idx[0]], ctx.n)


def plot_spectrum(cal: Calibrator, path: Path) -> None:
    plt = _plt()
    ctx, hold = _holdout_view(cal)
    shown = _shown_rows(cal, ctx, hold)
    every = _series_rows(cal, ctx, shown)            # the whole record of the shown series: no gap to bridge
    rows = _first_block(shown, ctx.n)                # held-out rows, contiguous, for the autocorrelation
    dt = float(np.median(np.diff(ctx.t[rows]))) if rows.size > 1 else float(np.median(np.diff(ctx.t)))
    fig, ax = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
    for k, (lab, col) in enumerate((("base model", "tab:red"), ("final model", "tab:blue"))):
        res = cal.residual(ctx, 0 if k == 0 else None)
        r = res[rows]
        if r.size < 16 or every.size < 64:
            continue
        f, pxx = residual_psd(ctx.t[every], res[every])
        ax[0].loglog(f, pxx, color=col, lw=1, label=f"residual, {lab}")
        from swiftfin.calibration.statistics import acf
        a = acf(r, min(200, r.size // 3))
        ax[1].plot(np.arange(a.size) * dt, a, color=col, lw=1, label=lab)
    ax[0].set_title("whole record (training and held-out rows)", fontsize=8)
    ax[1].set_title("held-out rows", fontsize=8)
    ax[0].set_xlabel("frequency [Hz]")
    ax[0].set_ylabel(f"PSD [{cal.target_unit_}^2/Hz]")
    ax[0].legend(fontsize=8)
    n = rows.size
    ax[1].axhline(2.58 / math.sqrt(max(n, 1)), color="0.5", ls=":", lw=0.8)
    ax[1].axhline(-2.58 / math.sqrt(max(n, 1)), color="0.5", ls=":", lw=0.8, label="99 % white-noise band")
    ax[1].set_xlabel("lag [s]")
    ax[1].set_ylabel("autocorrelation [-]")
    ax[1].legend(fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _fmt(v, std=None, unit=""):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    s = f"{v:.4g}"
    if std is not None and isinstance(std, float) and math.isfinite(std):
        s += f" ± {std:.2g}"
    return s + (f" {unit}" if unit and unit != "-" else "")


def _num(x) -> float:
    return float("nan") if x is None else float(x)


def markdown(rep: dict, plots: dict[str, str]) -> str:
    u = rep["units"]["target"]
    lines = [f"# Fit report: `{rep['family']}`", "", rep.get("description", ""), ""]
    lines += [f"- data: {rep.get('data', '')}", f"- held out: {rep.get('holdout', '')}",
              f"- samples: {rep['n_samples']} ({rep['n_train']} train, {rep['n_holdout']} held out)", ""]
    for note in rep.get("notes", []):
        lines.append(f"> warning: {note}")
    lines += ["## Summary", "", "| model | RMSE train | RMSE held out |", "|---|---|---|",
              f"| base ({'; '.join(rep['baseline']['terms'])}) | {_fmt(rep['baseline']['rmse_train'])} {u} | "
              f"{_fmt(rep['baseline']['rmse_holdout'])} {u} |"]
    for e in rep["added_effects"]:
        lines.append(f"| + {e['name']} | {_fmt(e['rmse_train_after'])} {u} | {_fmt(e['rmse_holdout_after'])} {u} |")
    lines.append("")
    fin = rep["final"]
    nf = rep.get("noise_floor")
    if nf is not None and math.isfinite(nf) and nf > 0:
        lines += [f"Noise floor {_fmt(nf)} {u} (the held-out residual's sample-to-sample differences / sqrt 2: what "
                  f"no model removes); the final held-out RMSE is {fin['rmse_holdout'] / nf:.2f} x it.", ""]
    lines.append(f"Final residual {'is white' if fin['residual_white'] else 'still has structure'} "
                 f"(structure score {_num(fin['diagnosis']['structure_score']):.3f}, threshold "
                 f"{rep['criterion']['whiteness_threshold']}).")
    if rep["unexplained_structure"]:
        lines.append("")
        lines.append("**Unexplained structure:** the final residual still has structure that no candidate effect "
                     "in the library explains with plausible parameters. The model lacks something not in the "
                     "library (or an effect's timing/shape is only approximate); do not trust the fit further than "
                     "the listed effects.")
    hint = rep.get("unvalidated_hint")
    if hint:
        lines += ["", f"Lead (not a finding): on the training rows **{hint['name']}** would lower the RMSE from "
                      f"{_fmt(hint['rmse_train_now'])} to {_fmt(hint['rmse_train'])} {u}, but it was not added: "
                      f"{hint['why_not_added']}."]
    if not rep["added_effects"]:
        lines += ["", "No effect was added: " + ("the base model already explains the data to the noise level."
                                                 if not rep["unexplained_structure"] else
                                                 "no candidate lowered the held-out error significantly with "
                                                 "physically plausible parameters.")]
    lines += ["", "## Added effects (in the order found)", ""]
    for e in rep["added_effects"]:
        lines.append(f"### {e['name']}  ({e['confidence']} confidence)")
        lines.append("")
        if e.get("meaning"):
            lines += [f"*Physics:* {e['meaning']}", "", f"*Fingerprint:* {e['fingerprint']}", ""]
        lines.append(f"Held-out RMSE {_fmt(e['rmse_holdout_before'])} -> {_fmt(e['rmse_holdout_after'])} {u} "
                     f"(drop {100 * _num(e['evidence'].get('relative_drop_full')):.1f} %, "
                     f"p = {_num(e['evidence'].get('p_value_full')):.2g}).")
        lines += ["", "| parameter | value ± 1 sigma |", "|---|---|"]
        for k, v in e["params"].items():
            lines.append(f"| {k} | {_fmt(v['value'], v['std'], v['unit'])} |")
        for k, v in e.get("physical", {}).items():
            lines.append(f"| {k} (derived) | {_fmt(v['value'], v['std'], v['unit'])} |")
        lines.append("")
        if e.get("twins_outside"):
            lines += [f"*Outside the library, the same fingerprint:* {e['twins_outside']}.", ""]
        if e["evidence"].get("confidence_capped"):
            lines += [f"Confidence capped at {e['confidence']}: {e['evidence']['confidence_capped']}.", ""]
        if e["indistinguishable_from"]:
            lines += [f"The data cannot tell this effect from: **{', '.join(e['indistinguishable_from'])}** "
                      f"(held-out errors not significantly different). Treat the name as one of these.", ""]
        if e["name"] in plots:
            lines += [f"![{e['name']}]({plots[e['name']]})", ""]
    removed = [s for s in rep.get("steps", []) if str(s.get("decision", "")).startswith("remove ")]
    if removed:
        lines += ["## Effects removed again (backward pruning)", ""]
        for s in removed:
            lines.append(f"- **{s['decision'][7:]}**: given the effects found after it, it lowered the held-out "
                         f"error by only {100 * _num(s.get('relative_drop_given_others')):.1f} % "
                         f"(p = {_num(s.get('p_value')):.2g}); it stood in for one of them."
                         + (f" Implausible: {'; '.join(s['plausibility'])}." if s.get("plausibility") else ""))
        lines.append("")
    lines += ["## Plots", ""]
    for key in ("measured_vs_model", "residual_spectrum"):
        if key in plots:
            lines += [f"![{key}]({plots[key]})", ""]
    crit = rep["criterion"]
    lines += ["## Method", "",
              f"Forward selection with backward pruning. An effect is added when it lowers the held-out RMSE by more "
              f"than {100 * crit['min_relative_drop']:.0f} % with p < {crit['alpha']:g} ({crit['test']}) and "
              f"physically plausible parameters; selection stops when the residual's structure score falls below "
              f"{crit['whiteness_threshold']} or nothing qualifies. Held-out data: {rep.get('holdout', '')}. "
              f"Uncertainties: 1 sigma from the Jacobian and the residual variance, inflated for autocorrelation "
              f"(n / n_eff); thresholds from the profile.", ""]
    if rep.get("equivalent_effects"):
        lines += ["Effects the physics makes look alike in this data: " +
                  "; ".join(" ~ ".join(g) for g in rep["equivalent_effects"]) + ".", ""]
    d0 = rep["baseline_diagnosis"]
    lines += ["## Residual diagnostics (held out)", "", "| | base | final |", "|---|---|---|"]
    for k in ("rmse", "mean_fraction", "ar_predictable", "velocity_binned", "position_binned", "input_xcorr_max",
              "input_xcorr_lag_s", "ljung_box_p", "structure_score", "structure_score_train"):
        lines.append(f"| {k} | {_fmt(d0.get(k))} | {_fmt(fin['diagnosis'].get(k))} |")
    lines.append("")
    lines.append(f"Units: {', '.join(f'{k} [{v}]' for k, v in rep['units'].items())}.")
    return "\n".join(lines) + "\n"


def write_report(cal: Calibrator, out_dir: str | Path, *, data: str = "", holdout: str = "",
                 notes: list[str] | None = None, plots: bool = True, extra: dict | None = None,
                 extra_markdown: str = "") -> dict:
    """Write ``fit_report.json``, ``fit_report.md`` and the PNGs into ``out_dir``; return the JSON content.
    ``extra``: more top-level entries of the JSON (e.g. the joint's replay in MuJoCo, calibration.replay), and
    ``extra_markdown`` their section of the markdown."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rep = cal.report_dict()
    rep["noise_floor"] = noise_floor(cal)
    rep["data"] = data
    rep["holdout"] = holdout or rep.get("holdout", "")
    rep["notes"] = list(notes or [])
    for e in rep["added_effects"]:
        eff = cal.family.effect(e["name"])
        e["meaning"] = eff.meaning
        e["fingerprint"] = eff.fingerprint
        e["twins_outside"] = eff.twins_outside
    files: dict[str, str] = {}
    if plots:
        plot_measured_vs_model(cal, out / "measured_vs_model.png")
        files["measured_vs_model"] = "measured_vs_model.png"
        plot_spectrum(cal, out / "residual_spectrum.png")
        files["residual_spectrum"] = "residual_spectrum.png"
        for j, (eff, _) in enumerate(cal.effects_):
            name = f"residual_vs_{eff.name}.png"
            plot_fingerprint(cal, j, out / name)
            files[eff.name] = name
    rep["plots"] = files
    rep = jsonable(rep)
    if extra:
        rep.update(jsonable(extra))
    (out / "fit_report.json").write_text(json.dumps(rep, indent=2, allow_nan=False))
    (out / "fit_report.md").write_text(markdown(rep, files) + ("\n" + extra_markdown if extra_markdown else ""))
    return rep
