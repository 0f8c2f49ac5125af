"""Coverage of the Floquet exponents' and the HTF branches' 95 % intervals (METHOD.md section 22),
by Monte Carlo on systems simulated outside lptv.

Systems (the noise-free steady state computed once per system, outside lptv):

- 'ct-real': the damped Mathieu equation y'' + 2 z wn y' + wn^2 (1 + eps cos w0 t) y = wn^2 u with
  z = 0.1, wn = 1, eps = 0.3, w0 = 2: inside the first tongue, so its multipliers are a real
  negative pair (exponents -0.027 + 1j and -0.173 + 1j), stable: a parametric resonance held off
  by the damping. Steady state by SciPy's solve_ivp (shooting over one period), the truth's
  exponents from solve_ivp's monodromy matrix, its HTF by solve_ivp's response to exp(j w_l t).
- 'ct-complex': the same equation with z = 0.05, eps = 0.1, w0 = 1.7 (a complex pair,
  -0.05 +- 0.7035j).
- 'dt': the discrete-time test system of lptv.examples (its harmonics scaled by 0.3, on N = 32
  samples per period: a complex pair, -0.348 +- 0.0495j), the recursion run in NumPy to steady state; the truth's multipliers from the NumPy product, its HTF from the
  recursion's response to exp(j w_l k).

Per realisation: white noise on u and y, P periods, lptv.identify (SML, the true structure),
lptv.floquet(res) and res.htf_band(branches -1, 0, 1) on the excited lines. Counted: Re and Im of
each exponent inside its interval (an exponent of a real multiplier has Im exactly on 0 or w0/2
in the estimate and the truth alike: counted apart as 'exact'), the HTF ellipse and magnitude
band at the excited lines, first_order_ok, the time of the fit and of the intervals.

    python bench/python/bench_floquet_coverage.py --runs 400 --systems ct dt --periods 4 8
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import lptv  # noqa: E402
from lptv.reference import floquet as ref_floquet  # noqa: E402

BRANCHES = (-1, 0, 1)


def _mathieu():
    z, wn, eps, w0 = 0.1, 1.0, 0.3, 2.0
    a = np.array([[wn ** 2 * eps / 2, wn ** 2, wn ** 2 * eps / 2], [0, 2 * z * wn, 0], [0, 1.0, 0]], complex)
    b = np.array([[0, wn ** 2, 0]], complex)
    return dict(a=a, b=b, w0=w0, ts=None, N=128, excited=np.arange(1, 16), lines=np.arange(1, 20),
                structure=dict(na=2, nb=0, ka=[1, 0, 0], kb=0), snr=(50.0, 40.0))


def _mathieu_complex():
    z, wn, eps, w0 = 0.05, 1.0, 0.1, 1.7
    a = np.array([[wn ** 2 * eps / 2, wn ** 2, wn ** 2 * eps / 2], [0, 2 * z * wn, 0], [0, 1.0, 0]], complex)
    b = np.array([[0, wn ** 2, 0]], complex)
    return dict(a=a, b=b, w0=w0, ts=None, N=128, excited=np.arange(1, 16), lines=np.arange(1, 20),
                structure=dict(na=2, nb=0, ka=[1, 0, 0], kb=0), snr=(50.0, 40.0))


def _discrete():
    # the discrete-time example's coefficients, their harmonics scaled by 0.3, on N = 32 samples
    # per period: a complex pair (at the example's own N = 256 the smaller multiplier, 1e-37,
    # lies below the rounding of the product, eps times 1e-25)
    from lptv.examples import DISCRETE_STRUCTURE, discrete_model

    m = discrete_model()
    a = m.a.copy()
    a[:, :m.ka] *= 0.3
    a[:, m.ka + 1:] *= 0.3
    N = 32
    return dict(a=a, b=m.b, w0=2 * np.pi / N, ts=1.0, N=N, excited=np.arange(1, 14), lines=np.arange(1, 14),
                structure=dict(DISCRETE_STRUCTURE), snr=(45.0, 30.0))


SYSTEMS = {"ct-real": _mathieu, "ct-complex": _mathieu_complex, "dt": _discrete}


def _coef_at(c, w0, t):
    K = (c.shape[1] - 1) // 2
    return np.real(np.exp(1j * np.outer(np.atleast_1d(t), np.arange(-K, K + 1)) * w0) @ c.T)


def _ct_steady(a, b, w0, u_of_t, N, complex_input=False):
    """One period of the steady-state output on N samples: shooting with solve_ivp (nb = 0)."""
    from scipy.integrate import solve_ivp

    na = a.shape[0] - 1
    T0 = 2 * np.pi / w0

    def rhs(t, x):
        av, bv = _coef_at(a, w0, t)[0], _coef_at(b, w0, t)[0]
        d = np.empty_like(x)
        d[:-1] = x[1:]
        d[-1] = (bv[0] * u_of_t(t) - av[:na] @ x) / av[na]
        return d

    dtype = complex if complex_input else float
    x0 = np.zeros(na, dtype)
    forced = solve_ivp(rhs, (0, T0), x0, method="DOP853", rtol=1e-11, atol=1e-13).y[:, -1]
    Phi = ref_floquet.monodromy(a, w0)
    xs = np.linalg.solve(np.eye(na) - Phi, forced)
    t = np.arange(N) * T0 / N
    sol = solve_ivp(rhs, (0, T0), xs, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=t)
    return sol.y[0]


def _dt_steady(a, b, w0, u, periods=4):
    """The recursion sum_n a_n[k] y[k+n] = sum_m b_m[k] u[k+m] run to steady state (periods)."""
    na, nb, N = a.shape[0] - 1, b.shape[0] - 1, u.size
    kk = np.arange(N)
    av, bv = _coef_at(a, w0, kk), _coef_at(b, w0, kk)
    y = np.zeros(periods * N + na, complex if np.iscomplexobj(u) else float)
    uu = np.tile(u, periods + 1)
    for k in range(periods * N):
        i = k % N
        rhs = sum(bv[i, m] * uu[k + m] for m in range(nb + 1)) - sum(av[i, n] * y[k + n] for n in range(na))
        y[k + na] = rhs / av[i, na]
    return y[(periods - 1) * N:periods * N]


def _true_htf(sys_, lines):
    """G_k(w_l), k in BRANCHES, of the true system by its response to exp(j w_l t)."""
    a, b, w0, N = sys_["a"], sys_["b"], sys_["w0"], sys_["N"]
    G = np.zeros((len(BRANCHES), len(lines)), complex)
    for j, l in enumerate(lines):
        if sys_["ts"]:
            u = np.exp(2j * np.pi * l * np.arange(N) / N)
            y = _dt_steady(a, b, w0, u)
        else:
            y = _ct_steady(a, b, w0, lambda t, l=l: np.exp(1j * l * w0 * t), 4 * N, complex_input=True)
        Y = np.fft.fft(y) / y.size
        for i, k in enumerate(BRANCHES):
            G[i, j] = Y[(l + k) % y.size]
    return G


def world(name):
    s = SYSTEMS[name]()
    N, w0 = s["N"], s["w0"]
    rng = np.random.default_rng(99)
    ph = rng.uniform(0, 2 * np.pi, s["excited"].size)
    amp = np.sqrt(2.0 / s["excited"].size)
    n = np.arange(N)
    u0 = sum(amp * np.cos(2 * np.pi * l * n / N + p) for l, p in zip(s["excited"], ph))
    if s["ts"]:
        y0 = _dt_steady(s["a"], s["b"], w0, u0)
    else:
        T0 = 2 * np.pi / w0
        y0 = _ct_steady(s["a"], s["b"], w0, lambda t: sum(amp * np.cos(l * w0 * t + p) for l, p in
                                                         zip(s["excited"], ph)), N)
        del T0
    s.update(u0=u0, y0=np.real(y0), exponents=ref_floquet.exponents(s["a"], w0, s["ts"]),
             htf=_true_htf(s, s["excited"]))
    return s


def one(args):
    s, P, seed = args
    rng = np.random.default_rng(seed)
    su = np.std(s["u0"]) * 10 ** (-s["snr"][0] / 20)
    sy = np.std(s["y0"]) * 10 ** (-s["snr"][1] / 20)
    u = s["u0"] + su * rng.standard_normal((P, s["N"]))
    y = s["y0"] + sy * rng.standard_normal((P, s["N"]))
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = lptv.identify(u, y, **s["structure"], w0=s["w0"], ts=s["ts"], lines=s["lines"], method="sml")
    t1 = time.perf_counter()
    f = lptv.floquet(res)
    t2 = time.perf_counter()
    band = res.htf_band(lines=s["excited"], branches=BRANCHES)
    t3 = time.perf_counter()
    ci = f.confidence_interval(0.95)
    w0 = s["w0"]
    from lptv.model.floquet_uncertainty import match

    truth = match(f.exponents, s["exponents"], w0)
    cov_re = (ci[:, 0, 0] <= truth.real) & (truth.real <= ci[:, 0, 1])
    exact = (f.exponents_std[:, 1] == 0) | (f.exponents_std[:, 1] < 1e-9 * max(1.0, w0))
    cov_im = (ci[:, 1, 0] <= truth.imag) & (truth.imag <= ci[:, 1, 1])
    im_exact_ok = exact & (np.abs(truth.imag - f.exponents.imag) < 1e-6 * w0)
    mb = band.magnitude_band()
    tg = np.abs(s["htf"])
    # the parameters' own intervals: is the covariance or its propagation off?
    from lptv.judgement.parameters import _value

    true_model = lptv.Model(s["a"], s["b"], w0=w0, ts=s["ts"])
    eta_true = np.array([_value(true_model, nm) for nm in res.eta_names])
    free = np.diag(res.covariance) > 0
    pci = res.confidence_interval(0.95)
    eta_cov = ((pci[:, 0] <= eta_true) & (eta_true <= pci[:, 1]))[free]
    return dict(re=cov_re, im=np.where(exact, -1, cov_im.astype(int)), im_exact_ok=im_exact_ok[exact],
                ell=band.contains(s["htf"]).ravel(), mag=((mb[..., 0] <= tg) & (tg <= mb[..., 1])).ravel(),
                eta=eta_cov, ok=bool(f.first_order_ok), notes=f.uncertainty_notes, p=f.stable_probability, t_fit=t1 - t0, t_floquet=t2 - t1,
                t_band=t3 - t2)


def se(p, n):
    return np.sqrt(max(p * (1 - p), 1e-12) / max(n, 1))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=400)
    ap.add_argument("--systems", nargs="+", default=list(SYSTEMS))
    ap.add_argument("--periods", nargs="+", type=int, default=[4, 8])
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args(argv)
    print(f"{'system':6} {'P':>2} {'R':>4}  {'Re cover':>15}  {'Im cover':>15}  {'Im exact':>8}  "
          f"{'HTF ellipse':>15}  {'HTF |G|':>15}  {'eta cover':>9}  {'1st ok':>6}  {'fit ms':>7} {'floq ms':>7} {'band ms':>7}")
    for name in a.systems:
        s = world(name)
        print(f"# {name}: true exponents {np.round(s['exponents'], 5)}", flush=True)
        for P in a.periods:
            tasks = [(s, P, 1000 * P + i) for i in range(a.runs)]
            if a.workers > 1:
                with ProcessPoolExecutor(a.workers) as ex:
                    out = list(ex.map(one, tasks, chunksize=8))
            else:
                out = [one(t) for t in tasks]
            re = np.concatenate([o["re"] for o in out])
            im = np.concatenate([o["im"] for o in out])
            imc = im[im >= 0]
            ex_ok = np.concatenate([o["im_exact_ok"] for o in out])
            ell = np.concatenate([o["ell"] for o in out])
            mag = np.concatenate([o["mag"] for o in out])
            pr, pi_, pe, pm = re.mean(), imc.mean() if imc.size else np.nan, ell.mean(), mag.mean()
            ok = np.mean([o["ok"] for o in out])
            pe_eta = np.concatenate([o["eta"] for o in out]).mean()
            kinds = {}
            for o in out:
                for n in o["notes"]:
                    k = n.split(":")[1].split("(")[0].strip()[:40] if ":" in n else n[:40]
                    kinds[k] = kinds.get(k, 0) + 1
            tf, tq, tb = (1e3 * np.median([o[k] for o in out]) for k in ("t_fit", "t_floquet", "t_band"))
            print(f"{name:6} {P:2d} {a.runs:4d}  {pr:6.3f} +- {se(pr, a.runs):5.3f}  "
                  f"{pi_:6.3f} +- {se(pi_, a.runs):5.3f}  {ex_ok.mean() if ex_ok.size else np.nan:8.3f}  "
                  f"{pe:6.3f} +- {se(pe, a.runs):5.3f}  {pm:6.3f} +- {se(pm, a.runs):5.3f}  {pe_eta:9.3f}  {ok:6.3f}  "
                  f"{tf:7.2f} {tq:7.2f} {tb:7.2f}", flush=True)
            for k, v in sorted(kinds.items(), key=lambda kv: -kv[1]):
                print(f"#   notes: {v} x {k}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
