"""The stability of an estimate with its uncertainty for the command line: the Floquet exponents
with their 95 % intervals, the multipliers' moduli and the probability of stability (METHOD.md
section 22), for summary.json, the printed summary and report.html; one output or several alike."""
from __future__ import annotations

from typing import Optional

import numpy as np

import lptv

LEVEL = 0.95


def stability_summary(res) -> Optional[dict]:
    """A dict of plain values for summary.json, or one with only 'error' when the intervals cannot be
    had (no covariance, an undecided model); None for a model without dynamics (na = 0)."""
    try:
        f = lptv.floquet(res, level=LEVEL)
    except (ValueError, lptv.NumericalError) as e:
        return {"error": str(e)}
    if f.exponents.size == 0:
        return None
    ci = f.confidence_interval(LEVEL)
    mi = f.multiplier_modulus_interval(LEVEL)
    mods = np.abs(f.multipliers_of_exponents)
    rows = []
    for i, lam in enumerate(f.exponents):
        rows.append({"re": float(lam.real), "im": float(lam.imag),
                     "std_re": float(f.exponents_std[i, 0]), "std_im": float(f.exponents_std[i, 1]),
                     "re_interval": [float(x) for x in ci[i, 0]], "im_interval": [float(x) for x in ci[i, 1]],
                     "multiplier_modulus": float(mods[i]),
                     "multiplier_modulus_interval": [float(x) for x in mi[i]]})
    return {"level": LEVEL, "method": f.uncertainty_method, "is_stable": f.is_stable,
            "stable_probability": f.stable_probability, "first_order_ok": f.first_order_ok,
            "notes": list(f.uncertainty_notes), "exponents": rows}


def stability_text(s: Optional[dict]) -> str:
    """The lines the command prints (empty for None)."""
    if s is None:
        return ""
    if "error" in s:
        return f"stability: no intervals ({s['error']})"
    pct = f"{100 * s['level']:g} %"
    out = [f"stability (Floquet exponents, {pct} intervals): P(stable) = {_prob(s['stable_probability'])}"]
    for e in s["exponents"]:
        lo, hi = e["re_interval"]
        ilo, ihi = e["im_interval"]
        out.append(f"  lambda = {e['re']:.6g} {'+' if e['im'] >= 0 else '-'} {abs(e['im']):.6g}j: "
                   f"Re {e['re']:.6g} +- {e['std_re']:.2g} 1/s [{lo:.6g}, {hi:.6g}], "
                   f"Im [{ilo:.6g}, {ihi:.6g}] rad/s, |mu| {e['multiplier_modulus']:.4g} "
                   f"[{e['multiplier_modulus_interval'][0]:.4g}, {e['multiplier_modulus_interval'][1]:.4g}]")
    out += [f"  note: {n}" for n in s["notes"]]
    return "\n".join(out)


def _prob(p) -> str:
    if p is None:
        return "-"
    if p > 0.9999:
        return f"{p:.6f}" if p < 1 else "1 (to the approximation's precision)"
    return f"{p:.4f}"


def stability_section(rep, s: Optional[dict]):
    """The report's table of the exponents with their intervals."""
    if s is None:
        return
    rep.heading("Stability with its uncertainty")
    if "error" in s:
        rep.paragraph(f"No intervals on the Floquet exponents: {s['error']}.")
        return
    rep.paragraph(
        f"Floquet exponents of the estimate with their {100 * s['level']:g} % intervals from the parameter "
        f"covariance ({s['method']}; METHOD.md section 22): the system is stable when every decay rate "
        f"Re lambda is negative. Probability of stability under the estimate's distribution: "
        f"{_prob(s['stable_probability'])}." + ("" if s["first_order_ok"] in (True, None) else
                                                " First order does not hold everywhere: " + "; ".join(s["notes"]) + "."))
    rep.table(["Re lambda (1/s)", "interval", "Im lambda (rad/s)", "interval", "|mu|", "interval"],
              [[f"{e['re']:.6g}", f"[{e['re_interval'][0]:.6g}, {e['re_interval'][1]:.6g}]", f"{e['im']:.6g}",
                f"[{e['im_interval'][0]:.6g}, {e['im_interval'][1]:.6g}]", f"{e['multiplier_modulus']:.4g}",
                f"[{e['multiplier_modulus_interval'][0]:.4g}, {e['multiplier_modulus_interval'][1]:.4g}]"]
               for e in s["exponents"]])
