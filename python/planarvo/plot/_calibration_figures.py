"""The calibration figures: each parameter's estimate with its sigmas over the whole drive and
over windows of it, and the graph's residuals per motion pair."""
from __future__ import annotations

import math
from typing import List, Optional, Sequence

import numpy as np

from . import _style as S
from ._calibration_data import CalibrationData
from ._io import ExtrinsicsFile

# (name, index in the graph's (x, y, scale, yaw), index in the YAML's six, unit scale, unit)
GRAPH_PANELS = (("x", 0, 0, 1e3, "mm"), ("y", 1, 1, 1e3, "mm"), ("z (height, scale)", 2, 2, 1e3, "mm"),
                ("yaw", 3, 5, 180 / math.pi, "deg"))
YAML_PANELS = (("roll", 3, 180 / math.pi, "deg"), ("pitch", 4, 180 / math.pi, "deg"))


def _bars(ax, xs, values, sigmas, color, label) -> None:
    sigmas = np.asarray(sigmas, dtype=float)
    ax.errorbar(xs, values, yerr=3 * sigmas, fmt="none", ecolor=color, elinewidth=0.9, capsize=3, alpha=0.6)
    ax.errorbar(xs, values, yerr=sigmas, fmt="o", color=color, ms=4, elinewidth=2.4, capsize=0, label=label)


def _held(ax, text: str) -> None:
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", fontsize=8.5, color="#555555",
            wrap=True)
    ax.set_yticks([])
    ax.set_xticks([])
    ax.grid(False)
    ax.set_ylabel("")


def _graph_panel(ax, runs, xs, g, y, k, extr, truth) -> None:
    """One graph parameter over the runs; y limits from the determined runs (±3σ), the runs the
    data do not determine marked 'n/d' at the bottom."""
    val = np.array([r.result.value[g] if r.result is not None else np.nan for r in runs]) * k
    sig = np.array([math.sqrt(max(r.result.covariance[g, g], 0.0)) if r.result is not None else np.nan
                    for r in runs]) * k
    ok = np.array([r.result is not None and r.result.ok for r in runs])
    _bars(ax, xs[ok], val[ok], sig[ok], S.COLORS["estimate"], "estimate ±1σ (thick), ±3σ")
    ax.plot(0, extr.values[y] * k, marker="D", mfc="none", mec="black", ms=8, ls="none", label="the YAML's")
    refs = [extr.values[y] * k]
    if truth is not None:
        ax.axhline(truth.values[y] * k, color=S.COLORS["truth"], lw=1.2, ls="--", label="true")
        refs.append(truth.values[y] * k)
    lo = np.nanmin(np.concatenate([val[ok] - 3 * sig[ok], refs]))
    hi = np.nanmax(np.concatenate([val[ok] + 3 * sig[ok], refs]))
    pad = 0.08 * (hi - lo) if hi > lo else 1e-3 * max(abs(hi), 1.0)
    ax.set_ylim(lo - pad, hi + pad)
    for x in xs[~ok]:
        ax.text(x, lo - 0.5 * pad, "n/d", ha="center", va="center", fontsize=8, color="#999999")
    ax.ticklabel_format(axis="y", useOffset=False)


def estimates_figure(data: CalibrationData, extr: ExtrinsicsFile, truth: Optional[ExtrinsicsFile],
                     out_dir: str, formats: Sequence[str]) -> List[str]:
    runs = [data.whole] + data.windows
    labels = ["all"] + ["w%s" % r.label for r in data.windows]
    fig, axes = S.figure(5.2, 2, 3, margins=dict(left=0.1, right=0.98, bottom=0.08, top=0.83, wspace=0.65,
                                                 hspace=0.45))
    flat = axes.ravel()
    xs = np.arange(len(runs))
    for ax, (name, g, y, k, unit) in zip(flat, GRAPH_PANELS):
        ax.set_xticks(xs)
        ax.set_xticklabels(labels)
        ax.set_ylabel(unit)
        ax.set_title(name)
        if not data.whole.result.estimated[g]:
            _held(ax, "%s held at %g,\nnot estimated" % ("scale" if g == 2 else name, data.whole.result.value[g]))
            continue
        _graph_panel(ax, runs, xs, g, y, k, extr, truth)
    for ax, (name, y, k, unit) in zip(flat[4:], YAML_PANELS):
        ax.set_title("%s (from images)" % name)
        if name not in extr.estimated:
            _held(ax, "%s given (%.3f deg),\nnot estimated" % (name, extr.values[y] * k))
            continue
        _bars(ax, [0], [extr.values[y] * k], [extr.sigmas[y] * k], S.COLORS["estimate"], None)
        if truth is not None:
            ax.axhline(truth.values[y] * k, color=S.COLORS["truth"], lw=1.2, ls="--")
        ax.set_xticks([0])
        ax.set_xticklabels(["YAML"])
        ax.set_xlim(-1, 1)
        ax.set_ylabel(unit)
        ax.ticklabel_format(axis="y", useOffset=False)
    handles, names = flat[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="upper center", ncol=4, frameon=False, bbox_to_anchor=(0.5, 1.0))
    fig.text(0.5, 0.915, "Whole drive (all) and %d consecutive windows (w1..), each calibrated on its own; "
             "n/d: not determined by that window" % len(data.windows), ha="center", fontsize=9, color="#444444")
    return S.save(fig, out_dir, "calibration_estimates", formats)


def residuals_figure(data: CalibrationData, out_dir: str, formats: Sequence[str]) -> List[str]:
    res, out = data.residuals, data.outlier
    fig, axes = S.figure(5.6, 3, 2, sharex="col", gridspec_kw={"width_ratios": [3, 1.2]},
                         margins=dict(left=0.1, right=0.98, bottom=0.09, top=0.9, wspace=0.25, hspace=0.15))
    idx = np.arange(len(res.chi2))
    names = ("x (forward)", "y (left)", "θ")
    for c in range(3):
        ax, hx = axes[c, 0], axes[c, 1]
        v = res.normalised[:, c]
        lim = max(4.0, float(np.percentile(np.abs(v[~out]), 99.5)) * 1.15 if (~out).any() else 4.0)
        shown = np.clip(v, -0.97 * lim, 0.97 * lim)
        ax.plot(idx[~out], shown[~out], ".", ms=2.5, color=S.COLORS["estimate"], label="pair")
        if out.any():
            ax.plot(idx[out], shown[out], "x", ms=4, color=S.COLORS["outlier"],
                    label="gated out (%d; clipped to the axes)" % out.sum())
        ax.axhline(0, color="black", lw=0.6)
        ax.set_ylabel("%s / σ" % names[c])
        ax.set_ylim(-lim, lim)
        inl = v[~out]
        bins = np.linspace(-lim, lim, 41)
        hx.hist(inl, bins=bins, density=True, orientation="horizontal", color=S.COLORS["estimate"], alpha=0.6,
                label="inliers")
        g = np.linspace(-lim, lim, 200)
        hx.plot(np.exp(-0.5 * g ** 2) / math.sqrt(2 * math.pi), g, color="black", lw=1.0, label="N(0, 1)")
        hx.set_ylim(-lim, lim)
        hx.set_yticklabels([])
        hx.text(0.97, 0.95, "sd %.2f" % np.std(inl), transform=hx.transAxes, ha="right", va="top", fontsize=8.5)
    axes[0, 0].legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, frameon=False)
    axes[0, 1].legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=1, frameon=False, fontsize=7.5)
    axes[2, 0].set_xlabel("motion pair")
    axes[2, 1].set_xlabel("density")
    fig.suptitle("Residuals at the whole drive's estimate: odometry − mapped sensor motion, per component / its σ",
                 fontsize=10, y=0.995)
    return S.save(fig, out_dir, "calibration_residuals", formats)
