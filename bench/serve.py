#!/usr/bin/env python3
"""The live radar's benchmark (docs/performance.md, "The live radar"): `xbandsim serve` on a
coastal scene at X times real time with N spoke clients connected, so that a revolution must
be rendered, put through the video chain and sent to every client in 1/X of the antenna's
rotation period (X = 2: the issue's "under half the rotation period"). It reports, for the
revolutions after the first two (the first renders cold):

- the wall time between revolutions at a client, against the budget (period / X);
- how long the server held its clock back waiting for a revolution (0 when it keeps up);
- the server's own time for a revolution (render, video chain, plots and tracker, from
  /api/scenario), as a ratio to the budget: the margin left.

Needs websockets and protobuf (scripts/requirements-check.txt; target/check-venv has them
after scripts/test.sh).

Usage: python bench/serve.py [--xbandsim target/release/xbandsim]
       [--scene scenes/harbour-departure.toml] [--clients 8] [--speed 2] [--revolutions 12]
"""
import argparse
import asyncio
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "scripts"))
import websockets  # noqa: E402

from check_serve import decode, finish, http, start  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--xbandsim", default="target/release/xbandsim")
    ap.add_argument("--scene", default="scenes/harbour-departure.toml")
    ap.add_argument("--clients", type=int, default=8)
    ap.add_argument("--speed", type=float, default=2.0)
    ap.add_argument("--revolutions", type=int, default=12)
    a = ap.parse_args()
    p, where = start(a.xbandsim, ["serve", a.scene, "--listen", "127.0.0.1:0", "--speed", str(a.speed)])
    base = where["http"]
    radar = http(base, "/v1/api/radars")[1]["1"]
    period = radar["rotationPeriodS"]
    budget = period / a.speed
    starts, works, held = [], [], []

    async def client(k):
        async with websockets.connect(radar["streamUrl"], max_size=None) as ws:
            while len(starts) < a.revolutions + 3:
                b = await ws.recv()
                if k == 0:
                    first = decode(b).spokes[0]
                    if first.bearing == 0:
                        starts.append(time.perf_counter())
                        s = http(base, "/api/scenario")[1]
                        c = s["counters"]
                        works.append(c["last_render_s"] + c["last_video_s"] + c["last_tracker_s"])
                        held.append(s["held_s"])

    async def run():
        await asyncio.gather(*[client(k) for k in range(a.clients)])

    asyncio.run(run())
    status = http(base, "/api/scenario")[1]
    finish(p)
    gaps = [b - x for x, b in zip(starts[2:], starts[3:])]
    mean_gap = sum(gaps) / len(gaps)
    work = works[3:]
    mean_work = sum(work) / len(work)
    held_s = held[-1] - held[2]
    print()
    print(f"scene {a.scene}: {radar['spokesPerRevolution']} spokes x {radar['maxSpokeLen']} samples, "
          f"period {period:.2f} s; {a.clients} clients at {a.speed}x real time (budget {budget:.3f} s a revolution)")
    print(f"| revolution at the clients, every | {mean_gap:.3f} s | {mean_gap / budget:.2f}x the budget |")
    print(f"| clock held back over {len(gaps)} revolutions | {held_s:.3f} s | scenario s |")
    print(f"| server work a revolution (render + video chain + plots and tracker) | {mean_work:.3f} s (max {max(work):.3f}) | "
          f"{mean_work / budget:.2f} of the budget, {mean_work / period:.2f} of the period |")
    print(f"| clients dropped | {status['counters']['clients_dropped']} | |")


if __name__ == "__main__":
    main()
