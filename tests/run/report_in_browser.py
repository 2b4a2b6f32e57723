#!/usr/bin/env python3
"""report.html in a real browser: headless Chromium loads the page identify
wrote, its DOM must hold the status, the estimates, warnings, sweeps and
validation tables and one inline SVG per figure image of the run, and its
screenshot must not be blank (many colours, a fair share of non-white pixels).

  report_in_browser.py IDENTIFY CONFIG WORK_DIR [--validation]

--validation: the run has validation prediction intervals, so the page must
hold their table too.

Without a browser (chromium on PATH) it says so and exits 77, which CTest
reports as skipped.
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

SKIP = 77


def png_pixels(path):
    """The RGB(A) rows of an 8-bit, non-interlaced PNG, unfiltered."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        raise SystemExit(f"{path}: unexpected PNG format {header}")
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, row = line[0], bytearray(line[1:])
        for i in range(stride):
            left = row[i - channels] if i >= channels else 0
            up = previous[i]
            upper_left = previous[i - channels] if i >= channels else 0
            if kind == 1:
                row[i] = (row[i] + left) & 0xFF
            elif kind == 2:
                row[i] = (row[i] + up) & 0xFF
            elif kind == 3:
                row[i] = (row[i] + (left + up) // 2) & 0xFF
            elif kind == 4:
                p = left + up - upper_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - upper_left)
                predictor = left if pa <= pb and pa <= pc else (up if pb <= pc else upper_left)
                row[i] = (row[i] + predictor) & 0xFF
        rows.append(bytes(row))
        previous = row
    return width, height, channels, rows


def main():
    identify, config, work = sys.argv[1:4]
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        print("report_in_browser: SKIPPED: no chromium on PATH "
              "(apt-get install chromium, or bash cmake/install-debian-deps.sh)")
        return SKIP
    shutil.rmtree(work, ignore_errors=True)
    out = os.path.join(work, "out")
    run = subprocess.run([identify, "--config", config, "--output_dir", out],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(f"identify exited {run.returncode}:\n{run.stderr}")
    page = "file://" + os.path.abspath(os.path.join(out, "report.html"))
    flags = ["--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
             f"--user-data-dir={os.path.join(work, 'profile')}"]
    dom = subprocess.run([browser, *flags, "--dump-dom", page], capture_output=True,
                         text=True, timeout=120).stdout
    svgs = [n for n in os.listdir(out) if n.endswith(".svg")]
    checks = {
        "the status": r'<div class="status ok" id="status"><b>converged</b>',
        "the estimates table": r'<table id="estimates">(.|\n)*eta_e',
        "the warnings": r'<ul id="warnings">',
        "the sweeps table": r'<table id="sweeps">(.|\n)*% from the bracket centre',
        "the configuration": r'<pre id="config">',
    }
    if "--validation" in sys.argv[4:]:
        checks["the validation table"] = r'<table id="validation">(.|\n)*jump-down'
    failures = [name for name, pattern in checks.items() if not re.search(pattern, dom)]
    if len(svgs) < 2 or dom.count("<svg") != len(svgs):
        failures.append(f"{len(svgs)} SVG files, {dom.count('<svg')} inline <svg> in the DOM")
    shot = os.path.join(work, "report.png")
    subprocess.run([browser, *flags, f"--screenshot={shot}", "--window-size=1200,3000", page],
                   capture_output=True, timeout=120)
    if not os.path.exists(shot):
        failures.append("no screenshot")
    else:
        width, height, channels, rows = png_pixels(shot)
        colours, non_white, total = set(), 0, 0
        for row in rows[::7]:
            for x in range(0, width * channels, channels * 5):
                pixel = row[x:x + 3]
                colours.add(pixel)
                non_white += pixel != b"\xff\xff\xff"
                total += 1
        if len(colours) < 20 or non_white < 0.02 * total:
            failures.append(f"a blank-looking screenshot: {len(colours)} colours, "
                            f"{non_white} of {total} samples not white")
    if failures:
        print("report_in_browser: FAILED: " + "; ".join(failures))
        return 1
    print(f"report_in_browser: {len(svgs)} figures and every table in the DOM; "
          f"screenshot {width}x{height}, {len(colours)} colours")
    return 0


if __name__ == "__main__":
    sys.exit(main())
