"""The Monte Carlo study as tables (pandas), files (CSV, Parquet), text and figures.

The statistics are computed with NumPy (:meth:`MonteCarloTables.statistics`); pandas is needed
for the tables only, matplotlib for the figures.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from .executors import require

_FORMATS = ("csv", "parquet")


class MonteCarloTables:
    """Tables, files and figures of :class:`lptv.MonteCarloResult` (a mixin: the fields are
    the result's)."""

    # ------------------------------------------------------------------ statistics (NumPy)
    def _ok(self, method):
        return np.array([f["ok"] for f in self.fits if f["method"] == method], bool)

    def statistics(self, method: str) -> dict:
        """Per free parameter of ``method``: n, bias, its standard error, RMS error, empirical
        std, CRB std, variance / CRB, mean reported std and coverage (NaN without a covariance)."""
        if method not in self.methods:
            raise ValueError(f"method must be one of the study's {self.methods}, got {method!r}")
        ok = self._ok(method)
        E = self.estimates[method][ok][:, self.free]
        S = self.std[method][ok][:, self.free]
        err = E - self.truth[self.free]
        n, k = E.shape
        crb_std = self.crb.std[self.free]
        nan = np.full(k, np.nan)
        from scipy.stats import norm

        z = norm.ppf(0.5 + self.level / 2)
        has_std = n > 0 and bool(np.all(np.isfinite(S)))
        var = E.var(axis=0, ddof=1) if n > 1 else nan
        return dict(
            parameter=np.array(self.eta_names)[self.free], n=n, true=self.truth[self.free],
            mean=E.mean(axis=0) if n else nan, bias=err.mean(axis=0) if n else nan,
            bias_se=np.sqrt(var / max(n, 1)), rms=np.sqrt(np.mean(err ** 2, axis=0)) if n else nan,
            std=np.sqrt(var), crb_std=crb_std, var_over_crb=var / crb_std ** 2,
            reported_std=S.mean(axis=0) if has_std else nan,
            coverage=(np.abs(err) <= z * S).mean(axis=0) if has_std else nan)

    # ------------------------------------------------------------------ tables (pandas)
    def table(self):
        """Tidy table, one row per (run, method, free parameter) of the successful fits:
        run, method, parameter, true, estimate, std (reported), error, covered.

        >>> # mc.table().groupby(["method", "parameter"]).error.describe()
        """
        pd = require("pandas", "MonteCarloResult.table")
        names = np.array(self.eta_names)[self.free]
        from scipy.stats import norm

        z = norm.ppf(0.5 + self.level / 2)
        parts = []
        for m in self.methods:
            ok = self._ok(m)
            runs = np.flatnonzero(ok)
            E = self.estimates[m][ok][:, self.free]
            S = self.std[m][ok][:, self.free]
            T = np.broadcast_to(self.truth[self.free], E.shape)
            cov = pd.array(np.abs(E - T) <= z * S, dtype="boolean")
            if not np.all(np.isfinite(S)):
                cov[:] = pd.NA
            parts.append(pd.DataFrame({
                "run": np.repeat(runs, names.size), "method": m, "parameter": np.tile(names, runs.size),
                "true": T.ravel(), "estimate": E.ravel(), "std": S.ravel(), "error": (E - T).ravel(),
                "covered": cov.ravel()}))
        return pd.concat(parts, ignore_index=True)

    def fit_table(self):
        """One row per (run, method), failures included: ok, error (the message), converged,
        iterations, cost, fraction_above_0db, residue_ok, warnings (joined by '; ')."""
        pd = require("pandas", "MonteCarloResult.fit_table")
        return pd.DataFrame([dict(f, warnings="; ".join(f["warnings"])) for f in self.fits])

    def summary(self):
        """One row per (method, free parameter): the columns of :meth:`statistics`."""
        pd = require("pandas", "MonteCarloResult.summary")
        frames = []
        for m in self.methods:
            s = self.statistics(m)
            frames.append(pd.DataFrame(dict(method=m, **s)))
        return pd.concat(frames, ignore_index=True).set_index(["method", "parameter"])

    def overview(self):
        """One row per method: runs, failures, not_converged, residue_rejected (fraction of the
        fits whose normalised-residue test fails), coverage pooled over the parameters and its
        binomial standard error (as if the parameters were independent), variance / CRB median and max (relative sampling error of one ratio
        ``var_over_crb_se``), largest |bias| in standard errors."""
        pd = require("pandas", "MonteCarloResult.overview")
        rows = []
        for m in self.methods:
            fits = [f for f in self.fits if f["method"] == m]
            ok = [f for f in fits if f["ok"]]
            s = self.statistics(m)
            n = s["n"]
            cov = float(np.mean(s["coverage"])) if n else np.nan
            rows.append(dict(
                method=m, runs=len(fits), failures=len(fits) - len(ok),
                not_converged=sum(not f["converged"] for f in ok),
                residue_rejected=np.mean([not f["residue_ok"] for f in ok]) if ok else np.nan,
                coverage=cov,
                coverage_se=np.sqrt(self.level * (1 - self.level) / (n * s["true"].size)) if n else np.nan,
                var_over_crb_median=float(np.median(s["var_over_crb"])) if n > 1 else np.nan,
                var_over_crb_max=float(np.max(s["var_over_crb"])) if n > 1 else np.nan,
                var_over_crb_se=np.sqrt(2.0 / (n - 1)) if n > 1 else np.nan,
                max_abs_bias_in_se=float(np.max(np.abs(s["bias"]) / s["bias_se"])) if n > 1 else np.nan))
        return pd.DataFrame(rows).set_index("method")

    def save(self, directory, format: str = "csv") -> dict:
        """Write estimates.<format> (:meth:`table`), fits.<format> (:meth:`fit_table`),
        summary.csv and overview.csv into ``directory``; returns {name: path}.

        ``format='parquet'`` needs pyarrow (``pip install 'lptv[batch]'``).
        """
        if format not in _FORMATS:
            raise ValueError(f"format must be one of {_FORMATS}, got {format!r}")
        from .._validate import as_path

        out = Path(as_path(directory, "directory"))
        out.mkdir(parents=True, exist_ok=True)
        paths = {"estimates": out / f"estimates.{format}", "fits": out / f"fits.{format}",
                 "summary": out / "summary.csv", "overview": out / "overview.csv"}
        if format == "parquet":
            require("pyarrow", "writing Parquet")
        # each file whole or not at all: a study killed while saving leaves no half table
        for name, frame in (("estimates", self.table()), ("fits", self.fit_table())):
            with atomic_path(paths[name]) as tmp:
                if format == "parquet":
                    frame.to_parquet(tmp, index=False)
                else:
                    frame.to_csv(tmp, index=False)
        for name, frame in (("summary", self.summary()), ("overview", self.overview())):
            with atomic_path(paths[name]) as tmp:
                frame.to_csv(tmp)
        return paths

    def report(self) -> str:
        """The study in a few lines of text (per method)."""
        d = self.design
        lines = [f"Monte Carlo: {self.runs} realisations x {len(self.methods)} method(s), P = {self.periods}, "
                 f"SNR {d['snr_in_db']:g} dB in / {d['snr_out_db']:g} dB out, {int(self.free.sum())} free "
                 f"parameters on {len(d['fit_lines'])} lines; {self.executor}, {self.elapsed:.1f} s "
                 f"({self.fits_per_minute:.0f} fits/min)"]
        for m in self.methods:
            fits = [f for f in self.fits if f["method"] == m]
            ok = [f for f in fits if f["ok"]]
            s = self.statistics(m)
            ratio = s["var_over_crb"]
            text = (f"  {m:6s} {len(ok)}/{len(fits)} fits ok, {sum(not f['converged'] for f in ok)} not "
                    f"converged, residue test rejects {100 * np.mean([not f['residue_ok'] for f in ok]) if ok else np.nan:.1f} %")
            if s["n"] > 1:
                text += f"; var/CRB median {np.median(ratio):.3f} (max {np.max(ratio):.3f})"
            if s["n"] and np.all(np.isfinite(s["coverage"])):
                text += f"; {100 * self.level:g} % coverage {100 * np.mean(s['coverage']):.1f} %"
            lines.append(text)
        failed = [f for f in self.fits if not f["ok"]]
        if failed:
            lines.append(f"  first failure: run {failed[0]['run']} {failed[0]['method']}: {failed[0]['error']}")
        return "\n".join(lines)

    # ------------------------------------------------------------------ figures (matplotlib)
    def plot_errors(self, parameter=None, ax=None):
        """Histogram of the errors against the normal law of the Cramer-Rao bound.

        With ``parameter`` (a name of ``eta_names``): that parameter's error per method and
        N(0, CRB). Without: all free parameters' errors divided by their CRB std, pooled, and
        N(0, 1). Returns the axes.
        """
        from ..plots import _axes

        ax = _axes(ax)
        names = list(np.array(self.eta_names)[self.free])
        if parameter is not None and parameter not in names:
            raise ValueError(f"parameter must be one of the free parameters {names}, got {parameter!r}")
        j = None if parameter is None else names.index(parameter)
        crb_std = self.crb.std[self.free]
        lo_hi = []
        for m in self.methods:
            E = self.estimates[m][self._ok(m)][:, self.free] - self.truth[self.free]
            x = (E / crb_std).ravel() if j is None else E[:, j]
            if x.size:
                ax.hist(x, bins=min(60, max(10, int(np.sqrt(x.size)))), density=True, histtype="step",
                        label=m.upper())
                lo_hi.append(np.percentile(x, [0.5, 99.5]))
        s = 1.0 if j is None else crb_std[j]
        lim = max([4 * s] + [float(np.max(np.abs(v))) for v in lo_hi])
        t = np.linspace(-lim, lim, 400)
        ax.plot(t, np.exp(-0.5 * (t / s) ** 2) / (s * np.sqrt(2 * np.pi)), "k--", lw=1, label="CRB normal")
        ax.set_xlabel("error / CRB std (all parameters)" if j is None else f"error of {parameter}")
        ax.set_ylabel("density")
        ax.legend(fontsize=8)
        return ax

    def plot_coverage(self, ax=None):
        """Coverage of the reported intervals per free parameter and method, with the level and
        its +-2 binomial standard deviations. Returns the axes."""
        from ..plots import _axes

        ax = _axes(ax)
        names = list(np.array(self.eta_names)[self.free])
        x = np.arange(len(names))
        n_max = 0
        for k, m in enumerate(self.methods):
            s = self.statistics(m)
            if s["n"] and np.all(np.isfinite(s["coverage"])):
                ax.plot(x + 0.1 * k, 100 * s["coverage"], "o", ms=4, label=m.upper())
                n_max = max(n_max, s["n"])
        ax.axhline(100 * self.level, color="k", lw=1)
        if n_max:
            band = 200 * np.sqrt(self.level * (1 - self.level) / n_max)
            ax.axhspan(100 * self.level - band, min(100, 100 * self.level + band), color="0.85", zorder=0,
                       label="+-2 binomial std")
        ax.set_xticks(x)
        ax.set_xticklabels(names, rotation=90, fontsize=7)
        ax.set_ylabel(f"coverage of {100 * self.level:g} % intervals (%)")
        ax.legend(fontsize=8)
        return ax
