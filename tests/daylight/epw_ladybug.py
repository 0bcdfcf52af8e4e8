"""A year of weather written and read back by ladybug-core's EPW class, for
tests/daylight_peers.rs: writes <dir>/year.epw (values in deterministic patterns) and prints
ladybug's reading of it as JSON: the location and, per field, (month, day, hour, value) with
ladybug's datetimes (an hourly-summed quantity labelled with the start of its hour, a
point-in-time one with its instant)."""

import json
import os
import sys

from ladybug.epw import EPW
from ladybug.location import Location

path = os.path.join(sys.argv[1], "year.epw")
epw = EPW.from_missing_values()
epw.location = Location("Lyon", "-", "FRA", 45.73, 5.08, 1.0, 240.0)
n = 8760
epw.direct_normal_radiation.values = [(k * 37 % 900) if 6 <= k % 24 <= 18 else 0 for k in range(n)]
epw.diffuse_horizontal_radiation.values = [k * 13 % 300 for k in range(n)]
epw.direct_normal_illuminance.values = [k * 3701 % 90000 for k in range(n)]
epw.diffuse_horizontal_illuminance.values = [k * 1301 % 30000 for k in range(n)]
epw.dew_point_temperature.values = [round(-5 + (k * 7 % 250) / 10, 1) for k in range(n)]
epw.save(path)

back = EPW(path)
loc = back.location
fields = {}
for name in ["direct_normal_radiation", "diffuse_horizontal_radiation",
             "direct_normal_illuminance", "diffuse_horizontal_illuminance",
             "dew_point_temperature"]:
    c = getattr(back, name)
    fields[name] = [[d.month, d.day, d.hour, v] for d, v in zip(c.datetimes, c.values)]
json.dump({"path": path, "latitude": loc.latitude, "longitude": loc.longitude,
           "time_zone": loc.time_zone, "elevation": loc.elevation, "fields": fields}, sys.stdout)
