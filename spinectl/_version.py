"""The version of spinectl, in the basics layer so that any layer can name it in its outputs.

The package root re-exports it as ``spinectl.__version__``; ``pyproject.toml`` states the
same number for the packagers (``tests/suites/test_architecture.py`` checks that they agree).
"""

__version__ = "0.1.0"
