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
    """A `$` or `!` sentence of at most 82 characters (with CR LF) whose two upper-case hex
    digits after `*` are the XOR of the bytes between."""
    if line[:1] not in ("$", "!") or len(line) + 2 > 82:
        return False
    body, _, given = line[1:].partition("*")
    value = 0
    for ch in body.encode():
        value ^= ch
    return given == f"{value:02X}"


def utc_fields(unix_s):
    """(hhmmss.ss, ddmmyy) of POSIX seconds, the second rounded down to the hundredth."""
    import datetime
    whole = math.floor(unix_s)
    t = datetime.datetime.fromtimestamp(whole, datetime.timezone.utc)
    hundredths = min(int(math.floor((unix_s - whole + t.second) * 100 + 1e-6)), 5999)
    return f"{t.hour:02d}{t.minute:02d}{hundredths // 100:02d}.{hundredths % 100:02d}", \
        t.strftime("%d%m%y")


def longest_interval_s(ais_class, speed_kn):
    """The longest a position report may wait in this state (ITU-R M.1371-5 Tables 1 and 2;
    class A's when holding course), s."""
    if ais_class == "B":
        return 30.0 if speed_kn > 2.0 else 180.0
    if speed_kn < 0.1:
        return 180.0
    return 10.0 if speed_kn <= 14.0 else 6.0 if speed_kn <= 23.0 else 2.0


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
    last_time = -math.inf
    last_report = {}  # mmsi: (time, longest wait)
    for t in truth:
        if t["time_s"] < last_time:
            problems.append(f"t = {t['time_s']} s after t = {last_time} s: the log goes back in time")
        last_time = t["time_s"]
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
                time, date = utc_fields(t["unix_s"])
                if msg.sentence_type in ("GGA", "RMC") and msg.data[0] != time:
                    problems.append(f"{where}: {msg.sentence_type} time {msg.data[0]}, truth {time}")
                if msg.sentence_type == "RMC" and msg.datestamp.strftime("%d%m%y") != date:
                    problems.append(f"{where}: RMC date {msg.datestamp}, truth {date}")
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
            first = pending[0].decode().split(",")
            if fields[1] != first[1] or fields[3] != first[3] or fields[2] != str(len(pending)):
                problems.append(f"{where}: fragment {line!r} does not follow {first!r}")
            if fields[1] != fields[2] and not fields[6].startswith("0*"):
                problems.append(f"{where}: a fragment before the last has fill bits: {line!r}")
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
            if m.msg_type == 5 or (m.msg_type == 24 and m.partno == 0):
                name = t["source"].upper()[:20]
                if (m.shipname or "").strip() != name.strip():
                    problems.append(f"{where}: name {m.shipname!r}, truth {name!r}")
        report = messages[-1]
        if report.second != math.floor(t["unix_s"]) % 60:
            problems.append(f"{where}: AIS second {report.second}, truth {t['unix_s']}")
        if report.msg_type == 1 and int(report.status) != (1 if speed_kn < 0.1 else 0):
            problems.append(f"{where}: navigational status {report.status} at {speed_kn:.2f} kn")
        previous = last_report.get(t["mmsi"])
        if previous is not None and t["time_s"] - previous[0] > previous[1] + 1e-6:
            problems.append(f"{where}: {t['time_s'] - previous[0]:.2f} s since the last report, "
                            f"more than the {previous[1]:.0f} s its state allows")
        ais_class = "B" if report.msg_type == 18 else "A"
        last_report[t["mmsi"]] = (t["time_s"], longest_interval_s(ais_class, speed_kn))
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
