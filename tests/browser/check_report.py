#!/usr/bin/env python3
"""Opens `rmapgen render`'s report.html in a real headless browser and checks what a reader
sees: every image decodes at the size of the PNG it carries, the figures' table is there, and
the page logs no error. Usage:

    check_report.py REPORT.html [--metrics metrics.json] [--self-test] [--chromium PATH]

Chromium is Debian's (/usr/bin/chromium, or $CHROMIUM), driven by Playwright from PyPI with
`executable_path` (Playwright's own browser download is not used). `--metrics` also requires
one image for every PNG the render's metrics.json lists. `--self-test` first shows that the
check fails: on copies of the report with one image's data corrupted, one image's source
missing, and the table removed, each must be refused, naming what is wrong. Exit 0 when
the report passes (and the self-test refused every copy), 1 when not, 2 for bad input.
"""

import argparse
import base64
import json
import os
import re
import struct
import sys
import tempfile
from pathlib import Path

from chromium import CHROMIUM_ARGS

IMG = re.compile(r'<img alt="([^"]*)" src="data:image/png;base64,([A-Za-z0-9+/=]*)">')


def png_size(data: bytes):
    """Width and height from a PNG's IHDR, or None when it is not a PNG."""
    if len(data) < 24 or data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
        return None
    return struct.unpack(">II", data[16:24])


def expected_images(html: str):
    """(alt, width, height) of every embedded image, from the page's own bytes."""
    out = []
    for alt, b64 in IMG.findall(html):
        size = png_size(base64.b64decode(b64))
        out.append((alt, size))
    return out


def check(page, path: Path, metrics) -> list:
    """Every problem a reader of `path` would meet, as one line each (empty: it passes)."""
    html = path.read_text()
    want = expected_images(html)
    errors = []
    console = []
    page.on("console", lambda m: console.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: console.append(str(e)))
    page.goto(path.resolve().as_uri(), wait_until="load")
    seen = page.evaluate(
        """() => Array.from(document.images).map(i => ({
            alt: i.alt, complete: i.complete, w: i.naturalWidth, h: i.naturalHeight,
            shown: i.getBoundingClientRect().width }))"""
    )
    if not seen:
        errors.append("no image on the page")
    by_alt = {s["alt"]: s for s in seen}
    for alt, size in want:
        s = by_alt.get(alt)
        if s is None:
            errors.append(f"image {alt!r}: not on the page")
        elif size is None:
            errors.append(f"image {alt!r}: its data is not a PNG")
        elif not s["complete"] or (s["w"], s["h"]) != tuple(size):
            errors.append(
                f"image {alt!r}: the browser decoded {s['w']}x{s['h']}, the PNG is {size[0]}x{size[1]}"
            )
        elif s["shown"] <= 0:
            errors.append(f"image {alt!r}: laid out with no width")
    for s in seen:
        if not s["complete"] or s["w"] == 0:
            errors.append(f"image {s['alt']!r}: did not load")
        if s["alt"] not in {a for a, _ in want}:
            errors.append(f"image {s['alt']!r}: not an embedded PNG (src is elsewhere)")
    if metrics is not None:
        for name in metrics:
            if name not in by_alt:
                errors.append(f"image {name!r} of metrics.json: not on the page")
    rows = page.evaluate(
        "() => Array.from(document.querySelectorAll('tr')).map(r => r.innerText)"
    )
    for label in ("largest error", "PSNR"):
        if not any(label in r for r in rows):
            errors.append(f"the figures' table has no {label!r} row")
    for c in console:
        errors.append(f"the page logged an error: {c}")
    return errors


def metrics_images(path: Path):
    """The PNG names a render's metrics.json lists, wherever in it they are."""
    names = []

    def walk(v):
        if isinstance(v, str) and v.endswith(".png"):
            names.append(v)
        elif isinstance(v, dict):
            for x in v.values():
                walk(x)
        elif isinstance(v, list):
            for x in v:
                walk(x)

    walk(json.loads(path.read_text()))
    return names


def faults(html: str):
    """(what, page) copies of the report that a sound check must refuse."""
    m = IMG.search(html)
    if m is None:
        return []
    alt, b64 = m.group(1), m.group(2)
    raw = bytearray(base64.b64decode(b64))
    # Keep the PNG signature and header, break the image data: the browser cannot decode it.
    raw[33:] = b"\x00" * (len(raw) - 33)
    broken = base64.b64encode(bytes(raw)).decode()
    return [
        (f"corrupt data in {alt!r}", html.replace(b64, broken, 1)),
        (
            f"{alt!r} from a missing file",
            html.replace(m.group(0), f'<img alt="{alt}" src="missing-{os.getpid()}.png">', 1),
        ),
        ("no table", re.sub(r"<table>.*?</table>", "", html, flags=re.S)),
    ]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report", type=Path)
    ap.add_argument("--metrics", type=Path)
    ap.add_argument("--self-test", action="store_true")
    ap.add_argument("--chromium", default=os.environ.get("CHROMIUM", "/usr/bin/chromium"))
    a = ap.parse_args()
    for p in [a.report] + ([a.metrics] if a.metrics else []):
        if not p.is_file():
            print(f"check_report: {p}: no such file", file=sys.stderr)
            return 2
    if not os.access(a.chromium, os.X_OK):
        print(f"check_report: {a.chromium}: no Chromium there (apt-get install chromium)", file=sys.stderr)
        return 2
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        print("check_report: playwright is not installed (make venv)", file=sys.stderr)
        return 2
    metrics = metrics_images(a.metrics) if a.metrics else None
    html = a.report.read_text()
    failed = False
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=a.chromium, args=CHROMIUM_ARGS)
        try:
            if a.self_test:
                cases = faults(html)
                if not cases:
                    print("check_report: the report has no image to corrupt", file=sys.stderr)
                    return 1
                with tempfile.TemporaryDirectory() as tmp:
                    for what, page_html in cases:
                        copy = Path(tmp) / "report.html"
                        copy.write_text(page_html)
                        page = browser.new_page()
                        errs = check(page, copy, None)
                        page.close()
                        if errs:
                            print(f"self-test: {what}: refused ({errs[0]})")
                        else:
                            print(f"self-test: {what}: PASSED, the check cannot see it")
                            failed = True
            page = browser.new_page()
            errs = check(page, a.report, metrics)
            page.close()
        finally:
            browser.close()
    for e in errs:
        print(f"{a.report}: {e}")
    if errs or failed:
        return 1
    n = len(expected_images(html))
    print(f"{a.report}: {n} images decoded at their size in {a.chromium}; the figures are shown")
    return 0


if __name__ == "__main__":
    sys.exit(main())
