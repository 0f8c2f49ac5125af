"""Large grids: the conditioning check must not refuse accurate systems whose entries grow
like (l w0)^na, and the band and sparse backends must agree there."""
import numpy as np

import lptv
from lptv.examples import paper_model


def test_large_grid_is_not_refused_and_backends_agree():
    m = paper_model()
    L = 100_000  # (L w0)^2 = 1.6e7: entries span seven decades
    rng = np.random.default_rng(0)
    U = np.zeros(L + 1, complex)
    idx = rng.choice(np.arange(1, L + 1), 500, replace=False)
    U[idx] = np.exp(2j * np.pi * rng.random(idx.size))
    band = lptv.simulate(m, U, guard=16, solver="band", full_output=True)
    klu = lptv.simulate(m, U, guard=16, solver="klu")
    assert band.solver == "band"
    # both are backward stable on a well-conditioned (componentwise) system
    assert np.abs(band.Y - klu).max() <= 1e-12 * np.abs(klu).max()
