"""``docs/studies.md``'s estimate line, as ``spinectl study`` states it before a long run, at the build.

The study of the page's example (1000 x 1000 points of E and Lambda over 0-8 cm, 100 values of K, every output,
the default chunk size) estimated for 2 local workers by :func:`spinectl.landscape.study.run.estimate` from the
outputs at one point, as ``run_study`` does before it makes the store (about a second; nothing is solved beyond
the probe point).
"""

from __future__ import annotations

EXAMPLE = """[axes]
E = { start = 0.0, stop = 0.08, num = 1000 }
Lambda = { start = 0.0, stop = 0.08, num = 1000 }
K = { start = 0.0, stop = 99.0, num = 100 }
"""
"""The page's example study: 1000 x 1000 points x 100 values of K, all outputs (the default)."""

WORKERS = 2
"""Local worker processes of the example."""


def estimate_line() -> str:
    """The line ``spinectl study`` prints first for :data:`EXAMPLE` with :data:`WORKERS` local workers."""
    from spinectl.landscape import study
    from spinectl.landscape.study import run

    parsed = study.parse_study(EXAMPLE)
    return run.estimate(parsed, parsed.n_chunks, run._probe(parsed), WORKERS).line()


def estimate_block() -> str:
    """:func:`estimate_line` in a ``text`` block (``_generated/studies-estimate.md``)."""
    return "```text\n" + estimate_line() + "\n```\n"
