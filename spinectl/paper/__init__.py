"""The paper's study (Wagner et al. 2012, doi:10.1186/1742-4682-9-13): its grid, landmarks, figures and verdicts.

docs/reproduction.md; the main job is :func:`spinectl.paper.reproduce`; the modules: CONTRIBUTING.md's
map; symbols and units: docs/glossary.md.
"""

from .reproduction import reproduce

__all__ = ["reproduce"]
