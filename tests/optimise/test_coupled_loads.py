"""Loads in the coupled chain's programmes (optimise/coupled/data.py, at_activation.py; docs/chain.md).

See "External loads" there.

The least local stiffness with a weight held is checked by its own constraint, diag(k) - K_loaded >= mu I
(the eigenvalues of that matrix, a second method beside the SDP's solver), and by monotonicity: a load whose
K_load is positive semidefinite (a weight held, like gravity's K_g) shrinks the feasible set, so it needs at least
as much local stiffness as none.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl import load_preset
from spinectl.errors import ParameterError
from spinectl.model.loads import PointLoad
from spinectl.optimise.coupled import coupled_stability_at

E, LAMBDA = 0.03, 0.04
PCSA = np.full(6, 10e-4)  # [m^2]


@pytest.fixture(scope="module")
def model():
    return load_preset("wagner2012")


def test_least_local_stiffness_holds_the_loaded_chain(model):
    """k of problem (a) with 300 N held satisfies diag(k) - K_loaded >= mu I and is at least the unloaded k's total."""
    bare = coupled_stability_at(model, E, LAMBDA, PCSA)
    loaded = coupled_stability_at(model, E, LAMBDA, PCSA, loads=[PointLoad((0.0, -300.0))])
    assert loaded.local.status in ("optimal", "optimal_inaccurate")
    k = loaded.local.local_stiffness
    least = np.linalg.eigvalsh(np.diag(k) - loaded.stiffness)[0]
    assert least >= model.optimisation.stability_margin - 1e-4 * max(1.0, np.abs(loaded.stiffness).max())
    assert np.sum(k) >= np.sum(bare.local.local_stiffness) - 1e-6
    assert loaded.margin < bare.margin  # the static margin falls with the weight held


def test_follower_load_refused_by_the_static_analyses(model):
    """A body-fixed load's K is not symmetric: the programmes refuse it in one ParameterError naming 'loads'."""
    with pytest.raises(ParameterError, match="loads: must be fixed in the ground"):
        coupled_stability_at(model, E, LAMBDA, PCSA, loads=[PointLoad((0.0, -10.0), "body")])
