"""The design question: how much intrinsic stiffness does a given reflex delay need? (``spinectl design``).

Two answers at one (E, Lambda), one per criterion (docs/reflex.md, "The design question"): joint by joint
(each CoR alone, the others fixed; the paper's criterion) the least co-contraction,
:mod:`~spinectl.reflex.design.joint`; for the chain (every CoR free) the least local stiffness at the
reflex's activation, :mod:`~spinectl.reflex.design.chain` (with its independent check, the rightmost root,
:mod:`~spinectl.reflex.design.roots`). Both at one delay (:func:`design`) or against the delay
(:func:`delay_curve`) by the same search, :mod:`~spinectl.reflex.design.curve`; the answers as data,
:mod:`~spinectl.reflex.design.result`; the chain against the passive stiffness (``--passive``),
:mod:`~spinectl.reflex.design.passive`; over every diagonal PD reflex (the rule's answer beside it), with the
cost of a delay margin, :mod:`~spinectl.reflex.design.gain_searched`.
"""

from .chain import CHAIN_SCAN, chain_curve, chain_design, chain_loop_at
from .curve import delay_curve, design
from .gain_searched import (
    COST_RATIO,
    SEARCH_BUDGET,
    SEARCH_SEED,
    SEARCH_STEPS,
    GainSearchedDesign,
    MarginCost,
    answer,
    gain_searched_design,
)
from .joint import BISECTIONS, SCAN, joint_design, least_activations, scan_margins, segment_margins_at
from .joint_searched import JointSearchedDesign, joint_searched_design
from .passive import (
    CRISCO_LOAD,
    PAPER_PASSIVE,
    THRESHOLD_TOLERANCE,
    PassiveCurve,
    crisco_stiffness,
    passive_chain_model,
    passive_curve,
)
from .result import LOCAL_MAX, REACTION_TIMES, ChainDesign, Design, DesignCurve, SegmentDesign
from .roots import MAX_EXPONENT, SPECTRAL_NODES, rightmost_root

__all__ = [
    "BISECTIONS",
    "CHAIN_SCAN",
    "COST_RATIO",
    "CRISCO_LOAD",
    "LOCAL_MAX",
    "MAX_EXPONENT",
    "PAPER_PASSIVE",
    "REACTION_TIMES",
    "SCAN",
    "SEARCH_BUDGET",
    "SEARCH_SEED",
    "SEARCH_STEPS",
    "SPECTRAL_NODES",
    "THRESHOLD_TOLERANCE",
    "ChainDesign",
    "Design",
    "DesignCurve",
    "GainSearchedDesign",
    "JointSearchedDesign",
    "MarginCost",
    "PassiveCurve",
    "SegmentDesign",
    "answer",
    "chain_curve",
    "chain_design",
    "chain_loop_at",
    "crisco_stiffness",
    "delay_curve",
    "design",
    "gain_searched_design",
    "joint_design",
    "joint_searched_design",
    "least_activations",
    "passive_chain_model",
    "passive_curve",
    "rightmost_root",
    "scan_margins",
    "segment_margins_at",
]
