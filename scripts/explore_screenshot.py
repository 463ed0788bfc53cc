"""Take the screenshot of ``spinectl explore`` shown in docs/explore.md.

    python scripts/explore_screenshot.py                 # writes docs/images/explore.png
    python scripts/explore_screenshot.py --out shot.png
    python scripts/explore_screenshot.py --url http://127.0.0.1:5006/ --out shot.png   # an explorer running

Serves the explorer from this checkout on a free loopback port (or takes the one at ``--url``), opens it in the
system's headless Chromium (tests/explore/browser_harness.py; scripts/setup installs
Chromium), waits for the landscapes, and saves the page as a palette PNG (small enough
to commit). Run it again after a change that shows in the app.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "explore"))

import browser_harness  # noqa: E402

COLOURS = 256
"""Colours of the committed PNG (a palette image is a third of the size of a full-colour one)."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "explore.png")
    parser.add_argument("--url", help="an explorer already running (default: serve one from this checkout)")
    args = parser.parse_args()
    executable = browser_harness.chromium()
    if executable is None:
        sys.exit(f"no Chromium at {browser_harness.CHROMIUM}: {browser_harness.INSTALL}")
    served = contextlib.nullcontext(args.url) if args.url else browser_harness.served()
    with served as url, browser_harness.opened(url, executable) as page:
        page.get_by_text("solved in").wait_for()  # the landscapes are drawn
        page.wait_for_timeout(1000)  # Bokeh paints its canvas after the data arrive
        shot = page.screenshot(clip={"x": 0, "y": 0, "width": 1390, "height": 900})
    image = Image.open(io.BytesIO(shot)).convert("RGB").quantize(COLOURS, method=Image.Quantize.FASTOCTREE)
    image.save(args.out, optimize=True)
    print(args.out)


if __name__ == "__main__":
    main()
