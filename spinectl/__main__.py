"""``python -m spinectl``: the command-line interface."""

from spinectl.cli import main

raise SystemExit(main())
