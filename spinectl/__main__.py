"""``python -m spinectl``: the command-line interface."""

from .cli import main

if __name__ == "__main__":  # not when imported, e.g. by the docs' walk of the package
    raise SystemExit(main())
