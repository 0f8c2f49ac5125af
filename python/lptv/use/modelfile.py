"""What a saved model needs for a later use (METHOD.md section 21): its ``context`` in model.json.

The coefficients and the covariance say what the model is; a later ``lptv validate`` or ``lptv
simulate`` also needs to know what it was fitted to: the channels and their units, the
sampling, the period, the structure, the estimator and the noise route. :func:`context_of`
collects them from what ``lptv identify`` writes into summary.json, :func:`check_context` reads
them back and refuses a tampered or foreign file, naming the key and what is wrong with it.
"""
from __future__ import annotations

import math
from typing import Optional

CONTEXT_VERSION = 1
ROUTES = ("periods", "one record", "realisations", "joint", "several channels")
_KEYS = ("version", "route", "inputs", "outputs", "fs", "period", "samples_per_period", "structure", "method",
         "noise", "lines")


def _channels(summary: dict, many: str, one: str):
    v = summary.get(many)
    if v is None:
        v = summary.get(one)
        v = None if v is None else [v]
    return None if v is None else [str(x) for x in v]


def context_of(summary: dict, model) -> dict:
    """The context of ``model`` from a command's summary (summary.json's keys: input(s),
    output(s), fs, w0, samples_per_period, na, nb, ka, kb, method, noise, first_line,
    last_line); keys the summary lacks stay None."""
    route = summary.get("route")
    if route not in ROUTES:
        route = "several channels" if "inputs" in summary else \
            "realisations" if "distortion" in summary else "joint" if "experiments" in summary else "periods"
    fs = summary.get("fs")
    if fs is None and summary.get("experiments"):
        fss = {e.get("fs") for e in summary["experiments"] if isinstance(e, dict)}
        fs = fss.pop() if len(fss) == 1 else None
    n = summary.get("samples_per_period")
    lines = None
    if summary.get("first_line") is not None and summary.get("last_line") is not None:
        lines = [int(summary["first_line"]), int(summary["last_line"])]

    def counts(k):
        return [int(x) for x in k] if isinstance(k, (list, tuple)) else int(k if k is not None else 0)

    return {
        "version": CONTEXT_VERSION, "route": route,
        "inputs": _channels(summary, "inputs", "input") or ["u"] * _n_inputs(model),
        "outputs": _channels(summary, "outputs", "output") or ["y"] * _n_outputs(model),
        "fs": None if fs is None else float(fs),
        "period": float(model.period),
        "samples_per_period": None if n is None else int(n),
        "structure": {"na": int(model.na), "nb": int(model.nb), "ka": counts(summary.get("ka", model.ka)),
                      "kb": counts(summary.get("kb", model.kb))},
        "method": summary.get("method"), "noise": summary.get("noise"), "lines": lines,
    }


def _n_inputs(model) -> int:
    return int(getattr(model, "n_inputs", 1))


def _n_outputs(model) -> int:
    return int(getattr(model, "n_outputs", 1))


def _fail(key, problem):
    raise ValueError(f"context.{key}: {problem}")


def _int(v, key, minimum=0):
    if isinstance(v, bool) or not isinstance(v, int) or v < minimum:
        _fail(key, f"must be an integer >= {minimum}, got {v!r}")
    return v


def _number(v, key):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
        _fail(key, f"must be a positive finite number, got {v!r}")
    return float(v)


def _counts(v, key, order):
    if isinstance(v, list):
        if len(v) != order + 1:
            _fail(key, f"must hold one harmonic count per coefficient ({order + 1}), got {len(v)}")
        return [_int(x, key) for x in v]
    return _int(v, key)


def check_context(ctx, model) -> dict:
    """``ctx`` checked against the model it came with: every key present with the right type
    and consistent with the coefficients (the channel counts, the period, the structure's
    orders and harmonics, a discrete model's sampling); a ValueError naming the key otherwise."""
    if not isinstance(ctx, dict):
        raise ValueError(f"context must be an object (the channels, sampling and structure of the fit), "
                         f"got {type(ctx).__name__}")
    for k in _KEYS:
        if k not in ctx:
            _fail(k, "missing (a model.json written by lptv identify holds it)")
    unknown = [k for k in ctx if k not in _KEYS]
    if unknown:
        _fail(unknown[0], f"unknown key (keys: {', '.join(_KEYS)})")
    if ctx["version"] != CONTEXT_VERSION or isinstance(ctx["version"], bool):
        _fail("version", f"must be {CONTEXT_VERSION}, got {ctx['version']!r}")
    if ctx["route"] not in ROUTES:
        _fail("route", f"must be one of {', '.join(ROUTES)}, got {ctx['route']!r}")
    for key, n in (("inputs", _n_inputs(model)), ("outputs", _n_outputs(model))):
        v = ctx[key]
        if not isinstance(v, list) or not all(isinstance(x, str) and x.strip() for x in v):
            _fail(key, f"must be a list of channel names, got {v!r}")
        if len(v) != n:
            _fail(key, f"names {len(v)} channel(s) but the coefficients have {n}")
    period = _number(ctx["period"], "period")
    if not math.isclose(period, model.period, rel_tol=1e-9):
        _fail("period", f"is {period:.10g} s but the coefficients' w0 gives {model.period:.10g} s")
    fs = None if ctx["fs"] is None else _number(ctx["fs"], "fs")
    n = None if ctx["samples_per_period"] is None else _int(ctx["samples_per_period"], "samples_per_period", 1)
    if model.discrete:
        if fs is not None and not math.isclose(fs * model.ts, 1.0, rel_tol=1e-9):
            _fail("fs", f"is {fs:g} Hz but the discrete-time model's ts = {model.ts:g} s")
        if n is not None and n != model.samples_per_period:
            _fail("samples_per_period", f"is {n} but the discrete-time model has {model.samples_per_period}")
    s = ctx["structure"]
    if not isinstance(s, dict) or set(s) != {"na", "nb", "ka", "kb"}:
        _fail("structure", f"must be an object with na, nb, ka, kb, got {s!r}")
    for key in ("na", "nb"):
        if _int(s[key], f"structure.{key}") != getattr(model, key):
            _fail(f"structure.{key}", f"is {s[key]} but the coefficients have {key} = {getattr(model, key)}")
    for key, order in (("ka", model.na), ("kb", model.nb)):
        k = _counts(s[key], f"structure.{key}", order)
        kmax = max(k) if isinstance(k, list) else k
        if kmax > getattr(model, key):
            _fail(f"structure.{key}", f"asks for {kmax} harmonics but the coefficients hold {getattr(model, key)}")
    for key in ("method", "noise"):
        if ctx[key] is not None and not isinstance(ctx[key], str):
            _fail(key, f"must be a name or null, got {ctx[key]!r}")
    lines = ctx["lines"]
    if lines is not None and (not isinstance(lines, list) or len(lines) != 2
                              or _int(lines[0], "lines") > _int(lines[1], "lines")):
        _fail("lines", f"must be [first, last] or null, got {lines!r}")
    return dict(ctx)


def channels(model) -> Optional[tuple]:
    """(inputs, outputs) named in the model's context, or None (a model saved without one)."""
    ctx = getattr(model, "context", None)
    return None if ctx is None else (tuple(ctx["inputs"]), tuple(ctx["outputs"]))
