#!/usr/bin/env python3
"""Checks an NMEA 0183 log of `xbandsim nmea` (docs/live.md) with the clients a chart plotter
would use and against the truth it was made from: every sentence's checksum; the own ship's
GGA, RMC, VTG and HDT read by pynmea2 1.19.0; every AIS message (fragments joined) decoded by
pyais 3.3.1 — its type, MMSI, position, speed, course, heading and name. Positions are
checked twice: against the truth's latitude and longitude to the sentence's resolution, and
against the truth's ENU metres taken to the globe here, independently of xbandsim, by the
meridian and prime-vertical radii of curvature of WGS84 at the origin (good to well under a
metre within a few kilometres of it).

Usage: check_nmea.py NMEA_LOG TRUTH_JSONL ORIGIN_LON_DEG ORIGIN_LAT_DEG
"""
import json
import math
import sys

# WGS84.
A_M = 6378137.0
F = 1 / 298.257223563
E2 = F * (2 - F)

# A position's resolution: 1/10 000 minute of arc, deg.
POSITION_DEG = 1e-4 / 60
# How far the flat-earth reference may stray from the geodesic within a few km, m.
REFERENCE_M = 1.0


def checksum_ok(line):
    body, _, given = line[1:].partition("*")
    value = 0
    for ch in body.encode():
        value ^= ch
    return given.strip().upper() == f"{value:02X}"


def local_to_lon_lat(x_m, y_m, lon0, lat0):
    """ENU metres about (lon0, lat0) to (lon, lat) with the radii of curvature there."""
    phi = math.radians(lat0)
    s = 1 - E2 * math.sin(phi) ** 2
    meridian = A_M * (1 - E2) / s ** 1.5
    prime_vertical = A_M / math.sqrt(s)
    lat = lat0 + math.degrees(y_m / meridian)
    lon = lon0 + math.degrees(x_m / (prime_vertical * math.cos(math.radians((lat0 + lat) / 2))))
    return lon, lat


def metres_apart(lon1, lat1, lon2, lat2):
    phi = math.radians((lat1 + lat2) / 2)
    north = math.radians(lat2 - lat1) * A_M
    east = math.radians(lon2 - lon1) * A_M * math.cos(phi)
    return math.hypot(north, east)


def angle_apart(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


def check(log_lines, truth, lon0, lat0):
    """Problems found (empty when all is well), and counts of what was checked."""
    import pynmea2
    from pyais import decode

    problems, counts = [], {"sentences": 0, "own_ship": 0, "ais": 0}
    at = 0
    for t in truth:
        group = log_lines[at:at + t["sentences"]]
        at += t["sentences"]
        where = f"t = {t['time_s']} s, {t['source']}"
        if len(group) != t["sentences"]:
            problems.append(f"{where}: the log ends early")
            break
        for line in group:
            counts["sentences"] += 1
            if not checksum_ok(line):
                problems.append(f"{where}: bad checksum: {line}")
        ref_lon, ref_lat = local_to_lon_lat(*t["position_m"], lon0, lat0)
        if metres_apart(ref_lon, ref_lat, t["lon_deg"], t["lat_deg"]) > REFERENCE_M:
            problems.append(f"{where}: xbandsim's lat/lon is "
                            f"{metres_apart(ref_lon, ref_lat, t['lon_deg'], t['lat_deg']):.2f} m "
                            "from the position's own reckoning")
        speed_kn = math.hypot(*t["velocity_mps"]) / (1852 / 3600)
        course = math.degrees(math.atan2(*t["velocity_mps"])) % 360
        if t["source"] == "own_ship":
            counts["own_ship"] += 1
            for line in group:
                try:
                    msg = pynmea2.parse(line.strip(), check=True)
                except pynmea2.ParseError as e:
                    problems.append(f"{where}: pynmea2 cannot read {line!r}: {e}")
                    continue
                if msg.sentence_type in ("GGA", "RMC"):
                    if abs(msg.latitude - t["lat_deg"]) > POSITION_DEG or \
                            abs(msg.longitude - t["lon_deg"]) > POSITION_DEG:
                        problems.append(f"{where}: {msg.sentence_type} at {msg.latitude}, "
                                        f"{msg.longitude}, truth {t['lat_deg']}, {t['lon_deg']}")
                if msg.sentence_type == "RMC" and abs(float(msg.spd_over_grnd) - speed_kn) > 0.051:
                    problems.append(f"{where}: RMC speed {msg.spd_over_grnd}, truth {speed_kn:.3f}")
                if msg.sentence_type == "VTG" and speed_kn > 0.1 and \
                        angle_apart(float(msg.true_track), course) > 0.051:
                    problems.append(f"{where}: VTG course {msg.true_track}, truth {course:.2f}")
                if msg.sentence_type == "HDT" and \
                        angle_apart(float(msg.heading), t["heading_deg"]) > 0.051:
                    problems.append(f"{where}: HDT {msg.heading}, truth {t['heading_deg']:.2f}")
            continue
        # AIS: join each message's fragments, decode, and check the position report (last).
        messages, pending = [], []
        for line in group:
            pending.append(line.strip().encode())
            fields = line.split(",")
            if fields[1] == fields[2]:
                try:
                    messages.append(decode(*pending))
                except Exception as e:  # pyais raises its own kinds for each defect
                    problems.append(f"{where}: pyais cannot decode {pending}: {e}")
                pending = []
        types = [m.msg_type for m in messages]
        if types != t["messages"]:
            problems.append(f"{where}: message types {types}, truth {t['messages']}")
            continue
        counts["ais"] += len(messages)
        for m in messages:
            if m.mmsi != t["mmsi"]:
                problems.append(f"{where}: MMSI {m.mmsi}, truth {t['mmsi']}")
            if m.msg_type in (5, 24) and getattr(m, "shipname", None) not in (None, ""):
                name = t["source"].upper()[:20]
                if m.shipname.strip() != name.strip():
                    problems.append(f"{where}: name {m.shipname!r}, truth {name!r}")
        report = messages[-1]
        if abs(report.lat - t["lat_deg"]) > POSITION_DEG or abs(report.lon - t["lon_deg"]) > POSITION_DEG:
            problems.append(f"{where}: AIS position {report.lat}, {report.lon}, "
                            f"truth {t['lat_deg']}, {t['lon_deg']}")
        if abs(report.speed - speed_kn) > 0.051:
            problems.append(f"{where}: AIS speed {report.speed}, truth {speed_kn:.3f}")
        if speed_kn > 0.1 and angle_apart(report.course, course) > 0.051:
            problems.append(f"{where}: AIS course {report.course}, truth {course:.2f}")
        if angle_apart(report.heading, t["heading_deg"]) > 0.5:
            problems.append(f"{where}: AIS heading {report.heading}, truth {t['heading_deg']:.2f}")
    if at != len(log_lines):
        problems.append(f"the log has {len(log_lines) - at} lines the truth does not account for")
    return problems, counts


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__.strip().splitlines()[-1])
    log_path, truth_path = sys.argv[1], sys.argv[2]
    lon0, lat0 = float(sys.argv[3]), float(sys.argv[4])
    with open(log_path, newline="") as f:
        text = f.read()
    if text and not text.endswith("\r\n"):
        sys.exit(f"{log_path}: sentences must end in CR LF")
    lines = [line for line in text.split("\r\n") if line]
    with open(truth_path) as f:
        truth = [json.loads(line) for line in f if line.strip()]
    problems, counts = check(lines, truth, lon0, lat0)
    if problems:
        sys.exit("\n".join(problems[:20]) + (f"\n... {len(problems)} problems" if len(problems) > 20 else ""))
    print(f"{log_path}: {counts['sentences']} sentences with good checksums; "
          f"{counts['own_ship']} own-ship fixes and {counts['ais']} AIS messages decoded by "
          "pynmea2 and pyais match the truth")


if __name__ == "__main__":
    main()
