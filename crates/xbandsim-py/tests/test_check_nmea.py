"""scripts/check_nmea.py on logs made here with pynmea2's and pyais' own encoders: a log that
says what its truth says passes; a position 10 m off, a wrong MMSI and a broken checksum are
each caught. (`scripts/test.sh` runs the checker on `xbandsim nmea`'s log of the crossing
scene.) No xbandsim binary is needed."""

import importlib.util
import math

import pytest

from conftest import ROOT

pytest.importorskip("pyais", reason="pip install -r scripts/requirements-check.txt")
pytest.importorskip("pynmea2", reason="pip install -r scripts/requirements-check.txt")

spec = importlib.util.spec_from_file_location("check_nmea", ROOT / "scripts" / "check_nmea.py")
check_nmea = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_nmea)

LON0, LAT0 = -4.14, 50.33


def truth(source, x, y, vx, vy, heading, mmsi=None, messages=(), sentences=1):
    lon, lat = check_nmea.local_to_lon_lat(x, y, LON0, LAT0)
    return {"time_s": 0.0, "unix_s": 0.0, "source": source, "mmsi": mmsi,
            "messages": list(messages), "position_m": [x, y], "lon_deg": lon, "lat_deg": lat,
            "velocity_mps": [vx, vy], "heading_deg": heading, "sentences": sentences}


def ddmm(value, width):
    v = abs(value)
    d = int(v)
    return f"{d:0{width}d}{(v - d) * 60:07.4f}"


def gga(t, lat_shift_deg=0.0):
    import pynmea2
    lat = t["lat_deg"] + lat_shift_deg
    msg = pynmea2.GGA("GP", "GGA", ("000000.00", ddmm(lat, 2), "N", ddmm(t["lon_deg"], 3), "W",
                                   "1", "08", "1.0", "6.0", "M", "0.0", "M", "", ""))
    return str(msg) + "\r\n"


def ais_report(t, mmsi):
    second = int(t["unix_s"]) % 60
    from pyais.encode import encode_dict
    speed = math.hypot(*t["velocity_mps"]) / (1852 / 3600)
    course = math.degrees(math.atan2(*t["velocity_mps"])) % 360
    fields = {"type": 1, "mmsi": mmsi, "status": 0, "second": second,
              "lon": t["lon_deg"], "lat": t["lat_deg"],
              "speed": round(speed, 1), "course": round(course, 1),
              "heading": round(t["heading_deg"])}
    return [s + "\r\n" for s in encode_dict(fields, radio_channel="A", talker_id="AI")]


def test_a_log_that_matches_its_truth_passes_and_errors_are_caught():
    own = truth("own_ship", 0.0, 0.0, 0.0, 0.0, 0.0)
    ship = truth("ship", 800.0, -600.0, 3.0, 4.0, 36.87, mmsi=235000001, messages=[1])
    good = [gga(own)] + ais_report(ship, 235000001)
    lines = [line.rstrip("\r\n") for line in good]
    problems, counts = check_nmea.check(lines, [own, ship], LON0, LAT0)
    assert problems == [] and counts["ais"] == 1 and counts["own_ship"] == 1, problems
    # The own ship 10 m north of where the truth has it.
    off = [gga(own, lat_shift_deg=10.0 / 111_200.0).rstrip("\r\n")] + lines[1:]
    problems, _ = check_nmea.check(off, [own, ship], LON0, LAT0)
    assert any("GGA" in p for p in problems), problems
    # Another transponder's report.
    other = [lines[0]] + [s.rstrip("\r\n") for s in ais_report(ship, 235000009)]
    problems, _ = check_nmea.check(other, [own, ship], LON0, LAT0)
    assert any("MMSI 235000009" in p for p in problems), problems
    # A broken checksum.
    broken = [lines[0][:-2] + "00"] + lines[1:]
    problems, _ = check_nmea.check(broken, [own, ship], LON0, LAT0)
    assert any("checksum" in p for p in problems), problems


def test_a_ship_under_way_reported_too_seldom_is_caught():
    own = truth("own_ship", 0.0, 0.0, 0.0, 0.0, 0.0)
    first = truth("ship", 800.0, -600.0, 3.0, 4.0, 36.87, mmsi=235000001, messages=[1])
    later = dict(truth("ship", 980.0, -360.0, 3.0, 4.0, 36.87, mmsi=235000001, messages=[1]),
                 time_s=60.0, unix_s=60.0)
    lines = [gga(own)] + ais_report(first, 235000001) + ais_report(later, 235000001)
    lines = [line.rstrip("\r\n") for line in lines]
    problems, _ = check_nmea.check(lines, [own, first, later], LON0, LAT0)
    # 9.7 kn: a class A ship holding course reports every 10 s, not 60.
    assert any("60.00 s since the last report" in p for p in problems), problems
