"""The table of ``docs/reflex.md`` that ``spinectl design --decay-rate`` produces, measured at the build.

The ``wagner2012`` preset at E = 3 cm, Lambda = 4 cm, a 100 ms delay: the chain's least local stiffness for
stability alone and for each least decay rate, with its rightmost root, so that the page's numbers are those the
command prints, never typed.
"""

from __future__ import annotations

import numpy as np

from spinectl.model.config import load_preset

POINT = (0.03, 0.04)
"""E and Lambda [m]."""

DECAY_RATES = (0.0, 0.05, 0.1, 0.15, 0.2)
"""The decay rates sigma [1/s] of the rows (0: stability at the delay alone, ``--decay-rate`` not given)."""


def decay_table() -> str:
    """One row per decay rate: the total local stiffness, its multiple of k*, the rightmost root, the margin."""
    from spinectl.reflex.delay import delay_text
    from spinectl.reflex.design import answer

    model = load_preset("wagner2012")
    lines = [
        "| `--decay-rate` [1/s] | local stiffness, total [N m/rad] | multiple of k* | rightmost root Re s [1/s] "
        "| exact delay margin |",
        "| --- | --- | --- | --- | --- |",
    ]
    for sigma in DECAY_RATES:
        chain = answer(model, *POINT, decay=sigma).chain
        if np.isfinite(chain.fraction):
            cells = (
                f"{np.sum(chain.local_stiffness):.1f} | {chain.fraction:.4f} | {chain.max_root_real:.4g} | "
                f"{delay_text(chain.delay_margin)}"
            )
        else:
            cells = "none up to k* | - | - | -"
        lines.append(f"| {sigma:g}{' (not given)' if sigma == 0 else ''} | {cells} |")
    return "\n".join(lines) + "\n"
