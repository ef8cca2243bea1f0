#!/usr/bin/env python3
"""`rmapgen explore` in a real headless browser, as a user drives it. Usage:

    check_explore.py RMAPGEN [--chromium PATH] [--size N]

Starts `RMAPGEN explore --port 0` (the address it prints), opens the page in Debian's
Chromium (/usr/bin/chromium or $CHROMIUM) driven by Playwright with `executable_path`, waits
for the first render, then moves the index_bits slider one step with the keyboard and waits
for the new render. It checks:
- the design's image, as the page shows it (drawn on a canvas and read back), has the pixels
  of `RMAPGEN render` of the same configuration (index_bits + 1), and the bytes of every
  image the page shows equal that render's files (model, reference, signed error);
- the figures shown are that render's metrics.json;
- a click on the worst pixel of the design's image shows its path: the gradient of that pixel,
  every stage's ports (u_sort_shift.m_o ... i_o), and i_o equal to the pixel's value;
- the configuration the page saves is the render's configuration;
- switched to the volume, the page shows `RMAPGEN volume --synthetic` of the configuration and
  scene it saves (pixels and bytes), and a click on its worst pixel lists the samples of that
  pixel's ray and traces the heaviest: i_o equal to that sample's intensity in the list.
Before that it shows that the check can fail: against the render of the configuration before
the slider moved, the image must be refused. Last, a slow render (the fitted table) is stopped
with the page's button, and the page must say it was. Exit 0 when all pass, 1 when not, 2 for bad input.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import urllib.error
import urllib.request
import zlib
from pathlib import Path

from chromium import CHROMIUM_ARGS


def grey_png(data: bytes):
    """Width, height and rows of an 8-bit greyscale, non-interlaced PNG."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "a PNG"
    pos, idat = 8, b""
    w = h = None
    while pos < len(data):
        n = int.from_bytes(data[pos:pos + 4], "big")
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h = int.from_bytes(body[0:4], "big"), int.from_bytes(body[4:8], "big")
            assert body[8] == 8 and body[9] == 0 and body[12] == 0, "8-bit grey, not interlaced"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    rows, prev = [], bytearray(w)
    for y in range(h):
        f, line = raw[y * (w + 1)], bytearray(raw[y * (w + 1) + 1:(y + 1) * (w + 1)])
        for x in range(w):
            a = line[x - 1] if x else 0
            b, c = prev[x], prev[x - 1] if x else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else b if pb <= pc else c
                line[x] = (line[x] + pr) & 255
        rows.append(bytes(line))
        prev = line
    return w, h, rows


def cli_render(rmapgen, index_bits, size, out):
    subprocess.run([rmapgen, "render", "--index-bits", str(index_bits), "--size", str(size),
                    "--out", str(out), "--force"], check=True, capture_output=True)
    return out


def shown_pixels(page, sel):
    """The image as the page shows it: drawn on a canvas, read back, one byte a pixel."""
    return page.evaluate(
        """(sel) => { const img = document.querySelector(sel);
            const c = document.createElement('canvas');
            c.width = img.naturalWidth; c.height = img.naturalHeight;
            const g = c.getContext('2d'); g.drawImage(img, 0, 0);
            const d = g.getImageData(0, 0, c.width, c.height).data;
            const out = []; for (let i = 0; i < d.length; i += 4) out.push(d[i]);
            return {w: c.width, h: c.height, v: out}; }""", sel)


def image_bytes(page, sel):
    return bytes(page.evaluate(
        """async (sel) => { const r = await fetch(document.querySelector(sel).src);
            return Array.from(new Uint8Array(await r.arrayBuffer())); }""", sel))


def compare(page, render_dir, errors):
    """The shown images against a CLI render's files."""
    w, h, rows = grey_png((render_dir / "model.png").read_bytes())
    s = shown_pixels(page, "#model")
    if (s["w"], s["h"]) != (w, h):
        errors.append(f"the design's image is {s['w']}x{s['h']}, the CLI's {w}x{h}")
        return
    flat = b"".join(rows)
    bad = [i for i in range(len(flat)) if flat[i] != s["v"][i]]
    if bad:
        i = bad[0]
        errors.append(f"the design's image differs from the CLI's render in {len(bad)} pixels, "
                      f"first at ({i % w}, {i // w}): shown {s['v'][i]}, CLI {flat[i]}")
    for sel, name in (("#model", "model.png"), ("#reference", "reference.png"),
                      ("#error", "error_signed.png")):
        if image_bytes(page, sel) != (render_dir / name).read_bytes():
            errors.append(f"{sel}: its bytes are not the CLI's {name}")


def figures(page, render_dir, errors, what):
    """The render's metrics.json; the largest error the page shows must be its."""
    m = json.loads((render_dir / "metrics.json").read_text())
    shown = page.eval_on_selector("#max_abs_error", "e => e.textContent")
    if shown != str(m["max_abs_error"]):
        errors.append(f"{what}: largest error shown {shown}, metrics.json {m['max_abs_error']}")
    return m


def click_pixel(page, size, x, y):
    """Clicks pixel (x, y) of the design's image and waits for its trace."""
    box = page.eval_on_selector("#model", "e => [e.clientWidth, e.clientHeight]")
    page.click("#model", position={"x": (x + 0.5) * box[0] / size, "y": (y + 0.5) * box[1] / size})
    page.wait_for_function("(p) => document.body.dataset.traced === p", arg=f"{x},{y}", timeout=20000)


def wait_render(page, after):
    page.wait_for_function(
        "(after) => document.body.dataset.renderId && document.body.dataset.renderId !== after"
        " || document.body.dataset.error", arg=after, timeout=60000)
    err = page.evaluate("() => document.body.dataset.error || null")
    if err:
        raise SystemExit(f"check_explore: the page says: {err}")
    return page.evaluate("() => document.body.dataset.renderId")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rmapgen")
    ap.add_argument("--chromium", default=os.environ.get("CHROMIUM", "/usr/bin/chromium"))
    a = ap.parse_args()
    if not os.access(a.chromium, os.X_OK):
        print(f"check_explore: {a.chromium}: no Chromium there (apt-get install chromium)", file=sys.stderr)
        return 2
    from playwright.sync_api import sync_playwright

    server = subprocess.Popen([a.rmapgen, "explore", "--port", "0"], stdout=subprocess.PIPE,
                              text=True, start_new_session=True)
    errors = []
    try:
        line = server.stdout.readline()
        if not line.startswith("explore: http://127.0.0.1:"):
            print(f"check_explore: the explorer said {line!r}", file=sys.stderr)
            return 1
        url = line.split()[1]
        with tempfile.TemporaryDirectory() as tmp, sync_playwright() as pw:
            tmp = Path(tmp)
            browser = pw.chromium.launch(executable_path=a.chromium, args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            logged = []
            page.on("console", lambda m: logged.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: logged.append(str(e)))
            page.goto(url)
            first = wait_render(page, "")
            size = int(page.eval_on_selector("#size", "e => e.value"))
            ib = int(page.eval_on_selector("#w-index_bits", "e => e.value"))
            # Move the slider as a user does: focus it and press the right arrow.
            page.focus("#w-index_bits")
            page.keyboard.press("ArrowRight")
            second = wait_render(page, first)
            if int(page.eval_on_selector("#w-index_bits", "e => e.value")) != ib + 1:
                errors.append("the slider did not move")
            before = cli_render(a.rmapgen, ib, size, tmp / "before")
            after = cli_render(a.rmapgen, ib + 1, size, tmp / "after")
            # The check can fail: the render before the move is not what the page shows now.
            wrong = []
            compare(page, before, wrong)
            if not wrong:
                errors.append("self-test: the image before the slider moved PASSED the check")
            else:
                print(f"self-test: the render before the move: refused ({wrong[0]})")
            compare(page, after, errors)
            m = figures(page, after, errors, "sphere")
            # Click the worst pixel: its path through the pipeline.
            wx, wy = m["worst"]["x"], m["worst"]["y"]
            click_pixel(page, size, wx, wy)
            names = page.eval_on_selector_all("#trace tr[data-name]", "rs => rs.map(r => r.dataset.name)")
            for want in ("u_sort_shift.m_o", "u_normalise.u_o", "u_atan_rom.pu_o",
                         "u_map_lookup.e00_o", "u_interpolate.i_o", "i_o"):
                if want not in names:
                    errors.append(f"the trace has no {want}")
            i_o = page.eval_on_selector('#trace tr[data-name="i_o"] .value', "e => e.textContent")
            if int(i_o) != m["worst"]["model"]:
                errors.append(f"the trace's i_o is {i_o}, the pixel's value {m['worst']['model']}")
            head = page.eval_on_selector("#trace-head", "e => e.textContent")
            g = ", ".join(str(c) for c in m["worst"]["gradient"])
            if f"gradient ({g})" not in head:
                errors.append(f"the trace is of another gradient: {head!r}, want ({g})")
            # The configuration the page saves: what generate --config reads. The API answers
            # the page's token and nothing else.
            rid = page.evaluate("() => document.body.dataset.renderId")
            token = page.eval_on_selector('meta[name="rmapgen-token"]', "e => e.content")
            get = lambda path: urllib.request.urlopen(urllib.request.Request(
                f"{url}{path}", headers={"X-Rmapgen-Token": token})).read()
            try:
                urllib.request.urlopen(f"{url}api/config.toml?id={rid}")
                errors.append("the API answered a request without the token")
            except urllib.error.HTTPError as e:
                if e.code != 403:
                    errors.append(f"without the token the API answered {e.code}, not 403")
            saved = get(f"api/config.toml?id={rid}").decode()
            if f"index_bits = {ib + 1}" not in saved.splitlines():
                errors.append(f"the saved config.toml has not index_bits = {ib + 1}:\n{saved}")
            with page.expect_download() as dl:
                page.click("#save-config")
            if dl.value.suggested_filename != "config.toml":
                errors.append(f"the save button saves {dl.value.suggested_filename}")
            elif Path(dl.value.path()).read_text() != saved:
                errors.append("the save button's config.toml is not the API's")
            # The volume: the engine block, as `rmapgen volume --synthetic` renders it from the
            # configuration and scene the page saves.
            page.select_option("#object", "volume")
            third = wait_render(page, rid)
            cfg_file, scene_file = tmp / "v-config.toml", tmp / "v-scene.toml"
            for f, what in ((cfg_file, "config"), (scene_file, "scene")):
                f.write_bytes(get(f"api/{what}.toml?id={third}"))
            vol = tmp / "volume"
            subprocess.run([a.rmapgen, "volume", "--synthetic", "--config", str(cfg_file),
                            "--scene", str(scene_file), "--size", str(size), "--out", str(vol),
                            "--force"], check=True, capture_output=True)
            compare(page, vol, errors)
            vm = figures(page, vol, errors, "volume")
            vx, vy = vm["worst"]["x"], vm["worst"]["y"]
            click_pixel(page, size, vx, vy)
            rows = page.eval_on_selector_all("#samples tr", "rs => rs.length") - 1
            heaviest = page.eval_on_selector("#samples tr.module td:nth-child(4)", "e => e.textContent")
            v_i_o = page.eval_on_selector('#trace tr[data-name="i_o"] .value', "e => e.textContent")
            head = page.eval_on_selector("#trace-head", "e => e.textContent")
            if rows < 1:
                errors.append("volume: the clicked pixel lists no samples")
            if v_i_o != heaviest:
                errors.append(f"volume: the trace's i_o is {v_i_o}, the heaviest sample's intensity {heaviest}")
            if f"model {vm['worst']['model']}," not in head:
                errors.append(f"volume: the trace is not of the worst pixel (model {vm['worst']['model']}): {head!r}")
            errors += [f"the page logged an error: {e}" for e in logged]
            # A slow render (the fitted table) stopped with the page's button: the page says
            # why (the 503 it answers is logged by the browser, and expected).
            page.select_option("#comp_table", "ram")
            wait_render(page, page.evaluate("() => document.body.dataset.renderId"))
            page.select_option("#map_fit", "table")
            stopped = None
            for _ in range(600):
                if page.is_visible("#stop"):
                    page.click("#stop")
                stopped = page.evaluate("() => document.body.dataset.error || null")
                if stopped:
                    break
                page.wait_for_timeout(100)
            if stopped != "cancelled: stopped by a request to /api/cancel":
                errors.append(f"the stop button: the page says {stopped!r}")
            browser.close()
            print(f"check_explore: renders {first} and {second}, index_bits {ib} -> {ib + 1}; "
                  f"traced ({wx}, {wy}): i_o = {i_o}; volume render {third}, pixel ({vx}, {vy}) "
                  f"blends {rows} samples, the heaviest's i_o = {v_i_o}")
    finally:
        os.killpg(server.pid, 15)
        server.wait()
    for e in errors:
        print(f"check_explore: {e}")
    if errors:
        return 1
    print("check_explore: the page shows the CLI's renders (sphere and volume) pixel for pixel, "
          "their figures and the traces")
    return 0


if __name__ == "__main__":
    sys.exit(main())
