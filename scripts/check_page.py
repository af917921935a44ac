#!/usr/bin/env python3
"""Opens `xbandsim serve`'s page (docs/live.md, "The page") in headless Chromium, driven by
selenium, and checks what a person would see: the page loads from the binary alone (no
request leaves the server); the PPI fills within two revolutions; every vessel in range is
drawn where the truth puts it (each vessel: not the structures, buoys and reflectors); turning the gain down dims the picture; the truth overlay
draws when switched on; the scenario clock shows UTC. With --screenshot FILE it saves the page as a PNG (the README's).

Chromium and its driver come from Debian's packages (chromium, chromium-driver). Where they
are missing the check prints why and exits 0 — the only case it is skipped.

Usage: check_page.py XBANDSIM_BINARY SCENE [--screenshot FILE]
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SPEED = 4.0
FAILURES = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        FAILURES.append(what)


def main():
    binary, scene = sys.argv[1], sys.argv[2]
    shot = sys.argv[sys.argv.index("--screenshot") + 1] if "--screenshot" in sys.argv else None
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver_path = shutil.which("chromedriver")
    if not (chromium and driver_path):
        print("skipped: Chromium and chromedriver are not installed (Debian: apt-get install chromium chromium-driver)")
        return
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    p = subprocess.Popen([binary, "serve", scene, "--listen", "127.0.0.1:0", "--speed", str(SPEED)],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    base = None
    for line in p.stdout:
        print("  | " + line.rstrip())
        m = re.search(r" on (http://[0-9.:]+)/ ", line)
        if m:
            base = m.group(1)
        if line.startswith("Ctrl-C stops"):
            break
    profile = tempfile.mkdtemp(prefix="check-page-")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--window-size=1280,860", f"--user-data-dir={profile}"]:
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"performance": "ALL"})
    driver = webdriver.Chrome(service=Service(driver_path), options=options)
    try:
        driver.get(base + "/")
        radar = None
        for _ in range(100):
            radar = driver.execute_script("return window.xbandsim && window.xbandsim.radar")
            if radar:
                break
            time.sleep(0.1)
        check(bool(radar), "the page loads and reads the radar description")
        period = radar["rotationPeriodS"] / SPEED
        n = radar["spokesPerRevolution"]
        t0 = time.time()
        filled = False
        while time.time() < t0 + 2 * period + 1.0:
            if driver.execute_script("return window.xbandsim.bearingsSeen.size") == n:
                filled = True
                break
            time.sleep(0.05)
        took = driver.execute_script("return (performance.now() - window.xbandsim.firstSpokeAt) / 1000")
        check(filled and took <= 2 * period, f"the PPI fills within two revolutions ({took:.2f} s; a revolution is {period:.3f} s)")
        # Every ship in range where the truth puts it (the picture is at most a revolution old).
        time.sleep(period)
        levels = driver.execute_script("""
            const X = window.xbandsim, own = X.truth.own_ship.position_m, out = {};
            for (const o of X.truth.objects) {
              if (o.structure || ["buoy", "corner_reflector"].includes(o.class)) continue;
              const e = o.position_m[0] - own[0], n = o.position_m[1] - own[1], r = Math.hypot(e, n);
              if (r < 100 || r > 0.9 * X.range) continue;
              // The background: the same range at eight other bearings, 40 degrees apart.
              const around = [];
              for (let k = 1; k <= 8; k++) {
                const a = Math.atan2(e, n) + k * 40 * Math.PI / 180;
                around.push(X.levelAt(r * Math.sin(a), r * Math.cos(a), 10));
              }
              around.sort((a, b) => a - b);
              out[o.name] = [X.levelAt(e, n, 10), around[4]];
            }
            return out;""")
        check(levels and all(v >= 2 and v > bg for v, bg in levels.values()),
              f"every vessel in range drawn where its truth is, level 2 or more of 15 and over the median at its range: {levels}")
        before = driver.execute_script("return window.xbandsim.litFraction()")
        driver.execute_script("""
            const g = document.getElementById('control-2'); g.value = -30;
            g.dispatchEvent(new Event('change'));""")
        time.sleep(2.5 * period)
        after = driver.execute_script("return window.xbandsim.litFraction()")
        gain = driver.execute_script("return window.xbandsim.controls['2'] && window.xbandsim.controls['2'].value")
        check(gain == -30 and after < 0.5 * before, f"gain to -30 dB from the page dims the PPI: {before:.3f} -> {after:.3f} of the disc lit")
        driver.execute_script("""
            const g = document.getElementById('control-2'); g.value = 0;
            g.dispatchEvent(new Event('change'));""")
        driver.find_element("id", "truth").click()
        time.sleep(1.2)
        overlay = driver.execute_script("""
            const c = document.getElementById('overlay'), d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
            let k = 0; for (let i = 0; i < d.length; i += 4) if (d[i] === 0x4f && d[i + 1] === 0xc3 && d[i + 2] === 0xff) k++;
            return k;""")
        check(overlay > 50, f"the truth overlay draws boxes, names and vectors ({overlay} pixels)")
        clock = driver.find_element("id", "clock").text
        check(clock.endswith("UTC"), f"the scenario clock shows {clock!r}")
        # Nothing but the server was asked for anything.
        hosts = set()
        for entry in driver.get_log("performance"):
            msg = json.loads(entry["message"])["message"]
            if msg.get("method") == "Network.requestWillBeSent":
                url = msg["params"]["request"]["url"]
                if re.match(r"^(https?|wss?)://", url):
                    hosts.add(re.sub(r"^(\w+://[^/]+).*", r"\1", url))
        check(hosts <= {base, base.replace("http", "ws")}, f"every request goes to the server itself: {sorted(hosts)}")
        if shot:
            time.sleep(2 * period)
            driver.save_screenshot(shot)
            print(f"saved {shot}")
    finally:
        driver.quit()
        p.send_signal(signal.SIGINT)
        p.communicate(timeout=30)
        shutil.rmtree(profile, ignore_errors=True)
    if FAILURES:
        raise SystemExit(f"{len(FAILURES)} checks failed")
    print("all checks passed")


if __name__ == "__main__":
    main()
