"""Screenshot a report in headless Chromium: ``python scripts/screenshot_report.py REPORT.html OUT.png``.

Opens ``report.html`` from disk (no server) with the flags below and writes a
PNG of the first ``--height`` pixels of the page at 1280 px width. Exit status
2 with a one-line message when chromium is missing or fails.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
)


def find_chromium() -> str | None:
    """Path of the chromium binary, or None."""
    if Path(CHROMIUM).is_file():
        return CHROMIUM
    return shutil.which("chromium") or shutil.which("chromium-browser")


def screenshot(
    html: Path, png: Path, *, width: int = 1280, height: int = 4000, timeout: float = 120.0
) -> Path:
    """Render ``html`` to ``png``; raise RuntimeError when chromium is missing or fails."""
    exe = find_chromium()
    if exe is None:
        raise RuntimeError("chromium not found")
    html = Path(html).resolve()
    if not html.is_file():
        raise RuntimeError(f"{html}: no such file")
    png = Path(png).resolve()
    png.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="fepost-chromium-") as profile:
        cmd = [
            exe,
            *FLAGS,
            f"--user-data-dir={profile}",
            f"--screenshot={png}",
            f"--window-size={width},{height}",
            html.as_uri(),
        ]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0 or not png.is_file() or png.stat().st_size == 0:
        last = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"chromium failed (exit {proc.returncode}): {last}")
    return png


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("html", type=Path, help="report.html")
    p.add_argument(
        "png",
        type=Path,
        nargs="?",
        help="output PNG (default: report_screenshot.png beside the HTML)",
    )
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=4000)
    args = p.parse_args(argv)
    png = args.png or args.html.with_name("report_screenshot.png")
    try:
        screenshot(args.html, png, width=args.width, height=args.height)
    except (RuntimeError, OSError, subprocess.TimeoutExpired) as exc:
        print(f"screenshot_report: error: {exc}", file=sys.stderr)
        return 2
    print(png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
