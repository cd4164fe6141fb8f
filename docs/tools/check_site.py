"""Look at the built docs site in headless Chromium, as a reader's browser shows it.

Usage: ``python docs/tools/check_site.py SITE_DIR [SHOTS_DIR]`` (after ``mkdocs build -d SITE_DIR``;
``.ci/run`` calls it). The site is served over HTTP from a local port (pages with fragments
and the search index need a server, not ``file://``), and three pages are rendered: the API
page of the estimators (``LPC`` documented from its docstring), the walk-through, and a
notebook (its figures executed at build time and embedded as PNG). For each, the DOM
Chromium built must hold the page's landmarks, and a screenshot must not be blank. Exits 1
with one line per failure; the screenshots are kept in ``SHOTS_DIR`` when given. Needs
``chromium`` (or ``chromium-browser``) on PATH.
"""

from __future__ import annotations

import functools
import http.server
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

#: page -> strings its rendered DOM must contain
PAGES: dict[str, tuple[str, ...]] = {
    "api/estimators.html": ('id="clpc.LPC"', "fit", "Parameters"),
    "walkthrough.html": ("Walk-through", "clpc identify"),
    "examples/track_a_drive.html": ("Track a drive", "data:image/png;base64,", "converged=True"),
}


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    """Serves the site's files without a log line per request."""

    def log_message(self, format: str, *args: object) -> None:
        pass


def _render(browser: str, url: str, profile: Path, shot: Path) -> str:
    cmd = [
        browser, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        f"--user-data-dir={profile}", "--window-size=1200,1600", "--virtual-time-budget=5000",
    ]  # fmt: skip
    dom = subprocess.run(
        [*cmd, "--dump-dom", url], capture_output=True, text=True, timeout=120, check=True
    ).stdout
    shoot = [*cmd, f"--screenshot={shot}", url]
    subprocess.run(shoot, capture_output=True, timeout=120, check=True)
    return dom


def _blank(shot: Path) -> bool:
    from matplotlib.image import imread

    pixels = imread(shot)[..., :3]
    return float(pixels.std()) < 0.05


def main(site: Path, shots: Path | None = None) -> int:
    """Render :data:`PAGES` of the built ``site``; 0 when every page shows its landmarks."""
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        print("check_site: no chromium on PATH", file=sys.stderr)
        return 1
    handler = functools.partial(_QuietHandler, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    failures = []
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for page, landmarks in PAGES.items():
                url = f"http://127.0.0.1:{server.server_address[1]}/{page}"
                shot = Path(shots or tmp) / (page.replace("/", "_") + ".png")
                dom = _render(browser, url, Path(tmp) / "profile", shot)
                missing = [m for m in landmarks if m not in dom]
                if missing:
                    failures.append(f"{page}: the rendered page lacks {missing}")
                if _blank(shot):
                    failures.append(f"{page}: the screenshot is blank")
                else:
                    print(f"check_site: {page} rendered ({len(dom)} characters of DOM)")
    finally:
        server.shutdown()
    for line in failures:
        print(f"check_site: {line}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]), Path(sys.argv[2]) if len(sys.argv) > 2 else None))
