"""The FDS's small band LU (solver 'band', the continuous-time default) against the dense NumPy
reference for every bandwidth the kernel unrolls (2K+1 = 1..15) and the runtime-K code above,
several inputs at once, the half-grid route simulate takes for real inputs, and the HTF's many
right-hand sides. Discrete time has no band solver
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


@pytest.mark.parametrize("ka", [k for k in BANDWIDTHS if k > 0])
@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("depth", [0.2, 0.6])
def test_half_grid_route_matches_reference(make_model, make_spectrum, kappa, ka, seed, depth, tol):
    # A real input takes the half-grid route (lines 0..L, the last 2 ka rows as a small real
    # system) from grids of 2 ka + 1 lines each side; the smallest grids leave one band step.
    # Guard 0 on input lines 0..Lu: the grid is exactly -Lu..Lu, so 2 ka - 1 .. 2 ka + 2 cross
    # the smallest grid the route takes (2 ka + 1). Deeper modulation (0.6) makes the low
    # lines pivot.
    model = make_model(seed, "ct", ka=ka, kb=min(ka, 3), depth=depth)
    for Lu in (2 * ka - 1, 2 * ka, 2 * ka + 1, 2 * ka + 2, 40):
        U = make_spectrum(seed, model, Lu=Lu, ncols=2)
        if kappa(ref.band_matrix_A(model, Lu)) > tol.KAPPA_MAX:
            continue
        Y = lptv.simulate(model, U, guard=0)
        assert rel_diff(Y, ref.simulate(model, U, guard=0)) <= tol.BAND_KERNEL
