"""The FDS's small band LU (solver 'band', the continuous-time default) against the dense NumPy
reference for every bandwidth the kernel unrolls (2K+1 = 1..15) and the runtime-K code above,
several inputs at once, and the HTF's many right-hand sides. Discrete time has no band solver
(the grid wraps around); there the default KLU is compared with the same reference."""
import numpy as np
import pytest

import lptv
from lptv import reference as ref

GUARD = 20
BANDWIDTHS = [0, 1, 2, 3, 4, 5, 6, 7, 9]


def rel_diff(X, Xref):
    return float(np.max(np.abs(X - Xref)) / np.max(np.abs(Xref)))


@pytest.mark.parametrize("ka", BANDWIDTHS)
@pytest.mark.parametrize("seed", [1, 2, 3])  # seed 0 at ka = 9 has kappa 128 > KAPPA_MAX
def test_band_kernel_matches_reference(make_model, make_spectrum, kappa, ka, seed, tol):
    model = make_model(seed, "ct", ka=ka, kb=min(ka, 3))
    U = make_spectrum(seed, model, Lu=30, ncols=3)
    assert kappa(ref.band_matrix_A(model, 30 + GUARD)) <= tol.KAPPA_MAX
    r = lptv.simulate(model, U, guard=GUARD, full_output=True)
    assert r.solver == "band"
    assert rel_diff(r.Y, ref.simulate(model, U, guard=GUARD)) <= tol.BAND_KERNEL


@pytest.mark.parametrize("ka", BANDWIDTHS)
def test_band_kernel_htf_matches_reference(make_model, ka, tol):
    model = make_model(3, "ct", ka=ka)
    L = 25
    G = lptv.htf(model, L, solver="band")  # all 51 columns: blocks of the many-inputs solve
    assert rel_diff(G, ref.htf(model, L, list(range(-L, L + 1)))) <= tol.BAND_KERNEL


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_discrete_time_default_matches_reference(make_model, make_spectrum, seed, tol):
    model = make_model(seed, "dt")
    U = make_spectrum(seed, model)
    assert rel_diff(lptv.simulate(model, U), ref.simulate(model, U)) <= tol.BAND_KERNEL
