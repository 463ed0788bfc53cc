"""The table of ``docs/reflex.md`` that ``spinectl design --decay-rate`` produces, measured at the build.

The ``wagner2012`` preset at E = 3 cm, Lambda = 4 cm, a 100 ms delay: the least co-contraction joint by joint and
the chain's least local stiffness for stability alone and for each least decay rate, with the chain's rightmost
root, so that the page's numbers are those the
command prints, never typed.
"""

from __future__ import annotations

import numpy as np

from spinectl.model.config import load_preset

POINT = (0.03, 0.04)
"""E and Lambda [m]."""

DECAY_RATES = (0.0, 0.05, 0.1, 0.15, 0.2, 0.5)
"""The decay rates sigma [1/s] of the rows (0: stability at the delay alone, ``--decay-rate`` not given)."""


def decay_table() -> str:
    """One row per decay rate: the common co-contraction joint by joint; the chain's total local stiffness, its
    multiple of k*, its rightmost root and its exact delay margin."""
    from spinectl.reflex.delay import delay_text
    from spinectl.reflex.design import answer

    model = load_preset("wagner2012")
    lines = [
        "| `--decay-rate` [1/s] | joint by joint: co-contraction [1] | chain: local stiffness, total [N m/rad] "
        "| multiple of k* | rightmost root Re s [1/s] | exact delay margin |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for sigma in DECAY_RATES:
        result = answer(model, *POINT, decay=sigma)
        chain = result.chain
        joint = f"{result.activation:.4f}" if np.isfinite(result.activation) else "none in [0, 1]"
        if np.isfinite(chain.fraction):
            cells = (
                f"{np.sum(chain.local_stiffness):.1f} | {chain.fraction:.4f} | {chain.max_root_real:.4g} | "
                f"{delay_text(chain.delay_margin)}"
            )
        else:
            cells = "none up to k* | - | - | -"
        lines.append(f"| {sigma:g}{' (not given)' if sigma == 0 else ''} | {joint} | {cells} |")
    return "\n".join(lines) + "\n"
