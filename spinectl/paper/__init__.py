"""The paper's study (Wagner et al. 2012, doi:10.1186/1742-4682-9-13): its grid, landmarks, figures and verdicts.

docs/reproduction.md. The paper's grid and stiffnesses (:mod:`~spinectl.paper.grid`),
its landmarks measured on a landscape (:mod:`~spinectl.paper.landmarks`), the verdict
on each (:mod:`~spinectl.paper.verdicts`), Figures 3, 4 and S1
(:mod:`~spinectl.paper.figures`), the report (:mod:`~spinectl.paper.report`), the
calibration of the unstated parameters (:mod:`~spinectl.paper.calibration`) and the
main job, :func:`spinectl.paper.reproduce` (:mod:`~spinectl.paper.reproduction`).

Symbols and units: docs/glossary.md.
"""

from .reproduction import reproduce

__all__ = ["reproduce"]
