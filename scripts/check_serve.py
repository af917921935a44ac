#!/usr/bin/env python3
"""Connects to `xbandsim serve` (docs/live.md) as chart-plotter software would and checks
what it is sent, with clients written independently of xbandsim:

- the radar description of the mayara v1 API (`/v1/api/radars`) and its schema
  (`/v1/api/RadarMessage.proto`), whose fields must be mayara's `RadarMessage` field for field;
- the spoke stream, decoded by protobuf 7 (the Python package of Google's protocol buffers)
  from a descriptor built here from mayara's schema (keesverruijt/mayara,
  src/protos/RadarMessage.proto): spokes at the antenna's rate, every revolution's bearings
  each once, spoke times one spoke period apart, and every ship's echo in the spoke data where
  the truth (`/api/truth`) puts it at that spoke's time, in every revolution (strong in three of
  four: it fades with the ship's roll and multipath);
- eight spoke clients at once, all sent the same bytes, and a stalled client dropped while
  the others keep the antenna's rate;
- controls over the control WebSocket: gain down dims the picture, a bad value is refused
  with a message; bad REST requests get 4xx with a message;
- pause and resume;
- the NMEA 0183 feed over UDP and TCP: every sentence's checksum, the own ship's RMC read by
  pynmea2 at the truth's position, every AIS position report decoded by pyais at the truth's
  position, course and speed (within the messages' resolutions); the feed byte for byte the
  log `xbandsim nmea` writes for the same scenario; and the radar's TTM sentences (its
  tracker's confirmed tracks) each within 200 m of an object at its time, nine in ten within
  100 m;
- Ctrl-C: the server stops cleanly and its recording is complete; `xbandsim replay` of it
  sends the same spoke messages and NMEA lines again, byte for byte (to a client, in order, to
  the end, at the antenna's rate; to a new recording, identical), and a restart is recorded
  and replayed in its place without a burst;
- with --soak S: S seconds at full speed with clients coming and going and a stalled one,
  the server's resident memory sampled: it must stay bounded.

Usage: check_serve.py XBANDSIM_BINARY SCENE [--soak SECONDS]
"""
import asyncio
import json
import math
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

import pyais
import pynmea2
import websockets
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

SPEED = 4.0

# mayara's RadarMessage (src/protos/RadarMessage.proto): (field, number, type, label).
REFERENCE = {
    "RadarMessage": [("radar", 1, "uint32", ""), ("spokes", 2, "Spoke", "repeated")],
    "Spoke": [
        ("angle", 1, "uint32", ""),
        ("bearing", 2, "uint32", "optional"),
        ("range", 3, "uint32", ""),
        ("time", 4, "uint64", "optional"),
        ("lat", 6, "int64", "optional"),
        ("lon", 7, "int64", "optional"),
        ("data", 5, "bytes", ""),
    ],
}

FAILURES = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        FAILURES.append(what)


def radar_message_class():
    """The RadarMessage class, from a descriptor built from REFERENCE."""
    F = descriptor_pb2.FieldDescriptorProto
    types = {"uint32": F.TYPE_UINT32, "uint64": F.TYPE_UINT64, "int64": F.TYPE_INT64, "bytes": F.TYPE_BYTES}
    fdp = descriptor_pb2.FileDescriptorProto(name="check_radar_message.proto", syntax="proto3", package="check")
    top = fdp.message_type.add(name="RadarMessage")
    spoke = top.nested_type.add(name="Spoke")
    for message, fields in ((top, REFERENCE["RadarMessage"]), (spoke, REFERENCE["Spoke"])):
        for name, number, kind, label in fields:
            f = message.field.add(name=name, number=number)
            if kind == "Spoke":
                f.type = F.TYPE_MESSAGE
                f.type_name = ".check.RadarMessage.Spoke"
            else:
                f.type = types[kind]
            f.label = F.LABEL_REPEATED if label == "repeated" else F.LABEL_OPTIONAL
            if label == "optional":
                f.proto3_optional = True
                f.oneof_index = len(message.oneof_decl)
                message.oneof_decl.add(name="_" + name)
    pool = descriptor_pool.DescriptorPool()
    pool.Add(fdp)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName("check.RadarMessage"))


RadarMessage = radar_message_class()


def http(base, path, method="GET", body=None):
    """(status, parsed JSON or text) of a request."""
    data = None if body is None else (body if isinstance(body, bytes) else json.dumps(body).encode())
    req = urllib.request.Request(base + path, data=data, method=method, headers={"content-type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            status, text = r.status, r.read().decode()
    except urllib.error.HTTPError as e:
        status, text = e.code, e.read().decode()
    try:
        return status, json.loads(text)
    except ValueError:
        return status, text


def start(binary, args):
    """Starts `binary args`, returns (process, {"http": base URL, "tcp": (host, port)})."""
    p = subprocess.Popen([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    found = {}
    deadline = time.time() + 120
    while time.time() < deadline:
        line = p.stdout.readline()
        if not line:
            break
        print("  | " + line.rstrip())
        m = re.search(r" on (http://[0-9.:]+)/ ", line)
        if m:
            found["http"] = m.group(1)
        m = re.search(r"NMEA 0183 on tcp ([0-9.]+):([0-9]+)", line)
        if m:
            found["tcp"] = (m.group(1), int(m.group(2)))
        if line.startswith("Ctrl-C stops"):
            return p, found
    p.kill()
    raise SystemExit("the server did not start: " + json.dumps(found))


def finish(p):
    """Ctrl-C, then the rest of its output and its exit status."""
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=60)
    for line in out.splitlines():
        print("  | " + line)
    return p.returncode, out


def decode(message_bytes):
    m = RadarMessage()
    m.ParseFromString(message_bytes)
    return m


async def collect(url, seconds, stall=False):
    """[(wall time, bytes)] of a spoke client for `seconds`; a stalled client never reads
    (its socket's receive buffer made small, as a phone's on a poor link), then says whether
    the server has closed it: ("closed", why) or ("open", None)."""
    got = []
    sock = None
    if stall:
        host, port = re.match(r"ws://([^:/]+):(\d+)", url).groups()
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        sock.connect((host, int(port)))
    async with websockets.connect(url, max_size=None, max_queue=4 if stall else 1024, sock=sock) as ws:
        if stall:
            await asyncio.sleep(seconds)
            # Then it reads what was queued, for at most 5 s: a server that dropped it has
            # closed the connection behind those messages.
            end = time.time() + 5.0
            try:
                while time.time() < end:
                    await asyncio.wait_for(ws.recv(), 0.5)
            except websockets.exceptions.ConnectionClosed as e:
                return ("closed", repr(e))
            except asyncio.TimeoutError:
                pass
            return ("open", None)
        end = time.time() + seconds
        while time.time() < end:
            try:
                b = await asyncio.wait_for(ws.recv(), max(0.01, end - time.time()))
            except asyncio.TimeoutError:
                break
            got.append((time.time(), b))
    return got


def revolutions(spokes, n):
    """The complete revolutions in a list of (wall, spoke): lists of spokes from bearing 0."""
    revs, cur = [], None
    for wall, s in spokes:
        if s.bearing == 0:
            if cur is not None:
                revs.append(cur)
            cur = []
        if cur is not None:
            cur.append((wall, s))
    return [r for r in revs if r]


def truth_at(truths, t_s, name):
    """(own ship, object) positions at scenario time t_s, from the nearest snapshot moved on
    by its velocities."""
    t0, snap = min(truths, key=lambda x: abs(x[0] - t_s))
    dt = t_s - t0
    own = snap["own_ship"]
    o = next(o for o in snap["objects"] if o["name"] == name)
    op = [own["position_m"][i] + own["velocity_mps"][i] * dt for i in range(2)]
    p = [o["position_m"][i] + o["velocity_mps"][i] * dt for i in range(2)]
    return op, p, o, abs(dt)


def check_spokes(radar, spokes, truths, start_unix_s):
    n, samples = radar["spokesPerRevolution"], radar["maxSpokeLen"]
    period_s = radar["rotationPeriodS"]
    revs = revolutions(spokes, n)
    check(len(revs) >= 2, f"{len(revs)} complete revolutions received (at least 2)")
    whole = [r for r in revs if sorted(s.bearing for _, s in r) == list(range(n))]
    check(len(whole) == len(revs), f"every revolution has bearings 0..{n - 1} each once ({len(whole)}/{len(revs)})")
    walls = [r[0][0] for r in revs]
    if len(walls) >= 3:
        gaps = [b - a for a, b in zip(walls[1:], walls[2:])] or [walls[1] - walls[0]]
        mean = sum(gaps) / len(gaps)
        want = period_s / SPEED
        check(abs(mean / want - 1) < 0.15, f"a revolution every {mean:.3f} s of wall time (antenna: {want:.3f} s at {SPEED}x)")
    steps = []
    for r in revs:
        for (_, a), (_, b) in zip(r, r[1:]):
            steps.append(b.time - a.time)
    want_ms = period_s / n * 1000
    check(steps and all(abs(s - want_ms) <= 1.0 for s in steps), f"spoke times {want_ms:.3f} ms apart to the millisecond ({len(steps)} steps)")
    # Every ship's echo where the truth puts it.
    names = [o["name"] for o in truths[0][1]["objects"] if o["class"] in ("ship", "boat")]
    for name in names:
        hits, tried, levels = 0, 0, []
        for r in revs[1:]:
            by_bearing = {s.bearing: s for _, s in r}
            mid = r[len(r) // 2][1]
            range_m = mid.range
            sample_m = range_m / samples
            # The spoke nearest the object's bearing at that spoke's time (two passes).
            t_s = mid.time / 1000 - start_unix_s
            for _ in range(2):
                own, p, o, dt = truth_at(truths, t_s, name)
                e, nn = p[0] - own[0], p[1] - own[1]
                bearing = math.degrees(math.atan2(e, nn)) % 360
                b = round(bearing / 360 * n) % n
                t_s = by_bearing[b].time / 1000 - start_unix_s
            dist = math.hypot(e, nn)
            if not (100 < dist < 0.9 * range_m) or dt > 0.5:
                continue
            tried += 1
            half = (o["length_m"] / 2 + 10) / sample_m
            spread = max(3, round(2.0 / 360 * n))
            level = 0
            for k in range(b - spread, b + spread + 1):
                s = by_bearing[k % n]
                lo, hi = int(dist / sample_m - half), int(dist / sample_m + half) + 1
                # Video levels only: a Doppler code (2^bits and above) is no level.
                level = max([level] + [v for v in s.data[max(lo, 0):min(hi, len(s.data))] if v < 2 ** radar["bits"]])
            hits += level >= 8
            levels.append(level)
        # The echo fades with the ship's roll and the sea's multipath: it must be there in
        # every revolution (level 4 or more), and strong (8 or more) in three of four.
        check(tried > 0 and min(levels) >= 4 and hits >= 0.75 * tried,
              f"{name}: echo where the truth puts it in every revolution, level 8 or more in {hits} of {tried}: {levels}")
    check(len(names) >= 3, f"ships checked: {names}")


def nmea_lines(blob):
    return [l for l in blob.decode("ascii").split("\r\n") if l]


def checksum_ok(line):
    body, _, given = line[1:].partition("*")
    v = 0
    for ch in body.encode():
        v ^= ch
    return line[:1] in "$!" and given == f"{v:02X}"


def check_nmea(lines, truths, feed_truth):
    check(all(checksum_ok(l) for l in lines), f"all {len(lines)} NMEA sentences have correct checksums")
    by_time = {}
    for t in feed_truth:
        by_time.setdefault((round(t["time_s"] * 3), t["source"]), t)
    # The own ship: RMC positions against the feed's truth at that second.
    rmcs = [pynmea2.parse(l) for l in lines if l[3:6] == "RMC"]
    worst, matched = 0.0, 0
    for m in rmcs:
        secs = m.datetime.timestamp()
        t = by_time.get((round((secs - feed_truth[0]["unix_s"]) * 3), "own_ship"))
        if t:
            matched += 1
            worst = max(worst, abs(m.latitude - t["lat_deg"]), abs(m.longitude - t["lon_deg"]))
    check(rmcs and matched == len(rmcs) and worst <= 1e-4 / 60,
          f"{matched} of {len(rmcs)} RMC fixes read by pynmea2 at the truth's position (worst {worst * 60 * 1e4:.2f}e-4 min)")
    # AIS: positions, course and speed against the truth at the report's tick.
    sentences = [l for l in lines if l.startswith("!AIVDM")]
    decoded = []
    parts = []
    for l in sentences:
        fields = l.split(",")
        parts.append(l.encode())
        if fields[1] == fields[2]:
            decoded.append(pyais.decode(*parts).asdict())
            parts = []
    positions = [d for d in decoded if d["msg_type"] in (1, 2, 3, 18)]
    objects = {o["mmsi"]: o for o in truths[0][1]["objects"] if o.get("mmsi")}
    bad = []
    for d in positions:
        name = objects[d["mmsi"]]["name"]
        cands = [t for t in feed_truth if t["source"] == name and (t["unix_s"] % 60) // 1 == d["second"]]
        ok = any(
            abs(d["lat"] - t["lat_deg"]) <= 1e-4 / 60 + 1e-9
            and abs(d["lon"] - t["lon_deg"]) <= 1e-4 / 60 + 1e-9
            and abs(d["speed"] - math.hypot(*t["velocity_mps"]) / 0.514444) <= 0.05 + 1e-9
            for t in cands
        )
        if not ok:
            bad.append(d)
    check(positions and not bad, f"{len(positions)} AIS position reports decoded by pyais at the truth's position and speed ({len(bad)} off)")


def check_ttm(lines, truths, start_unix_s):
    """Every $RATTM (the radar's tracks) read by pynmea2 lies within 200 m of an object at
    its time, and nine in ten within 100 m (the baseline's truth gate; a track lags a boat
    that turns at a waypoint)."""
    check(len(lines) >= 3 and all(checksum_ok(l) for l in lines), f"{len(lines)} TTM sentences of the radar's tracks, checksums right")
    off, numbers, per_time = [], set(), {}
    for l in lines:
        m = pynmea2.parse(l)
        numbers.add(int(m.data[0]))
        per_time.setdefault(m.data[13], []).append(int(m.data[0]))
        d_m = float(m.data[1]) * 1852.0
        b = math.radians(float(m.data[2]))
        hh, mm, ss = int(m.data[13][:2]), int(m.data[13][2:4]), float(m.data[13][4:])
        t_s = (hh * 3600 + mm * 60 + ss) - (start_unix_s % 86400)
        near = min(truths, key=lambda x: abs(x[0] - t_s))
        dt = t_s - near[0]
        own = near[1]["own_ship"]
        p = [own["position_m"][i] + own["velocity_mps"][i] * dt for i in range(2)]
        at = (p[0] + d_m * math.sin(b), p[1] + d_m * math.cos(b))
        best = min(
            math.hypot(at[0] - (o["position_m"][0] + o["velocity_mps"][0] * dt), at[1] - (o["position_m"][1] + o["velocity_mps"][1] * dt))
            for o in near[1]["objects"]
        )
        if abs(dt) > 1.0 or best > 100.0:
            off.append((l, round(best), round(dt, 2)))
    clash = {t: k for t, k in per_time.items() if len(k) != len(set(k)) or not all(1 <= x <= 99 for x in k)}
    check(not clash, f"TTM target numbers 1-99, none twice at one time ({len(per_time)} times; clashes: {list(clash.items())[:3]})")
    far = [o for o in off if o[1] > 200 or abs(o[2]) > 1.0]
    check(not far and len(off) <= 0.1 * len(lines),
          f"every TTM within 200 m of an object at its time, {len(lines) - len(off)} of {len(lines)} within 100 m ({len(numbers)} targets; off: {off[:3]})")


def main():
    binary, scene = sys.argv[1], sys.argv[2]
    soak = float(sys.argv[sys.argv.index("--soak") + 1]) if "--soak" in sys.argv else 0.0
    work = tempfile.mkdtemp(prefix="check-serve-")
    rec = os.path.join(work, "run.xbsrec")
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    udp.bind(("127.0.0.1", 0))
    udp.setblocking(False)
    udp_port = udp.getsockname()[1]
    p, where = start(binary, ["serve", scene, "--listen", "127.0.0.1:0", "--speed", str(SPEED),
                              "--nmea-udp", f"127.0.0.1:{udp_port}", "--nmea-tcp", "127.0.0.1:0", "--record", rec])
    base = where["http"]
    tcp = socket.create_connection(where["tcp"])
    tcp.setblocking(False)
    # The truth, sampled all along (for the spokes' echoes and the TTM sentences).
    all_truths, sampling = [], threading.Event()

    def sample_truth():
        while not sampling.is_set():
            try:
                status, t = http(base, "/api/truth")
                if status == 200:
                    all_truths.append((t["time_s"], t))
            except OSError:
                pass
            time.sleep(0.1)

    sampler = threading.Thread(target=sample_truth, daemon=True)
    sampler.start()

    # The description and the schema.
    status, radars = http(base, "/v1/api/radars")
    radar = radars["1"]
    check(status == 200 and {"spokesPerRevolution", "maxSpokeLen", "streamUrl", "controlUrl", "legend", "controls"} <= set(radar),
          "the radar description has mayara v1's fields")
    types = [p["type"] for p in radar["legend"]["pixels"]]
    levels = 2 ** radar["bits"]
    check(types == ["normal"] * levels + ["dopplerApproaching", "dopplerReceding"]
          and radar["legend"]["dopplerApproaching"] == levels and radar["legend"]["dopplerReceding"] == levels + 1,
          f"the legend has a colour for each of the {levels} levels, then the Doppler codes {levels} and {levels + 1}")
    check({c["name"] for c in radar["controls"].values()} >= {"Range", "Gain", "Sea clutter", "Rain clutter", "Interference rejection"},
          "the controls: range, gain, sea, rain, interference rejection")
    status, proto = http(base, "/v1/api/RadarMessage.proto")
    served = set(re.findall(r"^\s*(optional |repeated )?(\w+) (\w+) = (\d+);", proto, re.M))
    want = {(l + " " if l else "", k, n, str(num)) for fields in REFERENCE.values() for n, num, k, l in fields}
    check(served == want, "the served RadarMessage.proto declares mayara's fields, numbers and types")
    start_unix_s = radar["startUnixS"]

    async def session():
        stream = radar["streamUrl"]
        stalled = asyncio.ensure_future(collect(stream, 8.0, stall=True))
        clients = [asyncio.ensure_future(collect(stream, 9.0)) for _ in range(8)]
        results = await asyncio.gather(*clients)
        stall = await stalled
        return results, stall

    results, stall = asyncio.run(session())
    truths = list(all_truths)
    spokes = [(w, s) for w, b in results[0] for s in decode(b).spokes]
    check_spokes(radar, spokes, truths, start_unix_s)
    # Each client's messages, from the first one client 0 also has, are client 0's in order.
    first = [b for _, b in results[0]]
    index = {b: i for i, b in enumerate(first)}
    same = True
    for r in results[1:]:
        got = [b for _, b in r]
        k = next((j for j, b in enumerate(got) if b in index), None)
        if k is None or k > 8:
            same = False
            continue
        i = index[got[k]]
        n = min(len(got) - k, len(first) - i)
        same &= n >= 0.9 * len(first) and got[k:k + n] == first[i:i + n]
    check(same, f"8 clients at once, sent the same messages in the same order ({[len(r) for r in results]})")
    status, scen = http(base, "/api/scenario")
    check(stall[0] == "closed" and scen["counters"]["clients_dropped"] >= 1, f"a stalled client is dropped ({stall[0]}, {scen['counters']['clients_dropped']} dropped)")

    # Controls: gain down dims the picture; bad values refused.
    async def gain_test():
        async with websockets.connect(radar["controlUrl"]) as ws:
            first = [json.loads(await ws.recv()) for _ in range(5)]
            before = await collect(radar["streamUrl"], 2.0)
            await ws.send(json.dumps({"id": "2", "value": -30}))
            echo = json.loads(await ws.recv())
            await asyncio.sleep(2 * radar["rotationPeriodS"] / SPEED)
            after = await collect(radar["streamUrl"], 2.0)
            await ws.send(json.dumps({"id": "2", "value": 500}))
            refused = json.loads(await ws.recv())
            await ws.send(json.dumps({"id": "2", "value": 0}))
            await ws.recv()
            return first, before, echo, after, refused

    first, before, echo, after, refused = asyncio.run(gain_test())
    lit = lambda got: sum(sum(1 for v in s.data if v) for _, b in got for s in decode(b).spokes) / max(1, sum(len(decode(b).spokes) for _, b in got))
    check({c["id"] for c in first} == {"1", "2", "3", "4", "5"}, "the control stream starts with every control's value")
    check(echo == {"id": "2", "value": -30.0}, f"gain set to -30 dB over the control stream ({echo})")
    check(lit(after) < 0.5 * lit(before), f"gain -30 dB dims the picture: {lit(before):.1f} -> {lit(after):.1f} lit samples a spoke")
    check("error" in refused and "-30 to 30" in refused["error"], f"gain 500 refused: {refused.get('error')}")
    for method, path, body, code in [
        ("PUT", "/v1/api/radars/1/controls/2", {"value": "loud"}, 400),
        ("PUT", "/v1/api/radars/1/controls/9", {"value": 1}, 400),
        ("PUT", "/v1/api/radars/7/controls/2", {"value": 1}, 404),
        ("PUT", "/v1/api/radars/1/controls/2", b"{not json", 400),
        ("POST", "/api/scenario", {"action": "rewind"}, 400),
        ("POST", "/api/scenario", {"speed": -1}, 400),
        ("GET", "/v1/api/nothing", None, 404),
    ]:
        status, reply = http(base, path, method, body)
        check(status == code and isinstance(reply, dict) and reply.get("error"), f"{method} {path} {body!r}: {status} {reply.get('error') if isinstance(reply, dict) else reply}")

    # Pause and resume.
    http(base, "/api/scenario", "POST", {"action": "pause"})
    t1 = http(base, "/api/scenario")[1]["time_s"]
    time.sleep(1.0)
    t2 = http(base, "/api/scenario")[1]["time_s"]
    http(base, "/api/scenario", "POST", {"action": "resume"})
    time.sleep(0.5)
    t3 = http(base, "/api/scenario")[1]["time_s"]
    check(t1 == t2 and t3 > t2 + 0.5 * SPEED * 0.5, f"paused at {t1:.2f} s (still {t2:.2f} s a second later), running again ({t3:.2f} s)")

    # NMEA over UDP and TCP, then Ctrl-C.
    time.sleep(1.0)
    sampling.set()
    sampler.join()
    code, out = finish(p)
    check(code == 0 and "recorded" in out, f"Ctrl-C stops the server cleanly (exit {code})")
    udp_blob = b""
    while True:
        try:
            udp_blob += udp.recv(65536)
        except BlockingIOError:
            break
    tcp_blob = b""
    try:
        while True:
            chunk = tcp.recv(65536)
            if not chunk:
                break
            tcp_blob += chunk
    except BlockingIOError:
        pass
    udp_lines, tcp_lines = nmea_lines(udp_blob), nmea_lines(tcp_blob)
    # The radar's own TTM sentences, between the feed's groups.
    ttms = [l for l in udp_lines if l[3:6] == "TTM"]
    feed_only = lambda lines: "".join(l + "\r\n" for l in lines if l[3:6] != "TTM").encode()
    udp_blob, tcp_blob = feed_only(udp_lines), feed_only(tcp_lines)
    udp_lines = [l for l in udp_lines if l[3:6] != "TTM"]
    tcp_lines = [l for l in tcp_lines if l[3:6] != "TTM"]
    log = os.path.join(work, "feed.nmea")
    feed_truth_path = os.path.join(work, "feed-truth.jsonl")
    subprocess.run([binary, "nmea", scene, "--duration-s", "120", "--out", log, "--truth", feed_truth_path], check=True, stdout=subprocess.DEVNULL)
    reference = open(log, "rb").read()
    feed_truth = [json.loads(l) for l in open(feed_truth_path)]
    check(udp_blob and reference.startswith(udp_blob), f"the UDP feed ({len(udp_lines)} sentences) is `xbandsim nmea`'s log byte for byte")
    check(tcp_blob and tcp_blob in reference, f"the TCP feed ({len(tcp_lines)} sentences) is a run of `xbandsim nmea`'s log")
    check_nmea(udp_lines, truths, feed_truth)
    check_ttm(ttms, all_truths, start_unix_s)

    # The recording replays byte for byte, to a client as to a new recording.
    rec2 = os.path.join(work, "replay.xbsrec")
    got, q, out = replay_with_client(binary, rec, rec2, 8.0)
    a, b = open(rec, "rb").read(), open(rec2, "rb").read()
    check(q.returncode == 0 and a == b, f"`xbandsim replay` records the recording again byte for byte ({len(a)} bytes, identical: {a == b})")
    sent = [payload for kind, _, payload in read_recording(rec) if kind == 1]
    received = [b for _, b in got]
    k = sent.index(received[0]) if received and received[0] in sent else -1
    check(k >= 0 and received == sent[k:k + len(received)] and k + len(received) == len(sent),
          f"a client of the replay gets the recorded spoke messages, in order, to the end ({len(received)} of {len(sent)})")
    check_rate(got, radar["rotationPeriodS"] / 8.0, "the replay")
    times = [t for kind, t, _ in read_recording(rec) if kind == 1]
    want_s = (times[-1] - times[0]) / 8.0
    took_s = got[-1][0] - got[0][0] if got else 0.0
    check(abs(took_s / want_s - 1) < 0.1, f"the replay takes {took_s:.2f} s of wall time for {times[-1] - times[0]:.1f} s recorded at 8x ({want_s:.2f} s)")

    # A restart is recorded, and replayed in its place without a burst.
    rec3, rec4 = os.path.join(work, "restart.xbsrec"), os.path.join(work, "restart-replay.xbsrec")
    r, where3 = start(binary, ["serve", scene, "--listen", "127.0.0.1:0", "--speed", "8", "--record", rec3])
    time.sleep(3.0)
    http(where3["http"], "/api/scenario", "POST", {"action": "restart"})
    time.sleep(3.0)
    finish(r)
    kinds = [kind for kind, _, _ in read_recording(rec3)]
    check(kinds.count(3) == 1, f"a restart is recorded ({kinds.count(3)} restart records)")
    got, q, out = replay_with_client(binary, rec3, rec4, 8.0)
    same = open(rec3, "rb").read() == open(rec4, "rb").read()
    check(q.returncode == 0 and same, "the replay of a restarted run records it again byte for byte")
    check_rate(got, radar["rotationPeriodS"] / 8.0, "the replay across the restart")

    if soak:
        soak_check(binary, scene, soak)
    if FAILURES:
        raise SystemExit(f"{len(FAILURES)} checks failed")
    print("all checks passed")


def read_recording(path):
    """[(kind, time_s, payload)] of a recording (docs/formats.md, "Live recordings")."""
    data = open(path, "rb").read()
    assert data[:8] == b"XBSREC01"
    at = 12 + int.from_bytes(data[8:12], "little")
    out = []
    while at < len(data) and data[at] != 255:
        kind = data[at]
        time_s = struct.unpack("<d", data[at + 1:at + 9])[0]
        n = int.from_bytes(data[at + 9:at + 13], "little")
        out.append((kind, time_s, data[at + 13:at + 13 + n]))
        at += 13 + n
    return out


def replay_with_client(binary, rec, rec_out, speed):
    """Replays `rec` (recording to `rec_out`) with a spoke client connected from the start:
    ([(wall, bytes)], process, output)."""
    q, where = start(binary, ["replay", rec, "--listen", "127.0.0.1:0", "--speed", str(speed), "--record", rec_out])
    radar = http(where["http"], "/v1/api/radars")[1]["1"]

    async def client():
        got = []
        try:
            async with websockets.connect(radar["streamUrl"], max_size=None) as ws:
                while True:
                    got.append((time.time(), await asyncio.wait_for(ws.recv(), 30)))
        except (websockets.exceptions.ConnectionClosed, asyncio.TimeoutError, OSError):
            pass
        return got

    got = asyncio.run(client())
    out, _ = q.communicate(timeout=60)
    for line in out.splitlines():
        print("  | " + line)
    return got, q, out


def check_rate(got, period_wall_s, what):
    """Messages arrive at the antenna's rate: no 0.1 s window holds more than twice a
    revolution's share (128 messages a revolution) plus 4."""
    times = [w for w, _ in got]
    share = 128 * 0.1 / period_wall_s
    worst = max((sum(1 for t in times[i:i + 400] if t - times[i] < 0.1) for i in range(len(times))), default=0)
    check(times and worst <= 2 * share + 4, f"{what}: at most {worst} messages in any 0.1 s (the antenna's rate gives {share:.0f})")


def rss_kib(pid):
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def soak_check(binary, scene, seconds):
    p, where = start(binary, ["serve", scene, "--listen", "127.0.0.1:0", "--speed", "100"])
    base = where["http"]
    radar = http(base, "/v1/api/radars")[1]["1"]
    samples = []

    async def churn():
        end = time.time() + seconds
        stalled = asyncio.ensure_future(collect(radar["streamUrl"], seconds, stall=True))
        while time.time() < end:
            await asyncio.gather(*[collect(radar["streamUrl"], 1.0) for _ in range(4)])
            samples.append((time.time(), rss_kib(p.pid), http(base, "/api/scenario")[1]["time_s"]))
        await stalled

    asyncio.run(churn())
    code, _ = finish(p)
    warm = [s for s in samples if s[0] >= samples[0][0] + seconds / 3]
    growth = max(s[1] for s in warm) - min(s[1] for s in warm)
    scenario_s = samples[-1][2]
    check(code == 0 and growth < 64 * 1024,
          f"soak: {seconds:.0f} s at full speed ({scenario_s:.0f} s of scenario, {scenario_s / 3600:.2f} h), resident memory {min(s[1] for s in warm) // 1024}-{max(s[1] for s in warm) // 1024} MiB after warm-up (growth {growth // 1024} MiB, under 64)")


if __name__ == "__main__":
    main()
